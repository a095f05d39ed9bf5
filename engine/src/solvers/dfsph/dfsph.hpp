// solvers/dfsph/dfsph.hpp (internal) — Divergence-free SPH (Bender & Koschier 2015, "Divergence-free
// smoothed particle hydrodynamics", SCA; and 2017, "Divergence-free SPH for
// incompressible and viscous fluids", IEEE TVCG). An implicit pressure
// solver: two iterative solves on the velocities per substep make the velocity
// field divergence-free and the predicted density ρ0, instead of an equation of
// state with a stiffness (solver.sound_speed is not read). Why each choice, the
// variants tried and the measurements: docs/SOLVERS.md, section dfsph.
//
// Quantities (Wendland C2 kernel W of support R; boundary samples b are frozen
// fluid of mass ρ0Ψ_b at rest; q = r/R):
//   (1) ρ_i = Σ_j m W_ij + Σ_b ρ0Ψ_b W_ib
//   (2) g_ij = m∇W_ij, except that below q = 1/4 it keeps the peak |∇W| along
//       x_i − x_j (a stacked pair has a direction and a magnitude; coincident
//       pairs take pairDelta's direction); G_i = Σ_j g_ij + Σ_b ρ0Ψ_b∇W_ib
//   (3) α_i = ρ_i / max(|G_i|² + Σ_j |g_ij|², 0.01 (ρ0/R)²), the paper's factor (0 without
//       neighbours) with its denominator at least about a two-hundredth of a full
//       neighbourhood's (about 2 (ρ0/R)² on a lattice at R = 2.5 dx)
//   (4) Dρ_i/Dt = G_i·v_i − Σ_j g_ij·v_j
//
// Substep (stages()):
//   1. grid, neighbours; ρ, g, G, α by (1)–(3), kept for the whole substep.
//   2. Divergence-free solve on v: source s_i = Dρ_i/Dt (4), until the mean
//      residual ≤ divergence_tolerance·ρ0/dt.
//   3. a = gravity + the scene's effects; v* = v + dt a.
//   4. Constant-density solve on v*: source s_i = ρ_i + dt Dρ_i/Dt − ρ0, the
//      compression ρ_i − ρ0 already present counting at most
//      ρ0·2·(3 m/s)·dt/dx (a pushout speed), until the mean residual ≤ tolerance·ρ0.
//   5. x += dt v (the World's swept collision follows); p = κρ for readers.
// Each solve starts from its previous substep's κ (fields "dfsph.kappa" = p/ρ,
// "dfsph.kappa_v" = κ_v·dt, permuted with the particles), applied once by B,
// then iterates two gathers:
//   A. δκ_i = ω s_i α_i / dt² (divergence: / dt), times 1.1 ρ0/ρ_i beyond
//      1.1 ρ0; κ_i + δκ_i ≥ 0 (no tension at a free surface: projected Jacobi
//      with the complementarity residual |s_i| where κ_i > 0, max(s_i, 0) where
//      κ_i = 0); the residuals summed per block.
//   B. v_i −= dt [Σ_j (δκ_i/ρ_i + δκ_j/ρ_j) g_ij + (δκ_i/ρ_i) Σ_b ρ0Ψ_b∇W_ib];
//      κ_i += δκ_i. The wall term is the paper's single term, so B is the
//      adjoint of A's prediction and a converged solve only removes energy.
// The floor in (3): a lone pair at the kernel's edge (spray) has a denominator down to 10⁻⁵ of a
// full neighbourhood's and a κ to match, since |∇W| vanishes there; warm-started into the next
// substep, where a neighbour nearer than the edge has a larger ∇W, that κ became a kick (traced
// in a 35 m/s jet at dx = 0.015: three lone drops went 5 → 66 → 165 → 1031 m/s over three
// substeps, and the run stopped). With the floor such a pair is only under-relaxed.
// ω = solver.relaxation (0.5: plain Jacobi diverges in 2D); after 5 plain
// iterations Chebyshev semi-iteration (Wang 2015) with ρ = chebyshev_rho,
// restarted when the residual grows; min_iterations to max_iterations. With
// clamp_negative_pressure = false κ takes either sign, and in a closed periodic
// box (both axes periodic, no walls) A first removes the source's mean.
//
// Time step: the least of velocity_cfl·R/v_max, 0.25·sqrt(R/a_max) (a without
// pressure), 0.1·sqrt(R/|g|) and 0.35·R/sqrt(|g| D), D the greatest depth
// below the highest particle of a column (strips of width R; gravity along a
// periodic axis counts for neither this nor the warm start). A substep shorter
// than 1 % of that limit and of the last solved substep (a frame's float
// remainder) runs without the solves.
//
// Every pass is a gather over fixed blocks and every mean a block reduction
// combined in block order: the same bits for any thread count.
//
// Moving bodies (Solver::movingSamples; body_samples.hpp; Akinci et al. 2012, "Versatile
// rigid-fluid coupling for incompressible SPH", as Bender & Koschier 2017 couple DFSPH to rigid
// bodies): a kinematic or dynamic body's samples b, placed at the body's pose at the substep's
// start with its velocity v_b = v + ω × r, enter the same sums as the static ones: ρ_i and α_i
// (frozen fluid of mass ρ0Ψ_b), G_i, the wall term of B, and the source (4) with the relative
// velocity Σ_b ρ0Ψ_b∇W_ib·(v_i − v_b). Body k's share of particle i's velocity change in one B
// is −dt q_i G_ik, G_ik = Σ_{b of k} ρ0Ψ_b∇W_ib (torque: T_ik = Σ_b arm_b × ρ0Ψ_b∇W_ib), so
// over a solve it is −dt Q_i G_ik, Q_i the q_i of every B (warm start included) combined by
// the velocities' Chebyshev recurrence (kept per particle in double: κ is clamped after the
// extrapolation, so Σ κ would not do). At the end of each solve every block adds −m Q_i G_ik
// (torque −m Q_i T_ik) per dynamic body to BodySamples::perBlock, particles in order; the
// body_forces stage gives the body the opposite impulse. These samples stay out of
// World::wallImpulse (wallGrad_ is the static walls' part only).
// Strong coupling: a dynamic body takes that impulse within the solves, not only after them
// (as Gissler et al. 2019, "Interlinked SPH pressure solvers for strong fluid-rigid coupling",
// solve the body with the fluid): after every B its velocity change so far in the substep,
// ΔV_k = m dt Σ_i Q_i G_ik / M_k and Δω_k = m dt Σ_i Q_i T_ik / I_k (both solves; blocks in
// order), moves its samples in A's source by G_ik·ΔV_k + T_ik Δω_k (∇W·(Δω × r) = Δω r × ∇W).
// Measured (crate 0.6 m × 0.2 m, density 500, spacing 0.01): taking the reaction only after
// the solve, the body light against the water it moves (added mass), each substep's impulse
// overshot and the crate floated at 0.078 m (Archimedes 0.1). Two more terms make the coupled
// Jacobi iteration converge: a particle beside body k adds a bound on the body's row of the
// coupled system, m (|G_ik| Σ_j |G_jk| / M_k + |T_ik| Σ_j |T_jk| / I_k), to α_i's denominator
// (lumpBodies: each particle's step allows for the body giving way to all of them at once; the
// absolute values keep the bound where particles push the body from opposite sides: with the
// signed row, G_ik·Σ_j G_jk, those pushes cancelled, and the divergence solve of a crate wedged
// against the tank's wall diverged, its residual doubling every two iterations);
// and each solve also iterates until the mean residual of the particles beside a dynamic
// body meets the tolerance (the body's mode is global, the mean over all particles hides
// it). Measured with these: draught 0.0959 m over the third second (0.0942 without the
// lumping, 0.0933 without either; 0.0976 with the Box2D skin alone and no samples); 0.0952 m
// with the bound and Box2D stepping with the substeps (docs/SCENES.md).
//
// Parameters (solver.*): tolerance, divergence_tolerance, max_iterations,
// min_iterations, relaxation, chebyshev_rho, velocity_cfl, divergence_solve. stats()
// reports the last solved substep's iterations and residuals.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "bodies/body_samples.hpp"
#include "solvers/solver.hpp"

