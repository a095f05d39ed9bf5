// The solver registry: the solvers of solvers.def, looked up by scene name.
#include <stdexcept>
#include <string>

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

std::pair<std::string, std::string> solverParamProblem(const SolverDef& def) {
  const SolverInfo* e = find(def.type);
  return e && e->check ? e->check(def) : std::pair<std::string, std::string>{};
}

std::unique_ptr<Solver> makeSolver(const SolverDef& def) {
  const SolverInfo* e = find(def.type);
  if (!e) throw std::invalid_argument("unknown solver '" + def.type + "'");
  return e->make(def);
}

}  // namespace sph2d
