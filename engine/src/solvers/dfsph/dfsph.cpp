// dfsph — Divergence-free SPH (Bender & Koschier 2015, "Divergence-free
// smoothed particle hydrodynamics", SCA; and 2017, "Divergence-free SPH for
// incompressible and viscous fluids", IEEE TVCG). An implicit pressure
// solver: two iterative solves per substep make the velocity field
// divergence-free and the predicted density equal to ρ0, instead of an
// equation of state with a stiffness (solver.sound_speed is not used).
//
// Substep: grid → neighbours → density (Wendland C2 summation, boundary
// samples as frozen fluid of mass ρ0Ψ_b) and the factor
//   α_i = ρ_i / (|Σ_j m∇W_ij + Σ_b ρ0Ψ_b∇W_ib|² + Σ_j |m∇W_ij|²)
// (0 when the denominator is tiny: an isolated particle) → divergence-free
// solve on v → a = gravity + the scene's effects, v* = v + dt a →
// constant-density solve on v* → x += dt v (the World then collides).
//
// Both solves iterate the same two gathers:
//   A: the source s_i — the predicted density error ρ*_i − ρ0 with
//      ρ*_i = ρ_i + dt Dρ_i/Dt (the divergence solve: Dρ_i/Dt itself), where
//      Dρ_i/Dt = Σ_j m (v_i − v_j)·∇W_ij + Σ_b ρ0Ψ_b v_i·∇W_ib (walls at rest);
//      the increment δκ_i = ω s_i α_i / dt² (divergence: ω s_i α_i / dt);
//      the residual, summed per block;
//   B: v_i −= dt [Σ_j m (δκ_i/ρ_i + δκ_j/ρ_j) ∇W_ij + Σ_b ρ0Ψ_b (δκ_i/ρ_i) ∇W_ib],
//      κ_i += δκ_i.
// Walls mirror the particle's κ with the paper's (and SPlisHSPlasH's)
// single term δκ_i/ρ_i: then the velocity update is the adjoint of the
// density prediction, so a converged solve only removes energy. (Measured on
// the resting column: the symmetric-looking 2δκ_i/ρ_i, with or without
// Adami-style hydrostatic extrapolation, holds the true pressure ρgH at the
// floor, but the warm start then adds energy and the tank churns at
// 0.04–0.2 m/s; with the single term it rests at ~0.01 m/s, and the
// wall-row pressure reads about 1.4 ρgH.)
// Relaxation ω (solver.relaxation, default 0.5): plain Jacobi (ω = 1)
// diverges in 2D. α_i is the exact diagonal, but on a square lattice with
// R = 2.5 dx the largest eigenvalue of diag⁻¹·A is 2.47 (2.12 for R = 2 dx),
// so ω must stay below 0.81; 0.8 diverged on both dam breaks, 0.7 held at
// dx = 0.02, and 0.6 diverged at the floor of the 1 m tank at dx = 12.5 mm
// (the wall rows' eigenvalues are larger than the bulk's); 0.5 held there.
// Chebyshev acceleration (solver.chebyshev_rho, default 0.98; Wang 2015,
// "A Chebyshev semi-iterative approach for accelerating projective and
// position-based dynamics"): after 5 plain iterations each new iterate is
// w_k (Jacobi iterate − previous iterate) + previous iterate, for v and κ
// alike (κ clamped at 0 again), w = 2/(2 − ρ²), then 4/(4 − ρ² w); a residual
// that grows restarts it. The relaxed Jacobi stalls on smooth modes (the
// divergence residual falls ~0.6 % per iteration at rest); Chebyshev halves
// the divergence iterations of the dam break (29 → 13 per substep).
// The free surface: κ_i stays ≥ 0 (no tension). Where κ_i = 0 that is the
// paper's clamp ρ* ≥ ρ0 (δκ_i ≥ 0); where κ_i > 0 a negative δκ_i takes back
// pressure the warm start or an earlier iteration over-applied, down to 0
// (projected Jacobi for the unilateral constraint). The residual is the
// complementarity one: |s_i| where κ_i > 0, max(s_i, 0) where κ_i = 0; its
// mean must be ≤ tolerance·ρ0 (divergence: ≤ divergence_tolerance·ρ0/dt,
// the density change one substep's divergence error makes, as in
// SPlisHSPlasH), after at least min_iterations and at most max_iterations.
// The divergence tolerance used to be per second (0.01 ρ0/s): on the 20k dam
// break (1.6 ms substeps) that took 35 divergence iterations a substep, 74 %
// of the step; at 1e-4 per substep (0.06 ρ0/s there) it takes 14, the whole
// step needs half the iterations, and the mean density error is unchanged
// (the constant-density solve holds it). The Taylor–Green vortex (5.6 ms
// substeps: 0.018 ρ0/s) decays within 1.8 % as before; at 0.1 ρ0/s it was 7 %.
// With solver.clamp_negative_pressure = false (a flow with no free surface)
// κ takes either sign and every |s_i| counts. When, in addition, both axes
// are periodic and there are no walls, a constant κ is (nearly) in the null
// space of the solve, and the mean of the summation-density error is not a
// compression: each pass A then removes the mean of the source first (one
// extra reduction), or κ drifts without bound (measured: a Taylor–Green
// vortex's pressure reached −7e33 Pa).
// Warm start: each solve starts from its previous substep's κ (particle
// fields "dfsph.kappa" [m²/s², = p/ρ] and "dfsph.kappa_v" [m²/s, κ_v·dt],
// permuted with the particles on reorder), applied once before iterating.
//
// Gradients m∇W_ij are computed once per substep with the density and kept
// with the neighbour's slot per neighbour entry (same layout as
// NeighbourLists), and Σ_j m∇W_ij + Σ_b ρ0Ψ_b∇W_ib once per particle, so an
// iteration reads no positions and takes no square roots. Every pass is a
// gather over fixed blocks and every mean is a block reduction combined in
// block order: the same bits for any thread count.
//
// Time step: dt ≤ velocity_cfl·R/v_max (velocity only; solver.cfl, the other
// solvers' CFL number on c + v_max, is not read), the other solvers' force
// limit 0.25·sqrt(R/a_max) with a the non-pressure acceleration (gravity +
// effects), and dt ≤ 0.1·sqrt(R/|g|), which sets the step of a fluid at rest:
// at 0.25·sqrt(R/g) the first, cold-started steps of the resting column did
// not converge within 100 iterations and at ν ≤ 0.001 m²/s it blew up; at
// 0.1·sqrt(R/g) it rests at ν = 0. velocity_cfl defaults to 0.4: on the dam
// break (10k particles) that is 10 substeps a frame instead of 15 at 0.25,
// and the mean density error stays below 0.02 %.
// And dt ≤ 0.35·R/sqrt(|g| D), D the greatest depth of a particle below
// the highest particle of its column (strips of width R across gravity, as
// the hydrostatic warm start; gravity along a periodic axis does not count
// for either, since a body force along a periodic channel builds no
// hydrostatic pressure): the stiffness of the hydrostatic pressure
// itself. The solves make ρ* = ρ0 for the positions of this substep; how the
// pressure force changes as the particles move (∇W under a pressure
// κ ≈ |g| D, a stiffness ~ κ/R²) is explicit, a wave of speed ~ sqrt(κ), and
// at rest the other limits do not see it: at dt = 0.1·sqrt(R/g),
// dt·sqrt(gD)/R = 0.1·sqrt(D/R), which grows with the depth in supports.
// Measured on the 2 m × 1 m tank at dx = 12.5 mm (12,800 particles, ν = 0,
// R = 31 mm, D = 1 m): at dt = 0.1·sqrt(R/g) (5.6 ms: 0.57 R/sqrt(κ_max),
// κ_max ≈ 1.2 g·1 m) the rows near the floor move in alternation (even rows
// down, odd rows up: a mode the SPH divergence does not see in the bulk, so
// neither solve damps it), the pattern flips sign every substep and its
// amplitude doubles (floor row v_y +0.012, −0.024, +0.11, −0.14 m/s over the
// first four substeps, with the symmetric wall term; with the single term
// the warm start's first kick, −1.4 m/s, hides it), the floor rows are
// crushed at the collision clearance (single particles 50 % compressed) and
// the tank erupts at t ≈ 0.09 s. Halving that step (0.05·sqrt(R/g)) rests;
// so does 0.5 R/sqrt(κ_max) for 0.5 s. The coarse tank (dx = 25 mm) ran at
// 0.40 R/sqrt(κ_max) under the old limits and held. Not the cause (each
// still erupted within 0.1–0.3 s at the old step): 500–2,000 iterations, a
// tenfold tighter tolerance, chebyshev_rho = 0, the symmetric wall term
// 2δκ_i/ρ_i (with α's wall part to match), no divergence solve, no or a
// halved warm start of κ_v, ν ≤ 0.003 m²/s (ν = 0.01 held, through its own,
// smaller, viscous step limit). A first version of the limit on the largest
// κ instead of the depth let a jammed particle's κ spike shorten the step,
// and a shorter step makes the density solve push harder (the wedge test
// gained 4× its potential energy): the depth is geometric and has no such
// feedback. With the limit (0.35 ≈ 0.38 R/sqrt(κ_max) at rest) the fine
// tank runs 5 substeps a frame instead of 3 and rests like the coarse one
// (measured with a driver, not the bench: 1.5 s, no blow-up, kinetic energy
// falling from 8.6 to 4.1 J, max speed ≤ 0.46 m/s after 0.25 s, mean density
// error 0.04 %, floor rows at 1.08–1.18 ρ0 g H). The coarse tank still runs
// 3 substeps a frame (the same bits). The dam break (a 2 m column; the
// limit binds until it has collapsed) takes 294 substeps instead of 258 at
// dx = 0.02 m and 541 instead of 493 at 0.01 m (20k particles; 9.4 wall s
// per simulated s on a busy machine before the per-substep divergence
// tolerance, 4.9 in the bench after it), its mean density error unchanged
// (0.07 %, 0.05 %). Known cost: the depth runs from the highest particle of
// a column, air gaps included, so a jet or spray above a pool shortens the
// step more than the pool's own depth needs.
// A substep shorter than 1 % of the solver's own limit and of the last solved
// substep (the World's float rounding remainder of a frame, ~1e-10 s) runs
// without the solves: the density solve would correct the existing
// compression at a speed ∝ 1/dt and leave κ ∝ 1/dt for the next warm start
// (it blew up the resting column). The limit alone is not enough: without
// gravity and at rest it is velocity_cfl·R/(1e-6 R), 4·10⁵ s, so every
// frame-long substep looked like a remainder: fluid added on top of fluid at
// rest in zero gravity (the stability suite) stayed twice as dense for good.
//
// Stacked and coincident particles (200 particles created at one point, the
// stability suite). Wendland's |∇W| = |gradK|(1 − q)³ r vanishes as r → 0:
// a stacked pair adds to ρ but hardly to ∇ρ, so its α is huge, and the
// linear density prediction asks for velocities of hundreds of m/s (pairDelta's
// tie-break direction gives a coincident pair a direction of length 1e-6 R:
// a direction, but no magnitude). In a clump where every particle neighbours
// every other one the Jacobi operator also exceeds its diagonal by about the
// neighbour count: each iteration overshoots, κ ≥ 0 takes it back, and the
// solve is a 2-cycle that ends where it began (measured: velocities 0 and
// 146 m/s in turn, 100 iterations a substep, the clump 70 ρ0 dense for good).
// Three measures, none of which acts on fluid near its rest density and
// spacing (pairs closer than 0.625 dx, compression beyond 10 %):
//   1. the solves' gradient keeps the peak magnitude of |∇W| (at q = 1/4,
//      r = 0.625 dx) for closer pairs, along d (Thomas & Couchman 1992's
//      modified gradient), so a stacked pair has a direction and a magnitude;
//   2. beyond 1.1 ρ0 a particle's Jacobi step is scaled by 1.1 ρ0/ρ_i (as
//      pbf's ρ0/ρ_i: the operator's largest eigenvalue grows with compression;
//      below 1.1 ρ0 the relaxation ω = 0.5 leaves a margin of 1.6);
//   3. the constant-density solve removes compression that is already there
//      at most at a pushout speed of 3 m/s (ρ0·2·3 m/s·dt/dx a substep, Box2D
//      v3's contact pushout): at 70 ρ0 the linearised prediction is far off,
//      and the whole error in one frame-long substep flung particles at
//      800 m/s. Ordinary compression (a few %) stays far below that cap.
// Without 2 the solve stays a 2-cycle (with 1 and 3 too); without 3 the
// first substeps fling particles past the guard's 500 m/s; without 1 a
// stacked pair still can (with 2 and 3 alone, one run of four stopped at
// 670 m/s: a pair 2 neighbours strong, α 10⁴ times the bulk's). Together the
// clump spreads across the tank within 1 s (peak speeds 6–24 m/s for 50–200
// particles, three seeds each).
//
// Parameters (solver.*): tolerance, divergence_tolerance, max_iterations,
// min_iterations, relaxation, chebyshev_rho, velocity_cfl, divergence_solve. stats()
// reports the last solved substep's iterations and residuals.
#include <algorithm>
#include <cmath>
#include <limits>