namespace sph2d {

/// The dfsph solver (the header); dfsph.cpp holds its fields, stages and time step,
/// dfsph_solve.cpp its two pressure solves.
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
  /// The moving bodies' samples are walls like the static ones, moving with their body (the header).
  bool movingSamples() const override { return true; }

  /// Creates the κ fields; density, α and gradients of the initial positions.
  void prepare(StepContext& c) override;

  /// The first pressure solve's warm start: the hydrostatic κ = |g|·(depth
  /// below the highest particle of the same column, strips of width R across
  /// gravity) + |g| dx/2, and p = κρ for readers. A column starts at rest
  /// and incompressible, so this is its pressure; without it the first
  /// solves build ρ0 g H from zero, and a Jacobi iteration needs about
  /// (H/dx)² iterations for that (measured: at dx = 5 mm the 2 m dam-break
  /// column crushed its floor rows by 55 % and blew up at t = 0.06 s).
  void hydrostaticWarmStart(StepContext& c, std::vector<Real>& kappa) const;

  /// Calls f(i, depth) with every particle's depth below the top of its column (stages.hpp).
  template <class F>
  void depths(const StepContext& c, F f) const {
    columnDepths(c, topScratch_, f);
  }

  /// velocity_cfl·R/v_max, 0.1·sqrt(R/|g|), 0.25·sqrt(R/a_max) and 0.35·R/sqrt(|g| D), whichever is least
  /// (docs/SOLVERS.md: the hydrostatic stiffness limit).
  Real maxTimeStep(const StepContext& c, Real vmax, Real amax) const override;

