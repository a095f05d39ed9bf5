// muller2003 — the SPH step of Müller, Charypar & Gross 2003, "Particle-based
// fluid simulation for interactive applications" (SCA 2003), in 2D: poly6
// density, p = K(ρ − ρ0) with K = c², the symmetric spiky pressure force
// m (p_i + p_j)/(2ρ_j) ∇W, gravity, the scene's effects (viscosity: the
// viscosity-kernel Laplacian), symplectic Euler. Walls: the boundary samples
// act as frozen fluid in the density, and push with the particle's own
// pressure only (the single term; see pressureForce). A moving body's samples
// (body_samples.hpp) are such walls too, moving with the body (the no-slip wall
// term takes the sample's velocity); their force on the fluid goes back to the body.
//
// Measured property (docs/SCENES.md): the density and gradient kernels differ,
// so the pressure force is not the gradient of an energy, and the symmetric
// average recovers ∇p/2. A resting column needs ν ≳ 0.005 m²/s to stay calm,
// and its pressure at rest grows by 2ρg per metre.
//
// The pair loops' lanes (scalar reference, SSE2, AVX2): muller2003_pairs.hpp.
#include <algorithm>
#include <cmath>

#include "solvers/muller2003/muller2003_pairs.hpp"

namespace sph2d {
namespace {

std::size_t density(StepContext& c, const Poly6<Real>& W) {
  ParticleStore& P = c.P;
  const NeighbourLists& L = c.nbr;
  const BoundarySet& B = c.boundary;
  const bool hasBoundary = !B.samples.empty();
  const BodySamples* moving = c.bodySamples && c.bodySamples->active() ? c.bodySamples : nullptr;
  const Real self = W.valueR2(0);
  const bool simd = !c.periodic.any() && !scalarPairLoops();
#ifdef SPH2D_AVX2_PAIRS
  const bool wide = useAvx2();
#endif
#ifdef SPH2D_SSE2_PAIRS
  const __m128 R24 = _mm_set1_ps(W.R2), c4 = _mm_set1_ps(W.c);
#else
  (void)simd;
#endif
  return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
    std::size_t bad = kNone;
    for (std::size_t i = b; i < e; ++i) {
      const Vec2 xi = P.x[i];
      const std::uint32_t* nb = L.of(i);
      const std::uint32_t cnt = L.count[i];
      const Vec2* X = P.x.data();
      Real total;  // Σ_j W_ij, pair k in lane k mod 8 (kSumLanes)
#ifdef SPH2D_AVX2_PAIRS
      if (simd && wide) {
        total = densitySum8(X, xi, nb, cnt, W);
      } else
#endif
#ifdef SPH2D_SSE2_PAIRS
          if (simd) {
        // Four kernel values at a time (the scalar expressions, lane-wise); lanes 0–3 in lo, 4–7 in hi.
        const __m128 xi4 = _mm_set1_ps(xi.x()), yi4 = _mm_set1_ps(xi.y());
        __m128 lo = _mm_setzero_ps(), hi = _mm_setzero_ps();
        for (std::uint32_t k = 0; k < cnt; k += 4) {
          // The last group may be partial: its missing lanes repeat the last neighbour and add +0.
          const std::uint32_t last = cnt - 1, n = std::min<std::uint32_t>(4, cnt - k);
          __m128 xj, yj;
          gather4(X, nb[k], nb[std::min(k + 1, last)], nb[std::min(k + 2, last)], nb[std::min(k + 3, last)], xj, yj);
          const __m128 dx = _mm_sub_ps(xi4, xj), dy = _mm_sub_ps(yi4, yj);
          const __m128 r2 = _mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy));
          const __m128 a = _mm_sub_ps(R24, r2);
          __m128 w = _mm_mul_ps(_mm_mul_ps(_mm_mul_ps(c4, a), a), a);
          w = _mm_and_ps(_mm_cmpnge_ps(r2, R24), w);  // valueR2: 0 for r² ≥ R²
          w = _mm_and_ps(w, _mm_load_ps(reinterpret_cast<const float*>(kLive4[n])));
          if (k & 4)
            hi = _mm_add_ps(hi, w);
          else
            lo = _mm_add_ps(lo, w);
        }
        total = laneTotal1(lo, hi);
      } else
#endif
      {
        Real lanes[kSumLanes] = {};
        for (std::uint32_t k = 0; k < cnt; ++k) {
          const Vec2 xj = X[nb[k]];
          Real dx = xi.x() - xj.x(), dy = xi.y() - xj.y();
          c.periodic.nearest(dx, dy);
          lanes[k % kSumLanes] += W.valueR2(dx * dx + dy * dy);
        }
        total = laneTotal(lanes);
      }
      const Real sum = self + total;
      Real rho = c.mass * sum;
      if (hasBoundary) {
        Real bs = 0;
        const std::uint32_t* bl = L.boundaryOf(i);
        for (std::uint32_t q = 0; q < L.boundaryCount[i]; ++q)
          bs += B.volume[bl[q]] * W.valueR2((xi - B.samples[bl[q]]).squaredNorm());
        rho += c.rho0 * bs;
      }
      if (moving) {
        Real ms = 0;
        const std::uint32_t* ml = L.movingOf(i);
        for (std::uint32_t q = 0; q < L.movingCount[i]; ++q)
          ms += moving->volume[ml[q]] * W.valueR2((xi - moving->x[ml[q]]).squaredNorm());
        rho += c.rho0 * ms;
      }
      P.rho[i] = rho;
      if (!std::isfinite(rho) && bad == kNone) bad = i;
    }
    return bad;
  });
}