#include "solvers/solver.hpp"

namespace sph2d {
namespace {

class Dfsph final : public Solver {
 public:
  /// Reads the solver.* keys listed above (the registry fills their defaults).
  explicit Dfsph(const SolverDef& d)
      : tol_(d.param("tolerance")),
        divTol_(d.param("divergence_tolerance")),
        maxIt_(int(std::lround(d.param("max_iterations")))),
        minIt_(int(std::lround(d.param("min_iterations")))),
        divSolve_(d.param("divergence_solve") != 0),
        omega_(Real(d.param("relaxation"))),
        cheb_(Real(d.param("chebyshev_rho"))),
        cfl_(Real(d.param("velocity_cfl"))),
        unilateral_(d.clampNegativePressure),
        kMin_(d.clampNegativePressure ? Real(0) : -std::numeric_limits<Real>::infinity()) {}

  /// "dfsph".
  const char* name() const override { return "dfsph"; }
  /// 0: incompressible, a column at rest has ρ0 at every depth.
  double hydrostaticFactor() const override { return 0; }
  /// Wendland C2.
  double densityKernel(double r, double R) const override { return WendlandC2<double>(R).value(r); }

  /// Creates the κ fields; density, α and gradients of the initial positions.
  void prepare(StepContext& c) override {
    std::vector<Real>& kappa = c.P.field("dfsph.kappa");
    c.P.field("dfsph.kappa_v");
    stageGrid(c, false);
    stageNeighbours(c);
    densityAndFactor(c, WendlandC2<Real>(c.R));
    hydrostaticWarmStart(c, kappa);
  }

