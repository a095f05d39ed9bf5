// solvers/pbf/pbf.hpp (internal) — the Pbf class, shared by pbf.cpp (the
// substep: prediction, the solve loop, the final density and the velocity),
// pbf_constraint.cpp (the two passes of one Jacobi iteration: constraint and
// correction), pbf_local.cpp (the local passes after the full ones) and
// pbf_params.cpp (the parameter table and the registrations of pbf and game).
//
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
//   With pushout_speed v_p > 0 (pbf; the velocity of step 4 is that of the positions
//   after the first solve below): the iterations of 3 first hold C_i ≤ K_i,
//   K_i = max(0, C⁰_i − 2 v_p dt/dx), C⁰_i the compression particle i starts the
//   substep with (ρ of its positions, left by earlier substeps): compression already
//   there becomes velocity at most at the pushout speed (dfsph's 3 m/s, Box2D v3's
//   contact pushout). Only when the plain constraints are then beyond the tolerances
//   do further iterations of C_i ≤ 0 push the rest out, moving positions only (Box2D's
//   soft step: its relax pass takes the velocity without the pushout's bias). At rest
//   K_i = 0 (2 v_p dt/dx is several times any compression a column keeps), so the
//   hydrostatic support, which is the velocity of correcting the compression gravity
//   keeps adding, is as before; a plain split (K_i = C⁰_i) left the first solve
//   within its tolerance after its first pass and the resting column churned at
//   0.85 m/s. Measured on 50 m/s jets into a funnel of zigzag chains: where the
//   iterations end unconverged (an impact), the compression they leave was removed in
//   the next substep as v = Δx/dt, faster than anything closed on it: a stagnant
//   particle on a tooth tip thrown at 73 m/s (Δx = 3 spacings in one substep), the
//   jet's single particles at up to 2.07 times its specific energy; shorter substeps
//   made it worse (the same Δx over a shorter dt).
//
// The game solver ("game" in solvers.def, quality "game") is this code with the
// defaults of pbfParams(true) and support 2 dx, no viscosity: 1 to 4 iterations
// a substep under a tolerance band, then local iterations over the particles still
// compressed (an active list; on a deep pile Chebyshev-weighted as the full passes:
// pbf_local.cpp); a substep set by a speed quantile and a per-particle move cap
// instead of the fastest particle; corrections that move positions only; and,
// before the prediction, the coarse-grid pressure projection of the velocities
// (grid_projection.hpp: Hybrid SPH, Raveendran et al. 2011), which carries the
// long hydrostatic mode that Jacobi iterations reach only slowly.
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
//   dynamics"), but not in a substep that starts beyond chebyshev_plain_above
//   (an impact): Jacobi corrects the long (hydrostatic) modes by about N/layers²
//   per N iterations, Chebyshev by N²/layers².
// - Materials of different rest density (the field "rest_ratio", r_i = ρ0_i/ρ0): the
//   constraint counts particles (C_i = δ_i/δ0 − 1, the number density of Solenthaler &
//   Pajarola 2008), and the projection weighs each particle by its inverse mass as
//   position-based dynamics does (Müller et al. 2007): Δx_i = (1/r_i)·(the step above) and
//   D_i = |∇_i C_i|²/r_i + Σ_j |∇_j C_i|²/r_j. λ stays a pressure (continuous across an
//   interface); a heavy particle is moved less by it, so gravity sorts the layers. XSPH
//   weighs neighbour j by sqrt(r_j/r_i) (symmetric in the masses). P.rho
//   is the density r_i ρ0 δ_i/δ0 after the substep, the number density during the solve.
// - No warm start from the previous substep's multipliers.
// - Convergence needs the mean compression and the largest below their tolerances.
// - Time step: min(max_dt, max_move · R / v_max, 0.35 R/sqrt(|g| D) without the
//   grid projection (D the deepest column: the hydrostatic stiffness, as dfsph's),
//   max_approach · R / w (w the fastest approach of two neighbours: a pair that
//   closes by more than about a spacing in one prediction is separated from the
//   wrong side, which turns into speed: with pushout_speed and max_move 1 the funnel
//   jets still threw particles at 1.6 times the jet's energy, at max_approach 0.5
//   at 1.2–1.4), limit). The compression left
//   after N iterations grows as dt²/N², so when max_iterations end unconverged
//   the limit drops to 0.5–0.9 of this substep (not below max_dt/32); when half
//   of them sufficed it grows back by 1.2 per substep.
//
// Parameters (solver.*): the table pbfParams (pbf_params.cpp), one column for pbf
// and one for game; docs/SCENES.md lists them.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "solvers/game/grid_projection.hpp"
#include "solvers/pbf/slot_set.hpp"
#include "solvers/solver.hpp"