void pressure(StepContext& c) {
  const Real stiffness = Real(c.def.soundSpeed * c.def.soundSpeed);
  const bool clampNegative = c.def.clampNegativePressure;
  ParticleStore& P = c.P;
  c.pool.parallelFor(P.size(), 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      Real p = stiffness * (P.rho[i] - c.rho0);
      if (clampNegative && p < 0) p = 0;
      P.p[i] = p;
      P.invRho[i] = Real(1) / P.rho[i];
      P.pOverRho[i] = p * P.invRho[i];
    }
  });
}

template <bool Visc>
std::size_t pressureForce(StepContext& c, const Spiky<Real>& spiky, const ViscosityTerm& vt,
                          const ImpactViscosity& impact, std::vector<Vec2d>& wallBlock) {
  ParticleStore& P = c.P;
  const BoundarySet& B = c.boundary;
  const bool hasBoundary = !B.samples.empty();
  BodySamples* moving = c.bodySamples && c.bodySamples->active() ? c.bodySamples : nullptr;
  PairConstants k{};
  k.R = spiky.R;
  k.spikyK = Real(-3) * spiky.c;  // dW/dr = −3c(R − r)²
  k.halfMass = Real(0.5) * c.mass;
  k.coincident2 = kCoincident2 * (c.R * c.R);
  k.impact = impact.on();
  if (k.impact) {
    k.impW0 = impact.w0;
    k.impInvW0 = Real(1) / impact.w0;
    k.impH = Real(0.5) * c.R;
    k.impEta2 = Real(0.01) * k.impH * k.impH;
    k.impK = Real(2) * c.mass * impact.alpha0 * Real(c.def.soundSpeed);
  }
  const ViscosityKernel<Real>& W = vt.W;
  if (Visc) {
    k.vR2 = W.R * W.R;
    k.vR3 = k.vR2 * W.R;
    k.lapK = Real(5) / (Real(3) * kPi<Real> * k.vR2 * k.vR3);
    k.rMin = W.rMin;
    k.rMin2 = W.rMin * W.rMin;
    k.invRMin = Real(1) / W.rMin;
    k.pairCap = vt.pairCap;
  }
  const bool simd = !c.periodic.any() && !scalarPairLoops();
#ifdef SPH2D_AVX2_PAIRS
  const bool wide = useAvx2();
#endif
  const Real* IR = P.invRho.data();
  const Real* POR = P.pOverRho.data();
  const Vec2* X = P.x.data();
  const Vec2* V = P.v.data();
  // The walls' force on the fluid (World::wallImpulse), Σ m a_wall per block, the blocks in order.
  const std::size_t blocks = (P.size() + kBlock - 1) / kBlock;
  if (c.wall) wallBlock.assign(blocks, Vec2d(0, 0));
  const std::size_t first = firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
    std::size_t bad = kNone;
    Vec2d wallAcc(0, 0);  // Σ a_wall over the block's particles
#ifdef SPH2D_SSE2_PAIRS
    const struct {
      __m128 R, spikyK, halfMass, one, thr, vR2, vR3, lapK, rMin, rMin2, invRMin, nine;
    } K4 = {_mm_set1_ps(k.R),           _mm_set1_ps(k.spikyK), _mm_set1_ps(k.halfMass), _mm_set1_ps(Real(1)),
            _mm_set1_ps(k.coincident2), _mm_set1_ps(k.vR2),    _mm_set1_ps(k.vR3),      _mm_set1_ps(k.lapK),
            _mm_set1_ps(k.rMin),        _mm_set1_ps(k.rMin2),  _mm_set1_ps(k.invRMin),  _mm_set1_ps(Real(9))};
#endif
#ifdef SPH2D_AVX2_PAIRS
    alignas(16) Real runSums[kRun][4];
    std::size_t runBegin = b, runStop = b;
#endif
    for (std::size_t i = b; i < e; ++i) {
      const Vec2 xi = X[i];
      const Real pi = P.p[i];
      const Real vix = V[i].x(), viy = V[i].y();
      // Σ m (p_i + p_j)/(2 ρ_j) ∇W (force density, Müller eq. 10) and Σ (v_j − v_i) ∇²W / ρ_j.
      const std::uint32_t* nb = c.nbr.of(i);
      const std::uint32_t cnt = c.nbr.count[i];
      std::uint32_t kk = 0;
      alignas(16) Real sums[4] = {0, 0, 0, 0};
#ifdef SPH2D_AVX2_PAIRS
      if (simd && wide) {
        if (i == runStop) {  // the next run of particles' pair sums, at once
          runBegin = i;
          runStop = std::min(e, i + kRun);
          pairSums8<Visc>(c, k, runBegin, runStop, runSums);
        }
        std::copy(runSums[i - runBegin], runSums[i - runBegin] + 4, sums);
        kk = cnt;
      } else
#endif
#ifdef SPH2D_SSE2_PAIRS
          if (simd) {
        // Pair k in lane k mod 8 (kSumLanes): lanes 0–3 in lo, 4–7 in hi.
        __m128 lo[4] = {_mm_setzero_ps(), _mm_setzero_ps(), _mm_setzero_ps(), _mm_setzero_ps()};
        __m128 hi[4] = {lo[0], lo[0], lo[0], lo[0]};
        const __m128 xi4 = _mm_set1_ps(xi.x()), yi4 = _mm_set1_ps(xi.y()), pi4 = _mm_set1_ps(pi);
        const __m128 vix4 = _mm_set1_ps(vix), viy4 = _mm_set1_ps(viy);
        const __m128 capI4 = _mm_set1_ps(k.pairCap / IR[i]);  // ViscosityTerm::pairCap · ρ_i
        // Adds the terms of pairs at.. at + n − 1 (n ≤ 4) to s; missing lanes repeat the last
        // pair and add +0, which leaves a sum unchanged (a sum that starts at +0 is never −0).
        auto group = [&](std::uint32_t at, std::uint32_t n, __m128 s[4]) {
          const std::uint32_t last = nb[cnt - 1];
          const std::uint32_t j0 = nb[at], j1 = n > 1 ? nb[at + 1] : last, j2 = n > 2 ? nb[at + 2] : last,
                              j3 = n > 3 ? nb[at + 3] : last;
          __m128 xj, yj;
          gather4(X, j0, j1, j2, j3, xj, yj);
          const __m128 dx = _mm_sub_ps(xi4, xj), dy = _mm_sub_ps(yi4, yj);
          const __m128 r2 = _mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy));
          if (__builtin_expect(_mm_movemask_ps(_mm_cmplt_ps(r2, K4.thr)) & ((1 << n) - 1), 0)) {
            alignas(16) Real t[4][4] = {};  // a coincident pair (rare): the scalar terms, in their lanes
            for (std::uint32_t q = 0; q < n; ++q) {
              Real tq[4];
              pairTermScalar<Visc>(c, k, i, nb[at + q], pi, vix, viy, tq);
              for (int l = 0; l < 4; ++l) t[l][q] = tq[l];
            }
            for (int l = 0; l < 4; ++l) s[l] = _mm_add_ps(s[l], _mm_load_ps(t[l]));
            return;
          }
          const __m128 irj = _mm_setr_ps(IR[j0], IR[j1], IR[j2], IR[j3]);
          const __m128 porj = _mm_setr_ps(POR[j0], POR[j1], POR[j2], POR[j3]);
          const __m128 sq = _mm_sqrt_ps(r2);
          const __m128 invr = _mm_div_ps(K4.one, sq);
          const __m128 a = _mm_sub_ps(K4.R, _mm_mul_ps(r2, invr));
          const __m128 gs = _mm_mul_ps(_mm_mul_ps(_mm_mul_ps(K4.spikyK, a), a), invr);
          __m128 wp = _mm_mul_ps(gs, _mm_mul_ps(K4.halfMass, _mm_add_ps(_mm_mul_ps(pi4, irj), porj)));
          __m128 vxj = _mm_setzero_ps(), vyj = _mm_setzero_ps();
          if (Visc || k.impact) gather4(V, j0, j1, j2, j3, vxj, vyj);
          if (k.impact) {  // pairTermScalar's impact term, lane-wise
            const __m128 nv = _mm_sub_ps(_mm_setzero_ps(), _mm_add_ps(_mm_mul_ps(_mm_sub_ps(vix4, vxj), dx),
                                                                      _mm_mul_ps(_mm_sub_ps(viy4, vyj), dy)));
            const __m128 w = _mm_mul_ps(nv, invr);
            const __m128 fast = _mm_cmpgt_ps(w, _mm_set1_ps(k.impW0));
            if (_mm_movemask_ps(fast) & ((1 << n) - 1)) {
              const __m128 rhoi = _mm_set1_ps(Real(1) / IR[i]);
              const __m128 sw =
                  _mm_min_ps(_mm_mul_ps(_mm_sub_ps(w, _mm_set1_ps(k.impW0)), _mm_set1_ps(k.impInvW0)), K4.one);
              const __m128 mu = _mm_div_ps(_mm_mul_ps(_mm_set1_ps(k.impH), nv), _mm_add_ps(r2, _mm_set1_ps(k.impEta2)));
              const __m128 f = _mm_div_ps(_mm_mul_ps(_mm_mul_ps(_mm_mul_ps(_mm_set1_ps(k.impK), rhoi), sw), mu),
                                          _mm_add_ps(rhoi, _mm_div_ps(K4.one, irj)));
              wp = _mm_or_ps(_mm_and_ps(fast, _mm_add_ps(wp, _mm_mul_ps(gs, f))), _mm_andnot_ps(fast, wp));
            }
          }
          __m128 t[4] = {_mm_mul_ps(dx, wp), _mm_mul_ps(dy, wp), _mm_setzero_ps(), _mm_setzero_ps()};
          if (Visc) {
            const __m128 big = _mm_cmpgt_ps(r2, K4.rMin2);
            const __m128 q = _mm_or_ps(_mm_and_ps(big, sq), _mm_andnot_ps(big, K4.rMin));
            const __m128 iq = _mm_or_ps(_mm_and_ps(big, invr), _mm_andnot_ps(big, K4.invRMin));
            const __m128 poly =
                _mm_add_ps(_mm_add_ps(_mm_add_ps(K4.vR3, _mm_mul_ps(K4.vR2, q)), _mm_mul_ps(_mm_mul_ps(K4.R, q), q)),
                           _mm_mul_ps(_mm_mul_ps(_mm_mul_ps(K4.nine, q), q), q));
            __m128 lap = _mm_mul_ps(_mm_mul_ps(K4.lapK, _mm_sub_ps(K4.R, q)), poly);
            lap = _mm_mul_ps(_mm_mul_ps(_mm_mul_ps(lap, iq), iq), iq);
            lap = _mm_and_ps(_mm_cmpnge_ps(r2, K4.vR2), lap);  // r² ≥ R²: 0
            const __m128 w =
                _mm_min_ps(_mm_mul_ps(lap, irj), capI4);  // the stability cap (std::min's value for finite lanes)
            t[2] = _mm_mul_ps(_mm_sub_ps(vxj, vix4), w);
            t[3] = _mm_mul_ps(_mm_sub_ps(vyj, viy4), w);
          }
          if (n < 4) {
            const __m128 live = _mm_load_ps(reinterpret_cast<const float*>(kLive4[n]));
            for (int l = 0; l < 4; ++l) t[l] = _mm_and_ps(t[l], live);
          }
          for (int l = 0; l < 4; ++l) s[l] = _mm_add_ps(s[l], t[l]);
        };
        for (; kk < cnt; kk += 4) group(kk, std::min<std::uint32_t>(4, cnt - kk), (kk & 4) ? hi : lo);
        kk = cnt;
        laneTotals4(lo, hi, sums);
      }