  /// The first pressure solve's warm start: the hydrostatic κ = |g|·(depth
  /// below the highest particle of the same column, strips of width R across
  /// gravity) + |g| dx/2, and p = κρ for readers. A column starts at rest
  /// and incompressible, so this is its pressure; without it the first
  /// solves build ρ0 g H from zero, and a Jacobi iteration needs about
  /// (H/dx)² iterations for that (measured: at dx = 5 mm the 2 m dam-break
  /// column crushed its floor rows by 55 % and blew up at t = 0.06 s).
  void hydrostaticWarmStart(StepContext& c, std::vector<Real>& kappa) const {
    Particles& P = c.P;
    const Real g = hydrostaticGravity(c).norm();
    if (!(g > 0) || P.size() == 0) return;
    depths(c, [&](std::size_t i, Real depth) {
      kappa[i] = g * (depth + Real(0.5) * c.dx);
      P.p[i] = kappa[i] * P.rho[i];
    });
  }

  /// The gravity that builds a hydrostatic pressure: its components along
  /// periodic axes are dropped (a body force along a periodic channel drives
  /// a flow; the pressure does not grow along it).
  static Vec2 hydrostaticGravity(const StepContext& c) {
    Vec2 g = c.gravity;
    if (c.periodic.x) g.x() = 0;
    if (c.periodic.y) g.y() = 0;
    return g;
  }

