// Scene loading: good scenes load, bad ones name file, line, column, key and what is allowed.
#include <doctest/doctest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"
#include "support/fixture.hpp"
#include "test_util.hpp"

using namespace sph2d;

namespace {
SceneError errorOf(const std::string& text) {
  try {
    parseScene(text, "bad.json");
  } catch (const SceneError& e) {
    return e;
  }
  FAIL("no SceneError for: " << text);
  return SceneError("", 0, 0, "", "");
}
}  // namespace

TEST_CASE("the default dam break scene loads with its documented values") {
  const SceneDef s = test::scene("dam_break.json");
  CHECK(s.name == "dam_break");
  CHECK(s.blocks.size() == 1);
  CHECK(s.bodies.size() == 1);
  CHECK(s.bodies[0].fixtures.size() == 4);
  CHECK(s.fps == 60);
  CHECK(s.duration == 4);
  CHECK(s.render.width == 960);
  CHECK(s.render.height == 540);
  CHECK(s.solver.type == "game");  // quality: game, real time (issue 15)
  CHECK(s.solver.spacing == 0.014);
  const std::size_t n = countBlockParticles(s);
  CHECK(n > 9000);
  CHECK(n < 11000);
}

TEST_CASE("the seed's dam break keeps the seed's solver one scene away, with the same tank and column") {
  const SceneDef a = test::scene("dam_break.json"), m = test::scene("dam_break_muller2003.json");
  CHECK(m.solver.type == "muller2003");
  CHECK(m.solver.soundSpeed == 25);
  CHECK(m.solver.viscosity == 0.01);
  CHECK(m.solver.spacing == a.solver.spacing);
  CHECK(countBlockParticles(m) == countBlockParticles(a));
  CHECK(m.bodies[0].fixtures.size() == a.bodies[0].fixtures.size());
  CHECK(m.render.width == a.render.width);
}

TEST_CASE("an unknown key names file, line, column, the key path and the allowed keys") {
  const SceneError e = errorOf("{\n  \"solver\": {\n    \"spacing\": 0.02,\n    \"spacng\": 1\n  }\n}\n");
  CHECK(e.file == "bad.json");
  CHECK(e.line == 4);
  CHECK(e.column == 5);
  CHECK(e.key == "solver.spacng");
  CHECK(std::string(e.what()).find("allowed keys: type, quality, spacing") != std::string::npos);
  CHECK(std::string(e.what()).rfind("bad.json:4:5: key 'solver.spacng'", 0) == 0);
}

TEST_CASE("a wrong type, a bad range and a bad choice are each reported at their key") {
  SceneError e = errorOf("{\"fps\": \"sixty\"}");
  CHECK(e.key == "fps");
  CHECK(e.message.find("expected a number, got a string") != std::string::npos);

  e = errorOf("{\"solver\": {\"spacing\": -0.1}}");
  CHECK(e.key == "solver.spacing");
  CHECK(e.message.find("> 0") != std::string::npos);

  e = errorOf("{\"solver\": {\"type\": \"magic\"}}");
  CHECK(e.message.find("allowed values: muller2003") != std::string::npos);

  e = errorOf("{\"boundaries\": [{\"fixtures\": [{\"shape\": \"box\", \"half_size\": [1, 0]}]}]}");
  CHECK(e.key == "boundaries[0].fixtures[0].half_size");

  e = errorOf(
      "{\"boundaries\": [{\"fixtures\": [{\"shape\": \"polygon\", \"vertices\": [[0,0],[2,0],[1,0.2],[2,2],[0,2]]}]}]}");
  CHECK(e.message.find("convex") != std::string::npos);

  e = errorOf("{\"fluid\": [{\"min\": [0, 0], \"max\": [1]}]}");
  CHECK(e.key == "fluid[0].max");
}

TEST_CASE("invalid JSON reports the line and column of the fault") {
  const SceneError e = errorOf("{\n  \"fps\": 60,\n  \"duration\": 4,,\n}\n");
  CHECK(e.line == 3);
  CHECK(e.column == 17);
  CHECK(e.message.find("invalid JSON") != std::string::npos);
}

TEST_CASE("a spacing too small for the particle budget is refused with the count") {
  const SceneError e = errorOf(
      "{\"max_particles\": 1000, \"solver\": {\"spacing\": 0.01}, \"fluid\": [{\"min\": [0,0], \"max\": [1,1]}]}");
  CHECK(e.key == "solver.spacing");
  CHECK(e.message.find("10000 particles") != std::string::npos);
}

TEST_CASE("a missing scene file names the file") {
  try {
    loadScene("/nonexistent/scene.json");
    FAIL("expected SceneError");
  } catch (const SceneError& e) {
    CHECK(e.file == "/nonexistent/scene.json");
    CHECK(e.message.find("cannot open") != std::string::npos);
  }
}

TEST_CASE("solver.quality presets pick a solver, and cannot be combined with solver.type") {
  CHECK(parseScene("{\"solver\": {\"quality\": \"game\"}}", "q.json").solver.type == "game");
  CHECK(parseScene("{\"solver\": {\"quality\": \"balanced\"}}", "q.json").solver.type == "wcsph");
  CHECK(parseScene("{\"solver\": {\"quality\": \"accurate\"}}", "q.json").solver.type == "dfsph");
  try {
    parseScene("{\"solver\": {\"quality\": \"game\", \"type\": \"wcsph\"}}", "q.json");
    FAIL("expected SceneError");
  } catch (const SceneError& e) {
    CHECK(e.key == "solver.quality");
  }
  try {
    parseScene("{\"solver\": {\"quality\": \"ultra\"}}", "q.json");
    FAIL("expected SceneError");
  } catch (const SceneError& e) {
    CHECK(e.message.find("game, balanced, accurate") != std::string::npos);
  }
}

TEST_CASE(
    "a scene or a program that names no solver is real time (the game preset), and a named solver starts from its own defaults") {
  // Issue 15: "real time by default". The game preset's values (its viscosity 0, support 2 and
  // its parameters), not muller2003's as before 24 Nov.
  const SolverDef game = qualityPreset("game");
  for (const SolverDef& d : {SceneDef().solver, parseScene("{}", "none.json").solver,
                             parseScene("{\"solver\": {\"spacing\": 0.03}}", "spacing.json").solver}) {
    CHECK(d.type == "game");
    CHECK(d.viscosity == game.viscosity);
    CHECK(d.supportRatio == game.supportRatio);
    CHECK(d.params == game.params);
  }
  // Naming a type gives that solver's defaults, not the game preset's with another name.
  const SolverDef named = parseScene("{\"solver\": {\"type\": \"muller2003\"}}", "m.json").solver;
  const SolverDef muller = solverDefaults("muller2003");
  CHECK(named.type == "muller2003");
  CHECK(named.viscosity == muller.viscosity);
  CHECK(named.supportRatio == muller.supportRatio);
  CHECK(named.params == muller.params);
  // And the World built from a default SceneDef runs the game solver's stages.
  SceneDef s;
  s.solver.spacing = 0.05;
  s.bodies.push_back(test::tankWalls(1.0, 1.0));
  s.blocks.push_back(test::block({0, 0}, {0.5, 0.5}));
  const World w(s, WorldOptions{1});
  const std::vector<std::string> st = w.stages();
  CHECK(std::find(st.begin(), st.end(), "grid_projection") != st.end());
}
