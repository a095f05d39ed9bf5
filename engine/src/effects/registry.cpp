// The effect registry: builds a scene's effect list from effects.def.
#include <stdexcept>

#include "effects/effect.hpp"
#include "particles/material_fields.hpp"

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
  const std::vector<MaterialDef> materials = sceneMaterials(scene);
  for (const MaterialDef& m : materials)
    if (viscosityOf(m, scene.solver) > 0) noModules("the viscosity effect (solver.viscosity or a material's > 0)");
  if (e.xsph) noModules("effects.xsph");
  if (!e.forceFields.empty()) noModules("effects.force_fields");
  if (e.surfaceTension) noModules("effects.surface_tension");
  if (e.shifting) noModules("effects.shifting");
  if (anyMiscible(materials)) noModules("mixing (materials[].miscible_with)");
  for (const MaterialDef& m : materials)
    if (m.granular()) noModules("a granular material (materials[].kind)");
  for (std::size_t a = 0; a < materials.size(); ++a)
    for (std::size_t b = 0; b < a; ++b)
      if (tensionBetween(materials, a, b) > 0) noModules("interface tension (materials[].tension_with)");
  return {};
}

/// Refused: user forces are an effect module.
std::unique_ptr<Effect> makeUserForceEffect(const std::vector<UserForce>*) { noModules("a user force"); }

#else

#define SPH2D_EFFECT(name) std::unique_ptr<Effect> name##Effect(const SceneDef& scene);
#include "effects/effects.def"
#undef SPH2D_EFFECT

EffectList makeEffects(const SceneDef& scene) {
  EffectList out;
  std::unique_ptr<Effect> e;
#define SPH2D_EFFECT(name) \
  if ((e = name##Effect(scene))) out.push_back(std::move(e));
#include "effects/effects.def"
#undef SPH2D_EFFECT
  return out;
}

#endif

}  // namespace sph2d
