// materials.cpp — the World's materials (docs/SCENES.md, "materials"): the scene's table
// or the solver's one fluid, those a game adds, and each particle's material. The
// per-particle field ("material", ParticleStore::kMaterial) exists only while the World
// holds more than one material: a World of one fluid allocates nothing for materials.
#include <limits>
#include <sstream>
#include <stdexcept>

#include "particles/material_fields.hpp"
#include "world/world_impl.hpp"

namespace sph2d {

void World::Impl::initMaterials() {
  const SolverDef& sd = scene.solver;
  const std::string file = scene.path.empty() ? "scene" : scene.path;
  if (!scene.materials.empty()) {
    const MaterialDef& first = scene.materials.front();
    if (first.density != sd.restDensity || (first.viscosity >= 0 && first.viscosity != sd.viscosity)) {
      std::ostringstream o;
      o.precision(9);
      o << "the first material is the solver's fluid: its density (" << first.density << ") and viscosity ("
        << first.viscosity << ") must be solver.rest_density's (" << sd.restDensity << ") and solver.viscosity's ("
        << sd.viscosity << "), or the viscosity absent (< 0)";
      throw SceneError(file, 0, 0, "materials[0]", o.str());
    }
  }
  materials.clear();
  const std::vector<MaterialDef> all = sceneMaterials(scene);
  for (std::size_t k = 0; k < all.size(); ++k) {
    const std::string problem = materialProblem(materials, all[k], sd);
    if (!problem.empty()) throw SceneError(file, 0, 0, "materials[" + std::to_string(k) + "]", problem);
    materials.push_back(all[k]);
  }
  if (materials.size() > 1) P.fieldU32(ParticleStore::kMaterial);
  if (anyMiscible(materials)) {  // the mixing effect's fields: every particle's concentrations and colour
    for (std::size_t k = 0; k < materials.size(); ++k) P.fieldD(ParticleStore::concentration(k));
    P.fieldU32(ParticleStore::kMixedColor);
  }
  if (densityContrast()) {
    const std::string problem = densityContrastProblem(scene);
    if (!problem.empty()) throw SceneError(file, 0, 0, "effects", problem);
    P.field(ParticleStore::kRestRatio, 1);
  }
}

bool World::Impl::densityContrast() const {
  for (const MaterialDef& m : materials)
    if (m.density != materials.front().density) return true;
  return false;
}

void World::Impl::fillRestRatio(std::size_t from) {
  std::vector<Real>* ratio = P.find(ParticleStore::kRestRatio);
  const std::vector<std::uint32_t>* material = P.findU32(ParticleStore::kMaterial);
  if (!ratio || !material) return;
  const double rho0 = materials.front().density;
  for (std::size_t i = from; i < ratio->size(); ++i) (*ratio)[i] = Real(materials[(*material)[i]].density / rho0);
}

void World::Impl::checkMaterial(std::uint32_t m, const char* call) const {
  if (m < materials.size()) return;
  std::ostringstream o;
  o << call << ": material " << m << " does not exist (the world has " << materials.size() << ":";
  for (std::size_t k = 0; k < materials.size(); ++k) o << (k ? ", " : " ") << k << " " << materials[k].name;
  o << "; World::addMaterial adds one)";
  throw std::invalid_argument(o.str());
}

void World::Impl::checkSceneMaterial(std::uint32_t m, const std::string& key) const {
  try {
    checkMaterial(m, "the scene");
  } catch (const std::invalid_argument& e) {
    std::string why = e.what();
    why.erase(0, std::string("the scene: ").size());
    throw SceneError(scene.path.empty() ? "scene" : scene.path, 0, 0, key, why);
  }
}

void World::Impl::setMaterial(std::size_t from, std::uint32_t m) {
  std::vector<std::uint32_t>* f = P.findU32(ParticleStore::kMaterial);
  if (!f) return;
  if (m != 0)  // the field starts at 0, the first material
    for (std::size_t i = from; i < f->size(); ++i) (*f)[i] = m;
  initMaterialFields(from);
}

void World::Impl::initMaterialFields(std::size_t from) {
  fillRestRatio(from);  // a new particle's ratio starts at 0
  const std::vector<std::uint32_t>* material = P.findU32(ParticleStore::kMaterial);
  if (material && P.findD(ParticleStore::concentration(0))) {
    for (std::size_t k = 0; k < materials.size(); ++k) {  // all of its own material
      std::vector<double>& c = *P.findD(ParticleStore::concentration(k));
      for (std::size_t i = from; i < c.size(); ++i) c[i] = (*material)[i] == k ? 1.0 : 0.0;
    }
    deriveFromConcentrations(P, materials, from);
  }
  // With a density contrast a new particle starts at its own rest density (ParticleStore::push
  // gives ρ0): the solvers that read the last density as a compression (pbf's pushout, the
  // game solver's grid) then see none.
  if (const std::vector<Real>* ratio = P.find(ParticleStore::kRestRatio)) {
    const Real rho0 = Real(materials.front().density);
    for (std::size_t i = from; i < P.size(); ++i) {
      P.rho[i] = (*ratio)[i] * rho0;
      P.invRho[i] = Real(1) / P.rho[i];
    }
  }
}

std::uint32_t World::addMaterial(const MaterialDef& m) {
  Impl& w = *impl_;
  const std::string problem = materialProblem(w.materials, m, w.scene.solver);
  if (!problem.empty()) throw std::invalid_argument("addMaterial: " + problem);
  if (!m.tensionWith.empty())
    throw std::invalid_argument(
        "addMaterial: an interface tension (tension_with) is set up from the scene's materials table when the World "
        "is built: a material added at run time has none");
  if (w.P.findD(ParticleStore::concentration(0)) || !m.miscibleWith.empty())
    throw std::invalid_argument(
        "addMaterial: mixing (miscible_with) is set up from the scene's materials table when the World is built: a "
        "World that mixes takes no more materials, and one added at run time mixes with none");
  const double nu = viscosityOf(m, w.scene.solver);
  Effect* viscosity = nullptr;
  for (const auto& e : w.effects)
    if (std::string(e->name()) == "viscosity") viscosity = e.get();
  if (!viscosity && nu > 0) {
    std::ostringstream o;
    o.precision(9);
    o << "addMaterial: viscosity " << nu
      << " m²/s in a World built without viscosity (every material's 0): give the material in the scene's "
         "materials table, so that the World is built with the viscosity effect";
    throw std::invalid_argument(o.str());
  }
  Effect* granular = nullptr;
  for (const auto& e : w.effects)
    if (std::string(e->name()) == "granular") granular = e.get();
  if (m.granular() && !granular)
    throw std::invalid_argument(
        "addMaterial: a granular material in a World built without one: give it in the scene's materials table, so "
        "that the World is built with the granular effect");
  if (m.density != w.materials.front().density) {
    const std::string effects = densityContrastProblem(w.scene);
    if (!effects.empty()) throw std::invalid_argument("addMaterial: " + effects);
  }
  w.materials.push_back(m);
  if (viscosity && nu != viscosityOf(w.materials.front(), w.scene.solver)) {
    // A viscosity of its own: the effect's largest ν, and muller2003 no longer folds one
    // viscosity into its pressure loop.
    viscosity->materialsChanged(w.materials, w.scene.solver);
    w.buildStages();
  }
  if (granular) granular->materialsChanged(w.materials, w.scene.solver);
  if (w.foam) w.foam->setGranular(w.granularMaterials());
  if (w.materials.size() == 2) {  // from now on each particle says which (every one there now: the first)
    w.P.fieldU32(ParticleStore::kMaterial);
    w.refreshView();
  }
  if (w.densityContrast() && !w.P.find(ParticleStore::kRestRatio)) {
    w.P.field(ParticleStore::kRestRatio, 1);  // every particle there now: its material's
    w.fillRestRatio(0);
  }
  return std::uint32_t(w.materials.size() - 1);
}

const std::vector<MaterialDef>& World::materials() const { return impl_->materials; }

std::uint32_t World::materialIndex(const std::string& name) const {
  const std::vector<MaterialDef>& all = impl_->materials;
  for (std::size_t k = 0; k < all.size(); ++k)
    if (all[k].name == name) return std::uint32_t(k);
  return kNoMaterial;
}

std::uint32_t World::materialOf(std::uint32_t id) const {
  const std::size_t i = slotOf(id);
  if (i == npos) return kNoMaterial;
  const std::vector<std::uint32_t>* f = impl_->P.findU32(ParticleStore::kMaterial);
  return f ? (*f)[i] : 0u;
}

double World::concentrationOf(std::uint32_t id, std::uint32_t material) const {
  const std::size_t i = slotOf(id);
  if (i == npos) return std::numeric_limits<double>::quiet_NaN();
  if (const std::vector<double>* c = impl_->P.findD(ParticleStore::concentration(material))) return (*c)[i];
  return materialOf(id) == material ? 1.0 : 0.0;
}

double World::totalConcentration(std::uint32_t material) const {
  const ParticleStore& P = impl_->P;
  double sum = 0;
  if (const std::vector<double>* c = P.findD(ParticleStore::concentration(material))) {
    for (const double v : *c) sum += v;
    return sum;
  }
  const std::vector<std::uint32_t>* m = P.findU32(ParticleStore::kMaterial);
  for (std::size_t i = 0; i < P.size(); ++i) sum += (m ? (*m)[i] : 0u) == material ? 1.0 : 0.0;
  return sum;
}

std::vector<std::uint8_t> World::Impl::granularMaterials() const {
  std::vector<std::uint8_t> g;
  for (const MaterialDef& m : materials) g.push_back(m.granular() ? 1 : 0);
  return g;
}

}  // namespace sph2d
