// pbf — Position Based Fluids (Macklin & Müller 2013, "Position Based Fluids",
// ACM TOG 32(4)) in 2D, for games: substeps up to a frame (max_dt, 1/60 s).
//
// One substep of length dt:
//   1. a = gravity (+ the scene's effects, on neighbour lists of the current x);
//      v* = v + dt a; x* = x + dt v*, swept out of the solids; x stays in xPrev
//      (the World's swept collision runs from xPrev after the substep).
//   2. Grid and neighbour lists on x*, kept for the whole substep as in the paper,
//      and the boundary samples within R of each x*.
//   3. Jacobi iterations of the density constraints C_i = ρ_i/ρ0 − 1:
//        Δλ_i = −s_i C_i / (|∇_i C_i|² + Σ_j |∇_j C_i|² + ε),
//        Δx_i = (m/ρ0) Σ_j (Δλ_i + Δλ_j + s_corr) ∇W_ij + Δλ_i Σ_b Ψ_b ∇W_ib,
//      each particle gathering its own Δx into a second buffer (no races), then
//      swept out of the solids. At least `iterations`, then until the mean
//      compression mean(max(C_i, 0)) ≤ tolerance and max(C_i) ≤ tolerance_max,
//      at most max_iterations.
//   4. ρ of the final x* (what the World reports), v = (x* − x)/dt, and XSPH:
//      v_i += c Σ_j (m/ρ_j)(v_j − v_i) W_ij, gathered into a copy.
//
// Design choices (the measurements behind them and the variants dropped:
// docs/SOLVERS.md and docs/SCENES.md, sections pbf):
// - One kernel, spiky (Müller et al. 2003), for the density and for ∇C, so ∇C is
//   the true gradient of C (a Newton step) and close pairs still repel (its
//   gradient does not vanish at r = 0; coincident pairs use tieBreakDirection).
//   Pairs that drift past R during the iterations get W = 0.
// - Walls: boundary samples are static particles of mass ρ0Ψ_b in ρ_i and in
//   ∇_i C_i, and have no constraint of their own (λ_b = 0: the Jacobian of C is
//   used as it is).
// - Multipliers accumulate over the iterations of a substep and are clamped
//   λ_i ≤ 0: only compression is corrected (no tension, no clumping), and a later
//   iteration may undo part of an earlier push. P.p = −ρ0 λ / dt².
// - Step size: ε = relaxation · D0 with D0 = Σ_j |∇_j C_i|² on a full rest
//   lattice (scale-free). A compressed particle's step is scaled by s_i = ρ0/ρ_i:
//   the largest eigenvalue of the Jacobi step grows with compression.
// - Chebyshev semi-iteration on the positions (Wang 2015, "A Chebyshev
//   semi-iterative approach for accelerating projective and position-based
//   dynamics"): Jacobi corrects the long (hydrostatic) modes by about N/layers²
//   per N iterations, Chebyshev by N²/layers².
// - No warm start from the previous substep's multipliers.
// - Convergence needs the mean compression and the largest below their tolerances.
// - Time step: min(max_dt, max_move · R / v_max, limit). The compression left
//   after N iterations grows as dt²/N², so when max_iterations end unconverged
//   the limit drops to 0.5–0.9 of this substep (not below max_dt/32); when half
//   of them sufficed it grows back by 1.2 per substep.
//
// Parameters (solver.*): iterations, max_iterations, tolerance, tolerance_max,
// relaxation, chebyshev, tensile_k, tensile_n, tensile_dq, xsph, max_dt, max_move.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

#if defined(__SSE2__) && !defined(SPH2D_NO_SIMD)
#include <emmintrin.h>
#endif

#include "solvers/solver.hpp"

