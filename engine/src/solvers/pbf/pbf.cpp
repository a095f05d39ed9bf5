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
// The game solver ("game" in solvers.def, quality "game") is this code with the
// defaults of pbfParams(true) and support 2 dx, no viscosity: 1 to 4 iterations
// a substep under a tolerance band, then local iterations over the particles still
// compressed (an active list); a substep set by a speed quantile and a per-particle
// move cap instead of the fastest particle; corrections that move positions only;
// and, before the prediction, the coarse-grid pressure projection of the
// velocities (grid_projection.hpp: Hybrid SPH, Raveendran et al. 2011), which
// carries the long hydrostatic mode that Jacobi iterations reach only slowly.
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

#include "grid_projection.hpp"
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
  /// Lanes below `valid` from a, the rest from b.
  static Lane4 firstLanes(unsigned valid, Lane4 a, Lane4 b) {
    const __m128 m = _mm_castsi128_ps(_mm_cmplt_epi32(_mm_set_epi32(3, 2, 1, 0), _mm_set1_epi32(int(valid))));
    return {_mm_or_ps(_mm_and_ps(m, a.v), _mm_andnot_ps(m, b.v))};
  }
  /// Bit l set where lane l of a < b.
  static int less(Lane4 a, Lane4 b) { return _mm_movemask_ps(_mm_cmplt_ps(a.v, b.v)); }
  /// The x and y of X[j[0..3]] (pairs of floats), one 64-bit load each.
  static void gatherXY(const float* xy, const std::uint32_t* j, Lane4& xs, Lane4& ys) {
    const __m128 a = _mm_loadh_pi(_mm_castpd_ps(_mm_load_sd(reinterpret_cast<const double*>(xy + 2 * std::size_t(j[0])))),
                                  reinterpret_cast<const __m64*>(xy + 2 * std::size_t(j[1])));
    const __m128 b = _mm_loadh_pi(_mm_castpd_ps(_mm_load_sd(reinterpret_cast<const double*>(xy + 2 * std::size_t(j[2])))),
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
  friend Lane4 operator+(Lane4 a, Lane4 b) { return map(a, b, [](float x, float y) { return x + y; }); }
  friend Lane4 operator-(Lane4 a, Lane4 b) { return map(a, b, [](float x, float y) { return x - y; }); }
  friend Lane4 operator*(Lane4 a, Lane4 b) { return map(a, b, [](float x, float y) { return x * y; }); }
  friend Lane4 operator/(Lane4 a, Lane4 b) { return map(a, b, [](float x, float y) { return x / y; }); }
  static Lane4 sqrt(Lane4 a) { return {{std::sqrt(a.v[0]), std::sqrt(a.v[1]), std::sqrt(a.v[2]), std::sqrt(a.v[3])}}; }
  // _mm_max_ps(a, b) returns b when either is NaN: so does this.
  static Lane4 max(Lane4 a, Lane4 b) { return map(a, b, [](float x, float y) { return x > y ? x : y; }); }
  static Lane4 firstLanes(unsigned valid, Lane4 a, Lane4 b) {
    return {{valid > 0 ? a.v[0] : b.v[0], valid > 1 ? a.v[1] : b.v[1], valid > 2 ? a.v[2] : b.v[2], valid > 3 ? a.v[3] : b.v[3]}};
  }
  static int less(Lane4 a, Lane4 b) {
    return (a.v[0] < b.v[0]) | ((a.v[1] < b.v[1]) << 1) | ((a.v[2] < b.v[2]) << 2) | ((a.v[3] < b.v[3]) << 3);
  }
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

class Pbf final : public Solver {
 public:
  explicit Pbf(const SolverDef& d)
      : name_(d.type == "game" ? "game" : "pbf"),
        iterations_(int(std::lround(d.param("iterations")))),
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
        maxMove_(Real(d.param("max_move"))),
        toVelocity_(Real(d.param("correction_to_velocity"))), adaptiveDt_(d.param("adaptive_dt") != 0),
        quantile_(Real(d.param("speed_quantile"))), moveCap_(Real(d.param("move_cap"))),
        localIterations_(int(std::lround(d.param("local_iterations")))), resolveEach_(d.param("resolve_each") != 0) {
    if (d.param("grid_cell") > 0)
      projection_ = std::make_unique<GridProjection>(Real(d.param("grid_cell")), Real(d.param("grid_fluid_fraction")),
                                                     Real(d.param("grid_compression_rate")), Real(d.param("grid_tolerance")),
                                                     int(std::lround(d.param("grid_max_iterations"))));
    if (projection_) projection_->pic_ = Real(d.param("grid_pic"));
  }

  const char* name() const override { return name_; }
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
    if (quantile_ > 0 && c.P.size() > 0) vmax = robustSpeed(c);
    if (vmax > 0) dt = std::min(dt, maxMove_ * c.R / vmax);
    return dt;
  }

  /// The speed that at most speed_quantile of the particles exceed (at least
  /// one particle may): spray does not set everyone's substep; predict caps
  /// the few faster particles' move instead.
  Real robustSpeed(const StepContext& c) const {
    const Particles& P = c.P;
    const std::size_t n = P.size();
    std::vector<Real>& s = speedScratch_;
    s.resize(n);
    c.pool.parallelFor(n, kStreamBlock, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) s[i] = P.v[i].squaredNorm();
    });
    const std::size_t skip = std::min(n - 1, std::size_t(double(quantile_) * double(n)));
    std::nth_element(s.begin(), s.begin() + std::ptrdiff_t(n - 1 - skip), s.end());
    return std::sqrt(s[n - 1 - skip]);
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
    if (projection_) {
      s.push_back(plainStage("predict_velocity", [](StepContext& c) {
        c.pool.parallelFor(c.P.size(), kStreamBlock, [&](std::size_t b, std::size_t e) {
          for (std::size_t i = b; i < e; ++i) {
            c.P.v[i] = c.P.v[i] + c.P.a[i] * c.dt;
            c.P.a[i] = Vec2::Zero();  // in v now; predict adds nothing more
          }
        });
      }));
      s.push_back(Stage{"grid_projection", [this](StepContext& c) { return projection_->project(c); }});
    }
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
      if (k >= iterations_ && (localIterations_ > 0 ? meanCompression_ <= tolerance_ : converged())) break;
      // Chebyshev weights (Wang 2015): ω1 = 1, ω2 = 2/(2 − ρ²), ω_{k+1} = 4/(4 − ρ²ω_k).
      omega = k == 0 ? Real(1) : k == 1 ? Real(2) / (Real(2) - rho2) : Real(4) / (Real(4) - rho2 * omega);
      const std::size_t badC = correct(c, lambda, omega);
      if (badC != kNone) return badC;
    }
    // Local iterations: only the particles near a compression above tolerance_max
    // (and their neighbours) take further Jacobi steps; the rest keep their place.
    int local = 0;
    if (localIterations_ > 0 && maxCompression_ > toleranceMax_) {
      active_.resize(n);
      halo_.resize(n);
      const Real thr = Real(0.5) * toleranceMax_;
      const bool pending = used < maxIt;  // the last constraint pass's step is not applied yet
      if (!pending) {
        const std::size_t bad = constraint(c, lambda);
        if (bad != kNone) return bad;
      }
      for (; local < localIterations_ && maxCompression_ > toleranceMax_; ++local) {
        // Active: compressed above half the tolerance, or next to such a particle.
        c.pool.parallelFor(n, kBlock, [&](std::size_t b, std::size_t e) {
          for (std::size_t i = b; i < e; ++i) {
            bool on = c.P.rho[i] > c.rho0 * (Real(1) + thr);
            const std::uint32_t* nb = c.nbr.of(i);
            for (std::uint32_t k = 0; k < c.nbr.count[i] && !on; ++k) on = c.P.rho[nb[k]] > c.rho0 * (Real(1) + thr);
            active_[i] = on;
          }
        });
        activeList_.clear();
        for (std::size_t i = 0; i < n; ++i)
          if (active_[i]) activeList_.push_back(std::uint32_t(i));
        for (std::size_t i = 0; i < n; ++i)  // only the listed particles take their step of the last pass
          if (!active_[i]) dLambda_[i] = 0;
        std::size_t bad = correct(c, lambda, Real(1), &activeList_);
        if (bad != kNone) return bad;
        bad = constraint(c, lambda, &activeList_);
        if (bad != kNone) return bad;
      }
    }
    if (local > 0) {
      // The local iterations moved the listed particles: the density of those and of
      // their neighbours is summed again (the rest kept ρ and W of the last full pass).
      c.pool.parallelFor(n, kBlock, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
          bool on = active_[i] != 0;
          const std::uint32_t* nb = c.nbr.of(i);
          for (std::uint32_t k = 0; k < c.nbr.count[i] && !on; ++k) on = active_[nb[k]] != 0;
          halo_[i] = on;
        }
      });
      activeList_.clear();
      for (std::size_t i = 0; i < n; ++i)
        if (halo_[i]) activeList_.push_back(std::uint32_t(i));
      const std::size_t bad = constraint(c, lambda, &activeList_);
      if (bad != kNone) return bad;
      rhoCurrent_ = true;  // every ρ (and W) is that of the current positions again
    }
    stats_.pressureIterations = used + local;  // corrections applied
    stats_.densityError = double(meanCompression_);
    if (tolerance_ > 0 && adaptiveDt_) {
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
    const Real capSpeed = moveCap_ > 0 ? moveCap_ * maxMove_ * c.R / dt : Real(0), capSpeed2 = capSpeed * capSpeed;
    return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      std::size_t bad = kNone;
      for (std::size_t i = b; i < e; ++i) {
        Vec2 v = P.v[i] + P.a[i] * dt;
        if (capSpeed2 > 0) {
          const Real s2 = v.squaredNorm();
          if (s2 > capSpeed2) v *= std::sqrt(capSpeed2 / s2);
        }
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

  /// Density of x*, the constraint and the multiplier step Δλ_i (keeping λ ≤ 0); the
  /// mean compression. Caches the spiky gradient factor per pair (∇W = gK g d) and
  /// the wall part of ∇_i C_i for correct() (same positions).
  /// With `list` (a local iteration), only the listed particles; the mean is then not updated.
  std::size_t constraint(StepContext& c, const std::vector<Real>& lambda, const std::vector<std::uint32_t>* list = nullptr) {
    Particles& P = c.P;
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
    const std::size_t first = c.pool.reduce(count, step, kNone, [&](std::size_t b, std::size_t e) {
      std::size_t bad = kNone;
      double err = 0;
      Real worst = 0;
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
          if (!periodic) {
            // Four neighbours at once; lanes past the list read particle i and become
            // pairs outside the support (r² = 4R², d = 0).
            std::uint32_t js[4] = {nb[k], valid > 1 ? nb[k + 1] : std::uint32_t(i), valid > 2 ? nb[k + 2] : std::uint32_t(i),
                                   valid > 3 ? nb[k + 3] : std::uint32_t(i)};
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
          gxv.store(gx4);
          gyv.store(gy4);
          const Lane4 a3 = a * a * a;
          a3.store(w4);
          for (std::uint32_t l = 0; l < valid; ++l) {  // only i's own entries (a local pass runs particles in any order)
            gc[k + l] = Grad{gx4[l], gy4[l]};
            wc[k + l] = w4[l];
          }
          sw = sw + a3;
          sx = sx + gxv;
          sy = sy + gyv;
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
        const Real C = rho / c.rho0 - Real(1);
        const Real D = gix * gix + giy * giy + g2;
        const Real scale = rho > c.rho0 ? c.rho0 / rho : Real(1);
        const Real lOld = lambda[i];
        const Real lNew = std::min(Real(0), lOld - scale * C / (D + eps_));
        dLambda_[i] = lNew - lOld;
        P.rho[i] = rho;
        err += double(std::max(Real(0), C));
        worst = std::max(worst, C);
        if (bad == kNone && !std::isfinite(lNew)) bad = i;
      }
      blockErr_[b / step] = err;
      blockMax_[b / step] = worst;
      return bad;
    }, [](std::size_t a, std::size_t b2) { return std::min(a, b2); });
    double sum = 0;
    Real mx = 0;
    for (std::size_t k = 0; k < parts; ++k) {  // in block order: the same for any thread count
      sum += blockErr_[k];
      mx = std::max(mx, blockMax_[k]);
    }
    if (!list) meanCompression_ = Real(sum / double(P.size()));
    maxCompression_ = mx;
    rhoCurrent_ = list == nullptr;  // a full pass: ρ and W are those of the current positions
    return first;
  }

  /// x*_i += (m/ρ0) Σ_j (Δλ_i + Δλ_j + s_corr) ∇W_ij + Δλ_i Σ_b Ψ_b ∇W_ib (a gather into
  /// a second buffer), combined with the previous iterate by the Chebyshev weight ω and
  /// swept out of the solids; λ follows the same combination.
  /// With `list` (a local iteration): only the listed particles move, in place (the
  /// pass reads no neighbour position), and without Chebyshev.
  std::size_t correct(StepContext& c, std::vector<Real>& lambda, Real omega, const std::vector<std::uint32_t>* list = nullptr) {
    Particles& P = c.P;
    const Spiky<Real> S(c.R);
    const Real wK = S.c * c.R * c.R * c.R, gK = Real(-3) * S.c * c.R * c.R;
    const Real invVg = Real(1) / -(c.mass / c.rho0 * gK);
    const bool tensile = sCorrScale_ != 0;
    const Real wRatio = wK * invWdq_;
    const int sn = tensileN_;
    const Real* L = dLambda_.data();
    const bool cheb = omega != Real(1);
    xNew_.resize(P.size());
    const std::size_t count = list ? list->size() : P.size();
    const std::size_t step = list ? kLocalBlock : kBlock;
    const std::size_t first = c.pool.reduce(count, step, kNone, [&](std::size_t b, std::size_t e) {
      std::size_t bad = kNone;
      for (std::size_t idx = b; idx < e; ++idx) {
        const std::size_t i = list ? (*list)[idx] : idx;
        const std::uint32_t cnt = c.nbr.count[i];
        const std::uint32_t* nb = c.nbr.of(i);
        const Grad* gc = gradCache_[i / kBlock].data() + c.nbr.start[i];
        const Real li = L[i];
        Real tx = 0, ty = 0;
        for (std::uint32_t k = 0; k < cnt; ++k) {
          const std::uint32_t j = nb[k];
          Real f = li + L[j];
          if (tensile) {
            // s_corr = −k (W(r)/W(Δq))^n; |G_ij| = V gK a²/r·r gives a back.
            const Real gr = std::sqrt(gc[k].x * gc[k].x + gc[k].y * gc[k].y) * invVg;  // a²
            const Real a = std::sqrt(gr);
            const Real ratio = wRatio * a * a * a;  // W(r)/W(Δq)
            Real p = ratio;
            for (int t = 1; t < sn; ++t) p *= ratio;
            f += sCorrScale_ * p;
          }
          tx += f * gc[k].x;
          ty += f * gc[k].y;
        }
        const Vec2 d = Vec2(tx, ty) + wallGrad_[i] * li;
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
        if (resolveEach_ && c.nbr.boundaryCount[i]) {
          Vec2 vd = Vec2::Zero();
          c.boundary.resolve(x, vd, x0, c.clearance);
        }
        (list ? P.x[i] : xNew_[i]) = x;
        if (bad == kNone && !allFinite(x)) bad = i;
      }
      return bad;
    }, [](std::size_t a, std::size_t b2) { return std::min(a, b2); });
    rhoCurrent_ = false;
    if (list) return first;
    // x^{k−1} ← x^k, x^k ← x^{k+1}: buffers rotate, nothing is copied.
    xOld_.swap(P.x);
    P.x.swap(xNew_);
    return first;
  }

  /// The pressure reported for particle i: −ρ0 λ_i/dt² of the constraint, plus ρ0 κ of the
  /// grid projection when there is one (it carries the hydrostatic part).
  Real pressure(const StepContext& c, const std::vector<Real>* lam, Real pK, std::size_t i) const {
    Real p = lam ? std::max(Real(0), pK * (*lam)[i]) : Real(0);
    if (projection_) p += c.rho0 * std::max(Real(0), projection_->kappaAt(c.P.x[i]));
    return p;
  }

  /// ρ of the final positions (what the World reports), 1/ρ, p (pressure()). Caches W_ij/wK for XSPH.
  std::size_t finalDensity(StepContext& c, Real dt) {
    Particles& P = c.P;
    if (rhoCurrent_) {  // the last constraint pass already summed ρ (and cached W) at these positions
      const std::vector<Real>* lam = P.find("pbf.lambda");
      const Real pK = dt > 0 ? -c.rho0 / (dt * dt) : Real(0);
      c.pool.parallelFor(P.size(), kStreamBlock, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
          const Real p = pressure(c, lam, pK, i);
          P.invRho[i] = Real(1) / P.rho[i];
          P.p[i] = p;
          P.pOverRho[i] = p * P.invRho[i];
        }
      });
      return kNone;
    }
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
        const Real p = pressure(c, lam, pK, i);
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
    const Real kc = toVelocity_;
    const Vec2* V0 = P.v.data();
    // The velocity of particle j: from its move (PBF), or its predicted velocity
    // plus a share kc of the correction's (kc < 1: corrections move positions only).
    auto vel = [&](std::size_t j) -> Vec2 {
      if (kc == Real(0)) return V0[j];  // corrections moved positions only
      const Vec2 moved = (X[j] - X0[j]) * invDt;
      return kc == Real(1) ? moved : Vec2(V0[j] + (moved - V0[j]) * kc);
    };
    const std::size_t first = firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      const Real* cache = cm > 0 ? gCache_[b / kBlock].data() : nullptr;
      std::size_t bad = kNone;
      for (std::size_t i = b; i < e; ++i) {
        const Vec2 vi = vel(i);
        Vec2 v = vi;
        if (cm > 0) {
          const std::uint32_t* nb = c.nbr.of(i);
          const std::uint32_t cnt = c.nbr.count[i];
          const Real* wc = cache + c.nbr.start[i];
          Real sx = 0, sy = 0;
          for (std::uint32_t k = 0; k < cnt; ++k) {
            const std::uint32_t j = nb[k];
            const Real f = wc[k] * IR[j];
            if (kc == Real(1)) {
              sx += f * ((X[j].x() - X0[j].x()) * invDt - vi.x());
              sy += f * ((X[j].y() - X0[j].y()) * invDt - vi.y());
            } else {
              const Vec2 vj = vel(j);
              sx += f * (vj.x() - vi.x());
              sy += f * (vj.y() - vi.y());
            }
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

  const char* name_;  ///< "pbf" or "game" (the same method, registered with other defaults)
  int iterations_, maxIterations_;
  Real tolerance_, toleranceMax_, relaxation_, chebyshev_, tensileK_;
  int tensileN_;
  Real tensileDq_, xsph_, maxDt_, maxMove_, toVelocity_;
  bool adaptiveDt_;
  Real quantile_, moveCap_;
  int localIterations_;
  bool resolveEach_;
  std::vector<std::uint8_t> active_;
  std::vector<std::uint32_t> activeList_;
  std::vector<std::uint8_t> halo_;
  static constexpr std::size_t kLocalBlock = 32;  ///< particles per job of a local iteration (few, clustered)
  mutable std::vector<Real> speedScratch_;
  std::unique_ptr<GridProjection> projection_;  ///< the coarse-grid projection (grid_cell > 0)

  Real d0_ = 0, eps_ = 0, invWdq_ = 0, sCorrScale_ = 0;
  Real meanCompression_ = 0, maxCompression_ = 0;
  bool rhoCurrent_ = false;  ///< the last constraint pass saw every particle at its current position
  SolverStats stats_;
  Real dtLimit_ = std::numeric_limits<Real>::infinity();  ///< shortened while the iterations do not converge
  std::vector<Real> dLambda_, lOld_;
  std::vector<Vec2> wallGrad_;             ///< the boundary part of ∇_i C_i
  std::vector<double> blockErr_;           ///< compression per block (fixed-order sum)
  std::vector<Real> blockMax_;             ///< largest compression per block
  std::vector<std::vector<Real>> gCache_;  ///< per pair W/wK (final density, XSPH), laid out like NeighbourLists
  struct Grad {
    Real x, y;
  };
  std::vector<std::vector<Grad>> gradCache_;  ///< per pair G_ij = (m/ρ0)∇W_ij of the last constraint pass
  std::vector<Vec2> xNew_, vNew_, xOld_;
};

}  // namespace

/// pbf's registration (solvers.def) and its parameters.
/// The parameters of pbf and of game (the same method; game's defaults make it real-time).
std::vector<SolverParam> pbfParams(bool game) {
  auto g = [game](double classic, double realtime) { return game ? realtime : classic; };
  return {
      {"iterations", g(4, 1), 1, 1000, "Jacobi iterations of the density constraint per substep, at least (integer)"},
      {"max_iterations", g(100, 4), 1, 1000, "iterations over all particles per substep, at most (integer)"},
      {"tolerance", 0.01, 0, 1, "stop once mean(max(ρ/ρ0 − 1, 0)) ≤ this … (0: only when nothing is compressed, so usually `max_iterations`)"},
      {"tolerance_max", g(0.05, 0.08), 0.001, 10, "… and the largest compression max(ρ/ρ0 − 1) ≤ this"},
      {"local_iterations", g(0, 40), 0, 1000,
       "then at most this many iterations on the particles near a compression above tolerance_max (and their neighbours)"},
      {"relaxation", 0.5, 0, 100, "ε of the constraint denominator, in units of its value on a full rest lattice"},
      {"chebyshev", 0.9, 0, 0.99, "Chebyshev acceleration: spectral radius estimate ρ (0: plain Jacobi)"},
      {"tensile_k", 0, 0, 1, "s_corr strength k, in multipliers of a unit density error (0: off)"},
      {"tensile_n", 4, 1, 8, "s_corr exponent n (integer)"},
      {"tensile_dq", 0.2, 0.01, 0.9, "s_corr reference distance Δq, in units of the support R"},
      {"xsph", 0.01, 0, 1, "XSPH velocity smoothing c"},
      {"max_dt", 1.0 / 60.0, 1e-5, 0.1, "largest substep (s)"},
      {"max_move", g(1, 2), 0.05, 10, "dt ≤ max_move · R / v_speed: largest move per substep, in support radii"},
      {"speed_quantile", g(0, 0.002), 0, 0.1,
       "v_speed is the speed this share of the particles exceeds (0: the largest): spray does not set the substep"},
      {"move_cap", g(0, 1.5), 0, 100, "> 0: no particle moves more than move_cap · max_move · R in a substep (its speed is cut)"},
      {"adaptive_dt", g(1, 0), 0, 1, "1: shorter substeps while max_iterations end above the tolerances"},
      {"correction_to_velocity", g(1, 0), 0, 1, "share of the density correction's move that becomes velocity"},
      {"resolve_each", 1, 0, 1, "1: every correction is swept out of the solids (0: the World's collision after the substep)"},
      {"grid_cell", g(0, 2), 0, 16, "coarse-grid projection (Hybrid SPH): cell size in spacings (0: none)"},
      {"grid_fluid_fraction", g(0.5, 0.15), 0.01, 1,
       "a grid cell is fluid above this fraction of a full cell's particle weight (low: the surface's cells count, and a pool comes to rest)"},
      {"grid_compression_rate", 0, 0, 1, "share of a grid cell's mean compression its velocity removes per substep"},
      {"grid_tolerance", 1e-3, 1e-7, 1, "grid solve: the density change per substep its largest residual may stand for"},
      {"grid_max_iterations", 200, 1, 10000, "grid solve: conjugate-gradient iterations at most"},
      {"grid_pic", g(0, 0.05), 0, 1, "share of the projected grid velocity the particles take (PIC; the rest is the FLIP change)"},
  };
}

/// pbf's registration (solvers.def): classic Position Based Fluids.
SolverInfo pbfSolver() {
  return {"pbf", pbfParams(false), [](const SolverDef& d) -> std::unique_ptr<Solver> { return std::make_unique<Pbf>(d); }};
}

/// game's registration (solvers.def): pbf with the coarse-grid projection, local
/// iterations and a robust substep, the real-time end (docs/PERFORMANCE.md).
SolverInfo gameSolver() {
  return {"game", pbfParams(true), [](const SolverDef& d) -> std::unique_ptr<Solver> { return std::make_unique<Pbf>(d); },
          [](SolverDef& d) {
            d.viscosity = 0;      // XSPH smooths; an explicit viscosity would limit the substep
            d.supportRatio = 2;   // 8 neighbours at rest: measured as accurate as 2.5 here, at half the pairs
          }};
}

}  // namespace sph2d
