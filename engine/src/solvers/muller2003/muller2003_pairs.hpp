// solvers/muller2003/muller2003_pairs.hpp (internal; included by muller2003.cpp only) — the
// pair loops' machinery: the fixed lanes of every pair sum (kSumLanes, laneTotal), the pair
// term in scalar code (pairTermScalar: the reference) and the SSE2/AVX2 helpers and loops that
// reproduce it lane for lane (the same operations in the same order: the same bits on any CPU;
// the pinned-hash tests compare the scalar pair loops with these).
#pragma once

#include <algorithm>
#include <cmath>

#include "bodies/body_samples.hpp"
#include "core/constants.hpp"
#include "effects/effect.hpp"
#include "solvers/impact_viscosity.hpp"
#include "solvers/solver.hpp"

#include "core/simd.hpp"
#ifdef SPH2D_SIMD_SSE2
#define SPH2D_SSE2_PAIRS 1
#endif
#if defined(SPH2D_SSE2_PAIRS) && defined(SPH2D_SIMD_X86_DISPATCH)
#define SPH2D_AVX2_PAIRS 1
#endif

namespace sph2d {
namespace {

#ifdef SPH2D_SSE2_PAIRS
/// Positions (or velocities) of four particles as their x and y lanes: one 8-byte load each.
inline void gather4(const Vec2* X, std::uint32_t j0, std::uint32_t j1, std::uint32_t j2, std::uint32_t j3, __m128& xs,
                    __m128& ys) {
  static_assert(sizeof(Vec2) == 2 * sizeof(float), "a Vec2 is two floats");
  const __m128 a = _mm_loadh_pi(_mm_castpd_ps(_mm_load_sd(reinterpret_cast<const double*>(X + j0))),
                                reinterpret_cast<const __m64*>(X + j1));
  const __m128 b = _mm_loadh_pi(_mm_castpd_ps(_mm_load_sd(reinterpret_cast<const double*>(X + j2))),
                                reinterpret_cast<const __m64*>(X + j3));
  xs = _mm_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0));
  ys = _mm_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1));
}

/// All lanes, or the first n of a group of four (n < 4): the live lanes of a last, partial group.
alignas(16) constexpr std::uint32_t kLive4[5][4] = {
    {0, 0, 0, 0}, {~0u, 0, 0, 0}, {~0u, ~0u, 0, 0}, {~0u, ~0u, ~0u, 0}, {~0u, ~0u, ~0u, ~0u}};
#endif

#ifdef SPH2D_AVX2_PAIRS
/// True when this CPU runs the AVX2 pair loops (checked once) and the baseline is not forced (stages.hpp).
bool useAvx2() {
  static const bool have = __builtin_cpu_supports("avx2");
  return have && !baselineSimdOnly();
}

/// Positions (or velocities) of the eight particles j[0..7] as their x and y lanes.
__attribute__((target("avx2"))) inline void gather8(const Vec2* base, const std::uint32_t* j, __m256& xs, __m256& ys) {
  __m128 p0, p1, p2, p3;  // x and y of j0..j3, then of j4..j7
  gather4(base, j[0], j[1], j[2], j[3], p0, p1);
  gather4(base, j[4], j[5], j[6], j[7], p2, p3);
  xs = _mm256_insertf128_ps(_mm256_castps128_ps256(p0), p2, 1);
  ys = _mm256_insertf128_ps(_mm256_castps128_ps256(p1), p3, 1);
}
#endif

/// The lanes of the pair sums: the terms of pair k of a list go to partial sum k mod
/// kSumLanes, and the lanes are added in one fixed tree (laneTotal). Every path (scalar,
/// SSE2, AVX2) adds the same terms to the same lanes in the same order, so the bits are
/// the same on any CPU and for any thread count; eight chains instead of one let the
/// vector loops run at their throughput rather than at the latency of one add.
constexpr std::uint32_t kSumLanes = 8;

/// Particles whose pair sums one call of pairSums8 computes: its constants are set once a run,
/// and the caller's per-particle code follows on the run's results.
constexpr std::size_t kRun = 64;

/// Σ of eight partial sums in the fixed tree ((s0+s4) + (s2+s6)) + ((s1+s5) + (s3+s7)).
inline Real laneTotal(const Real s[kSumLanes]) {
  const Real a0 = s[0] + s[4], a1 = s[1] + s[5], a2 = s[2] + s[6], a3 = s[3] + s[7];
  return (a0 + a2) + (a1 + a3);
}