namespace sph2d {
namespace {

/// Four floats operated on together: SSE2 when the compiler targets it, else four
/// scalar operations. Every operation is IEEE single precision, correctly rounded
/// per lane (add, mul, div, sqrt, max), so both paths give the same bits.
struct Lane4 {
#if defined(__SSE2__) && !defined(SPH2D_NO_SIMD)
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
#else
  float v[4];
  static Lane4 load(const float* p) { return {{p[0], p[1], p[2], p[3]}}; }
  static Lane4 all(float x) { return {{x, x, x, x}}; }
  void store(float* p) const { std::memcpy(p, v, sizeof v); }
  template <class F>
  static Lane4 map(Lane4 a, Lane4 b, F f) {
    return {{f(a.v[0], b.v[0]), f(a.v[1], b.v[1]), f(a.v[2], b.v[2]), f(a.v[3], b.v[3])}};
  }
  friend Lane4 operator+(Lane4 a, Lane4 b) { return map(a, b, [](float x, float y) { return x + y; }); }
  friend Lane4 operator-(Lane4 a, Lane4 b) { return map(a, b, [](float x, float y) { return x - y; }); }
  friend Lane4 operator*(Lane4 a, Lane4 b) { return map(a, b, [](float x, float y) { return x * y; }); }
  friend Lane4 operator/(Lane4 a, Lane4 b) { return map(a, b, [](float x, float y) { return x / y; }); }
  static Lane4 sqrt(Lane4 a) { return {{std::sqrt(a.v[0]), std::sqrt(a.v[1]), std::sqrt(a.v[2]), std::sqrt(a.v[3])}}; }
  // _mm_max_ps(a, b) returns b when either is NaN: so does this.
  static Lane4 max(Lane4 a, Lane4 b) { return map(a, b, [](float x, float y) { return x > y ? x : y; }); }
#endif
  /// ((l0 + l1) + l2) + l3, the same order on both paths.
  float sum() const {
    float t[4];
    store(t);
    return ((t[0] + t[1]) + t[2]) + t[3];
  }
};
static_assert(std::is_same<Real, float>::value, "Lane4 is single precision");

class Pbf final : public Solver {
 public:
  explicit Pbf(const SolverDef& d)
      : iterations_(int(std::lround(d.param("iterations")))),
        maxIterations_(int(std::lround(d.param("max_iterations")))),
        tolerance_(Real(d.param("tolerance"))),
        toleranceMax_(Real(d.param("tolerance_max"))),
        relaxation_(Real(d.param("relaxation"))),
        chebyshev_(Real(d.param("chebyshev"))),
        tensileK_(Real(d.param("tensile_k"))),
        tensileN_(int(std::lround(d.param("tensile_n")))),
        tensileDq_(Real(d.param("tensile_dq"))),
        xsph_(Real(d.param("xsph"))),
        maxDt_(Real(d.param("max_dt"))),
        maxMove_(Real(d.param("max_move"))) {}

  const char* name() const override { return "pbf"; }
  // The projection holds ρ0 at any depth (up to the tolerance): start uncompressed.
  double hydrostaticFactor() const override { return 0; }

  double densityKernel(double r, double R) const override { return Spiky<double>(R).value(r); }

  void prepare(StepContext& c) override {
    calibrate(c);
    c.P.field("pbf.lambda");
    if (c.P.size() == 0) return;
    stageGrid(c, false);
    stageNeighbours(c);
    finalDensity(c, Real(0));
  }

  double minTimeStep(const StepContext& c) const override {
    (void)c;
    return double(maxDt_) / 32;
  }

  Real maxTimeStep(const StepContext& c, Real vmax, Real amax) const override {
    (void)amax;
    Real dt = std::min(maxDt_, dtLimit_);
    if (vmax > 0) dt = std::min(dt, maxMove_ * c.R / vmax);
    return dt;
  }

  /// Correction passes and the mean compression after them, of the last substep.
  SolverStats stats() const override { return stats_; }