namespace sph2d {

/// The parameters of pbf and of game (the same method; game's defaults make it real-time).
std::vector<SolverParam> pbfParams(bool game);

/// Position Based Fluids: one object per World, for solver.type "pbf" or "game".
class Pbf final : public Solver {
 public:
  /// Reads the solver.* parameters of `d` (all filled: fillSolverDefaults).
  explicit Pbf(const SolverDef& d);

  /// "pbf" or "game".
  const char* name() const override { return name_; }
  /// 0: start uncompressed (the solve holds ρ0 at any depth, up to the tolerance).
  double hydrostaticFactor() const override { return 0; }

  /// The spiky kernel (Müller et al. 2003), the one the constraint sums density with.
  double densityKernel(double r, double R) const override { return Spiky<double>(R).value(r); }

  /// Calibrates D0, then the density and pressure of the current positions.
  void prepare(StepContext& c) override;

  /// max_dt/32, the floor of the step-limit controller (a correction becomes a
  /// velocity by dividing by dt, so shorter substeps are refused).
  double minTimeStep(const StepContext& c) const override {
    (void)c;
    return double(maxDt_) / 32;
  }

  /// min(max_dt, the non-convergence limit, max_move · R / v), v the speed
  /// quantile's speed when speed_quantile > 0.
  Real maxTimeStep(const StepContext& c, Real vmax, Real amax) const override;

  /// The speed that at most speed_quantile of the particles exceed (at least
  /// one particle may): spray does not set everyone's substep; predict caps
  /// the few faster particles' move instead.
  Real robustSpeed(const StepContext& c) const;

  /// Correction passes and the mean compression after them, of the last substep.
  SolverStats stats() const override { return stats_; }
  /// The step limit and the grid projection's warm start (World::save).
  void saveState(StateOut& out) const override;
  /// Reads what saveState() wrote.
  void loadState(StateIn& in) override;

  /// With corrections that move positions only (correction_to_velocity < 1: game), an elastic
  /// group's particles take only their own corrections into velocity (pbf_groups.cpp).
  bool groupCorrections() const override { return toVelocity_ < 1; }
  /// The elastic groups' particles' own moves of the last solve, times 1 − kc (in cross_).
  const std::vector<Vec2>* groupMoves() const override { return ownVel_.empty() ? nullptr : &cross_; }

  /// [grid → neighbours, when effects run] → external → effects → predict →
  /// predicted_grid → predicted_neighbours → density_solve → density → velocity.
  std::vector<Stage> stages(bool effects) override;

 private:
  /// Jacobi iterations of the density constraints on the predicted positions
  /// (Chebyshev-accelerated) until the tolerances; then the step-limit controller.
  std::size_t solve(StepContext& c);

  /// The last constraint pass met both tolerances.
  bool converged() const { return meanCompression_ <= tolerance_ && maxCompression_ <= toleranceMax_; }

  /// D0 = Σ_j (m/ρ0)² |∇W|² over a full square lattice (the typical constraint denominator).
  void calibrate(const StepContext& c);