#ifdef SPH2D_SSE2_PAIRS
/// laneTotal of one sum whose lanes 0–3 are lo and 4–7 hi.
inline Real laneTotal1(__m128 lo, __m128 hi) {
  const __m128 a = _mm_add_ps(lo, hi);                  // a_q = s_q + s_{q+4}
  const __m128 b = _mm_add_ps(a, _mm_movehl_ps(a, a));  // a0 + a2, a1 + a3
  return _mm_cvtss_f32(_mm_add_ss(b, _mm_shuffle_ps(b, b, _MM_SHUFFLE(1, 1, 1, 1))));
}
#endif

#ifdef SPH2D_AVX2_PAIRS
/// Σ_j W(|x_i − x_j|) over slot i's list, eight pairs at a time (AVX2, chosen at run time):
/// the scalar valueR2 lane for lane, pair k in lane k mod 8 (kSumLanes); no periodic axis.
__attribute__((target("avx2"))) Real densitySum8(const Vec2* X, const Vec2& xi, const std::uint32_t* nb,
                                                 std::uint32_t cnt, const Poly6<Real>& W) {
  const __m256 xi8 = _mm256_set1_ps(xi.x()), yi8 = _mm256_set1_ps(xi.y());
  const __m256 R28 = _mm256_set1_ps(W.R2), c8 = _mm256_set1_ps(W.c);
  const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  __m256 s = _mm256_setzero_ps();
  for (std::uint32_t k = 0; k < cnt; k += 8) {
    const std::uint32_t n = std::min<std::uint32_t>(8, cnt - k);
    std::uint32_t j[8];
    for (std::uint32_t l = 0; l < 8; ++l)
      j[l] = nb[std::min(k + l, cnt - 1)];  // missing lanes repeat the last (zeroed)
    __m256 xj, yj;
    gather8(X, j, xj, yj);
    const __m256 dx = _mm256_sub_ps(xi8, xj), dy = _mm256_sub_ps(yi8, yj);
    const __m256 r2 = _mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy));
    const __m256 a = _mm256_sub_ps(R28, r2);
    __m256 w = _mm256_mul_ps(_mm256_mul_ps(_mm256_mul_ps(c8, a), a), a);
    w = _mm256_and_ps(_mm256_cmp_ps(r2, R28, _CMP_NGE_UQ), w);  // valueR2: 0 for r² ≥ R²
    // Missing lanes add +0, which leaves a sum unchanged: a sum that starts at +0 is never −0.
    w = _mm256_and_ps(w, _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_set1_epi32(int(n)), iota)));
    s = _mm256_add_ps(s, w);
  }
  return laneTotal1(_mm256_castps256_ps128(s), _mm256_extractf128_ps(s, 1));
}
#endif

// The pressure force's pair loop, with the viscosity folded in (stepper.cpp,
// Solver::foldViscosity): the viscosity effect's own pass recomputed r and 1/r of
// every pair; here one square root and one division serve both. The per-pair terms
// are computed four (SSE2) or eight (AVX2) pairs at a time: element-wise IEEE
// operations only, the same operations in the same order as the scalar expressions.
// Each of the four sums (pressure x, y; viscosity x, y) is kept in eight partial sums,
// pair k of the list in partial sum k mod 8, added in a fixed tree at the end
// (kSumLanes, laneTotal): the scalar loop does the same, so every path gives the same bits.

/// The constants of one pair term: the spiky gradient and, with the viscosity, its Laplacian.
struct PairConstants {
  Real R, spikyK, halfMass, coincident2;
  // The impact viscosity (impact_viscosity.hpp): on, w0, 1/w0, h = R/2, 0.01h², 2 m α c.
  bool impact;
  Real impW0, impInvW0, impH, impEta2, impK;
  // ViscosityKernel::laplacianR2's constants, computed as it computes them.
  Real vR2, vR3, pairCap, lapK, rMin, rMin2, invRMin;  // pairCap: ViscosityTerm::pairCap
};

