// The World's stepper (engine/src/world/stepper.cpp): the substep is one list of
// stages built with the World, rebuilt when effects change; the time-step
// policy turns slivers of a step into a drift.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "sph2d/world.hpp"
#include "support/fixture.hpp"

using namespace sph2d;

namespace {

std::uint64_t callsOf(const World& w, const std::string& stage) {
  for (const StageTiming& t : w.profile().stages)
    if (t.name == stage) return t.calls;
  return 0;
}

using test::maxSpeed;

}  // namespace

TEST_CASE("the stage list exists from construction: the solver's stages, the effects at its marker, then collision") {
  const SceneDef s = test::scene("tests/resting_column.json");  // muller2003 with viscosity
  World w(s, WorldOptions{1});
  // muller2003 folds the viscosity (the first effect) into its pressure force's pair loop.
  const std::vector<std::string> expected = {
      "grid",        "neighbours", "density",          "pressure", "pressure_force+viscosity",
      "force_limit", "integrate",  "max_acceleration", "collide"};
  CHECK(w.stages() == expected);
  w.stepFrame();
  CHECK(w.stages() == expected);  // running it does not change it
  for (const std::string& name : expected) CHECK(callsOf(w, name) == w.counters().substeps);
}

TEST_CASE("switching an effect or adding a user force rebuilds the list, and a switched-off effect runs no stage") {
  SceneDef s = test::scene("tests/resting_column.json");
  s.effects.xsph = true;
  World w(s, WorldOptions{1});
  auto has = [&](const std::string& n) {
    const auto st = w.stages();
    return std::find(st.begin(), st.end(), n) != st.end();
  };
  CHECK(has("xsph"));
  w.setEffectEnabled("xsph", false);
  CHECK_FALSE(has("xsph"));
  w.stepFrame();
  CHECK(callsOf(w, "xsph") == 0);
  w.setEffectEnabled("xsph", true);
  CHECK_FALSE(has("user_force"));
  w.setUserForces({UserForce{Vec2d(0.3, 0.3), 0.2, 10}});
  CHECK(has("user_force"));
  // Effects run in the registry's order, user forces last, all before integrate.
  const auto st = w.stages();
  const auto at = [&](const std::string& n) { return std::find(st.begin(), st.end(), n) - st.begin(); };
  CHECK(at("pressure_force+viscosity") < at("xsph"));  // muller2003 folds the viscosity (the first effect)
  CHECK(at("xsph") < at("user_force"));
  CHECK(at("user_force") < at("integrate"));
}

TEST_CASE("muller2003 folds the viscosity into its pressure force only while it is the first enabled effect") {
  SceneDef s = test::scene("tests/resting_column.json");  // muller2003 with viscosity
  World w(s, WorldOptions{1});
  auto has = [&](const std::string& n) {
    const auto st = w.stages();
    return std::find(st.begin(), st.end(), n) != st.end();
  };
  CHECK(has("pressure_force+viscosity"));
  CHECK_FALSE(has("viscosity"));
  w.setEffectEnabled("viscosity", false);
  CHECK(has("pressure_force"));
  CHECK_FALSE(has("pressure_force+viscosity"));
  w.stepFrame();
  CHECK(callsOf(w, "pressure_force+viscosity") == 0);
  SceneDef ws = s;  // a solver that does not fold keeps the effect's own stage
  ws.solver.type = "wcsph";
  ws.solver.params.clear();
  World v(ws, WorldOptions{1});
  const auto st = v.stages();
  CHECK(std::find(st.begin(), st.end(), "viscosity") != st.end());
}

namespace {

void sliverOnlyDrifts(const std::string& solver) {
  SceneDef s = test::scene("tests/resting_column.json");
  s.solver.type = solver;
  s.solver.params.clear();
  World w(s, WorldOptions{1});
  for (int f = 0; f < 30; ++f) w.stepFrame();
  const double v0 = maxSpeed(w), t0 = w.time();
  const std::vector<StageTiming> before = w.profile().stages;
  // A caller stepping "up to time t" asks for a remainder of a microsecond, many times.
  for (int k = 0; k < 50; ++k) w.step(1e-6);
  CHECK(w.time() == doctest::Approx(t0 + 50e-6).epsilon(1e-9));
  for (const StageTiming& t : before) {
    CAPTURE(t.name);
    CHECK(callsOf(w, t.name) == t.calls);  // no stage of the substep ran (the drift is its own list)
  }
  MESSAGE(solver << ": largest speed " << v0 << " -> " << maxSpeed(w) << " m/s");
  CHECK(maxSpeed(w) < v0 + 0.01);  // gravity over 50 µs adds 0.5 mm/s
  w.stepFrame();                   // and a normal frame after it is still calm
  CHECK(maxSpeed(w) < std::max(2 * v0, 0.3));
}

/// The same with a jelly resting on the floor (an elastic group): the drift's groups stage has
/// no substep's corrections to take into its velocity (the game solver's were the last full
/// substep's; taken over a microsecond they kicked the jelly at hundreds of m/s).
void sliverKeepsJellyAtRest(const std::string& solver) {
  SceneDef s = test::tank(solver, 1.0, 1.0, 0.02);
  World w(s, WorldOptions{1});
  GroupDef g;
  g.region = test::block({0.4, 0.01}, {0.6, 0.21});
  g.stiffness = 0.5;
  w.createGroup(g);
  for (int f = 0; f < 90; ++f) w.stepFrame();
  const double v0 = maxSpeed(w);
  for (int k = 0; k < 50; ++k) w.step(1e-6);
  MESSAGE(solver << " with a jelly: largest speed " << v0 << " -> " << maxSpeed(w) << " m/s");
  CHECK(maxSpeed(w) < v0 + 0.01);
  w.stepFrame();
  CHECK(maxSpeed(w) < std::max(2 * v0, 0.3));
}

}  // namespace

TEST_CASE_EVERY_SOLVER("a sliver of a step only drifts (no solver stage runs, nothing is kicked)", sliverOnlyDrifts)
TEST_CASE_EVERY_SOLVER("a sliver of a step leaves a resting jelly at rest", sliverKeepsJellyAtRest)

TEST_CASE("the guard stops a run at the first non-finite value and names stage and particle") {
  SceneDef s = test::scene("tests/small_dam_break.json");
  s.gravity = Vec2d(0, std::nan(""));
  World w(s, WorldOptions{2});
  try {
    w.stepFrame();
    FAIL("expected SimulationError");
  } catch (const SimulationError& e) {
    CHECK(e.stage == "pressure_force+viscosity");  // gravity is added there: the first stage to see the NaN
    CHECK(e.step == 0);
    CHECK(std::string(e.what()).find("particle id") != std::string::npos);
  }
}
