// The solver registry: the solvers of solvers.def, looked up by scene name.
#include <stdexcept>
#include <string>
#include <utility>

#include "core/range_message.hpp"
#include "solvers/solver.hpp"

namespace sph2d {

#define SPH2D_SOLVER(name) SolverInfo name##Solver();
#include "solvers/solvers.def"
#undef SPH2D_SOLVER

namespace {

const std::vector<SolverInfo>& entries() {
  static const std::vector<SolverInfo> e = {
#define SPH2D_SOLVER(name) name##Solver(),
#include "solvers/solvers.def"
#undef SPH2D_SOLVER
  };
  return e;
}

const SolverInfo* find(const std::string& type) {
  for (const auto& e : entries())
    if (type == e.name) return &e;
  return nullptr;
}

}  // namespace

const std::vector<std::string>& solverNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& e : entries()) n.push_back(e.name);
    return n;
  }();
  return names;
}

const std::vector<SolverParam>& solverParams(const std::string& type) {
  static const std::vector<SolverParam> none;
  const SolverInfo* e = find(type);
  return e ? e->params : none;
}

void tuneSolverDefaults(SolverDef& def) {
  const SolverInfo* e = find(def.type);
  if (e && e->tune) e->tune(def);
}

const std::vector<std::string>& qualityPresets() {
  static const std::vector<std::string> q = {"game", "balanced", "accurate"};
  return q;
}

SolverDef solverDefaults(const std::string& type) {
  if (!find(type)) throw std::invalid_argument("unknown solver '" + type + "'");
  SolverDef d;
  d.type = type;
  tuneSolverDefaults(d);
  fillSolverDefaults(d);
  return d;
}

SolverDef qualityPreset(const std::string& quality) {
  // The solver of each preset, chosen from docs/ACCURACY.md's and docs/PERFORMANCE.md's measurements.
  if (quality == "game") return solverDefaults("game");
  if (quality == "balanced") return solverDefaults("wcsph");
  if (quality == "accurate") return solverDefaults("dfsph");
  throw std::invalid_argument("unknown quality preset '" + quality + "'; presets: game, balanced, accurate");
}

void fillSolverDefaults(SolverDef& def) {
  for (const SolverParam& p : solverParams(def.type))
    if (!def.params.count(p.key)) def.params[p.key] = p.def;
}

const std::vector<SharedSolverKey>& sharedSolverKeys() {
  // The ranges the scene loader enforces (scene_sections.cpp reads them from here).
  static const std::vector<SharedSolverKey> k = {
      {"spacing", 0, 10, true, [](const SolverDef& d) { return d.spacing; }},
      {"support_ratio", 1.5, 4, false, [](const SolverDef& d) { return d.supportRatio; }},
      {"rest_density", 0, 1e5, true, [](const SolverDef& d) { return d.restDensity; }},
      {"sound_speed", 0, 1e4, true, [](const SolverDef& d) { return d.soundSpeed; }},
      {"viscosity", 0, 100, false, [](const SolverDef& d) { return d.viscosity; }},
      {"cfl", 0, 1, true, [](const SolverDef& d) { return d.cfl; }},
      {"max_substeps", 1, 100000, false, [](const SolverDef& d) { return double(d.maxSubsteps); }},
      {"reorder_interval", 0, 1000000, false, [](const SolverDef& d) { return double(d.reorderInterval); }},
      {"max_speed", 0, 1e6, true, [](const SolverDef& d) { return d.maxSpeed; }},
  };
  return k;
}

namespace {
/// {"solver.<key>", why} when v is not finite or outside its range (the loader's message).
std::pair<std::string, std::string> outOfRange(const std::string& key, double v, double lo, double hi, bool loOpen) {
  std::string why = rangeProblem(v, lo, hi, loOpen);
  return why.empty() ? std::pair<std::string, std::string>{} : std::make_pair("solver." + key, std::move(why));
}
}  // namespace

std::pair<std::string, std::string> solverParamProblem(const SolverDef& def) {
  // A SolverDef built in code (or changed after loading) is held to the loader's ranges:
  // the shared keys, then each parameter, which must be one the solver declares.
  for (const SharedSolverKey& k : sharedSolverKeys())
    if (auto p = outOfRange(k.key, k.get(def), k.lo, k.hi, k.loOpen); !p.first.empty()) return p;
  const SolverInfo* e = find(def.type);
  if (!e) return {"solver.type", "unknown solver '" + def.type + "'"};
  for (const auto& [key, value] : def.params) {
    const SolverParam* sp = nullptr;
    for (const SolverParam& q : e->params)
      if (q.key == key) sp = &q;
    if (!sp) {
      std::string keys;
      for (const SolverParam& q : e->params) keys += (keys.empty() ? "" : ", ") + q.key;
      return {"solver." + key, "not a parameter of the " + def.type +
                                   " solver (to change a solver's type, start from solverDefaults(\"" + def.type +
                                   "\")); its parameters: " + keys};
    }
    if (auto p = outOfRange(key, value, sp->lo, sp->hi, false); !p.first.empty()) return p;
  }
  return e->check ? e->check(def) : std::pair<std::string, std::string>{};
}

std::string solverDefProblem(const SolverDef& def) {
  SolverDef d = def;
  fillSolverDefaults(d);
  const auto p = solverParamProblem(d);
  return p.first.empty() ? std::string() : p.first + ": " + p.second;
}

std::unique_ptr<Solver> makeSolver(const SolverDef& def) {
  const SolverInfo* e = find(def.type);
  if (!e) throw std::invalid_argument("unknown solver '" + def.type + "'");
  return e->make(def);
}

}  // namespace sph2d
