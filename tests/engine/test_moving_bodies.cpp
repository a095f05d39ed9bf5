// Moving bodies (engine/src/moving_bodies.cpp): kinematic bodies of the scene, and a
// game's non-static bodies, push the fluid and are never entered by it.
#include <doctest/doctest.h>

#include <box2d/box2d.h>

#include <cmath>

#include "support/fixture.hpp"

using namespace sph2d;

namespace {

/// A 2 m × 1 m tank with 0.4 m of still water and a kinematic paddle (0.06 m × 0.5 m,
/// its foot 0.05 m above the floor) at x = 0.3 moving right at 1 m/s.
SceneDef paddleScene(const std::string& solver) {
  SceneDef s = test::tank(solver, 2.0, 1.0, 0.02);
  s.blocks.push_back(test::block({0, 0}, {2.0, 0.4}));
  BodyDef paddle;
  paddle.type = BodyDef::Type::Kinematic;
  paddle.position = Vec2d(0.3, 0.3);
  paddle.velocity = Vec2d(1.0, 0);
  paddle.fixtures.push_back(test::boxShape({0, 0}, {0.03, 0.25}));
  s.bodies.push_back(paddle);
  return s;
}

/// Particles deeper than 0.1 spacing inside any moving body.
std::size_t insideMoving(const World& w) {
  std::size_t n = 0;
  const std::vector<Collider> shapes = w.movingColliders();
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const Vec2 x = w.particles().x[i];
    for (const Collider& c : shapes) {
      Real depth = 1e30f;
      if (c.kind == Collider::Kind::Circle) depth = c.radius - (x - c.center).norm();
      else
        for (std::size_t f = 0; f < c.vertices.size(); ++f) depth = std::min(depth, -c.normals[f].dot(x - c.vertices[f]));
      if (depth > Real(0.1) * w.spacing()) ++n;
    }
  }
  return n;
}

}  // namespace

TEST_CASE("moving bodies: a kinematic paddle at 1 m/s pushes the water ahead of it and is never entered") {
  for (const char* solver : {"game", "wcsph"}) {
    INFO(solver);
    World w(paddleScene(solver), WorldOptions{2});
    REQUIRE(w.movingColliders().size() == 1);
    std::size_t worst = 0;
    for (int f = 0; f < 30; ++f) {  // 0.5 s: the paddle travels from x = 0.3 to 0.8
      w.stepFrame();
      worst = std::max(worst, insideMoving(w));
    }
    CHECK(worst == 0);
    const Collider paddle = w.movingColliders()[0];
    const double front = double(paddle.hi.x()) + w.origin().x();
    CHECK(std::abs(front - (0.83)) < 0.01);  // it moved with its velocity
    double sum = 0;
    int n = 0;
    for (std::size_t i = 0; i < w.particleCount(); ++i) {
      const Vec2d x = w.worldPosition(i);
      if (x.x() > front && x.x() < front + 0.06 && x.y() > 0.1 && x.y() < 0.35) {
        sum += double(w.particles().v[i].x());
        ++n;
      }
    }
    REQUIRE(n > 10);
    MESSAGE(std::string(solver) << ": " << n << " particles just ahead of the paddle, mean vx " << sum / n << " m/s");
    CHECK(sum / n >= 0.5);
    CHECK(test::outside(w, 2.0, 1.0) == 0);
  }
}

TEST_CASE("moving bodies: a turning bar in a game's b2World stirs the water, never entered, the same bits on 1, 2 and 3 threads") {
  std::uint64_t first = 0;
  for (int threads = 1; threads <= 3; ++threads) {
    b2World level(b2Vec2(0, -9.81f));
    b2BodyDef wallsDef;
    b2Body* walls = level.CreateBody(&wallsDef);
    for (const auto& [c, h] : {std::pair<b2Vec2, b2Vec2>{{0.5f, -0.1f}, {0.7f, 0.1f}}, {{-0.1f, 0.5f}, {0.1f, 0.7f}},
                               {{1.1f, 0.5f}, {0.1f, 0.7f}}}) {
      b2PolygonShape box;
      box.SetAsBox(h.x, h.y, c, 0);
      walls->CreateFixture(&box, 0);
    }
    b2BodyDef barDef;
    barDef.type = b2_kinematicBody;
    barDef.position.Set(0.5f, 0.25f);
    barDef.angularVelocity = 4.0f;  // the game turns it
    b2Body* bar = level.CreateBody(&barDef);
    b2PolygonShape shape;
    shape.SetAsBox(0.2f, 0.02f);
    bar->CreateFixture(&shape, 0);
    SceneDef s;
    s.solver = solverDefaults("wcsph");
    s.solver.spacing = 0.02;
    s.blocks.push_back(test::block({0, 0}, {1.0, 0.45}));
    World w(s, level, WorldOptions{threads});
    std::size_t worst = 0;
    for (int f = 0; f < 20; ++f) {
      w.stepFrame();
      level.Step(1.0f / 60, 8, 3);  // the game steps its own world
      worst = std::max(worst, insideMoving(w));
    }
    CHECK(worst == 0);
    CHECK(test::meanSpeed(w) > 0.05);  // the bar set the water moving
    if (threads == 1) first = w.stateHash();
    CHECK_MESSAGE(w.stateHash() == first, "threads " << threads);
  }
}

TEST_CASE("moving bodies: the scene format takes kinematic bodies, and refuses dynamic ones and open kinematic shapes by key") {
  const SceneDef s = parseScene(R"({"boundaries": [{"type": "kinematic", "position": [1, 1], "velocity": [0.5, 0],
      "angular_velocity": 2, "fixtures": [{"shape": "circle", "radius": 0.1}]}]})", "k.json");
  REQUIRE(s.bodies.size() == 1);
  CHECK(s.bodies[0].type == BodyDef::Type::Kinematic);
  CHECK(s.bodies[0].velocity == Vec2d(0.5, 0));
  CHECK(s.bodies[0].angularVelocity == 2);
  const std::pair<const char*, const char*> bad[] = {
      {R"({"boundaries": [{"type": "dynamic", "fixtures": []}]})", "boundaries[0].type"},
      {R"({"boundaries": [{"type": "kinematic", "fixtures": [{"shape": "edge", "vertices": [[0, 0], [1, 0]]}]}]})",
       "boundaries[0].fixtures[0].shape"},
      {R"({"boundaries": [{"velocity": [1, 0], "fixtures": []}]})", "boundaries[0].velocity"}};  // a static body has none
  for (const auto& [text, key] : bad) {
    try {
      parseScene(text, "bad.json");
      FAIL("accepted: " << std::string(text));
    } catch (const SceneError& e) {
      INFO(std::string(e.what()));
      CHECK(e.key == key);
    }
  }
}
