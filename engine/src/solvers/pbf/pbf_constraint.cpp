// pbf_constraint.cpp — the two passes of one Jacobi iteration of Position Based
// Fluids (Macklin & Müller 2013, "Position Based Fluids", ACM TOG 32(4)), the
// solver's hot loop: constraint() sums ρ_i with the spiky kernel (Müller et al.
// 2003) over fluid and wall samples, C_i = ρ_i/ρ0 − 1 and the multiplier step
// Δλ_i (four neighbour pairs at a time, Lane4); correct() gathers
// Δx_i = (m/ρ0) Σ_j (Δλ_i + Δλ_j + s_corr) ∇W_ij + Δλ_i Σ_b Ψ_b ∇W_ib and
// combines it with the previous iterate by the Chebyshev weight (Wang 2015).
// The loop that calls them: pbf.cpp; the method: pbf.hpp.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <type_traits>

#include "core/simd.hpp"

#include "solvers/pbf/pbf.hpp"

namespace sph2d {
namespace {

/// Four floats operated on together: SSE2 when the compiler targets it, else four
/// scalar operations. Every operation is IEEE single precision, correctly rounded
/// per lane (add, mul, div, sqrt, max), so both paths give the same bits.
struct Lane4 {
#ifdef SPH2D_SIMD_SSE2
  __m128 v;
  static Lane4 load(const float* p) { return {_mm_loadu_ps(p)}; }
  static Lane4 all(float x) { return {_mm_set1_ps(x)}; }
  void store(float* p) const { _mm_storeu_ps(p, v); }
  friend Lane4 operator+(Lane4 a, Lane4 b) { return {_mm_add_ps(a.v, b.v)}; }
  friend Lane4 operator-(Lane4 a, Lane4 b) { return {_mm_sub_ps(a.v, b.v)}; }
  friend Lane4 operator*(Lane4 a, Lane4 b) { return {_mm_mul_ps(a.v, b.v)}; }
  friend Lane4 operator/(Lane4 a, Lane4 b) { return {_mm_div_ps(a.v, b.v)}; }
  static Lane4 sqrt(Lane4 a) { return {_mm_sqrt_ps(a.v)}; }
  static Lane4 max(Lane4 a, Lane4 b) { return {_mm_max_ps(a.v, b.v)}; }
  /// Lanes below `valid` from a, the rest from b.
  static Lane4 firstLanes(unsigned valid, Lane4 a, Lane4 b) {
    const __m128 m = _mm_castsi128_ps(_mm_cmplt_epi32(_mm_set_epi32(3, 2, 1, 0), _mm_set1_epi32(int(valid))));
    return {_mm_or_ps(_mm_and_ps(m, a.v), _mm_andnot_ps(m, b.v))};
  }
  /// Bit l set where lane l of a < b.
  static int less(Lane4 a, Lane4 b) { return _mm_movemask_ps(_mm_cmplt_ps(a.v, b.v)); }
  /// p[0..7] = x0, y0, x1, y1, x2, y2, x3, y3.
  static void storeInterleaved(float* p, Lane4 x, Lane4 y) {
    _mm_storeu_ps(p, _mm_unpacklo_ps(x.v, y.v));
    _mm_storeu_ps(p + 4, _mm_unpackhi_ps(x.v, y.v));
  }
  /// p[j[0..3]].
  static Lane4 gather(const float* p, const std::uint32_t* j) {
    return {_mm_set_ps(p[j[3]], p[j[2]], p[j[1]], p[j[0]])};
  }
  /// The x and y of X[j[0..3]] (pairs of floats), one 64-bit load each.
  static void gatherXY(const float* xy, const std::uint32_t* j, Lane4& xs, Lane4& ys) {
    const __m128 a =
        _mm_loadh_pi(_mm_castpd_ps(_mm_load_sd(reinterpret_cast<const double*>(xy + 2 * std::size_t(j[0])))),
                     reinterpret_cast<const __m64*>(xy + 2 * std::size_t(j[1])));
    const __m128 b =
        _mm_loadh_pi(_mm_castpd_ps(_mm_load_sd(reinterpret_cast<const double*>(xy + 2 * std::size_t(j[2])))),
                     reinterpret_cast<const __m64*>(xy + 2 * std::size_t(j[3])));
    xs.v = _mm_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0));
    ys.v = _mm_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1));
  }