/// The four contributions of pair (i, j) in scalar code: out = {fpx, fpy, fvx, fvy}
/// increments (the reference the SIMD lanes reproduce; also coincident pairs and the tail).
/// With the impact viscosity (k.impact), a pair closing faster than w0 adds −m Π ∇W to the
/// pressure part, Π = α(w) c μ̄ 2/(ρ_i + ρ_j), μ̄ = h (−v_ij·x_ij)/(r² + 0.01h²), written into
/// the force density as ρ_i m Π ∇W (impK = 2 m α c, so ρ_i impK s μ̄/(ρ_i + ρ_j)).
template <bool Visc>
inline void pairTermScalar(const StepContext& c, const PairConstants& k, std::size_t i, std::uint32_t j, Real pi,
                           Real vix, Real viy, Real out[4]) {
  const Real* IR = c.P.invRho.data();
  const Real* POR = c.P.pOverRho.data();
  Real dx, dy, r2;
  pairDelta(c, i, j, dx, dy, r2);  // coincident pairs: a fixed, antisymmetric direction
  // One square root and one division per pair.
  const Real sq = std::sqrt(r2);
  const Real invr = Real(1) / sq;
  const Real r = r2 * invr;
  const Real a = k.R - r;
  const Real irj = IR[j];
  // Spiky gradient dW/dr · d/r, dW/dr = −3c(R − r)², times m (p_i + p_j)/(2 ρ_j).
  const Real g = k.spikyK * a * a * invr;
  Real wp = g * (k.halfMass * (pi * irj + POR[j]));
  if (k.impact) {
    const Vec2* V = c.P.v.data();
    const Real nv = -((vix - V[j].x()) * dx + (viy - V[j].y()) * dy);  // −v_ij·x_ij
    const Real w = nv * invr;                                          // approach speed
    if (w > k.impW0) {
      const Real rhoi = Real(1) / IR[i];
      const Real s = std::min((w - k.impW0) * k.impInvW0, Real(1));
      const Real mu = k.impH * nv / (r2 + k.impEta2);
      wp = wp + g * (k.impK * rhoi * s * mu / (rhoi + Real(1) / irj));
    }
  }
  out[0] = dx * wp;
  out[1] = dy * wp;
  if (Visc) {
    // ViscosityKernel::laplacianR2 of the pair's own r² (the tie-break only gives a
    // coincident pair a direction; its r² is below rMin², where q = rMin).
    const Vec2* X = c.P.x.data();
    Real ex = X[i].x() - X[j].x(), ey = X[i].y() - X[j].y();
    c.periodic.nearest(ex, ey);
    const Real r2v = ex * ex + ey * ey;
    Real lap = 0;
    if (!(r2v >= k.vR2)) {
      const bool big = r2v > k.rMin2;  // then r2v == r2 (not coincident): sq, invr are its own
      const Real q = big ? sq : k.rMin;
      const Real iq = big ? invr : k.invRMin;
      lap = k.lapK * (k.R - q) * (k.vR3 + k.vR2 * q + k.R * q * q + Real(9) * q * q * q) * iq * iq * iq;
    }
    const Real w = std::min(lap * irj, k.pairCap / IR[i]);  // the stability cap (ViscosityTerm::pairCap)
    const Vec2* V = c.P.v.data();
    out[2] = (V[j].x() - vix) * w;
    out[3] = (V[j].y() - viy) * w;
  } else {
    out[2] = out[3] = 0;
  }
}

/// The pair sums {fpx, fpy, fvx, fvy} of slot i in scalar code, lane by lane (the
/// reference the SIMD loops reproduce; also the periodic path).
template <bool Visc>
void pairSumsScalar(const StepContext& c, const PairConstants& k, std::size_t i, const std::uint32_t* nb,
                    std::uint32_t cnt, Real pi, Real vix, Real viy, Real sums[4]) {
  Real lanes[4][kSumLanes] = {};
  for (std::uint32_t q = 0; q < cnt; ++q) {
    Real t[4];
    pairTermScalar<Visc>(c, k, i, nb[q], pi, vix, viy, t);
    for (int l = 0; l < 4; ++l) lanes[l][q % kSumLanes] += t[l];
  }
  for (int l = 0; l < 4; ++l) sums[l] = laneTotal(lanes[l]);
}

#ifdef SPH2D_SSE2_PAIRS
/// laneTotal of four sums at once: lo holds lanes 0–3 and hi lanes 4–7 of {fpx, fpy, fvx, fvy}.
inline void laneTotals4(__m128 lo[4], const __m128 hi[4], Real* sums) {
  for (int l = 0; l < 4; ++l) lo[l] = _mm_add_ps(lo[l], hi[l]);  // a_q = s_q + s_{q+4}
  _MM_TRANSPOSE4_PS(lo[0], lo[1], lo[2], lo[3]);                 // row q = a_q of the four sums
  _mm_store_ps(sums, _mm_add_ps(_mm_add_ps(lo[0], lo[2]), _mm_add_ps(lo[1], lo[3])));
}
#endif