  /// grid → neighbours → density (and α) → divergence_solve → gravity → effects →
  /// predict_velocity → pressure_solve → integrate.
  std::vector<Stage> stages(bool) override;

  /// Iterations and residuals of the last substep.
  SolverStats stats() const override { return stats_; }

 private:
  /// ρ, 1/ρ, α, the per-neighbour (slot, m∇W_ij) and per particle Σ_j m∇W_ij + Σ_b ρ0Ψ_b∇W_ib.
  std::size_t densityAndFactor(StepContext& c, const WendlandC2<Real>& W);

  /// A dynamic body moves with what all its neighbours push it by at once, which a particle's
  /// Jacobi step alone does not see: the factor of a particle beside body k takes a bound on the
  /// body's row of the coupled system, m (|G_ik| Σ_j |G_jk| / M_k + |T_ik| Σ_j |T_jk| / I_k), into
  /// its denominator (sums in block order).
  void lumpBodies(StepContext& c);

  /// One solve: warm start, then iterations of (B, A) until the mean error is small.
  /// divergence: the divergence-free solve (source Dρ/Dt), else the constant-density solve.
  void solve(StepContext& c, bool divergence);

  /// v_i −= dt [Σ_j m (κ_i/ρ_i + κ_j/ρ_j) ∇W_ij + Σ_b ρ0Ψ_b (κ_i/ρ_i) ∇W_ib] with κ = scale·kappa; then kappa = κ.
  /// Returns the walls' share Σ_i Δv_i of the velocity change (correctPass).
  Vec2d warmStart(StepContext& c, std::vector<Real>& kappa, Real scale);

  /// Pass A: the source of every particle, its κ increment (dk_, and dk_/ρ in q_)
  /// and the sum of the complementarity residuals, combined in block order.
  struct Sums {
    double err = 0, src = 0;
    double bodyErr = 0, bodyN = 0;  ///< the residuals of the particles beside a dynamic body, their count
  };
  /// The mean residual of pass A; in a closed domain (closed_) the source's
  /// mean is first found by a pass with no shift, then removed.
  double sourceMean(StepContext& c, const std::vector<Real>& kappa, bool divergence);

  Sums sourcePass(StepContext& c, const std::vector<Real>& kappa, bool divergence, Real shift);

  /// Pass B: v_i −= dt [Σ_j (q_i + q_j) m∇W_ij + q_i Σ_b ρ0Ψ_b∇W_ib]; κ_i += dk_i
  /// (w ≠ 1: the Chebyshev step from the previous iterate). Returns the walls' share of the
  /// Jacobi step, Σ_i −dt q_i Σ_b ρ0Ψ_b∇W_ib, summed per block and the blocks in order.
  Vec2d correctPass(StepContext& c, std::vector<Real>& kappa, Real w = 1);

  /// The dynamic bodies' velocity change so far in the substep (strong coupling: the solve's
  /// next source sees the samples move with it): ΔV_k = Δ_prev + m dt Σ_i Q_i G_ik / M_k,
  /// Δω_k = Δω_prev + m dt Σ_i Q_i T_ik / I_k, the blocks' sums in block order.
  void bodyResponse(const StepContext& c, std::size_t blocks);

