// The solver registry (engine/src/solvers/registry.cpp): every solver of
// solvers.def is built by its scene name, declares its own parameters with
// defaults inside their ranges, and a scene built in code gets those defaults.
#include <doctest/doctest.h>

#include <set>
#include <stdexcept>
#include <string>

#include "solvers/solver.hpp"

using namespace sph2d;

TEST_CASE("every registered solver is built by its name, with its parameters' defaults, and says its name") {
  REQUIRE(solverNames().size() >= 4);
  for (const std::string& type : solverNames()) {
    CAPTURE(type);
    SolverDef def;
    def.type = type;
    fillSolverDefaults(def);
    const auto solver = makeSolver(def);
    REQUIRE(solver != nullptr);
    CHECK(std::string(solver->name()) == type);
    std::set<std::string> keys;
    for (const SolverParam& p : solverParams(type)) {
      CAPTURE(p.key);
      CHECK(keys.insert(p.key).second);  // each key once
      CHECK(p.lo <= p.def);
      CHECK(p.def <= p.hi);
      CHECK(def.params.at(p.key) == p.def);  // filled with the default
    }
    CHECK(def.params.size() == keys.size());
  }
}

TEST_CASE("fillSolverDefaults keeps the parameters a scene gives and fills only the missing ones") {
  SolverDef def;
  def.type = "dfsph";
  def.params["tolerance"] = 0.0005;
  fillSolverDefaults(def);
  CHECK(def.params.at("tolerance") == 0.0005);
  CHECK(def.params.at("max_iterations") == 100);
  CHECK(def.params.size() == solverParams("dfsph").size());
}

TEST_CASE("an unknown solver type is refused by name and has no parameters") {
  SolverDef def;
  def.type = "sph-from-the-future";
  CHECK(solverParams(def.type).empty());
  fillSolverDefaults(def);
  CHECK(def.params.empty());
  try {
    makeSolver(def);
    FAIL("an unknown solver was built");
  } catch (const std::invalid_argument& e) {
    CHECK(std::string(e.what()).find("'sph-from-the-future'") != std::string::npos);
  }
}
