// Which effects a scene's step runs, in a fixed order.
#include "effects/effect.hpp"

namespace sph2d {

std::unique_ptr<Effect> makeLaplacianViscosity(double nu, bool noSlip);
std::unique_ptr<Effect> makeXsph(double c);
std::unique_ptr<Effect> makeForceFields(const std::vector<ForceFieldDef>& fields);
std::unique_ptr<Effect> makeSurfaceTension(const SurfaceTensionDef& def);
std::unique_ptr<Effect> makeParticleShifting(double strength);

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

}  // namespace sph2d