#endif
      (void)simd;
      if (kk < cnt) pairSumsScalar<Visc>(c, k, i, nb, cnt, pi, vix, viy, sums);
      const Vec2 fp(sums[0], sums[1]);
      const Real invRhoi = IR[i];
      // A wall sample's ∇²W at most (ViscosityTerm::pairCap): a division, so only near a wall.
      const auto capWall = [&] { return vt.pairCap / invRhoi * c.rho0; };
      Vec2 acc = -fp * invRhoi;
      if (hasBoundary) {
        // Boundary samples as frozen fluid of mass ρ0·Ψ_b that carries no
        // pressure of its own: m (p_i + 0)/(2ρ_b) ∇W with ρ_b = ρ0 (the single
        // term p_i/ρ_i² of Akinci et al. 2012, in Müller's symmetric form). A pressure
        // mirrored onto the sample (p_b = p_i extrapolated hydrostatically,
        // Adami, Hu & Adams 2012) makes the wall force depend on where the
        // particle sits relative to each sample, so it does net work on fluid
        // oscillating against the wall: with only ν to dissipate it, the long
        // rest of tests/stability (dx = 0.04, c = 25, ν = 0.01) heated up to
        // ~200 J/m (mean speed ~1 m/s) within 6 s; with the single term it stays
        // below 0.6 J/m. The single term pushes half as hard as the mirrored
        // pressure, so the wall row sits more compressed (the resting column's
        // most compressed particle: about 4 % instead of 2–3.5 %).
        Vec2 gb = Vec2::Zero();
        const std::uint32_t* bl = c.nbr.boundaryOf(i);
        for (std::uint32_t q = 0; q < c.nbr.boundaryCount[i]; ++q) {
          const Vec2 d = xi - B.samples[bl[q]];
          gb += spiky.gradient(d, std::sqrt(d.squaredNorm())) * B.volume[bl[q]];
        }
        const Vec2 aWall = gb * (Real(0.5) * pi * invRhoi);
        acc -= aWall;
        wallAcc -= aWall.cast<double>();
      }
      acc += c.gravity;
      if (Visc) {
        // The viscosity effect's acceleration (viscosity.cpp), added after gravity as its stage added it.
        Vec2 av = Vec2(sums[2], sums[3]) * (vt.muMass * invRhoi);
        if (vt.walls) {
          Real sum = 0;  // Σ_b Ψ_b ∇²W_ib
          const std::uint32_t* bl = c.nbr.boundaryOf(i);
          const std::uint32_t bc = c.nbr.boundaryCount[i];
          const Real cap = bc > 0 ? capWall() : Real(0);
          for (std::uint32_t q = 0; q < bc; ++q) {
            const std::uint32_t s = bl[q];
            sum += B.volume[s] * std::min(W.laplacianR2((xi - B.samples[s]).squaredNorm()), cap);
          }
          const Vec2 aWall = Vec2(vix, viy) * (vt.wallFactor * invRhoi * sum);
          av -= aWall;
          wallAcc -= aWall.cast<double>();
        }
        if (!allFinite(av) && bad == kNone) bad = i;
        acc += av;
      }
      if (moving && c.nbr.movingCount[i] > 0) {
        // The moving bodies' samples: the same wall terms (the no-slip term with the sample's
        // velocity), body by body; each body's share of the acceleration is its reaction.
        const std::uint32_t* ml = c.nbr.movingOf(i);
        const std::uint32_t mc = c.nbr.movingCount[i];
        const Real pK = Real(0.5) * pi * invRhoi;
        const Real cap = capWall();
        moving->forEachBody(ml, mc, [&](std::uint32_t body, const std::uint32_t* run, const std::uint32_t* runEnd) {
          Vec2 gb = Vec2::Zero(), lv = Vec2::Zero();
          Real tb = 0, tv = 0;  // Σ arm × (the pair's term), for the torque
          for (const std::uint32_t* p = run; p != runEnd; ++p) {
            const std::uint32_t s = *p;
            const Vec2 d = xi - moving->x[s];
            const Real rr = d.squaredNorm();
            const Vec2 g = spiky.gradient(d, std::sqrt(rr)) * moving->volume[s];
            gb += g;
            tb += BodySamples::torque(moving->arm[s], g);
            if (Visc && vt.noSlip) {
              const Vec2 u = (Vec2(vix, viy) - moving->v[s]) * (moving->volume[s] * std::min(W.laplacianR2(rr), cap));
              lv += u;
              tv += BodySamples::torque(moving->arm[s], u);
            }
          }
          const Real vK = Visc && vt.noSlip ? vt.wallFactor * invRhoi : Real(0);
          const Vec2 aBody = -(gb * pK) - lv * vK;
          acc += aBody;
          if (moving->placed[body].dynamic)
            moving->addReaction(b / kBlock, body, aBody.cast<double>() * double(c.momentumMass),
                                -(double(tb) * double(pK) + double(tv) * double(vK)) * double(c.momentumMass));
        });
      }
      P.a[i] = acc;
      if (!allFinite(acc) && bad == kNone) bad = i;
    }
    if (c.wall) wallBlock[b / kBlock] = wallAcc;
    return bad;
  });
  // The World multiplies it by the substep integrate takes (force_limit may still shorten it).
  if (c.wall) c.wall->force += sumInOrder(wallBlock, blocks) * double(c.momentumMass);
  return first;
}

