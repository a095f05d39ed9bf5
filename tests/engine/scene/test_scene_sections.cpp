// The scene's section readers (engine/src/scene_sections.*), called one by one
// on a parsed document: what each fills, that an absent section leaves the
// defaults (the solver's own parameters included), and that a section is
// checked against the sections parseScene reads before it.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "scene/json_reader.hpp"
#include "scene/scene_reader.hpp"
#include "scene/scene_sections.hpp"
#include "solvers/solver.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"
#include "support/fixture.hpp"
#include "test_util.hpp"

using namespace sph2d;

namespace {

/// A parsed document and a Reader over it.
struct Doc {
  explicit Doc(const std::string& text) : doc(parseJsonWithPositions(text, "s.json")), r(doc, "s.json") {}
  JsonDoc doc;
  Reader r;
};

/// The message a section reader fails with on `text` ("" when it passes).
template <class Fn>
std::string failure(const std::string& text, SceneDef& s, Fn read) {
  const Doc d(text);
  try {
    read(d.r, d.doc.root, s);
  } catch (const SceneError& e) {
    return e.key + ": " + e.message;
  }
  return "";
}

}  // namespace

TEST_CASE("readSolver fills every parameter the solver declares, with or without a solver key") {
  for (const std::string& type : solverNames()) {
    INFO(type);
    // No solver key: the game preset with its defaults, whatever the SceneDef held (a scene
    // that names no solver is real time).
    const Doc d("{}");
    SceneDef s;
    s.solver = solverDefaults(type);
    readSolver(d.r, d.doc.root, s);
    CHECK(s.solver.type == "game");
    CHECK(s.solver.params.size() == solverParams("game").size());
    for (const SolverParam& sp : solverParams("game")) CHECK(s.solver.param(sp.key) == sp.def);
  }
  CHECK(solverParams("pbf").size() > 0);  // so that the loop above checks something
  for (const std::string& type : solverNames()) {
    INFO(type);
    const Doc d("{\"solver\": {\"type\": \"" + type + "\", \"spacing\": 0.03}}");
    SceneDef s;
    readSolver(d.r, d.doc.root, s);
    CHECK(s.solver.type == type);
    CHECK(s.solver.spacing == 0.03);
    CHECK(s.solver.params.size() == solverParams(type).size());
    for (const SolverParam& sp : solverParams(type)) CHECK(s.solver.param(sp.key) == sp.def);
  }
  // A given parameter overrides its default; the others keep theirs.
  const Doc d("{\"solver\": {\"type\": \"pbf\", \"iterations\": 7}}");
  SceneDef s;
  readSolver(d.r, d.doc.root, s);
  CHECK(s.solver.param("iterations") == 7);
  CHECK(s.solver.param("max_iterations") == 100);
  // Another solver's parameter is an unknown key.
  SceneDef w;
  CHECK(failure("{\"solver\": {\"type\": \"wcsph\", \"iterations\": 4}}", w, readSolver)
            .rfind("solver.iterations: unknown key", 0) == 0);
}