#else
  float v[4];
  static Lane4 load(const float* p) { return {{p[0], p[1], p[2], p[3]}}; }
  static Lane4 all(float x) { return {{x, x, x, x}}; }
  void store(float* p) const { std::memcpy(p, v, sizeof v); }
  template <class F>
  static Lane4 map(Lane4 a, Lane4 b, F f) {
    return {{f(a.v[0], b.v[0]), f(a.v[1], b.v[1]), f(a.v[2], b.v[2]), f(a.v[3], b.v[3])}};
  }
  friend Lane4 operator+(Lane4 a, Lane4 b) {
    return map(a, b, [](float x, float y) { return x + y; });
  }
  friend Lane4 operator-(Lane4 a, Lane4 b) {
    return map(a, b, [](float x, float y) { return x - y; });
  }
  friend Lane4 operator*(Lane4 a, Lane4 b) {
    return map(a, b, [](float x, float y) { return x * y; });
  }
  friend Lane4 operator/(Lane4 a, Lane4 b) {
    return map(a, b, [](float x, float y) { return x / y; });
  }
  static Lane4 sqrt(Lane4 a) { return {{std::sqrt(a.v[0]), std::sqrt(a.v[1]), std::sqrt(a.v[2]), std::sqrt(a.v[3])}}; }
  // _mm_max_ps(a, b) returns b when either is NaN: so does this.
  static Lane4 max(Lane4 a, Lane4 b) {
    return map(a, b, [](float x, float y) { return x > y ? x : y; });
  }
  static Lane4 firstLanes(unsigned valid, Lane4 a, Lane4 b) {
    return {{valid > 0 ? a.v[0] : b.v[0], valid > 1 ? a.v[1] : b.v[1], valid > 2 ? a.v[2] : b.v[2],
             valid > 3 ? a.v[3] : b.v[3]}};
  }
  static int less(Lane4 a, Lane4 b) {
    return (a.v[0] < b.v[0]) | ((a.v[1] < b.v[1]) << 1) | ((a.v[2] < b.v[2]) << 2) | ((a.v[3] < b.v[3]) << 3);
  }
  static void storeInterleaved(float* p, Lane4 x, Lane4 y) {
    for (int l = 0; l < 4; ++l) {
      p[2 * l] = x.v[l];
      p[2 * l + 1] = y.v[l];
    }
  }
  static Lane4 gather(const float* p, const std::uint32_t* j) { return {{p[j[0]], p[j[1]], p[j[2]], p[j[3]]}}; }
  static void gatherXY(const float* xy, const std::uint32_t* j, Lane4& xs, Lane4& ys) {
    for (int l = 0; l < 4; ++l) {
      xs.v[l] = xy[2 * std::size_t(j[l])];
      ys.v[l] = xy[2 * std::size_t(j[l]) + 1];
    }
  }
#endif
  /// ((l0 + l1) + l2) + l3, the same order on both paths.
  float sum() const {
    float t[4];
    store(t);
    return ((t[0] + t[1]) + t[2]) + t[3];
  }
};
static_assert(std::is_same<Real, float>::value, "Lane4 is single precision");

/// std::min(a, b) = (b < a ? b : a) and std::max(a, b) = (a < b ? b : a) of two floats as
/// one minss(b, a) or maxss(b, a), which return a when either is NaN: the same values,
/// with no branch on the data (the compiler branched, and compression is no pattern).
inline float minOf(float a, float b) {
#ifdef SPH2D_SIMD_SSE2
  return _mm_cvtss_f32(_mm_min_ss(_mm_set_ss(b), _mm_set_ss(a)));
#else
  return std::min(a, b);
#endif
}
inline float maxOf(float a, float b) {
#ifdef SPH2D_SIMD_SSE2
  return _mm_cvtss_f32(_mm_max_ss(_mm_set_ss(b), _mm_set_ss(a)));
#else
  return std::max(a, b);
#endif
}

}  // namespace