class Muller2003 final : public Solver {
 public:
  explicit Muller2003(const SolverDef& d)
      : c_(d.soundSpeed), impact_(Real(d.param("impact_alpha")), Real(d.param("impact_speed") * d.soundSpeed)) {}
  const char* name() const override { return "muller2003"; }
  // p = c²(ρ − ρ0) and the symmetric force recovers ∇p/2: ρ = ρ0(1 + 2 g z / c²).
  double hydrostaticFactor() const override { return 2.0 / (c_ * c_); }

  double densityKernel(double r, double R) const override { return Poly6<double>(R).value(r); }

  /// The moving bodies' samples are walls like the static ones (body_samples.hpp).
  bool movingSamples() const override { return true; }

  void prepare(StepContext& c) override {
    stageGrid(c, false);
    stageNeighbours(c);
    density(c, Poly6<Real>(c.R));
    pressure(c);
  }

  /// The CFL limit cfl·R/(c + v_max) and the force limit.
  Real maxTimeStep(const StepContext& c, Real vmax, Real amax) const override {
    Real dt = Real(c.def.cfl) * c.R / (Real(c.def.soundSpeed) + vmax);
    if (amax > 0) dt = std::min(dt, kForceCfl * std::sqrt(c.R / amax));
    return dt;
  }