  /// Calls f(i, depth) for every particle with its depth below the highest
  /// particle of the same column (strips of width R across the hydrostatic
  /// gravity). Needs hydrostaticGravity(c) ≠ 0.
  template <class F>
  void depths(const StepContext& c, F f) const {
    const Particles& P = c.P;
    const Vec2 gh = hydrostaticGravity(c);
    const Vec2 up = -gh / gh.norm(), across(up.y(), -up.x());
    Real sMin = std::numeric_limits<Real>::infinity(), sMax = -sMin;
    for (std::size_t i = 0; i < P.size(); ++i) {
      const Real s = across.dot(P.x[i]);
      sMin = std::min(sMin, s);
      sMax = std::max(sMax, s);
    }
    const std::size_t strips = std::min<std::size_t>(std::size_t((sMax - sMin) / c.R) + 1, 1u << 20);
    std::vector<Real>& top = topScratch_;  // reused: maxTimeStep runs this every substep
    top.assign(strips, -std::numeric_limits<Real>::infinity());
    auto strip = [&](const Vec2& x) {
      return std::min(strips - 1, std::size_t(std::max(Real(0), (across.dot(x) - sMin) / c.R)));
    };
    for (std::size_t i = 0; i < P.size(); ++i) {
      Real& t = top[strip(P.x[i])];
      t = std::max(t, up.dot(P.x[i]));
    }
    for (std::size_t i = 0; i < P.size(); ++i) f(i, top[strip(P.x[i])] - up.dot(P.x[i]));
  }

  /// velocity_cfl·R/v_max, 0.1·sqrt(R/|g|), 0.25·sqrt(R/a_max) and 0.35·R/sqrt(|g| D), whichever is least.
  Real maxTimeStep(const StepContext& c, Real vmax, Real amax) const override {
    Real dt = cfl_ * c.R / std::max(vmax, Real(1e-6) * c.R);
    const Real g = c.gravity.norm();
    if (g > 0) dt = std::min(dt, Real(0.1) * std::sqrt(c.R / g));
    if (amax > 0) dt = std::min(dt, kForceCfl * std::sqrt(c.R / amax));
    // The hydrostatic pressure's own stiffness: dt ≤ 0.35·R/sqrt(|g| D) (see the header).
    const Real gh = hydrostaticGravity(c).norm();
    if (gh > 0 && c.P.size() > 0) {
      Real dMax = 0;
      depths(c, [&](std::size_t, Real depth) { dMax = std::max(dMax, depth); });
      if (dMax > 0) dt = std::min(dt, kPressureCfl * c.R / std::sqrt(gh * dMax));
    }
    return dt;
  }