std::size_t Pbf::constraint(StepContext& c, const std::vector<Real>& lambda, const std::vector<std::uint32_t>* list) {
  ParticleStore& P = c.P;
  const BoundarySet& B = c.boundary;
  const Spiky<Real> S(c.R);
  const Real invR = Real(1) / c.R, wK = S.c * c.R * c.R * c.R, gK = Real(-3) * S.c * c.R * c.R;
  const Real V = c.mass / c.rho0, Vg = V * gK;
  const Real tiny2 = Real(1e-12) * c.R * c.R;
  const Real far2 = Real(4) * c.R * c.R;
  const std::size_t blocks = c.nbr.perBlock.size();
  gradCache_.resize(blocks);
  gCache_.resize(blocks);
  for (std::size_t k = 0; k < blocks; ++k) {
    const std::size_t need = c.nbr.perBlock[k].size() + 4;  // + padding of the last particle
    if (gradCache_[k].size() < need) gradCache_[k].resize(need);
    if (gCache_[k].size() < need) gCache_[k].resize(need);
  }
  const std::size_t count = list ? list->size() : P.size();
  const std::size_t step = list ? kLocalBlock : kBlock;
  const std::size_t parts = (count + step - 1) / step;
  blockErr_.resize(parts);
  blockMax_.resize(parts);
  const Vec2* X = P.x.data();
  const bool periodic = c.periodic.any();
  const Real* invRatio = invRatio_.empty() ? nullptr : invRatio_.data();  // 1/r_i: a density contrast
  // The first solve of a pushout substep: C_i − K_i (pbf.hpp, pushout_speed).
  const Real* start = againstStart_ ? P.find("pbf.carried")->data() : nullptr;
  blockPlainErr_.resize(parts);
  blockPlainMax_.resize(parts);
  // The block's loop, compiled once with a density contrast and once without (no test of it
  // in the pair loop of one material).
  auto block = [&](auto contrastTag, std::size_t b, std::size_t e) {
    constexpr bool kContrast = decltype(contrastTag)::value;
    std::size_t bad = kNone;
    double err = 0, plainErr = 0;
    Real worst = 0, plainWorst = 0;
    const Lane4 zero = Lane4::all(0), one = Lane4::all(1), vInvR = Lane4::all(invR), vVg = Lane4::all(Vg);
    const Lane4 vFar2 = Lane4::all(far2), vTiny2 = Lane4::all(tiny2);
    const float* xy = reinterpret_cast<const float*>(X);
    alignas(16) Real dxs[4], dys[4], r2s[4], gx4[4], gy4[4], w4[4];
    for (std::size_t idx = b; idx < e; ++idx) {
      const std::size_t i = list ? (*list)[idx] : idx;
      const std::uint32_t cnt = c.nbr.count[i];
      const std::uint32_t* nb = c.nbr.of(i);
      Grad* gc = gradCache_[i / kBlock].data() + c.nbr.start[i];
      Real* wc = gCache_[i / kBlock].data() + c.nbr.start[i];
      const Real xix = X[i].x(), xiy = X[i].y();
      // a = 1 − r/R; W = wK a³; G_ij = V gK (a²/r) d; four pairs at a time, the
      // last group padded with pairs outside the support (r² = 4R², d = 0).
      Lane4 sw = zero, sx = zero, sy = zero, s2 = zero;
      const Lane4 xi4 = Lane4::all(xix), yi4 = Lane4::all(xiy);
      for (std::uint32_t k = 0; k < cnt; k += 4) {
        Lane4 dxv, dyv, q2;
        const std::uint32_t valid = std::min<std::uint32_t>(4, cnt - k);
        // Four neighbours at once; lanes past the list read particle i and become
        // pairs outside the support (r² = 4R², d = 0).
        const std::uint32_t js[4] = {nb[k], valid > 1 ? nb[k + 1] : std::uint32_t(i),
                                     valid > 2 ? nb[k + 2] : std::uint32_t(i),
                                     valid > 3 ? nb[k + 3] : std::uint32_t(i)};
        if (!periodic) {
          Lane4 xs, ys;
          Lane4::gatherXY(xy, js, xs, ys);
          dxv = Lane4::firstLanes(valid, xi4 - xs, zero);
          dyv = Lane4::firstLanes(valid, yi4 - ys, zero);
          q2 = Lane4::firstLanes(valid, dxv * dxv + dyv * dyv, vFar2);
          if (Lane4::less(q2, vTiny2)) {  // a coincident pair (rare): the scalar path below
            dxv.store(dxs);
            dyv.store(dys);
            q2.store(r2s);
            for (std::uint32_t l = 0; l < valid; ++l)
              if (r2s[l] < tiny2) {
                const Vec2 tb = tieBreakDirection(P.id[i], P.id[js[l]]) * std::sqrt(tiny2);
                dxs[l] = tb.x();
                dys[l] = tb.y();
                r2s[l] = dxs[l] * dxs[l] + dys[l] * dys[l];
              }
            dxv = Lane4::load(dxs);
            dyv = Lane4::load(dys);
            q2 = Lane4::load(r2s);
          }
        } else {
          for (std::uint32_t l = 0; l < 4; ++l) {
            if (k + l < cnt) {
              const std::uint32_t jj = nb[k + l];
              Real dx = xix - X[jj].x(), dy = xiy - X[jj].y();
              if (periodic) c.periodic.nearest(dx, dy);
              Real r2 = dx * dx + dy * dy;
              if (r2 < tiny2) {  // coincident: a fixed, antisymmetric direction
                const Vec2 tb = tieBreakDirection(P.id[i], P.id[jj]) * std::sqrt(tiny2);
                dx = tb.x();
                dy = tb.y();
                r2 = dx * dx + dy * dy;
              }
              dxs[l] = dx;
              dys[l] = dy;
              r2s[l] = r2;
            } else {
              dxs[l] = dys[l] = 0;
              r2s[l] = far2;
            }
          }
          dxv = Lane4::load(dxs);
          dyv = Lane4::load(dys);
          q2 = Lane4::load(r2s);
        }
        const Lane4 r = Lane4::sqrt(q2);
        const Lane4 a = Lane4::max(one - r * vInvR, zero);
        const Lane4 g = a * a / r;
        const Lane4 gxv = vVg * g * dxv, gyv = vVg * g * dyv;
        const Lane4 a3 = a * a * a;
        if (!list) {
          // A full pass runs a block's particles in slot order: lanes past i's list
          // land on the next particle's entries (or the block's padding), which that
          // particle writes afterwards.
          Lane4::storeInterleaved(reinterpret_cast<float*>(gc + k), gxv, gyv);
          a3.store(wc + k);
        } else {  // only i's own entries (a local pass runs particles in any order)
          gxv.store(gx4);
          gyv.store(gy4);
          a3.store(w4);
          for (std::uint32_t l = 0; l < valid; ++l) {
            gc[k + l] = Grad{gx4[l], gy4[l]};
            wc[k + l] = w4[l];
          }
        }
        sw = sw + a3;
        sx = sx + gxv;
        sy = sy + gyv;
        if constexpr (kContrast)  // Σ_j |∇_j C_i|²/r_j
          s2 = s2 + (gxv * gxv + gyv * gyv) * Lane4::gather(invRatio, js);
        else
          s2 = s2 + gxv * gxv + gyv * gyv;
      }
      const Real w = Real(1) + sw.sum(), g2 = s2.sum();  // self: W(0) = wK
      Real rho = c.mass * wK * w;
      Real gix = sx.sum(), giy = sy.sum();
      Vec2 wall = Vec2::Zero();
      const std::uint32_t bc = c.nbr.boundaryCount[i];
      if (bc) {
        const std::uint32_t* bl = c.nbr.boundaryOf(i);
        const Vec2 xi = P.x[i];
        Real bw = 0, bx = 0, by = 0;
        for (std::uint32_t k = 0; k < bc; ++k) {
          const std::uint32_t s = bl[k];
          const Vec2 d = xi - B.samples[s];
          const Real r = std::max(std::sqrt(d.squaredNorm()), std::sqrt(tiny2));
          const Real a = std::max(Real(0), Real(1) - r * invR);
          const Real psi = B.volume[s];
          bw += psi * a * a * a;
          const Real g = psi * a * a / r;
          bx += g * d.x();
          by += g * d.y();
        }
        rho += c.rho0 * wK * bw;
        wall = Vec2(gK * bx, gK * by);
        gix += wall.x();
        giy += wall.y();
      }
      wallGrad_[i] = wall;
      const Real plainC = rho / c.rho0 - Real(1);
      const Real C = start ? plainC - start[i] : plainC;
      // With a density contrast every term is weighed by its particle's 1/r, ε by i's: a
      // material of uniform r then steps as one material does.
      Real D;
      if constexpr (kContrast)
        D = (gix * gix + giy * giy + eps_) * invRatio[i] + g2 - eps_;
      else
        D = gix * gix + giy * giy + g2;
      // ρ0/ρ when compressed, else 1: min(1, ρ0/ρ) is the same value (ρ ≥ 0; for ρ > ρ0,
      // ρ0/ρ rounds to 1 at most; for ρ ≤ ρ0, to 1 at least).
      const Real scale = minOf(Real(1), c.rho0 / rho);
      const Real lOld = lambda[i];
      const Real lNew = minOf(Real(0), lOld - scale * C / (D + eps_));
      dLambda_[i] = lNew - lOld;
      P.rho[i] = rho;
      err += double(maxOf(Real(0), C));
      worst = maxOf(worst, C);
      if (start) {
        plainErr += double(maxOf(Real(0), plainC));
        plainWorst = maxOf(plainWorst, plainC);
      }
      if (bad == kNone && !std::isfinite(lNew)) bad = i;
    }
    blockErr_[b / step] = err;
    blockMax_[b / step] = worst;
    blockPlainErr_[b / step] = start ? plainErr : err;
    blockPlainMax_[b / step] = start ? plainWorst : worst;
    return bad;
  };
  const std::size_t first = c.pool.reduce(
      count, step, kNone,
      [&](std::size_t b, std::size_t e) {
        return invRatio ? block(std::true_type{}, b, e) : block(std::false_type{}, b, e);
      },
      [](std::size_t a, std::size_t b2) { return std::min(a, b2); });
  double sum = 0, plainSum = 0;
  Real mx = 0, plainMx = 0;
  for (std::size_t k = 0; k < parts; ++k) {  // in block order: the same for any thread count
    sum += blockErr_[k];
    mx = std::max(mx, blockMax_[k]);
    plainSum += blockPlainErr_[k];
    plainMx = std::max(plainMx, blockPlainMax_[k]);
  }
  if (!list) {
    meanCompression_ = Real(sum / double(P.size()));
    plainMean_ = Real(plainSum / double(P.size()));
  }
  maxCompression_ = mx;
  plainMax_ = plainMx;
  rhoCurrent_ = list == nullptr;  // a full pass: ρ and W are those of the current positions
  return first;
}