  /// Folds the Laplacian viscosity into the pressure force's pair loop.
  bool foldViscosity(Effect* viscosity) override {
    viscosity_ = viscosity;
    return viscosity != nullptr;
  }

  /// grid → neighbours → density (poly6) → pressure → pressure_force (spiky) → effects → force_limit → integrate;
  /// with a folded viscosity, pressure_force+viscosity and the effects without it.
  std::vector<Stage> stages(bool) override {
    std::vector<Stage> s =
        explicitStages([](StepContext& c) { return density(c, Poly6<Real>(c.R)); }, pressure,
                       [this](StepContext& c) {
                         return pressureForce<false>(c, Spiky<Real>(c.R), ViscosityTerm{}, impact_, wallBlock_);
                       });
    if (Effect* v = viscosity_) {
      for (Stage& st : s)
        if (st.name == "pressure_force") {
          st.name = "pressure_force+viscosity";
          st.run = [this, v](StepContext& c) {
            return pressureForce<true>(c, Spiky<Real>(c.R), v->viscosityTerm(c), impact_, wallBlock_);
          };
        }
    }
    return s;
  }

 private:
  double c_;
  ImpactViscosity impact_;        ///< impact_alpha, impact_speed (impact_viscosity.hpp)
  Effect* viscosity_ = nullptr;   ///< the folded viscosity effect (foldViscosity), or null
  std::vector<Vec2d> wallBlock_;  ///< per block of kBlock particles, Σ of the walls' acceleration
};

}  // namespace

/// muller2003's registration (solvers.def): its parameters are the impact viscosity's
/// (solver.sound_speed is its stiffness).
SolverInfo muller2003Solver() {
  return {"muller2003", {kImpactAlphaParam, kImpactSpeedParam}, [](const SolverDef& d) -> std::unique_ptr<Solver> {
            return std::make_unique<Muller2003>(d);
          }};
}

}  // namespace sph2d
