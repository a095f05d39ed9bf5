// materials.cpp — a scene's `materials` table and the one rule every way of adding a
// material follows (materialProblem): the scene loader, World's constructor and
// World::addMaterial all ask it, so a table refused in a file is refused in code too.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "scene/scene_sections.hpp"

namespace sph2d {
namespace {

std::string names(const std::vector<MaterialDef>& materials) {
  std::string out;
  for (const MaterialDef& m : materials) out += (out.empty() ? "" : ", ") + m.name;
  return out;
}

}  // namespace

double viscosityOf(const MaterialDef& m, const SolverDef& solver) {
  return m.viscosity < 0 ? solver.viscosity : m.viscosity;
}

bool takesDensityContrast(const std::string& solver) {
  return solver == "wcsph" || solver == "pbf" || solver == "game";
}

std::string densityContrastProblem(const SceneDef& scene) {
  const EffectsDef& e = scene.effects;
  const char* effect = e.xsph ? "xsph" : e.shifting ? "shifting" : e.surfaceTension ? "surface_tension" : nullptr;
  if (!effect) return "";
  return std::string("effects.") + effect +
         " does not take materials of different density yet (it weighs neighbours by one particle mass)";
}

std::vector<MaterialDef> sceneMaterials(const SceneDef& scene) {
  if (!scene.materials.empty()) return scene.materials;
  MaterialDef m;
  m.density = scene.solver.restDensity;
  m.viscosity = scene.solver.viscosity;
  m.color = scene.render.water;
  m.transmission = scene.render.transmission;
  return {m};
}

std::string materialProblem(const std::vector<MaterialDef>& materials, const MaterialDef& m, const SolverDef& solver) {
  std::ostringstream o;
  o.precision(9);
  if (m.name.empty() || m.name.size() > MaterialDef::kMaxName)
    o << "a material's name must be 1 to " << MaterialDef::kMaxName << " characters";
  else if (materials.size() >= MaterialDef::kMaxMaterials)
    o << "a World holds at most " << MaterialDef::kMaxMaterials << " materials";
  else if (!(m.density >= MaterialDef::kMinDensity && m.density <= MaterialDef::kMaxDensity))
    o << "density must be in " << MaterialDef::kMinDensity << ".." << MaterialDef::kMaxDensity << " kg/m³, got "
      << m.density;
  else if (!(m.viscosity <= MaterialDef::kMaxViscosity) || (m.viscosity < 0 && m.viscosity != -1))
    o << "viscosity must be in 0.." << MaterialDef::kMaxViscosity << " m²/s (or absent: the solver's), got "
      << m.viscosity;
  if (o.tellp() == 0 && !(m.diffusion >= 0 && m.diffusion <= MaterialDef::kMaxDiffusion))
    o << "diffusion must be in 0.." << MaterialDef::kMaxDiffusion << " m²/s, got " << m.diffusion;
  if (o.tellp() == 0 && !(m.frictionAngle >= 0 && m.frictionAngle <= MaterialDef::kMaxFrictionAngle))
    o << "friction_angle must be in 0.." << MaterialDef::kMaxFrictionAngle << " degrees, got " << m.frictionAngle;
  if (o.tellp() == 0 && !(m.cohesion >= 0 && m.cohesion <= MaterialDef::kMaxCohesion))
    o << "cohesion must be in 0.." << MaterialDef::kMaxCohesion << " Pa, got " << m.cohesion;
  if (o.tellp() == 0 && m.granular() && solver.type != "game")
    o << "kind \"granular\" needs solver.type \"game\" (its friction acts between the pressure projection "
         "and the move), got \""
      << solver.type << "\"";
  else if (o.tellp() == 0 && m.granular() && !(solver.param("grid_cell") > 0))
    o << "kind \"granular\" needs the game solver's grid projection (solver.grid_cell above 0, its default 2)";
  for (double c : m.color)
    if (o.tellp() == 0 && !(c >= 0 && c <= 1)) o << "color components must be in 0..1, got " << c;
  for (double t : m.transmission)
    if (o.tellp() == 0 && !(t >= 0 && t <= 1)) o << "transmission components must be in 0..1, got " << t;
  if (o.tellp() != 0) return o.str();
  for (const MaterialDef& other : materials)
    if (other.name == m.name) return "the name \"" + m.name + "\" is taken (materials: " + names(materials) + ")";
  for (const std::string& n : m.miscibleWith) {
    bool known = n == m.name;
    for (const MaterialDef& other : materials) known = known || other.name == n;
    if (!known)
      return "miscible_with names \"" + n + "\", which is no material before it (materials: " +
             (materials.empty() ? std::string("none") : names(materials)) + ")";
  }
  for (const auto& [n, sigma] : m.tensionWith) {
    const MaterialDef* other = nullptr;
    for (const MaterialDef& candidate : materials)
      if (candidate.name == n) other = &candidate;
    if (!other)
      return "tension_with names \"" + n + "\", which is no material before it (materials: " +
             (materials.empty() ? std::string("none") : names(materials)) + ")";
    if (!(sigma >= 0 && sigma <= MaterialDef::kMaxTension)) {
      o << "tension_with." << n << " must be in 0.." << MaterialDef::kMaxTension << " N/m, got " << sigma;
      return o.str();
    }
    const bool listed =
        std::find(m.miscibleWith.begin(), m.miscibleWith.end(), n) != m.miscibleWith.end() ||
        std::find(other->miscibleWith.begin(), other->miscibleWith.end(), m.name) != other->miscibleWith.end();
    if (listed && sigma > 0)
      return "tension_with names \"" + n +
             "\", which it mixes with (miscible_with): a pair that mixes has no interface";
  }
  if (materials.empty()) return "";
  // wcsph, pbf and game take a density contrast (number density), muller2003 and dfsph one
  // rest density for all particles; every solver a viscosity per material.
  const MaterialDef& first = materials.front();
  if (m.density != first.density && !takesDensityContrast(solver.type))
    o << "density " << m.density << " kg/m³ differs from the first material's (" << first.name << ", " << first.density
      << "): solver '" << solver.type
      << "' takes materials of one density (wcsph, pbf and game take a density contrast)";
  return o.str();
}

void readMaterials(const Reader& r, const nlohmann::json& root, SceneDef& s) {
  if (!root.contains("materials")) return;
  const nlohmann::json& arr = root.at("materials");
  if (!arr.is_array() || arr.empty())
    r.fail("materials", "expected an array of one or more materials, got " + describe(arr));
  const nlohmann::json* solver = root.contains("solver") ? &root.at("solver") : nullptr;
  for (std::size_t k = 0; k < arr.size(); ++k) {
    const std::string p = "materials[" + std::to_string(k) + "]";
    const nlohmann::json& j = arr[k];
    r.requireObject(j, p);
    r.checkKeys(j, p,
                {"name", "density", "viscosity", "color", "transmission", "miscible_with", "diffusion", "tension_with",
                 "kind", "friction_angle", "cohesion"});
    MaterialDef m;
    if (!j.contains("name")) r.fail(Reader::sub(p, "name"), "missing; expected the material's name");
    m.name = r.string(j, p, "name", "", {});
    // The first material is the solver's fluid: its density and viscosity default to the
    // solver's, and may not contradict them.
    const bool first = k == 0;
    m.density = r.number(j, p, "density", first ? s.solver.restDensity : 1000, MaterialDef::kMinDensity,
                         MaterialDef::kMaxDensity);
    if (j.contains("viscosity")) m.viscosity = r.number(j, p, "viscosity", 0, 0, MaterialDef::kMaxViscosity);
    m.color = r.color(j, p, "color", s.render.water);
    m.transmission = r.color(j, p, "transmission", s.render.transmission);
    m.diffusion = r.number(j, p, "diffusion", m.diffusion, 0, MaterialDef::kMaxDiffusion);
    if (r.string(j, p, "kind", "fluid", {"fluid", "granular"}) == "granular") m.kind = MaterialDef::Kind::granular;
    for (const char* key : {"friction_angle", "cohesion"})
      if (j.contains(key) && !m.granular())
        r.fail(Reader::sub(p, key), std::string(key) + " is a granular material's: give \"kind\": \"granular\"");
    m.frictionAngle = r.number(j, p, "friction_angle", m.frictionAngle, 0, MaterialDef::kMaxFrictionAngle);
    m.cohesion = r.number(j, p, "cohesion", m.cohesion, 0, MaterialDef::kMaxCohesion);
    if (j.contains("miscible_with")) {
      const nlohmann::json& mw = j.at("miscible_with");
      const std::string q = Reader::sub(p, "miscible_with");
      if (!mw.is_array()) r.fail(q, "expected an array of material names, got " + describe(mw));
      for (std::size_t i = 0; i < mw.size(); ++i) {
        if (!mw[i].is_string()) r.fail(q + "[" + std::to_string(i) + "]", "expected a material's name");
        m.miscibleWith.push_back(mw[i].get<std::string>());
      }
    }
    if (j.contains("tension_with")) {
      const nlohmann::json& tw = j.at("tension_with");
      const std::string q = Reader::sub(p, "tension_with");
      if (!tw.is_object())
        r.fail(q,
               "expected an object of material names and tensions in N/m, e.g. {\"water\": 0.03}, got " + describe(tw));
      for (auto it = tw.begin(); it != tw.end(); ++it)
        m.tensionWith.emplace_back(it.key(), r.number(tw, q, it.key(), 0, 0, MaterialDef::kMaxTension));
    }
    if (first) {
      for (const char* key : {"rest_density", "viscosity"}) {
        const bool density = std::string(key) == "rest_density";
        const double mine = density ? m.density : m.viscosity;
        const double theirs = density ? s.solver.restDensity : s.solver.viscosity;
        if (solver && solver->is_object() && solver->contains(key) && j.contains(density ? "density" : "viscosity") &&
            mine != theirs)
          r.fail(Reader::sub(p, density ? "density" : "viscosity"),
                 "the first material is the solver's fluid: its " + std::string(density ? "density" : "viscosity") +
                     " (" + j.at(density ? "density" : "viscosity").dump() + ") must be solver." + key + "'s (" +
                     solver->at(key).dump() + ") or absent");
      }
      s.solver.restDensity = m.density;
      if (m.viscosity >= 0) s.solver.viscosity = m.viscosity;
    }
    const std::string problem = materialProblem(s.materials, m, s.solver);
    if (!problem.empty()) {
      const char* key = problem.rfind("density", 0) == 0     ? "density"
                        : problem.rfind("viscosity", 0) == 0 ? "viscosity"
                        : problem.rfind("color", 0) == 0     ? "color"
                        : problem.rfind("diffusion", 0) == 0 ? "diffusion"
                        : problem.rfind("miscible", 0) == 0  ? "miscible_with"
                        : problem.rfind("tension", 0) == 0   ? "tension_with"
                        : problem.rfind("friction", 0) == 0  ? "friction_angle"
                        : problem.rfind("cohesion", 0) == 0  ? "cohesion"
                        : problem.rfind("kind", 0) == 0      ? "kind"
                                                             : "name";
      r.fail(problem.rfind("a World", 0) == 0 ? p : Reader::sub(p, key), problem);
    }
    s.materials.push_back(m);
  }
}

std::uint32_t readMaterialName(const Reader& r, const nlohmann::json& j, const std::string& path, const SceneDef& s) {
  if (!j.contains("material")) return 0;
  const std::vector<MaterialDef> all = sceneMaterials(s);
  std::vector<std::string> allowed;
  for (const MaterialDef& m : all) allowed.push_back(m.name);
  const std::string name = r.string(j, path, "material", "", allowed);
  for (std::size_t k = 0; k < all.size(); ++k)
    if (all[k].name == name) return std::uint32_t(k);
  return 0;
}

}  // namespace sph2d