  /// [grid → neighbours, when effects run] → external → effects → predict →
  /// predicted_grid → predicted_neighbours → density_solve → density → velocity.
  std::vector<Stage> stages(bool effects) override {
    std::vector<Stage> s;
    if (effects) {  // the effects read neighbours of the current positions
      s.push_back(plainStage("grid", [](StepContext& c) { stageGrid(c, false); }));
      s.push_back(plainStage("neighbours", [](StepContext& c) { stageNeighbours(c); }));
    }
    s.push_back(plainStage("external", [](StepContext& c) {
      Particles& P = c.P;
      c.pool.parallelFor(P.size(), kStreamBlock, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) P.a[i] = c.gravity;
      });
    }));
    s.push_back(Stage::effects());
    s.push_back(Stage{"predict", [this](StepContext& c) { return predict(c, c.P.field("pbf.lambda")); }});
    s.push_back(plainStage("predicted_grid", [](StepContext& c) { stageGrid(c, reorderThisStep(c)); }));
    s.push_back(plainStage("predicted_neighbours", [](StepContext& c) { stageNeighbours(c); }));
    s.push_back(Stage{"density_solve", [this](StepContext& c) { return solve(c); }});
    s.push_back(Stage{"density", [this](StepContext& c) { return finalDensity(c, c.dt); }});
    s.push_back(Stage{"velocity", [this](StepContext& c) { return velocity(c); }});
    return s;
  }

 private:
  /// Jacobi iterations of the density constraints on the predicted positions
  /// (Chebyshev-accelerated) until the tolerances; then the step-limit controller.
  std::size_t solve(StepContext& c) {
    const std::size_t n = c.P.size();
    if (n == 0) return kNone;
    if (!(d0_ > 0)) calibrate(c);
    std::vector<Real>& lambda = c.P.field("pbf.lambda");
    dLambda_.resize(n);
    lOld_.resize(n);
    wallGrad_.resize(n);
    const int maxIt = std::max(iterations_, maxIterations_);
    const Real rho2 = chebyshev_ * chebyshev_;
    Real omega = 1;
    int used = 0;
    for (int k = 0; k < maxIt; ++k, ++used) {
      const std::size_t bad = constraint(c, lambda);
      if (bad != kNone) return bad;
      if (k >= iterations_ && converged()) break;
      // Chebyshev weights (Wang 2015): ω1 = 1, ω2 = 2/(2 − ρ²), ω_{k+1} = 4/(4 − ρ²ω_k).
      omega = k == 0 ? Real(1) : k == 1 ? Real(2) / (Real(2) - rho2) : Real(4) / (Real(4) - rho2 * omega);
      const std::size_t badC = correct(c, lambda, omega);
      if (badC != kNone) return badC;
    }
    stats_.pressureIterations = used;  // corrections applied
    stats_.densityError = double(meanCompression_);
    if (tolerance_ > 0) {
      // The compression left after N iterations grows as dt²/N²: when max_iterations
      // did not reach the tolerance, the next substeps are shorter; when half of them
      // sufficed, the limit grows back towards max_dt.
      if (!converged()) {
        const Real ratio = std::min(tolerance_ / meanCompression_, toleranceMax_ / maxCompression_);
        dtLimit_ = c.dt * std::min(Real(0.9), std::max(Real(0.5), Real(0.9) * std::sqrt(ratio)));
        dtLimit_ = std::max(dtLimit_, maxDt_ / Real(32));  // a jam it cannot resolve must not stall the run
      } else if (2 * used <= maxIt) {
        dtLimit_ = std::min(maxDt_, dtLimit_ * Real(1.2));
      }
    }
    return kNone;
  }

  /// The last constraint pass met both tolerances.
  bool converged() const { return meanCompression_ <= tolerance_ && maxCompression_ <= toleranceMax_; }

  /// D0 = Σ_j (m/ρ0)² |∇W|² over a full square lattice (the typical constraint denominator).
  void calibrate(const StepContext& c) {
    const double R = double(c.R), dx = double(c.dx);
    const double V = double(c.mass) / double(c.rho0);
    const Spiky<double> W(R);
    const int n = int(std::ceil(R / dx)) + 1;
    double s = 0;
    for (int j = -n; j <= n; ++j)
      for (int i = -n; i <= n; ++i) {
        if (i == 0 && j == 0) continue;
        const double g = W.derivative(std::sqrt(double(i * i + j * j)) * dx);
        s += g * g;
      }
    d0_ = Real(V * V * s);
    eps_ = relaxation_ * d0_;
    // s_corr = −k (W(r)/W(Δq))^n, in multipliers: 1/D0 corrects a density error of 1.
    invWdq_ = Real(1.0 / W.value(double(tensileDq_) * R));
    sCorrScale_ = Real(-double(tensileK_) / double(d0_));
  }

