// test_util.hpp — helpers shared by the tests: scene paths and small probes.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace sph2d {
/// "(x, y)": a vector in a test's message.
template <class T>
std::ostream& operator<<(std::ostream& o, const Vector2<T>& v) {
  return o << '(' << v.x() << ", " << v.y() << ')';
}
}  // namespace sph2d

namespace sph2d::test {

/// Absolute path of a file under assets/.
inline std::string asset(const std::string& rel) { return std::string(SPH2D_ASSETS) + "/" + rel; }

/// Loads a scene under assets/scenes/.
inline SceneDef scene(const std::string& rel) { return loadScene(asset("scenes/" + rel)); }

/// True when every position, velocity and density is finite.
inline bool allFiniteState(const World& w) {
  const Particles& P = w.particles();
  for (std::size_t i = 0; i < P.size(); ++i)
    if (!allFinite(P.x[i]) || !allFinite(P.v[i]) || !std::isfinite(P.rho[i])) return false;
  return true;
}

/// Every pressure solver, in the registry's order (a test checks it matches
/// engine/src/solvers/registry.cpp, so a new solver cannot be left out).
inline const std::vector<std::string>& solvers() {
  static const std::vector<std::string> s = {"muller2003", "wcsph", "pbf", "dfsph", "game"};
  return s;
}

}  // namespace sph2d::test

/// One doctest TEST_CASE per solver of sph2d::test::solvers(), named "NAME (solver)",
/// each calling FN(solver) with the solver's name (a std::string): CTest runs, times
/// and reports every solver on its own, and a failure names the solver.
#define TEST_CASE_EVERY_SOLVER(NAME, FN)                             \
  TEST_CASE(NAME " (muller2003)") { FN(std::string("muller2003")); } \
  TEST_CASE(NAME " (wcsph)") { FN(std::string("wcsph")); }           \
  TEST_CASE(NAME " (pbf)") { FN(std::string("pbf")); }               \
  TEST_CASE(NAME " (dfsph)") { FN(std::string("dfsph")); }           \
  TEST_CASE(NAME " (game)") { FN(std::string("game")); }