  /// xPrev = x; v += dt a; x += dt v, swept out of the solids; λ = 0.
  std::size_t predict(StepContext& c, std::vector<Real>& lambda);

  // pbf_constraint.cpp: the two passes of one Jacobi iteration.
  /// Density of x*, the constraint and the multiplier step Δλ_i (keeping λ ≤ 0); the
  /// mean compression. Caches the spiky gradient factor per pair (∇W = gK g d) and
  /// the wall part of ∇_i C_i for correct() (same positions).
  /// With `list` (a local iteration), only the listed particles; the mean is then not updated.
  std::size_t constraint(StepContext& c, const std::vector<Real>& lambda,
                         const std::vector<std::uint32_t>* list = nullptr);

  /// x*_i += (m/ρ0) Σ_j (Δλ_i + Δλ_j + s_corr) ∇W_ij + Δλ_i Σ_b Ψ_b ∇W_ib (a gather into
  /// a second buffer), combined with the previous iterate by the Chebyshev weight ω and
  /// swept out of the solids; λ follows the same combination.
  /// With `list` (a local iteration): only the listed particles move, in place (the
  /// pass reads no neighbour position); Chebyshev-weighted when the phase is
  /// (startLocalPhase), each particle from the iterate the last local pass left it.
  std::size_t correct(StepContext& c, std::vector<Real>& lambda, Real omega,
                      const std::vector<std::uint32_t>* list = nullptr);

  /// The pressure reported for particle i: −ρ0 λ_i/dt² of the constraint, plus ρ0 κ of the
  /// grid projection when there is one (it carries the hydrostatic part).
  Real pressure(const StepContext& c, const std::vector<Real>* lam, Real pK, std::size_t i) const;
  /// The velocity marker's stage (game): p of this substep's projection (κ) and the last
  /// density solve (λ), for the effects that run there (the granular friction's bound).
  std::size_t pressureNow(StepContext& c);

  /// ρ of the final positions (what the World reports), 1/ρ, p (pressure()). Caches W_ij/wK for XSPH.
  std::size_t finalDensity(StepContext& c, Real dt);

  /// The Jacobi iterations (Chebyshev-accelerated) of the current target until it converges or
  /// `maxIt` corrections are applied; adds the corrections to `used`. A bad slot, or kNone.
  std::size_t iterate(StepContext& c, std::vector<Real>& lambda, int maxIt, int& used);

  /// v = (x* − x)/dt, then XSPH v_i += c Σ_j (m/ρ_j)(v_j − v_i) W_ij (a gather into a copy).
  std::size_t velocity(StepContext& c);