  /// xPrev = x; v += dt a; x += dt v, swept out of the solids; λ = 0.
  std::size_t predict(StepContext& c, std::vector<Real>& lambda) {
    Particles& P = c.P;
    const Real dt = c.dt, vmax2 = c.maxSpeed * c.maxSpeed;
    return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      std::size_t bad = kNone;
      for (std::size_t i = b; i < e; ++i) {
        const Vec2 v = P.v[i] + P.a[i] * dt;
        const Vec2 x0 = P.x[i];
        Vec2 x = x0 + v * dt;
        Vec2 vd = v;  // resolve()'s velocity response is not used: v follows from the positions
        c.boundary.resolve(x, vd, x0, c.clearance);
        P.xPrev[i] = x0;
        P.v[i] = v;
        P.x[i] = x;
        lambda[i] = 0;
        if (bad == kNone && (!allFinite(x) || !allFinite(v) || v.squaredNorm() > vmax2)) bad = i;
      }
      return bad;
    });
  }

  /// d = x_i − x_j and r² of i's neighbours into dx, dy, r2, padded to a multiple of 4
  /// with pairs outside the support (r² = 4R², d = 0: every term vanishes). Returns the padded count.
  static std::size_t gather(const StepContext& c, std::size_t i, std::vector<Real>& dx,
                            std::vector<Real>& dy, std::vector<Real>& r2) {
    const std::uint32_t cnt = c.nbr.count[i];
    const std::uint32_t* nb = c.nbr.of(i);
    const std::size_t pad = (std::size_t(cnt) + 3) / 4 * 4;
    if (dx.size() < pad) {
      dx.resize(pad);
      dy.resize(pad);
      r2.resize(pad);
    }
    for (std::uint32_t k = 0; k < cnt; ++k) pairDelta(c, i, nb[k], dx[k], dy[k], r2[k]);
    for (std::size_t k = cnt; k < pad; ++k) {
      dx[k] = dy[k] = 0;
      r2[k] = Real(4) * c.R * c.R;
    }
    return pad;
  }

  /// Density of x*, the constraint and the multiplier step Δλ_i (keeping λ ≤ 0); the
  /// mean compression. Caches the spiky gradient factor per pair (∇W = gK g d) and
  /// the wall part of ∇_i C_i for correct() (same positions).
  std::size_t constraint(StepContext& c, const std::vector<Real>& lambda) {
    Particles& P = c.P;
    const BoundarySet& B = c.boundary;
    const Spiky<Real> S(c.R);
    const Real invR = Real(1) / c.R, wK = S.c * c.R * c.R * c.R, gK = Real(-3) * S.c * c.R * c.R;
    const Real V = c.mass / c.rho0, Vg = V * gK;
    const Real tiny2 = Real(1e-12) * c.R * c.R;
    gCache_.resize(c.nbr.perBlock.size());
    blockErr_.resize(c.nbr.perBlock.size());
    blockMax_.resize(c.nbr.perBlock.size());
    const std::size_t first = firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      std::vector<Real>& cache = gCache_[b / kBlock];
      const std::size_t need = c.nbr.perBlock[b / kBlock].size() + 4;  // + padding of the last particle
      if (cache.size() < need) cache.resize(need);
      std::vector<Real> dxs, dys, r2s;
      std::size_t bad = kNone;
      double err = 0;
      Real worst = 0;
      const Lane4 zero = Lane4::all(0), one = Lane4::all(1), vInvR = Lane4::all(invR);
      for (std::size_t i = b; i < e; ++i) {
        const std::size_t pad = gather(c, i, dxs, dys, r2s);
        // Particles are visited in slot order, so the padding written past i's pairs is
        // overwritten by i + 1's.
        Real* gc = cache.data() + c.nbr.start[i];
        // a = 1 − r/R; W = wK a³; ∇W = gK (a²/r) d; four pairs at a time.
        Lane4 sw = zero, sx = zero, sy = zero, s2 = zero;
        for (std::size_t k = 0; k < pad; k += 4) {
          const Lane4 q2 = Lane4::load(&r2s[k]), r = Lane4::sqrt(q2);
          const Lane4 a = Lane4::max(one - r * vInvR, zero);
          const Lane4 g = a * a / r;
          g.store(gc + k);
          sw = sw + a * a * a;
          sx = sx + g * Lane4::load(&dxs[k]);
          sy = sy + g * Lane4::load(&dys[k]);
          s2 = s2 + g * g * q2;
        }
        const Real w = Real(1) + sw.sum(), gx = sx.sum(), gy = sy.sum(), g2 = s2.sum();  // self: W(0) = wK
        Real rho = c.mass * wK * w;
        Real gix = Vg * gx, giy = Vg * gy;
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
        const Real C = rho / c.rho0 - Real(1);
        const Real D = gix * gix + giy * giy + Vg * Vg * g2;
        const Real scale = rho > c.rho0 ? c.rho0 / rho : Real(1);
        const Real lOld = lambda[i];
        const Real lNew = std::min(Real(0), lOld - scale * C / (D + eps_));
        dLambda_[i] = lNew - lOld;
        P.rho[i] = rho;
        err += double(std::max(Real(0), C));
        worst = std::max(worst, C);
        if (bad == kNone && !std::isfinite(lNew)) bad = i;
      }
      blockErr_[b / kBlock] = err;
      blockMax_[b / kBlock] = worst;
      return bad;
    });
    double sum = 0;
    Real mx = 0;
    for (std::size_t k = 0; k < blockErr_.size(); ++k) {  // in block order: the same for any thread count
      sum += blockErr_[k];
      mx = std::max(mx, blockMax_[k]);
    }
    meanCompression_ = Real(sum / double(P.size()));
    maxCompression_ = mx;
    return first;
  }

  /// x*_i += (m/ρ0) Σ_j (Δλ_i + Δλ_j + s_corr) ∇W_ij + Δλ_i Σ_b Ψ_b ∇W_ib (a gather into
  /// a second buffer), combined with the previous iterate by the Chebyshev weight ω and
  /// swept out of the solids; λ follows the same combination.
  std::size_t correct(StepContext& c, std::vector<Real>& lambda, Real omega) {
    Particles& P = c.P;
    const Spiky<Real> S(c.R);
    const Real invR = Real(1) / c.R, wK = S.c * c.R * c.R * c.R, gK = Real(-3) * S.c * c.R * c.R;
    const Real Vg = c.mass / c.rho0 * gK;
    const bool tensile = sCorrScale_ != 0;
    const Real wRatio = wK * invWdq_;
    const int sn = tensileN_;
    const Real* L = dLambda_.data();
    const bool cheb = omega != Real(1);
    xNew_.resize(P.size());
    const std::size_t first = firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      const Real* cache = gCache_[b / kBlock].data();
      std::size_t bad = kNone;
      for (std::size_t i = b; i < e; ++i) {
        const std::uint32_t cnt = c.nbr.count[i];
        const std::uint32_t* nb = c.nbr.of(i);
        const Real* gc = cache + c.nbr.start[i];
        const Real li = L[i];
        Real tx = 0, ty = 0;
        for (std::uint32_t k = 0; k < cnt; ++k) {
          const std::uint32_t j = nb[k];
          Real dx, dy, q2;
          pairDelta(c, i, j, dx, dy, q2);
          Real f = li + L[j];
          if (tensile) {
            const Real a = std::max(Real(0), Real(1) - std::sqrt(q2) * invR);
            const Real ratio = wRatio * a * a * a;  // W(r)/W(Δq)
            Real p = ratio;
            for (int t = 1; t < sn; ++t) p *= ratio;
            f += sCorrScale_ * p;
          }
          f *= gc[k];
          tx += f * dx;
          ty += f * dy;
        }
        const Vec2 d = Vec2(Vg * tx, Vg * ty) + wallGrad_[i] * li;
        const Vec2 x0 = P.x[i];
        Vec2 x = x0 + d;
        const Real lk = lambda[i];
        if (cheb) {
          x = xOld_[i] + (x - xOld_[i]) * omega;
          lambda[i] = lOld_[i] + (lk + li - lOld_[i]) * omega;
        } else {
          lambda[i] = lk + li;
        }
        lOld_[i] = lk;
        if (c.nbr.boundaryCount[i]) {
          Vec2 vd = Vec2::Zero();
          c.boundary.resolve(x, vd, x0, c.clearance);
        }
        xNew_[i] = x;
        if (bad == kNone && !allFinite(x)) bad = i;
      }
      return bad;
    });
    // x^{k−1} ← x^k, x^k ← x^{k+1}: buffers rotate, nothing is copied.
    xOld_.swap(P.x);
    P.x.swap(xNew_);
    return first;
  }

  /// ρ of the final positions (what the World reports), 1/ρ, p = −ρ0 λ/dt². Caches W_ij/wK for XSPH.
  std::size_t finalDensity(StepContext& c, Real dt) {
    Particles& P = c.P;
    const BoundarySet& B = c.boundary;
    const Spiky<Real> S(c.R);
    const Real invR = Real(1) / c.R, wK = S.c * c.R * c.R * c.R;
    const std::vector<Real>* lam = P.find("pbf.lambda");
    const Real pK = dt > 0 ? -c.rho0 / (dt * dt) : Real(0);
    gCache_.resize(c.nbr.perBlock.size());
    return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      std::vector<Real>& cache = gCache_[b / kBlock];
      const std::size_t need = c.nbr.perBlock[b / kBlock].size();
      if (cache.size() < need) cache.resize(need);
      std::size_t bad = kNone;
      const Vec2* X = P.x.data();
      for (std::size_t i = b; i < e; ++i) {
        const std::uint32_t cnt = c.nbr.count[i];
        const std::uint32_t* nb = c.nbr.of(i);
        Real* wc = cache.data() + c.nbr.start[i];
        const Real xix = X[i].x(), xiy = X[i].y();
        Real w = 1;
        for (std::uint32_t k = 0; k < cnt; ++k) {
          Real dx = xix - X[nb[k]].x(), dy = xiy - X[nb[k]].y();
          c.periodic.nearest(dx, dy);
          const Real a = std::max(Real(0), Real(1) - std::sqrt(dx * dx + dy * dy) * invR);
          wc[k] = a * a * a;
          w += wc[k];
        }
        Real rho = c.mass * wK * w;
        const std::uint32_t bc = c.nbr.boundaryCount[i];
        if (bc) {
          const std::uint32_t* bl = c.nbr.boundaryOf(i);
          Real bw = 0;
          for (std::uint32_t k = 0; k < bc; ++k) {
            const std::uint32_t s = bl[k];
            const Real a = std::max(Real(0), Real(1) - std::sqrt((P.x[i] - B.samples[s]).squaredNorm()) * invR);
            bw += B.volume[s] * a * a * a;
          }
          rho += c.rho0 * wK * bw;
        }
        const Real p = lam ? std::max(Real(0), pK * (*lam)[i]) : Real(0);
        P.rho[i] = rho;
        P.invRho[i] = Real(1) / rho;
        P.p[i] = p;
        P.pOverRho[i] = p * P.invRho[i];
        if (bad == kNone && !std::isfinite(rho)) bad = i;
      }
      return bad;
    });
  }

  /// v = (x* − x)/dt, then XSPH v_i += c Σ_j (m/ρ_j)(v_j − v_i) W_ij (a gather into a copy).
  std::size_t velocity(StepContext& c) {
    Particles& P = c.P;
    const Real invDt = Real(1) / c.dt, vmax2 = c.maxSpeed * c.maxSpeed;
    const Vec2* X = P.x.data();
    const Vec2* X0 = P.xPrev.data();
    const Real* IR = P.invRho.data();
    const Spiky<Real> S(c.R);
    const Real cm = xsph_ * c.mass * S.c * c.R * c.R * c.R;
    vNew_.resize(P.size());
    const std::size_t first = firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      const Real* cache = gCache_[b / kBlock].data();
      std::size_t bad = kNone;
      for (std::size_t i = b; i < e; ++i) {
        const Vec2 vi = (X[i] - X0[i]) * invDt;
        Vec2 v = vi;
        if (cm > 0) {
          const std::uint32_t* nb = c.nbr.of(i);
          const std::uint32_t cnt = c.nbr.count[i];
          const Real* wc = cache + c.nbr.start[i];
          Real sx = 0, sy = 0;
          for (std::uint32_t k = 0; k < cnt; ++k) {
            const std::uint32_t j = nb[k];
            const Real f = wc[k] * IR[j];
            sx += f * ((X[j].x() - X0[j].x()) * invDt - vi.x());
            sy += f * ((X[j].y() - X0[j].y()) * invDt - vi.y());
          }
          v += Vec2(sx, sy) * cm;
        }
        vNew_[i] = v;
        if (bad == kNone && (!allFinite(v) || v.squaredNorm() > vmax2)) bad = i;
      }
      return bad;
    });
    P.v.swap(vNew_);
    return first;
  }

  int iterations_, maxIterations_;
  Real tolerance_, toleranceMax_, relaxation_, chebyshev_, tensileK_;
  int tensileN_;
  Real tensileDq_, xsph_, maxDt_, maxMove_;

  Real d0_ = 0, eps_ = 0, invWdq_ = 0, sCorrScale_ = 0;
  Real meanCompression_ = 0, maxCompression_ = 0;
  SolverStats stats_;
  Real dtLimit_ = std::numeric_limits<Real>::infinity();  ///< shortened while the iterations do not converge
  std::vector<Real> dLambda_, lOld_;
  std::vector<Vec2> wallGrad_;             ///< the boundary part of ∇_i C_i
  std::vector<double> blockErr_;           ///< compression per block (fixed-order sum)
  std::vector<Real> blockMax_;             ///< largest compression per block
  std::vector<std::vector<Real>> gCache_;  ///< per pair, laid out like NeighbourLists
  std::vector<Vec2> xNew_, vNew_, xOld_;
};

}  // namespace