#ifdef SPH2D_AVX2_PAIRS
/// The pair sums {fpx, fpy, fvx, fvy} of slots i0..i1 − 1, eight pairs at a time (AVX2, chosen at
/// run time): the scalar terms' operations lane for lane, the gathers by index, pair k of a list
/// in lane k mod 8 (kSumLanes); no periodic axis. The constants are set once for the run.
template <bool Visc>
__attribute__((target("avx2"))) void pairSums8(const StepContext& c, const PairConstants& k, std::size_t i0,
                                               std::size_t i1, Real (*out)[4]) {
  const float* IR = c.P.invRho.data();
  const float* POR = c.P.pOverRho.data();
  const __m256 R8 = _mm256_set1_ps(k.R), spikyK = _mm256_set1_ps(k.spikyK), halfMass = _mm256_set1_ps(k.halfMass);
  const __m256 one = _mm256_set1_ps(Real(1)), thr = _mm256_set1_ps(k.coincident2);
  const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  for (std::size_t i = i0; i < i1; ++i) {
    const std::uint32_t* nb = c.nbr.of(i);
    const std::uint32_t cnt = c.nbr.count[i];
    const Vec2 xi = c.P.x[i];
    const Real pi = c.P.p[i], vix = c.P.v[i].x(), viy = c.P.v[i].y();
    const __m256 xi8 = _mm256_set1_ps(xi.x()), yi8 = _mm256_set1_ps(xi.y()), pi8 = _mm256_set1_ps(pi);
    const __m256 vix8 = _mm256_set1_ps(vix), viy8 = _mm256_set1_ps(viy);
    // Gathers by plain loads (the hardware gathers were slower on the EPYC measured).
    __m256 s0 = _mm256_setzero_ps(), s1 = s0, s2 = s0, s3 = s0;  // lanes of fpx, fpy, fvx, fvy
    for (std::uint32_t kk = 0; kk < cnt; kk += 8) {
      const std::uint32_t n = std::min<std::uint32_t>(8, cnt - kk);
      std::uint32_t j[8];
      for (std::uint32_t l = 0; l < 8; ++l)
        j[l] = nb[std::min(kk + l, cnt - 1)];  // missing lanes repeat the last (zeroed)
      __m256 xj, yj;
      gather8(c.P.x.data(), j, xj, yj);
      const __m256 dx = _mm256_sub_ps(xi8, xj), dy = _mm256_sub_ps(yi8, yj);
      const __m256 r2 = _mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy));
      if (__builtin_expect(_mm256_movemask_ps(_mm256_cmp_ps(r2, thr, _CMP_LT_OQ)) & ((1 << n) - 1), 0)) {
        alignas(32) Real t[4][8] = {};  // a coincident pair (rare): the scalar terms, in their lanes
        for (std::uint32_t q = 0; q < n; ++q) {
          Real tq[4];
          pairTermScalar<Visc>(c, k, i, nb[kk + q], pi, vix, viy, tq);
          for (int l = 0; l < 4; ++l) t[l][q] = tq[l];
        }
        s0 = _mm256_add_ps(s0, _mm256_load_ps(t[0]));
        s1 = _mm256_add_ps(s1, _mm256_load_ps(t[1]));
        s2 = _mm256_add_ps(s2, _mm256_load_ps(t[2]));
        s3 = _mm256_add_ps(s3, _mm256_load_ps(t[3]));
        continue;
      }
      const __m256 irj = _mm256_setr_ps(IR[j[0]], IR[j[1]], IR[j[2]], IR[j[3]], IR[j[4]], IR[j[5]], IR[j[6]], IR[j[7]]);
      const __m256 porj =
          _mm256_setr_ps(POR[j[0]], POR[j[1]], POR[j[2]], POR[j[3]], POR[j[4]], POR[j[5]], POR[j[6]], POR[j[7]]);
      __m256 sq, invr;
      if (n <= 4) {
        // A short last group: the square roots and divisions of its four lanes only (the
        // divider bounds this loop; a lane's result is the same at either width, the upper
        // lanes are 0 and masked off below).
        const __m128 sq4 = _mm_sqrt_ps(_mm256_castps256_ps128(r2));
        sq = _mm256_zextps128_ps256(sq4);
        invr = _mm256_zextps128_ps256(_mm_div_ps(_mm_set1_ps(Real(1)), sq4));
      } else {
        sq = _mm256_sqrt_ps(r2);
        invr = _mm256_div_ps(one, sq);
      }
      const __m256 a = _mm256_sub_ps(R8, _mm256_mul_ps(r2, invr));
      const __m256 gs = _mm256_mul_ps(_mm256_mul_ps(_mm256_mul_ps(spikyK, a), a), invr);
      __m256 wp = _mm256_mul_ps(gs, _mm256_mul_ps(halfMass, _mm256_add_ps(_mm256_mul_ps(pi8, irj), porj)));
      __m256 vxj = _mm256_setzero_ps(), vyj = _mm256_setzero_ps();
      if (Visc || k.impact) gather8(c.P.v.data(), j, vxj, vyj);
      if (k.impact) {  // pairTermScalar's impact term, lane-wise
        const __m256 nv = _mm256_sub_ps(
            _mm256_setzero_ps(),
            _mm256_add_ps(_mm256_mul_ps(_mm256_sub_ps(vix8, vxj), dx), _mm256_mul_ps(_mm256_sub_ps(viy8, vyj), dy)));
        const __m256 w = _mm256_mul_ps(nv, invr);
        const __m256 fast = _mm256_cmp_ps(w, _mm256_set1_ps(k.impW0), _CMP_GT_OQ);
        if (_mm256_movemask_ps(fast) & ((1 << n) - 1)) {
          const __m256 rhoi = _mm256_set1_ps(Real(1) / IR[i]);
          const __m256 sw =
              _mm256_min_ps(_mm256_mul_ps(_mm256_sub_ps(w, _mm256_set1_ps(k.impW0)), _mm256_set1_ps(k.impInvW0)), one);
          const __m256 mu =
              _mm256_div_ps(_mm256_mul_ps(_mm256_set1_ps(k.impH), nv), _mm256_add_ps(r2, _mm256_set1_ps(k.impEta2)));
          const __m256 f =
              _mm256_div_ps(_mm256_mul_ps(_mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(k.impK), rhoi), sw), mu),
                            _mm256_add_ps(rhoi, _mm256_div_ps(one, irj)));
          wp = _mm256_blendv_ps(wp, _mm256_add_ps(wp, _mm256_mul_ps(gs, f)), fast);
        }
      }
      __m256 t0 = _mm256_mul_ps(dx, wp), t1 = _mm256_mul_ps(dy, wp), t2 = _mm256_setzero_ps(), t3 = _mm256_setzero_ps();
      if (Visc) {
        const __m256 vR2 = _mm256_set1_ps(k.vR2);
        const __m256 big = _mm256_cmp_ps(r2, _mm256_set1_ps(k.rMin2), _CMP_GT_OQ);
        const __m256 q = _mm256_blendv_ps(_mm256_set1_ps(k.rMin), sq, big);
        const __m256 iq = _mm256_blendv_ps(_mm256_set1_ps(k.invRMin), invr, big);
        const __m256 poly =
            _mm256_add_ps(_mm256_add_ps(_mm256_add_ps(_mm256_set1_ps(k.vR3), _mm256_mul_ps(vR2, q)),
                                        _mm256_mul_ps(_mm256_mul_ps(R8, q), q)),
                          _mm256_mul_ps(_mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(Real(9)), q), q), q));
        __m256 lap = _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(k.lapK), _mm256_sub_ps(R8, q)), poly);
        lap = _mm256_mul_ps(_mm256_mul_ps(_mm256_mul_ps(lap, iq), iq), iq);
        lap = _mm256_and_ps(_mm256_cmp_ps(r2, vR2, _CMP_NGE_UQ), lap);  // r² ≥ R²: 0
        // The stability cap (ViscosityTerm::pairCap · ρ_i): std::min's value for finite lanes.
        const __m256 w = _mm256_min_ps(_mm256_mul_ps(lap, irj), _mm256_set1_ps(k.pairCap / IR[i]));
        t2 = _mm256_mul_ps(_mm256_sub_ps(vxj, vix8), w);
        t3 = _mm256_mul_ps(_mm256_sub_ps(vyj, viy8), w);
      }
      if (n < 8) {
        // Missing lanes add +0, which leaves a sum unchanged: a sum that starts at +0 is never −0.
        const __m256 live = _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_set1_epi32(int(n)), iota));
        t0 = _mm256_and_ps(t0, live);
        t1 = _mm256_and_ps(t1, live);
        t2 = _mm256_and_ps(t2, live);
        t3 = _mm256_and_ps(t3, live);
      }
      s0 = _mm256_add_ps(s0, t0);
      s1 = _mm256_add_ps(s1, t1);
      s2 = _mm256_add_ps(s2, t2);
      s3 = _mm256_add_ps(s3, t3);
    }
    __m128 lo[4] = {_mm256_castps256_ps128(s0), _mm256_castps256_ps128(s1), _mm256_castps256_ps128(s2),
                    _mm256_castps256_ps128(s3)};
    const __m128 hi[4] = {_mm256_extractf128_ps(s0, 1), _mm256_extractf128_ps(s1, 1), _mm256_extractf128_ps(s2, 1),
                          _mm256_extractf128_ps(s3, 1)};
    laneTotals4(lo, hi, out[i - i0]);
  }
}
#endif

}  // namespace
}  // namespace sph2d
