// effects/effect.hpp (internal) — an effect: physics a scene asks for beyond
// the pressure solver (viscosity, XSPH, force fields, surface tension,
// particle shifting, user forces).
//
// A scene's step runs only the effects the scene enables: an absent effect
// has no object, allocates no particle field and runs no stage. Each enabled
// effect is one stage of the substep's list, placed where the solver's
// effects marker is (after its pressure force for explicit solvers, before
// the pressure solve for the implicit ones). Most effects add an acceleration
// to P.a; particle shifting moves positions instead. An effect may limit the
// time step.
//
// A new effect: its own file in this folder with a
// `std::unique_ptr<Effect> NAMEEffect(const SceneDef&)` (nullptr when the
// scene does not enable it), and one line in effects.def.
#pragma once

#include <limits>
#include <memory>
#include <vector>

#include "core/kernels.hpp"
#include "sph2d/world.hpp"
#include "step/stages.hpp"

namespace sph2d {

/// The Laplacian viscosity's constants for one substep (viscosity.cpp): per fluid pair
/// a_i += muMass·IR_i Σ_j (v_j − v_i) ∇²W(r_ij) IR_j; with walls,
/// a_i −= v_i·(wallFactor·IR_i·Σ_b Ψ_b ∇²W_ib). A solver that folds the viscosity into
/// its own pair loop (Solver::foldViscosity) computes exactly this.
struct ViscosityTerm {
  ViscosityKernel<Real> W{Real(1)};
  Real muMass = 0;      ///< ν·s·ρ0·m (s: 1 / the Laplacian's lattice moment)
  Real wallFactor = 0;  ///< 2·ν·s·ρ0
  bool walls = false;   ///< no-slip walls with boundary samples
  bool noSlip = false;  ///< solver.no_slip: the walls' and the moving bodies' samples take part
  /// kViscousPairShare / (dt·μm) (constants.hpp): pair (i, j) takes min(∇²W_ij/ρ_j, pairCap·ρ_i),
  /// so that dt·μm·∇²W_ij/(ρ_i ρ_j) ≤ kViscousPairShare (symmetric: momentum is kept), and a
  /// wall sample min(∇²W_ib, pairCap·ρ_i·ρ0); no pair overshoots at any dt or density.
  Real pairCap = std::numeric_limits<Real>::infinity();
};

/// 1 / the viscosity kernel's Laplacian lattice moment (kernels.hpp) at the substep's R and dx,
/// computed again only when they change: the scale that makes the Laplacian viscosity exact
/// on a rest lattice (viscosity.cpp, and the granular effect's viscosity at its largest).
class LaplacianMomentScale {
 public:
  Real operator()(const StepContext& c) {
    if (c.R != R_ || c.dx != dx_) {
      const ViscosityKernel<double> Wd(double(c.R));
      scale_ = Real(1.0 / latticeLaplacianMoment([&](double r) { return Wd.laplacian(r); }, Wd.R, double(c.dx)));
      R_ = c.R;
      dx_ = c.dx;
    }
    return scale_;
  }

 private:
  Real scale_ = 1, R_ = -1, dx_ = -1;
};

class Effect {
 public:
  virtual ~Effect() = default;
  /// Stage name shown by --profile.
  virtual const char* name() const = 0;
  /// Runs the effect (adds to P.a, or moves x). Returns the first bad slot or kNone.
  virtual std::size_t apply(StepContext& c) = 0;
  /// The scene key whose value sets this effect's time-step limit (for error messages).
  virtual const char* limitKey() const { return name(); }
  /// False while an input event has switched the effect off (it then runs no stage).
  bool enabled = true;
  /// True for the Laplacian viscosity, which an explicit solver may fold into its
  /// pressure-force pair loop (stepper.cpp; the effect then runs no stage of its own).
  virtual bool foldable() const { return false; }
  /// True while the solver computes this effect in its own pair loop (set by the World).
  bool folded = false;
  /// True for an effect that runs where the solver's velocities are final, after the pressure
  /// and before the move (Stage::velocities()); false: at the effects marker, with the forces.
  virtual bool afterPressure() const { return false; }
  /// The World's materials changed (World::addMaterial); the World then rebuilds the stages.
  virtual void materialsChanged(const std::vector<MaterialDef>& materials, const SolverDef& solver) {
    (void)materials;
    (void)solver;
  }
  /// The constants of a foldable effect for this substep (others: never called).
  virtual ViscosityTerm viscosityTerm(const StepContext& c) {
    (void)c;
    return {};
  }
  /// Largest stable time step this effect allows.
  virtual Real maxTimeStep(const StepContext& c) const {
    (void)c;
    return std::numeric_limits<Real>::infinity();
  }
};

using EffectList = std::vector<std::unique_ptr<Effect>>;

/// The effects a scene enables, in the order of effects.def. Throws
/// std::invalid_argument in a build without effect modules when the scene asks for one.
EffectList makeEffects(const SceneDef& scene);

/// The effect that applies the current user forces (created when the first is set).
std::unique_ptr<Effect> makeUserForceEffect(const std::vector<UserForce>* forces);

}  // namespace sph2d