TEST_CASE(
    "a solver built in code is held to the ranges a scene file is: the reader's message, and the World refuses it") {
  // Every parameter of every solver, and every shared key, just outside each end of its range
  // (and not a number): solverDefProblem names the key with the reader's own message.
  auto readerSays = [](const std::string& type, const std::string& key, double v) {
    SceneDef s;
    char num[64];
    std::snprintf(num, sizeof num, "%.17g", v);
    const std::string m =
        failure("{\"solver\": {\"type\": \"" + type + "\", \"" + key + "\": " + num + "}}", s, readSolver);
    return m;
  };
  int checked = 0;
  for (const std::string& type : solverNames()) {
    for (const SolverParam& sp : solverParams(type)) {
      for (double v : {sp.lo - 1e-3 * (1 + std::fabs(sp.lo)), sp.hi + 1e-3 * (1 + std::fabs(sp.hi))}) {
        INFO(type << " " << sp.key << " = " << v);
        SolverDef d = solverDefaults(type);
        d.params[sp.key] = v;
        const std::string why = solverDefProblem(d);
        CHECK(why == readerSays(type, sp.key, v));
        CHECK(why.rfind("solver." + sp.key + ": value ", 0) == 0);
        ++checked;
      }
      SolverDef d = solverDefaults(type);
      d.params[sp.key] = std::nan("");
      CHECK(solverDefProblem(d).rfind("solver." + sp.key + ": value nan is out of range", 0) == 0);
    }
    for (const SharedSolverKey& k : sharedSolverKeys()) {
      const double v = k.loOpen ? k.lo : k.lo - 1;  // just outside the low end ([lo or (lo)
      INFO(type << " " << k.key << " = " << v);
      SolverDef d = solverDefaults(type);
      const std::string key = k.key;
      if (key == "spacing") d.spacing = v;
      if (key == "support_ratio") d.supportRatio = v;
      if (key == "rest_density") d.restDensity = v;
      if (key == "sound_speed") d.soundSpeed = v;
      if (key == "viscosity") d.viscosity = v;
      if (key == "cfl") d.cfl = v;
      if (key == "max_substeps") d.maxSubsteps = int(v);
      if (key == "reorder_interval") d.reorderInterval = int(v);
      if (key == "max_speed") d.maxSpeed = v;
      CHECK(k.get(d) == v);  // the setter above covers the key
      CHECK(solverDefProblem(d).rfind("solver." + key + ": value ", 0) == 0);
      ++checked;
    }
    // Another solver's parameter (or a misspelt one) is not this solver's.
    SolverDef d = solverDefaults(type);
    d.params["no_such_key"] = 1;
    CHECK(solverDefProblem(d).rfind("solver.no_such_key: not a parameter of the " + type + " solver", 0) == 0);
    CHECK(solverDefProblem(solverDefaults(type)).empty());
  }
  CHECK(checked > 100);
  // The World refuses such a solver, naming the key, before it builds anything.
  SceneDef s = test::wallScene(0.05, "game");
  s.blocks.push_back(test::block({0, 0}, {0.5, 0.5}));
  s.solver.params["max_move"] = 50;
  try {
    World w(s, WorldOptions{1});
    FAIL("max_move 50 was accepted");
  } catch (const SceneError& e) {
    CHECK(e.key == "solver.max_move");
    CHECK(e.message == "value 50 is out of range; allowed: >= 0.05 and <= 20");
  }
  s.solver.params["max_move"] = 10;
  s.solver.supportRatio = 1;
  CHECK_THROWS_AS(World(s, WorldOptions{1}), SceneError);
  s.solver.supportRatio = 2;
  World ok(s, WorldOptions{1});
  ok.stepFrame();
  CHECK(test::allFiniteState(ok));
}

TEST_CASE("a section reader leaves the scene's defaults when its key is absent") {
  const Doc d("{}");
  SceneDef s;
  const SceneDef defaults;
  readTopLevel(d.r, d.doc.root, s);
  readBoundaries(d.r, d.doc.root, s);
  readFluid(d.r, d.doc.root, s);
  readPeriodic(d.r, d.doc.root, s);
  readEffects(d.r, d.doc.root, s);
  readRender(d.r, d.doc.root, s);
  readEvents(d.r, d.doc.root, s);
  CHECK(s.name == defaults.name);
  CHECK(s.fps == defaults.fps);
  CHECK(s.maxParticles == defaults.maxParticles);
  CHECK(s.bodies.empty());
  CHECK(s.blocks.empty());
  CHECK_FALSE(s.periodic.any());
  CHECK_FALSE(s.effects.xsph);
  CHECK(s.effects.emitters.empty());
  CHECK(s.render.width == defaults.render.width);
  CHECK(s.render.camera.automatic);
  CHECK(s.events.empty());
}