/// pbf's registration (solvers.def) and its parameters.
SolverInfo pbfSolver() {
  return {"pbf",
          {{"iterations", 4, 1, 1000, "Jacobi iterations of the density constraint per substep, at least (integer)"},
           {"max_iterations", 100, 1, 1000, "iterations per substep, at most (integer); unconverged: shorter substeps"},
           {"tolerance", 0.01, 0, 1, "stop once mean(max(ρ/ρ0 − 1, 0)) ≤ this … (0: exactly `iterations`)"},
           {"tolerance_max", 0.05, 0.001, 10, "… and the largest compression max(ρ/ρ0 − 1) ≤ this"},
           {"relaxation", 0.5, 0, 100, "ε of the constraint denominator, in units of its value on a full rest lattice"},
           {"chebyshev", 0.9, 0, 0.99, "Chebyshev acceleration: spectral radius estimate ρ (0: plain Jacobi)"},
           {"tensile_k", 0, 0, 1, "s_corr strength k, in multipliers of a unit density error (0: off)"},
           {"tensile_n", 4, 1, 8, "s_corr exponent n (integer)"},
           {"tensile_dq", 0.2, 0.01, 0.9, "s_corr reference distance Δq, in units of the support R"},
           {"xsph", 0.01, 0, 1, "XSPH velocity smoothing c"},
           {"max_dt", 1.0 / 60.0, 1e-5, 0.1, "largest substep (s)"},
           {"max_move", 1, 0.05, 10, "dt ≤ max_move · R / v_max: largest move per substep, in support radii"}},
          [](const SolverDef& d) -> std::unique_ptr<Solver> { return std::make_unique<Pbf>(d); }};
}

}  // namespace sph2d