  /// grid → neighbours → density (and α) → divergence_solve → gravity → effects →
  /// predict_velocity → pressure_solve → integrate.
  std::vector<Stage> stages(bool) override {
    std::vector<Stage> s;
    s.push_back(plainStage("grid", [](StepContext& c) { stageGrid(c, reorderThisStep(c)); }));
    s.push_back(plainStage("neighbours", [](StepContext& c) { stageNeighbours(c); }));
    s.push_back(Stage{"density", [this](StepContext& c) {
                        c.P.field("dfsph.kappa");
                        c.P.field("dfsph.kappa_v");
                        closed_ = !unilateral_ && c.periodic.x && c.periodic.y && c.boundary.samples.empty();
                        stats_ = SolverStats{};
                        return densityAndFactor(c, WendlandC2<Real>(c.R));
                      }});
    if (divSolve_) s.push_back(plainStage("divergence_solve", [this](StepContext& c) { solve(c, true); }));
    s.push_back(plainStage("gravity", [](StepContext& c) {
      c.pool.parallelFor(c.P.size(), kStreamBlock, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) c.P.a[i] = c.gravity;
      });
    }));
    s.push_back(Stage::effects());
    s.push_back(plainStage("predict_velocity", [](StepContext& c) {
      c.pool.parallelFor(c.P.size(), kStreamBlock, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) c.P.v[i] += c.P.a[i] * c.dt;
      });
    }));
    s.push_back(plainStage("pressure_solve", [this](StepContext& c) { solve(c, false); }));
    s.push_back(Stage{"integrate", [this](StepContext& c) { return integrate(c); }});
    return s;
  }

  /// Iterations and residuals of the last substep.
  SolverStats stats() const override { return stats_; }

 private:
  /// ρ, 1/ρ, α, the per-neighbour (slot, m∇W_ij) and per particle Σ_j m∇W_ij + Σ_b ρ0Ψ_b∇W_ib.
  std::size_t densityAndFactor(StepContext& c, const WendlandC2<Real>& W) {
    Particles& P = c.P;
    const std::size_t n = P.size();
    const BoundarySet& B = c.boundary;
    const bool walls = !B.samples.empty();
    const NeighbourLists& L = c.nbr;
    pairs_.resize(L.perBlock.size());
    gradSum_.resize(n);
    alpha_.resize(n);
    dk_.resize(n);
    q_.resize(n);
    const Real R = c.R;
    const Real gradK = W.gradientScale;  // ∇W = gradK (1 − q)³ d
    const Real mGradK = c.mass * gradK;
    const Real aFlat = Real(1) - kFlatQ;
    const Real mGradFlat = mGradK * aFlat * aFlat * aFlat * (kFlatQ * R);  // m|∇W| at q = 1/4, times r/|d|
    const Real self = W.value(0);
    // Below this the factor's denominator means no neighbours at all (a full
    // neighbourhood gives about (ρ0/R)²).
    const Real eps = Real(1e-6) * (c.rho0 / R) * (c.rho0 / R);
    const Vec2* X = P.x.data();
    return firstBad(c.pool, n, [&](std::size_t b, std::size_t e) {
      std::size_t bad = kNone;
      std::vector<Pair>& G = pairs_[b / kBlock];
      G.resize(L.perBlock[b / kBlock].size());
      for (std::size_t i = b; i < e; ++i) {
        const std::uint32_t* nb = L.of(i);
        const std::uint32_t cnt = L.count[i];
        Pair* Gi = G.data() + L.start[i];
        Real sum = self, gx = 0, gy = 0, sq = 0;
        for (std::uint32_t k = 0; k < cnt; ++k) {
          const std::uint32_t j = nb[k];
          Real dx, dy, r2;
          pairDelta(c, i, j, dx, dy, r2);  // coincident pairs: a fixed, antisymmetric direction
          const Real r = std::sqrt(r2);
          const Real q = r * W.invR;
          const Real a = Real(1) - q;
          sum += W.valueQ(q);
          // m∇W_ij = g·d; below q = 1/4, where |∇W| peaks, the solves' gradient keeps
          // its peak magnitude along d (stacked and coincident pairs: see the header).
          const Real g = q < kFlatQ ? mGradFlat / r : mGradK * a * a * a;
          const Real gxk = g * dx, gyk = g * dy;
          Gi[k] = Pair{j, gxk, gyk};
          gx += gxk;
          gy += gyk;
          sq += gxk * gxk + gyk * gyk;
        }
        Real rho = c.mass * sum;
        Vec2 gb = Vec2::Zero();
        if (walls) {
          Real vol = 0;
          const Vec2 xi = X[i];
          const std::uint32_t* bl = L.boundaryOf(i);
          for (std::uint32_t k = 0; k < L.boundaryCount[i]; ++k) {
            const std::uint32_t s = bl[k];
            const Vec2 d = xi - B.samples[s];
            const Real q = std::sqrt(d.squaredNorm()) * W.invR;
            const Real a = Real(1) - q;
            vol += B.volume[s] * W.valueQ(q);
            gb += d * (gradK * a * a * a * B.volume[s]);
          }
          rho += c.rho0 * vol;
          gb *= c.rho0;
        }
        const Real tx = gx + gb.x(), ty = gy + gb.y();
        const Real denom = tx * tx + ty * ty + sq;
        P.rho[i] = rho;
        P.invRho[i] = Real(1) / rho;
        gradSum_[i] = Vec2(tx, ty);
        alpha_[i] = denom > eps ? rho / denom : Real(0);
        if (!std::isfinite(rho) && bad == kNone) bad = i;
      }
      return bad;
    });
  }

  /// One solve: warm start, then iterations of (B, A) until the mean error is small.
  /// divergence: the divergence-free solve (source Dρ/Dt), else the constant-density solve.
  void solve(StepContext& c, bool divergence) {
    Particles& P = c.P;
    const std::size_t n = P.size();
    std::vector<Real>& kappa = *P.find(divergence ? "dfsph.kappa_v" : "dfsph.kappa");
    const Real dt = c.dt;
    const double limit =
        divergence ? divTol_ * double(c.rho0) / double(dt) : tol_ * double(c.rho0);  // on the mean residual
    double err = 0;
    {
      // Stored κ_v is κ_v·dt of the previous substep (an impulse); κ is p/ρ.
      const Real scale = divergence ? Real(1) / dt : Real(1);
      if (cheb_ > 0) {
        vPrev_.resize(n);
        kPrev_.resize(n);
      }
      warmStart(c, kappa, scale);
      err = sourceMean(c, kappa, divergence);
    }
    int it = 0;
    if (cheb_ > 0) {
      vPrev_.assign(P.v.begin(), P.v.end());
      kPrev_.assign(kappa.begin(), kappa.end());
    }
    Real w = 1;
    int chebStart = kChebDelay;
    double lastErr = err;
    while (it < maxIt_ && (it < minIt_ || err > limit)) {
      // Chebyshev weights (Wang 2015): 1 for the first kChebDelay iterations,
      // then 2/(2 − ρ²), then 4/(4 − ρ² w).
      if (cheb_ > 0 && it >= chebStart)
        w = it == chebStart ? Real(2) / (Real(2) - cheb_ * cheb_) : Real(4) / (Real(4) - cheb_ * cheb_ * w);
      else
        w = 1;
      correctPass(c, kappa, w);
      err = sourceMean(c, kappa, divergence);
      ++it;
      // Safeguard: a residual that grows restarts the acceleration (plain steps first).
      if (cheb_ > 0 && it > chebStart && err > lastErr) chebStart = it + kChebDelay;
      lastErr = err;
    }
    if (divergence) {
      c.pool.parallelFor(n, 4096, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) kappa[i] *= dt;
      });
      stats_.divergenceIterations = it;
      stats_.divergenceError = err * double(dt) / double(c.rho0);
    } else {
      stats_.pressureIterations = it;
      stats_.densityError = err / double(c.rho0);
    }
  }

  /// v_i −= dt [Σ_j m (κ_i/ρ_i + κ_j/ρ_j) ∇W_ij + Σ_b ρ0Ψ_b (κ_i/ρ_i) ∇W_ib] with κ = scale·kappa; then kappa = κ.
  void warmStart(StepContext& c, std::vector<Real>& kappa, Real scale) {
    Particles& P = c.P;
    const std::size_t n = P.size();
    const Real* IR = P.invRho.data();
    Real* K = kappa.data();
    c.pool.parallelFor(n, 4096, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        dk_[i] = scale * K[i];
        q_[i] = dk_[i] * IR[i];
        K[i] = 0;  // correctPass adds dk_ back
      }
    });
    correctPass(c, kappa);
  }

  /// Pass A: the source of every particle, its κ increment (dk_, and dk_/ρ in q_)
  /// and the sum of the complementarity residuals, combined in block order.
  struct Sums {
    double err = 0, src = 0;
  };
  /// The mean residual of pass A; in a closed domain (closed_) the source's
  /// mean is first found by a pass with no shift, then removed.
  double sourceMean(StepContext& c, const std::vector<Real>& kappa, bool divergence) {
    const double n = double(std::max<std::size_t>(c.P.size(), 1));
    Real shift = 0;
    if (closed_) shift = Real(sourcePass(c, kappa, divergence, 0).src / n);
    return sourcePass(c, kappa, divergence, shift).err / n;
  }

  Sums sourcePass(StepContext& c, const std::vector<Real>& kappa, bool divergence, Real shift) {
    Particles& P = c.P;
    const NeighbourLists& L = c.nbr;
    const Vec2* V = P.v.data();
    const Real* K = kappa.data();
    const Real dt = c.dt, invDt = Real(1) / dt, rho0 = c.rho0;
    const Real wInvDt = omega_ * invDt, wInvDt2 = wInvDt * invDt;
    const bool unilateral = unilateral_;
    const Real kMin = kMin_;
    const Real kneeRho = kKneeDensity * rho0;
    const Real pushout = rho0 * Real(2) * kPushoutSpeed * dt / c.dx;  // [kg/m³] per substep
    return c.pool.reduce(
        P.size(), kBlock, Sums{},
        [&](std::size_t b, std::size_t e) {
          const std::vector<Pair>& G = pairs_[b / kBlock];
          double errSum = 0, srcSum = 0;
          for (std::size_t i = b; i < e; ++i) {
            const std::uint32_t cnt = L.count[i];
            const Pair* Gi = G.data() + L.start[i];
            // Σ_j m∇W_ij·(v_i − v_j) + Σ_b ρ0Ψ_b∇W_ib·v_i (walls at rest) = v_i·gradSum − Σ_j m∇W_ij·v_j.
            Real sx = 0, sy = 0;
            for (std::uint32_t k = 0; k < cnt; ++k) {
              const Vec2& vj = V[Gi[k].j];
              sx += Gi[k].gx * vj.x();
              sy += Gi[k].gy * vj.y();
            }
            const Real div = (gradSum_[i].x() * V[i].x() + gradSum_[i].y() * V[i].y()) - (sx + sy);
            Real src, dk;
            if (divergence) {
              src = div - shift;
              dk = src * alpha_[i] * wInvDt;
            } else {
              src = P.rho[i] + dt * div - rho0 - shift;
              // Compression already there is removed at most at the pushout rate.
              const Real excess = P.rho[i] - rho0 - pushout;
              if (excess > 0) src -= excess;
              dk = src * alpha_[i] * wInvDt2;
            }
            // Beyond the knee density the Jacobi step shrinks as ρ_knee/ρ_i.
            if (P.rho[i] > kneeRho) dk *= kneeRho * P.invRho[i];
            // Complementarity residual: where κ_i > 0 the constraint is active and
            // any deviation counts; where κ_i = 0 only compression does.
            errSum += double(K[i] > 0 || !unilateral ? std::fabs(src) : std::max(src, Real(0)));
            dk = std::max(dk, kMin - K[i]);  // κ stays ≥ 0: no tension at the free surface
            dk_[i] = dk;
            q_[i] = dk * P.invRho[i];
            srcSum += double(src);
          }
          return Sums{errSum, srcSum};
        },
        [](Sums a, Sums b) { return Sums{a.err + b.err, a.src + b.src}; });
  }

  /// Pass B: v_i −= dt [Σ_j (q_i + q_j) m∇W_ij + q_i Σ_b ρ0Ψ_b∇W_ib]; κ_i += dk_i
  /// (w ≠ 1: the Chebyshev step from the previous iterate).
  void correctPass(StepContext& c, std::vector<Real>& kappa, Real w = 1) {
    Particles& P = c.P;
    const NeighbourLists& L = c.nbr;
    Vec2* V = P.v.data();
    const Real* Q = q_.data();
    const Real dt = c.dt;
    const Real kMin = kMin_;
    c.pool.parallelFor(P.size(), kBlock, [&](std::size_t b, std::size_t e) {
      const std::vector<Pair>& G = pairs_[b / kBlock];
      for (std::size_t i = b; i < e; ++i) {
        const Real qi = Q[i];
        const std::uint32_t cnt = L.count[i];
        const Pair* Gi = G.data() + L.start[i];
        // Σ_j (q_i + q_j) m∇W_ij + q_i Σ_b ρ0Ψ_b∇W_ib = q_i gradSum + Σ_j q_j m∇W_ij.
        Real ax = 0, ay = 0;
        for (std::uint32_t k = 0; k < cnt; ++k) {
          const Real qj = Q[Gi[k].j];
          ax += Gi[k].gx * qj;
          ay += Gi[k].gy * qj;
        }
        ax += gradSum_[i].x() * qi;
        ay += gradSum_[i].y() * qi;
        const Vec2 vJ(V[i].x() - dt * ax, V[i].y() - dt * ay);
        const Real kJ = std::max(kappa[i] + dk_[i], kMin);
        if (cheb_ > 0) {  // x_{k+1} = w (x_Jacobi − x_{k−1}) + x_{k−1}; κ clamped again
          const Vec2 vOld = V[i];
          const Real kOld = kappa[i];
          V[i] = w == 1 ? vJ : Vec2((vJ - vPrev_[i]) * w + vPrev_[i]);
          kappa[i] = w == 1 ? kJ : std::max((kJ - kPrev_[i]) * w + kPrev_[i], kMin);
          vPrev_[i] = vOld;
          kPrev_[i] = kOld;
        } else {
          V[i] = vJ;
          kappa[i] = kJ;
        }
      }
    });
  }

  /// x += dt v (xPrev for the swept collision); p = κρ for readers. Returns the first bad slot.
  std::size_t integrate(StepContext& c) {
    Particles& P = c.P;
    const std::vector<Real>& kappa = *P.find("dfsph.kappa");
    const Real dt = c.dt;
    const Real vmax2 = c.maxSpeed * c.maxSpeed;
    return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      std::size_t bad = kNone;
      for (std::size_t i = b; i < e; ++i) {
        const Vec2 v = P.v[i];
        P.xPrev[i] = P.x[i];
        P.x[i] = P.x[i] + v * dt;
        P.p[i] = kappa[i] * P.rho[i];
        P.pOverRho[i] = kappa[i];
        if (bad == kNone && (!allFinite(P.x[i]) || !allFinite(v) || v.squaredNorm() > vmax2)) bad = i;
      }
      return bad;
    });
  }

  double tol_, divTol_;
  int maxIt_, minIt_;
  bool divSolve_;
  Real omega_;
  Real cheb_;                            ///< Chebyshev ρ (0: plain relaxed Jacobi)
  Real cfl_;                             ///< dt ≤ cfl_·R/v_max
  static constexpr int kChebDelay = 5;   ///< plain iterations before the acceleration starts
  static constexpr Real kPressureCfl = Real(0.35);  ///< dt ≤ kPressureCfl·R/sqrt(|g| D), D the greatest depth
  static constexpr Real kFlatQ = Real(0.25);        ///< below q = r/R = 1/4 the solves' |∇W| keeps its peak value
  static constexpr Real kKneeDensity = Real(1.1);   ///< beyond ρ = 1.1 ρ0 the Jacobi step shrinks as 1.1 ρ0/ρ
  static constexpr Real kPushoutSpeed = Real(3);    ///< [m/s] existing compression is removed at most this fast
  std::vector<Vec2> vPrev_;              ///< velocity before the last iteration (Chebyshev)
  std::vector<Real> kPrev_;              ///< κ before the last iteration (Chebyshev)
  /// One neighbour entry of an iteration: the neighbour's slot and m∇W_ij.
  struct Pair {
    std::uint32_t j;
    Real gx, gy;
  };
  std::vector<std::vector<Pair>> pairs_;  ///< per neighbour entry, block by block (as NeighbourLists)
  std::vector<Vec2> gradSum_;             ///< Σ_j m∇W_ij + Σ_b ρ0Ψ_b∇W_ib per particle
  std::vector<Real> alpha_;              ///< the DFSPH factor α_i
  std::vector<Real> dk_;                 ///< this iteration's κ increment
  std::vector<Real> q_;                  ///< dk_/ρ
  SolverStats stats_;
  mutable std::vector<Real> topScratch_;  ///< depths(): the highest particle per strip (reused: maxTimeStep runs it every substep)
  bool closed_ = false;  ///< set per substep: no wall, no free surface (both axes periodic, κ of either sign)
  bool unilateral_;  ///< solver.clamp_negative_pressure: κ ≥ 0 (a free surface); false: κ of either sign
  Real kMin_;        ///< 0, or −∞ without the clamp
};

}  // namespace

