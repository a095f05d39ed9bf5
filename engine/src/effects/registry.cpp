// Which effects a scene's step runs, in a fixed order.
#include <stdexcept>

#include "effects/effect.hpp"

namespace sph2d {

#ifdef SPH2D_NO_EFFECT_MODULES
// Built without the effect modules (CMake option SPH2D_NO_EFFECT_MODULES, the
// baseline of benchmarks/effects_overhead.sh): the registry is empty.

namespace {
/// Refuses `what`: this build has no effect modules.
[[noreturn]] void noModules(const std::string& what) {
  throw std::invalid_argument("this sph2d was built with SPH2D_NO_EFFECT_MODULES=ON: " + what + " is not available");
}
}  // namespace

/// No effects; a scene that enables one is refused (std::invalid_argument).
EffectList makeEffects(const SceneDef& scene) {
  const EffectsDef& e = scene.effects;
  if (scene.solver.viscosity > 0) noModules("the viscosity effect (solver.viscosity > 0)");
  if (e.xsph) noModules("effects.xsph");
  if (!e.forceFields.empty()) noModules("effects.force_fields");
  if (e.surfaceTension) noModules("effects.surface_tension");
  if (e.shifting) noModules("effects.shifting");
  return {};
}

/// Refused: user forces are an effect module.
std::unique_ptr<Effect> makeUserForceEffect(const std::vector<UserForce>*) { noModules("a user force"); }

#else

std::unique_ptr<Effect> makeLaplacianViscosity(double nu, bool noSlip);
std::unique_ptr<Effect> makeXsph(double c);
std::unique_ptr<Effect> makeForceFields(const std::vector<ForceFieldDef>& fields);
std::unique_ptr<Effect> makeSurfaceTension(const SurfaceTensionDef& def);
std::unique_ptr<Effect> makeParticleShifting(double strength);

/// The scene's effects in the fixed order viscosity, xsph, force fields, surface tension, shifting.
EffectList makeEffects(const SceneDef& scene) {
  EffectList out;
  const EffectsDef& e = scene.effects;
  if (scene.solver.viscosity > 0) out.push_back(makeLaplacianViscosity(scene.solver.viscosity, scene.solver.noSlip));
  if (e.xsph) out.push_back(makeXsph(e.xsphC));
  if (!e.forceFields.empty()) out.push_back(makeForceFields(e.forceFields));
  if (e.surfaceTension) out.push_back(makeSurfaceTension(e.tension));
  if (e.shifting) out.push_back(makeParticleShifting(e.shiftingStrength));
  return out;
}

#endif

}  // namespace sph2d