std::size_t Pbf::correct(StepContext& c, std::vector<Real>& lambda, Real omega,
                         const std::vector<std::uint32_t>* list) {
  ParticleStore& P = c.P;
  const Spiky<Real> S(c.R);
  const Real wK = S.c * c.R * c.R * c.R, gK = Real(-3) * S.c * c.R * c.R;
  const Real invVg = Real(1) / -(c.mass / c.rho0 * gK);
  const bool tensile = sCorrScale_ != 0;
  const Real wRatio = wK * invWdq_;
  const int sn = tensileN_;
  const Real* L = dLambda_.data();
  const bool cheb = omega != Real(1);
  const Real* invRatio = invRatio_.empty() ? nullptr : invRatio_.data();  // 1/r_i: a density contrast
  const bool elastic = !ownVel_.empty();                                  // elastic groups' particles (pbf_groups.cpp)
  xNew_.resize(P.size());
  const std::size_t count = list ? list->size() : P.size();
  const std::size_t step = list ? kLocalBlock : kBlock;
  // The walls' share of the moves, when they become velocity (pbf.hpp, wallMove_).
  const bool countWall = c.wall && toVelocity_ > 0;
  const std::size_t blocks = (count + step - 1) / step;
  if (countWall) wallBlock_.assign(2 * blocks, Vec2d(0, 0));
  // The block's loop, compiled once with a density contrast and once without.
  auto block = [&](auto contrastTag, std::size_t b, std::size_t e) {
    constexpr bool kContrast = decltype(contrastTag)::value;
    std::size_t bad = kNone;
    Vec2d wallD(0, 0), push(0, 0);
    for (std::size_t idx = b; idx < e; ++idx) {
      const std::size_t i = list ? (*list)[idx] : idx;
      const std::uint32_t cnt = c.nbr.count[i];
      const std::uint32_t* nb = c.nbr.of(i);
      const Grad* gc = gradCache_[i / kBlock].data() + c.nbr.start[i];
      const Real li = L[i];
      // The pair's factor: Δλ_i + Δλ_j, and s_corr = −k (W(r)/W(Δq))^n (|G_ij| = V gK a²/r·r
      // gives a back).
      auto pairFactor = [&](std::uint32_t k) {
        Real f = li + L[nb[k]];
        if (tensile) {
          const Real gr = std::sqrt(gc[k].x * gc[k].x + gc[k].y * gc[k].y) * invVg;  // a²
          const Real a = std::sqrt(gr);
          const Real ratio = wRatio * a * a * a;  // W(r)/W(Δq)
          Real p = ratio;
          for (int t = 1; t < sn; ++t) p *= ratio;
          f += sCorrScale_ * p;
        }
        return f;
      };
      Real tx = 0, ty = 0;
      for (std::uint32_t k = 0; k < cnt; ++k) {
        const Real f = pairFactor(k);
        tx += f * gc[k].x;
        ty += f * gc[k].y;
      }
      if (elastic && ownVel_[i]) {
        // An elastic group's particle: the part of its move its pairs with the others make
        // (pbf_groups.cpp), combined over the iterations as its position is.
        Real cx = 0, cy = 0;
        for (std::uint32_t k = 0; k < cnt; ++k) {
          if (ownVel_[nb[k]]) continue;
          const Real f = pairFactor(k);
          cx += f * gc[k].x;
          cy += f * gc[k].y;
        }
        Vec2 dc(cx, cy);
        if constexpr (kContrast) dc *= invRatio[i];
        if (list)
          cross_[i] += dc;
        else
          crossNew_[i] = cheb ? Vec2(crossOld_[i] + (cross_[i] + dc - crossOld_[i]) * omega) : Vec2(cross_[i] + dc);
      }
      const Vec2 dWall = wallGrad_[i] * li;
      // The walls' share in momentum: m·dWall (m_i = r_i m moves by dWall/r_i).
      Vec2 d = Vec2(tx, ty) + dWall;
      if constexpr (kContrast) d *= invRatio[i];
      if (countWall) wallD += dWall.cast<double>();
      const Vec2 x0 = P.x[i];
      Vec2 x = x0 + d;
      const Real lk = lambda[i];
      if (list && localChebyshev_) {
        // A local pass: the iterate before is the one this particle had when the last pass
        // moved it; a particle that pass did not move (new to the list) starts from where it is.
        // An elastic group's particle steps plainly (its cross moves are not combined), as does
        // one beside a moving body (startLocalPhase).
        if ((elastic && ownVel_[i]) || nearBody(x0)) {
          lambda[i] = lk + li;
          localMoved_[i] = 0;
        } else {
          const bool hasPrevious = localMoved_[i] + 1 == localPass_;
          const Vec2 xo = hasPrevious ? xOld_[i] : x0;
          const Real lo = hasPrevious ? lOld_[i] : lk;
          x = xo + (x - xo) * omega;
          lambda[i] = lo + (lk + li - lo) * omega;
          xOld_[i] = x0;
          localMoved_[i] = localPass_;
        }
      } else if (cheb) {
        x = xOld_[i] + (x - xOld_[i]) * omega;
        lambda[i] = lOld_[i] + (lk + li - lOld_[i]) * omega;
      } else {
        lambda[i] = lk + li;
      }
      lOld_[i] = lk;
      if (resolveEach_ && c.nbr.boundaryCount[i]) {
        Vec2 vd = Vec2::Zero();
        const Vec2 xFree = x;
        if (!c.boundary.clearOf(x, x0, c.clearance) && c.boundary.resolve(x, vd, x0, c.clearance) && countWall)
          push += (x.cast<double>() - xFree.cast<double>()) / (kContrast ? double(invRatio[i]) : 1.0);
      }
      (list ? P.x[i] : xNew_[i]) = x;
      if (bad == kNone && !allFinite(x)) bad = i;
    }
    if (countWall) {
      wallBlock_[2 * (b / step)] = wallD;
      wallBlock_[2 * (b / step) + 1] = push;
    }
    return bad;
  };
  const std::size_t first = c.pool.reduce(
      count, step, kNone,
      [&](std::size_t b, std::size_t e) {
        return invRatio ? block(std::true_type{}, b, e) : block(std::false_type{}, b, e);
      },
      [](std::size_t a, std::size_t b2) { return std::min(a, b2); });
  if (countWall) addWallMoves(blocks, cheb ? omega : Real(1), !list);
  rhoCurrent_ = false;
  if (list) return first;
  // x^{k−1} ← x^k, x^k ← x^{k+1}: buffers rotate, nothing is copied.
  xOld_.swap(P.x);
  P.x.swap(xNew_);
  if (elastic) {
    crossOld_.swap(cross_);
    cross_.swap(crossNew_);
  }
  return first;
}

Real Pbf::pressure(const StepContext& c, const std::vector<Real>* lam, Real pK, std::size_t i) const {
  Real p = lam ? std::max(Real(0), pK * (*lam)[i]) : Real(0);
  if (projection_) p += c.rho0 * std::max(Real(0), projection_->kappaAt(c.P.x[i]));
  return p;
}

std::size_t Pbf::pressureNow(StepContext& c) {
  const std::vector<Real>* lam = c.P.find("pbf.lambda");
  const Real pK = -c.rho0 / (c.dt * c.dt);
  c.pool.parallelFor(c.P.size(), kBlock, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) c.P.p[i] = pressure(c, lam, pK, i);
  });
  return kNone;
}

}  // namespace sph2d
