// effects/effect.hpp (internal) — an effect: a force the scene asks for.
//
// A scene's step runs only the effects the scene enables; an absent effect
// has no object, allocates no particle field and runs no stage. Each effect
// adds its acceleration to P.a after the solver's pressure force (or where
// the solver calls applyEffects), and may limit the time step.
#pragma once

#include <limits>
#include <memory>
#include <vector>

#include "sph2d/world.hpp"
#include "stages.hpp"

namespace sph2d {

class Effect {
 public:
  virtual ~Effect() = default;
  /// Stage name shown by --profile.
  virtual const char* name() const = 0;
  /// Adds this effect's acceleration to P.a. Returns the first bad slot or kNone.
  virtual std::size_t apply(StepContext& c) = 0;
  /// The scene key whose value sets this effect's time-step limit (for error messages).
  virtual const char* limitKey() const { return name(); }
  /// False while an input event has switched the effect off (it then runs no stage).
  bool enabled = true;
  /// Largest stable time step this effect allows.
  virtual Real maxTimeStep(const StepContext& c) const {
    (void)c;
    return std::numeric_limits<Real>::infinity();
  }
};

using EffectList = std::vector<std::unique_ptr<Effect>>;

/// The effects a scene enables, in a fixed order: viscosity, xsph, force
/// fields, surface tension. (The particle system — emitters, lifetimes,
/// sinks — runs in the World's emit and lifetime stages.)
EffectList makeEffects(const SceneDef& scene);

/// The effect that applies the current user forces (created when the first is set).
std::unique_ptr<Effect> makeUserForceEffect(const std::vector<UserForce>* forces);

/// Runs every effect as its own timed, guarded stage (nothing at all in a build
/// with SPH2D_NO_EFFECT_MODULES, the baseline of benchmarks/effects_overhead.sh).
inline void applyEffects(StepContext& c, StageRunner& run, const EffectList& effects) {
#ifdef SPH2D_NO_EFFECT_MODULES
  (void)c;
  (void)run;
  (void)effects;
#else
  for (const auto& e : effects)
    if (e->enabled) run.checked(e->name(), [&] { return e->apply(c); });
#endif
}

}  // namespace sph2d