/// dfsph's registration (solvers.def) and its parameters.
SolverInfo dfsphSolver() {
  return {"dfsph",
          {{"tolerance", 0.001, 1e-6, 0.1,
            "largest mean predicted density error |ρ* − ρ0|/ρ0 the pressure solve accepts (compression only where κ = 0)"},
           {"divergence_tolerance", 1e-4, 1e-8, 1,
            "largest mean |Dρ/Dt|·dt/ρ0 (the density change one substep's divergence error makes) the divergence-free solve accepts (compression only where κ_v = 0)"},
           {"max_iterations", 100, 1, 10000, "iterations per solve at most (each solve separately)"},
           {"min_iterations", 2, 0, 10000, "iterations per solve at least"},
           {"relaxation", 0.5, 0.05, 1, "Jacobi relaxation ω of both solves (κ increments are ω times the diagonal estimate)"},
           {"chebyshev_rho", 0.98, 0, 0.999,
            "Chebyshev acceleration of both solves (Wang 2015) with this spectral radius estimate; 0: plain relaxed Jacobi"},
           {"velocity_cfl", 0.4, 0.01, 1, "dt ≤ velocity_cfl·R/v_max (dfsph does not read solver.cfl, the CFL number on c + v_max)"},
           {"divergence_solve", 1, 0, 1, "1: run the divergence-free solve each substep; 0: constant-density solve only"}},
          [](const SolverDef& d) -> std::unique_ptr<Solver> { return std::make_unique<Dfsph>(d); }};
}

}  // namespace sph2d