TEST_CASE("each section reader fills its part of the scene") {
  const Doc d(R"({
    "name": "n", "fps": 30, "duration": 2, "max_particles": 1000,
    "boundaries": [{"position": [1, 2], "angle": 0.5, "fixtures": [
      {"shape": "box", "half_size": [1, 0.1], "friction": 0.4},
      {"shape": "chain", "loop": true, "vertices": [[0, 0], [1, 0], [1, 1]]}]}],
    "fluid": [{"min": [5, 5], "max": [6, 6], "velocity": [1, 0],
               "velocity_field": {"type": "taylor_green", "amplitude": 2}}],
    "periodic": {"y": [0, 4]},
    "effects": {"xsph": {"c": 0.1}, "sinks": [{"min": [0, 0], "max": [1, 1]}],
                "emitters": [{"position": [0, 3], "direction": [0, -2]}],
                "budget": {"max_particles": 500, "policy": "recycle_oldest"}},
    "render": {"width": 320, "mode": "particles", "camera": {"min": [0, 0], "max": [8, 6]}},
    "events": [{"t": 1, "type": "emitter", "index": 0, "enabled": false}]
  })");
  SceneDef s;
  const auto& root = d.doc.root;
  readTopLevel(d.r, root, s);
  readSolver(d.r, root, s);
  readBoundaries(d.r, root, s);
  readFluid(d.r, root, s);
  readPeriodic(d.r, root, s);
  readEffects(d.r, root, s);
  readRender(d.r, root, s);
  readEvents(d.r, root, s);
  CHECK(s.name == "n");
  CHECK(s.fps == 30);
  CHECK(s.maxParticles == 1000);
  REQUIRE(s.bodies.size() == 1);
  CHECK(s.bodies[0].angle == 0.5);
  REQUIRE(s.bodies[0].fixtures.size() == 2);
  CHECK(s.bodies[0].fixtures[0].friction == 0.4);
  CHECK(s.bodies[0].fixtures[1].type == ShapeDef::Type::Chain);
  CHECK(s.bodies[0].fixtures[1].loop);
  REQUIRE(s.blocks.size() == 1);
  CHECK(s.blocks[0].field.type == VelocityFieldDef::Type::TaylorGreen);
  CHECK(s.blocks[0].field.amplitude == 2);
  CHECK(s.periodic.y);
  CHECK_FALSE(s.periodic.x);
  CHECK(s.periodic.max.y() == 4);
  CHECK(s.effects.xsphC == 0.1);
  CHECK(s.effects.sinks.size() == 1);
  REQUIRE(s.effects.emitters.size() == 1);
  CHECK(s.effects.emitters[0].direction.y() == -1);  // normalised
  CHECK(s.effects.budgetPolicy == BudgetPolicy::RecycleOldest);
  CHECK(s.render.mode == "particles");
  CHECK_FALSE(s.render.camera.automatic);
  REQUIRE(s.events.size() == 1);
  CHECK(s.events[0].type == EventDef::Type::Emitter);
  CHECK_FALSE(s.events[0].enabled);
}

TEST_CASE("a section is checked against the sections read before it") {
  // A block inside a solid: refused once the boundaries are read.
  const std::string scene = R"({"boundaries": [{"fixtures": [{"shape": "circle", "radius": 5}]}],
                                "fluid": [{"min": [-1, -1], "max": [1, 1]}]})";
  SceneDef before;
  CHECK(failure(scene, before, readFluid) == "");
  SceneDef after;
  CHECK(failure(scene, after, readBoundaries) == "");
  CHECK(
      failure(scene, after, readFluid) ==
      "fluid[0]: the block lies entirely inside boundaries[0].fixtures[0] (a circle): every particle would be dropped");

  // A period against the support radius of the solver read before.
  const std::string periodic = R"({"solver": {"spacing": 0.01}, "periodic": {"x": [0, 0.1]}})";
  SceneDef coarse;  // default spacing 0.02: R = 0.05, the period must be 0.15 long
  CHECK(failure(periodic, coarse, readPeriodic).rfind("periodic.x: the period [0, 0.1] is 0.1 m long", 0) == 0);
  SceneDef fine;
  CHECK(failure(periodic, fine, readSolver) == "");
  CHECK(failure(periodic, fine, readPeriodic) == "");

  // An emitter event against the emitters read before.
  const std::string events = R"({"effects": {"emitters": [{"position": [0, 1]}]},
                                 "events": [{"t": 0, "type": "emitter", "index": 0, "enabled": false}]})";
  SceneDef none;
  CHECK(failure(events, none, readEvents) == "events[0].type: the scene has no emitters (effects.emitters)");
  SceneDef one;
  CHECK(failure(events, one, readEffects) == "");
  CHECK(failure(events, one, readEvents) == "");
}