  /// The moving bodies' share of this solve's velocity change, −dt Q_i G_ik per particle and
  /// dynamic body, as the force −m Q_i G_ik (torque −m Q_i T_ik) its block felt from the body
  /// (BodySamples::addReaction: particles in order within a block, blocks summed in order).
  void react(StepContext& c);

  /// x += dt v (xPrev for the swept collision); p = κρ for readers. Returns the first bad slot.
  std::size_t integrate(StepContext& c);

  double tol_, divTol_;
  int maxIt_, minIt_;
  bool divSolve_;
  Real omega_;
  Real cheb_;                                      ///< Chebyshev ρ (0: plain relaxed Jacobi)
  Real cfl_;                                       ///< dt ≤ cfl_·R/v_max
  static constexpr int kChebDelay = 5;             ///< plain iterations before the acceleration starts
  static constexpr Real kKneeDensity = Real(1.1);  ///< beyond ρ = 1.1 ρ0 the Jacobi step shrinks as 1.1 ρ0/ρ
  static constexpr Real kPushoutSpeed = Real(3);   ///< [m/s] existing compression is removed at most this fast
  /// α's denominator is at least this × (ρ0/R)² (a full neighbourhood's: about 2).
  static constexpr Real kFactorFloor = Real(0.01);
  std::vector<Vec2> vPrev_;  ///< velocity before the last iteration (Chebyshev)
  std::vector<Real> kPrev_;  ///< κ before the last iteration (Chebyshev)
  /// One neighbour entry of an iteration: the neighbour's slot and m∇W_ij.
  struct Pair {
    std::uint32_t j;
    Real gx, gy;
  };
  std::vector<std::vector<Pair>> pairs_;  ///< per neighbour entry, block by block (as NeighbourLists)
  std::vector<Vec2> gradSum_;             ///< Σ_j m∇W_ij + Σ_b ρ0Ψ_b∇W_ib per particle
  std::vector<Vec2> wallGrad_;            ///< its wall part Σ_b ρ0Ψ_b∇W_ib (World::wallImpulse)
  std::vector<Vec2d> wallBlock_;          ///< correctPass(): the walls' Σ Δv per block of kBlock
  /// One particle's term from one dynamic body's samples: G_ik = Σ_b ρ0Ψ_b∇W_ib, T_ik = Σ_b arm_b × ρ0Ψ_b∇W_ib.
  struct MovTerm {
    std::uint32_t body;
    Real gx, gy, t;
  };
  double bodyErr_ = 0;                          ///< sourceMean(): the mean residual beside the dynamic bodies (0: none)
  bool moving_ = false;                         ///< this substep has moving bodies' samples (BodySamples::active)
  std::vector<std::vector<MovTerm>> movTerms_;  ///< per block, particles in order
  std::vector<std::uint32_t> movStart_, movCount_;  ///< particle i's MovTerms in its block
  std::vector<Real> movSrc_;                        ///< Σ_b ρ0Ψ_b∇W_ib·v_b over the moving samples
  std::vector<double> qAcc_, qAccPrev_;             ///< Q_i of this solve so far (and at the previous iterate)
  std::vector<double> invMass_, invInertia_;        ///< per placed body (0: kinematic)
  std::vector<Vec2d> dv_, dvBase_;                  ///< per body: ΔV so far in the substep, and before this solve
  std::vector<double> dw_, dwBase_;                 ///< … and Δω
  std::vector<double> sumG_;                        ///< lumpBodies(): Σ_i |G_ik| per body
  std::vector<double> sumT_;                        ///< … and Σ_i |T_ik|
  std::vector<Vec2d> blockG_;                       ///< per block and body: Σ_i Q_i G_ik (block-major)
  std::vector<double> blockT_;                      ///< … and Σ_i Q_i T_ik
  std::vector<Real> alpha_;                         ///< the DFSPH factor α_i
  std::vector<Real> dk_;                            ///< this iteration's κ increment
  std::vector<Real> q_;                             ///< dk_/ρ
  SolverStats stats_;
  mutable std::vector<Real>
      topScratch_;       ///< depths(): the highest particle per strip (reused: maxTimeStep runs it every substep)
  bool closed_ = false;  ///< set per substep: no wall, no free surface (both axes periodic, κ of either sign)
  bool unilateral_;      ///< solver.clamp_negative_pressure: κ ≥ 0 (a free surface); false: κ of either sign
  Real kMin_;            ///< 0, or −∞ without the clamp
};

}  // namespace sph2d