  const char* name_;  ///< "pbf" or "game" (the same method, registered with other defaults)
  int iterations_, maxIterations_;
  /// A substep whose first constraint pass finds a compression above this runs plain Jacobi
  /// (chebyshev_plain_above; pbf 0.3, game 0: never). Chebyshev's weights assume the iteration's
  /// asymptotic regime; extrapolated from an impact's first iterations (compressions of 50 % and
  /// more, clamped multipliers) they pushed particles past where the constraint wanted them,
  /// and pbf turns that move into velocity: a 50 m/s jet's impact threw single particles at
  /// 7–10 times the jet's specific energy, 1.5–2.1 times without the weights there
  /// (docs/STABILITY.md). Gentle flows keep the acceleration (Poiseuille: 6.7 % either way, 11 %
  /// with plain Jacobi everywhere). game: its corrections move positions only.
  Real chebPlainAbove_;
  Real tolerance_, toleranceMax_, relaxation_, chebyshev_, tensileK_;
  int tensileN_;
  Real tensileDq_, xsph_, maxDt_, maxMove_, toVelocity_;
  /// pushout_speed (pbf.hpp, step 4): compression a substep starts with becomes velocity at most this fast [m/s] (0:
  /// off).
  Real pushoutSpeed_;
  /// max_approach: dt ≤ max_approach · R / w, w the fastest approach of two neighbours (field "pbf.approach").
  Real maxApproach_;
  bool adaptiveDt_;
  Real quantile_, moveCap_;
  int localIterations_;
  bool resolveEach_;
  /// Adds the particles of `list` (only those with ρ > *limit when given) and their
  /// neighbours to `out`; costs in proportion to the list, not to the particle count.
  void neighbourhood(const StepContext& c, const std::vector<std::uint32_t>& list, const Real* limit,
                     SlotSet& out) const;
  SlotSet active_;                         ///< the next local iteration's particles, as they are found
  SlotSet moved_;                          ///< every particle the local phase moved
  std::vector<std::uint32_t> activeList_;  ///< the particles of a local iteration (sorted)
  std::vector<std::uint32_t> lastList_;    ///< the particles the last constraint pass of the local phase wrote Δλ for
  std::vector<std::uint32_t> movedList_;   ///< moved_ listed for the halo pass (sorted)
  /// pbf_local.cpp: the local passes after the full ones (while a compression above
  /// tolerance_max is left, at most local_iterations); counts them in `local`. A bad slot, or kNone.
  std::size_t localPhase(StepContext& c, std::vector<Real>& lambda, int& local);
  /// Before a substep's local passes: whether they are Chebyshev-weighted (localChebyshev_), and
  /// a new phase's pass numbers.
  void startLocalPhase(const StepContext& c);
  bool localChebyshev_ = false;     ///< this substep's local passes take the Chebyshev weights
  bool plainSubstep_ = false;       ///< this substep's full passes ran plain Jacobi (chebyshev_plain_above)
  bool endedOnCorrection_ = false;  ///< the last iterate() ended with a correction (solve() then sums ρ once more)
  std::uint32_t localPass_ = 0;     ///< the number of the current local pass (counted across substeps)
  /// Per particle: the local pass that last took a weighted step for it (0: none, or a plain
  /// step), so that the next pass knows whether xOld_ and lOld_ hold its iterate before that one.
  std::vector<std::uint32_t> localMoved_;
  /// The moving bodies' reach over the substep (centre, squared radius): the particles within
  /// it take plain local steps (startLocalPhase).
  struct BodyReach {
    Vec2 centre;
    Real r2;
  };
  std::vector<BodyReach> localBodies_;
  /// Within a moving body's reach (localBodies_).
  bool nearBody(const Vec2& x) const {
    for (const BodyReach& b : localBodies_)
      if ((x - b.centre).squaredNorm() < b.r2) return true;
    return false;
  }
  static constexpr std::size_t kLocalBlock = 32;       ///< particles per job of a local iteration (few, clustered)
  mutable std::vector<Real> speedScratch_, speedTop_;  ///< robustSpeed(): squared speeds, each block's largest
  mutable std::vector<Real> depthScratch_;             ///< maxTimeStep(): the highest particle per strip (columnDepths)
  std::unique_ptr<GridProjection> projection_;         ///< the coarse-grid projection (grid_cell > 0)

  // Elastic groups under corrections that move positions only (pbf_groups.cpp). A jelly is held
  // up by its own density solve (its pairs, the walls) and its shape matching, both moves of
  // positions, so its particles take those moves into velocity; the moves of their pairs with
  // other particles stay positions on both sides, as the liquid's do (taken on one side, a
  // block of water thrown at a jelly gained 20 % of its momentum), and the grid's compression
  // shift does not move them (as velocity it stopped the jelly being pushed at all).
  /// Marks the particles of elastic groups (ownVel_; left empty when there are none or the
  /// corrections become velocity anyway).
  void markElastic(const StepContext& c);
  /// At the solve's start (the slots were reordered since the prediction): marks them again,
  /// clears the cross moves and keeps the positions.
  void startElastic(const StepContext& c);
  /// After the solve: the marked particles' own moves, (1 − kc)(x − start − cross), into cross_
  /// (the World's groups stage adds them over dt to their velocity: groupMoves()).
  void ownMoves(const StepContext& c);
  std::vector<std::uint8_t> ownVel_;  ///< per particle: 1 in an elastic group (empty: none)
  /// Per particle: the moves of its pairs with unmarked particles, combined over the iterations
  /// as the positions are (Chebyshev: the last, the one before, the next).
  std::vector<Vec2> cross_, crossOld_, crossNew_;
  std::vector<Vec2> xStart_;  ///< the positions the solve started from (marked particles)

  Real d0_ = 0, eps_ = 0, invWdq_ = 0, sCorrScale_ = 0;
  Real meanCompression_ = 0, maxCompression_ = 0;
  /// While the first solve of a pushout substep runs: the constraint is C_i − K_i (field "pbf.carried").
  bool againstStart_ = false;
  /// The plain constraint's mean and largest compression in the last full pass (= the above unless againstStart_).
  Real plainMean_ = 0, plainMax_ = 0;
  /// The velocity is that of xVel_ (the positions after the first solve), not of the final positions.
  bool velocityFromSnapshot_ = false;
  std::vector<Vec2> xVel_;
  Vec2d wallMoveVel_[2] = {Vec2d(0, 0), Vec2d(0, 0)};  ///< wallMove_ at the snapshot
  bool rhoCurrent_ = false;  ///< the last constraint pass saw every particle at its current position
  SolverStats stats_;
  Real dtLimit_ = std::numeric_limits<Real>::infinity();  ///< shortened while the iterations do not converge
  std::vector<Real> dLambda_, lOld_;
  /// 1/r_i with a density contrast (solve() fills it; else empty).
  std::vector<Real> invRatio_;
  /// XSPH with a density contrast (velocity()): per particle sqrt(r_j) m_j/ρ_j and 1/sqrt(r_i).
  std::vector<Real> xsphNeighbour_, xsphOwn_;
  std::vector<Vec2> wallGrad_;         ///< the boundary part of ∇_i C_i
  std::vector<double> blockErr_;       ///< compression per block (fixed-order sum)
  std::vector<Real> blockMax_;         ///< largest compression per block
  std::vector<double> blockPlainErr_;  ///< … of the plain constraint (pushout_speed's first solve)
  std::vector<Real> blockPlainMax_;
  std::vector<std::vector<Real>> gCache_;  ///< per pair W/wK (final density, XSPH), laid out like NeighbourLists
  struct Grad {
    Real x, y;
  };
  static_assert(sizeof(Grad) == 2 * sizeof(Real),
                "a Grad is two packed reals (the constraint stores four pairs at a time)");
  std::vector<std::vector<Grad>> gradCache_;  ///< per pair G_ij = (m/ρ0)∇W_ij of the last constraint pass
  std::vector<Vec2> xNew_, vNew_, xOld_;
  // World::wallImpulse when the moves become velocity (correction_to_velocity > 0; game: 0, so
  // none): Σ_i of the walls' share D_i of particle i's move this substep, [0] the density solve's
  // wall term Δλ_i Σ_b Ψ_b∇W_ib, [1] the sweeps' pushes out of the solids. Each follows the
  // positions' Chebyshev recurrence (linear, one ω for every particle, so the sums do too);
  // velocity() turns them into m·kc·D/dt.
  Vec2d wallMove_[2] = {Vec2d(0, 0), Vec2d(0, 0)};
  Vec2d wallMovePrev_[2] = {Vec2d(0, 0), Vec2d(0, 0)};  ///< … at the iterate xOld_ holds
  std::vector<Vec2d> wallBlock_;                        ///< per block: (wall term, push) partials of the last pass
  /// Adds the last pass's partials (wallBlock_, `blocks` of them) to wallMove_ through the
  /// Chebyshev weight `omega`; `rotate`: the pass rotated the position buffers (a full pass).
  void addWallMoves(std::size_t blocks, Real omega, bool rotate);
};

}  // namespace sph2d
