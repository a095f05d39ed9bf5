// Moving bodies (engine/src/world/moving_bodies.cpp, and their coupling in grid_projection.cpp):
// kinematic bodies of the scene, and a game's non-static bodies, push the fluid and are
// never entered by it; the fluid pushes the dynamic ones (crates float by Archimedes).
#include <doctest/doctest.h>

#include <box2d/box2d.h>

#include <cmath>
#include <map>
#include <sstream>

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

/// Particles deeper than 0.1 spacing inside any moving body, those below `floorBand` not
/// counted (fixture.hpp's insideMovingCount).
std::size_t insideMoving(const World& w, double floorBand = -1e300) { return test::insideMovingCount(w, floorBand); }

}  // namespace

TEST_CASE("moving bodies: a kinematic paddle at 1 m/s pushes the water ahead of it and is never entered") {
  for (const char* solver : {"game", "wcsph", "muller2003", "pbf", "dfsph"}) {
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
    const test::MeanVx ahead = test::meanVxIn(w, front, front + 0.06, 0.1, 0.35);
    REQUIRE(ahead.count > 10);
    MESSAGE(std::string(solver) << ": " << ahead.count << " particles just ahead of the paddle, mean vx " << ahead.mean
                                << " m/s");
    CHECK(ahead.mean >= 0.5);
    CHECK(test::outside(w, 2.0, 1.0) == 0);
  }
}

TEST_CASE(
    "moving bodies: a turning bar in a game's b2World stirs the water, never entered, the same bits on 1, 2 and 3 threads") {
  std::uint64_t first = 0;
  for (int threads = 1; threads <= 3; ++threads) {
    b2World level(b2Vec2(0, -9.81f));
    b2BodyDef wallsDef;
    b2Body* walls = level.CreateBody(&wallsDef);
    for (const auto& [c, h] : {std::pair<b2Vec2, b2Vec2>{{0.5f, -0.1f}, {0.7f, 0.1f}},
                               {{-0.1f, 0.5f}, {0.1f, 0.7f}},
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

TEST_CASE(
    "moving bodies: the scene format takes kinematic and dynamic bodies, and refuses open moving shapes and misplaced keys by key") {
  const SceneDef s = parseScene(R"({"boundaries": [{"type": "kinematic", "position": [1, 1], "velocity": [0.5, 0],
      "angular_velocity": 2, "fixtures": [{"shape": "circle", "radius": 0.1}]},
      {"type": "dynamic", "position": [2, 1], "velocity": [0, -1], "fixtures": [{"shape": "box", "half_size": [0.1, 0.1], "density": 500}]}]})",
                                "k.json");
  REQUIRE(s.bodies.size() == 2);
  CHECK(s.bodies[0].type == BodyDef::Type::Kinematic);
  CHECK(s.bodies[0].velocity == Vec2d(0.5, 0));
  CHECK(s.bodies[0].angularVelocity == 2);
  CHECK(s.bodies[1].type == BodyDef::Type::Dynamic);
  CHECK(s.bodies[1].velocity == Vec2d(0, -1));
  CHECK(s.bodies[1].fixtures[0].density == 500);
  World w(s);  // the b2World has the crate with its mass: 0.2 m × 0.2 m at 500 kg/m²
  const b2Body* crate = nullptr;
  for (const b2Body* b = w.box2d().GetBodyList(); b; b = b->GetNext())
    if (b->GetType() == b2_dynamicBody) crate = b;
  REQUIRE(crate);
  CHECK(crate->GetMass() == doctest::Approx(20.0).epsilon(1e-5));
  const std::pair<const char*, const char*> bad[] = {
      {R"({"boundaries": [{"type": "floating", "fixtures": []}]})", "boundaries[0].type"},
      {R"({"boundaries": [{"type": "kinematic", "fixtures": [{"shape": "edge", "vertices": [[0, 0], [1, 0]]}]}]})",
       "boundaries[0].fixtures[0].shape"},
      {R"({"boundaries": [{"type": "dynamic", "fixtures": [{"shape": "chain", "vertices": [[0, 0], [1, 0]]}]}]})",
       "boundaries[0].fixtures[0].shape"},
      {R"({"boundaries": [{"type": "dynamic", "fixtures": [{"shape": "circle", "radius": 0.1, "density": 0}]}]})",
       "boundaries[0].fixtures[0].density"},  // a massless body: Box2D would give it 1 kg
      {R"({"boundaries": [{"fixtures": [{"shape": "circle", "radius": 0.1, "density": 500}]}]})",
       "boundaries[0].fixtures[0].density"},  // only dynamic bodies have one
      {R"({"boundaries": [{"velocity": [1, 0], "fixtures": []}]})",
       "boundaries[0].velocity"}};  // a static body has none
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

namespace {

/// A 2 m × 1 m tank with 0.6 m of still water (spacing 0.01) and a dynamic crate, 0.6 m × 0.2 m
/// of density `density` kg/m², its centre at height `y`, solver `solver`.
SceneDef crateScene(const std::string& solver, double density, double y) {
  SceneDef s = test::tank(solver, 2.0, 1.0, 0.01);
  s.blocks.push_back(test::block({0, 0}, {2.0, 0.6}));
  BodyDef crate;
  crate.type = BodyDef::Type::Dynamic;
  crate.position = Vec2d(1.0, y);
  ShapeDef box = test::boxShape({0, 0}, {0.3, 0.1});
  box.density = density;
  crate.fixtures.push_back(box);
  s.bodies.push_back(crate);
  return s;
}

// The crate helpers shared with test_body_samples.cpp (tests/support/fixture.hpp).
using test::bottomOf;
using test::dynamicBody;
/// The water's surface height in [x0, x1] (fixture.hpp's crateSurface).
double surfaceIn(const World& w, double x0, double x1) { return test::crateSurface(w, x0, x1); }

/// Archimedes' draught of a box crate h tall of density `density` floating in water of density
/// 1000 (kg/m²; the scenes' rest density): its fixture, as Box2D weighs it, under water by
/// h·ρ_b/ρ0. The fluid is kept out of the box's skin (b2_polygonRadius) too, but the grid scales
/// the pressure on it to the fixture's area (moving_bodies.cpp shapeMoments), so the skin closes
/// the gaps Box2D leaves under resting bodies without making a body lighter than its density.
double archimedesDraught(double density, double h) { return h * density / 1000.0; }

}  // namespace

TEST_CASE(
    "moving bodies: in the game solver a crate of density 500 floats at Archimedes' draught, 2000 sinks to the floor, 1000 stays where it was put") {
  // Archimedes: a 0.2 m tall crate of density ρ_b floats with draught 0.2·ρ_b/ρ0 (its fixture's
  // bottom under the surface; the fluid meets it at its skin, 1 cm out, which the grid's
  // pressure does not count as body: archimedesDraught). The light crate is put on the surface
  // with 0.08 m under water; the others 0.15 m under it.
  for (const double density : {500.0, 2000.0, 1000.0}) {
    INFO("density " << density);
    const double y0 = density < 900 ? 0.62 : 0.35;
    World w(crateScene("game", density, y0), WorldOptions{2});
    const b2Body* crate = dynamicBody(w);
    REQUIRE(crate);
    double draught = 0, lowest = 1e300, farthest = 0;
    int n = 0, landed = -1;
    std::size_t entered = 0;
    for (int f = 0; f < 180; ++f) {
      w.stepFrame();
      if (landed < 0 && bottomOf(crate) < 0.03) landed = f + 1;
      entered = std::max(entered, insideMoving(w));
      farthest = std::max(farthest, std::fabs(double(crate->GetPosition().y) - y0));
      lowest = std::min(lowest, bottomOf(crate));
      if (f >= 120) {  // the third second: the mean over the last of the bobbing
        draught += 0.5 * (surfaceIn(w, 0.05, 0.5) + surfaceIn(w, 1.5, 1.95)) - bottomOf(crate);
        ++n;
      }
    }
    draught /= n;
    const double expected = archimedesDraught(density, 0.2);
    MESSAGE("density " << density << ": draught of the fixture over the third second " << draught << " m (Archimedes "
                       << expected << " m), lowest point " << lowest << " m, farthest from the start " << farthest
                       << " m");
    CHECK(entered == 0);
    CHECK(test::outside(w, 2.0, 1.0) == 0);
    if (density == 500) CHECK(std::fabs(draught - expected) <= 0.1 * expected);  // within 10 % of Archimedes
    if (density == 2000) {
      // On the floor (under 3 spacings of water), and later than in free fall: sinking 0.22 m
      // at g(1 − ρ0/ρ_b) = g/2 takes 0.3 s (18 frames) without drag; in free fall 0.21 s (13).
      MESSAGE("density 2000: on the floor after " << landed << " frames");
      CHECK(bottomOf(crate) < 0.03);
      CHECK(landed >= 18);
    }
    if (density == 1000) CHECK(farthest < 0.005);  // neutral: within 5 mm of where it was put
  }
}

TEST_CASE(
    "moving bodies: water thrown at a free crate in zero gravity keeps the momentum of water and crate together") {
  // No gravity, nothing reaches the walls: the only impulse is between the water and the
  // crate (pressure on the grid and contacts), so their momenta must sum to the start's.
  for (const char* solver : {"game", "wcsph", "dfsph"}) {
    INFO(solver);
    // The game solver's pressure reaches the crate on the grid, whose faces are corrected to
    // give a body its true area (markBodies): first order in the cell size, so the balance
    // is 2.4 % with the crate 10 × 15 cells (spacing 0.01) and 5.6 % at 5 × 7.5 (0.02).
    // wcsph's and dfsph's contacts and moving samples (body_samples.hpp) exchange exactly
    // opposite impulses (dfsph: each solve's wall terms of the crate's samples, summed).
    const double dx = 0.01;
    SceneDef s = test::tank(solver, 4.0, 4.0, dx);
    s.gravity = Vec2d(0, 0);
    FluidBlockDef drop = circleRegion(Vec2d(1.4, 2.0), 0.25, dx);
    drop.velocity = Vec2d(2.0, 0);
    s.blocks.push_back(drop);
    BodyDef crate;
    crate.type = BodyDef::Type::Dynamic;
    crate.position = Vec2d(2.2, 2.0);
    ShapeDef box = test::boxShape({0, 0}, {0.1, 0.15});
    box.density = 400;  // 12 kg against the drop's ~196 kg: it is thrown, the water splashes
    crate.fixtures.push_back(box);
    s.bodies.push_back(crate);
    World w(s, WorldOptions{2});
    const b2Body* body = dynamicBody(w);
    REQUIRE(body);
    auto bodyMomentum = [&]() -> Vec2d {
      return Vec2d(body->GetLinearVelocity().x, body->GetLinearVelocity().y) * double(body->GetMass());
    };
    const Vec2d p0 = test::momentum(w) + bodyMomentum();
    for (int f = 0; f < 36; ++f) w.stepFrame();  // 0.6 s: the drop meets the crate at about 0.15 s
    const Vec2d pBody = bodyMomentum(), p1 = test::momentum(w) + pBody;
    MESSAGE(std::string(solver) << ": momentum of water and crate from (" << p0.x() << ", " << p0.y() << ") to ("
                                << p1.x() << ", " << p1.y() << ") kg m/s; the crate's " << pBody.x() << " kg m/s");
    CHECK(test::outside(w, 0.3, 0.3, 3.7, 3.7) == 0);  // nothing reached the walls
    CHECK(pBody.x() > 0.05 * p0.x());                  // the water threw the crate
    CHECK((p1 - p0).norm() <= 0.05 * p0.norm());
  }
}

TEST_CASE("moving bodies: a 50 m/s jet against a game's dynamic box never passes through it, every solver") {
  // Until 25 Nov muller2003 failed: in frame 7 the box, shoved at 12.9 m/s, ran 0.2 m into the
  // far wall along its velocity within the frame (the fluid saw it at x 2.10–2.20, the wall's
  // face at 2.0), and when the game's Box2D step put it back in front of the wall, 11 particles
  // it had pushed were behind it. The `body_walls` stage now stops a body at a static fixture.
  for (const char* solver : {"game", "wcsph", "pbf", "dfsph", "muller2003"}) {
    INFO(solver);
    // The game's own b2World: a 2 m × 1 m tank and a 0.1 m × 0.4 m box of density 3000 on its
    // floor (upright: fixed rotation, so that "through it" stays well defined while the jet
    // shoves it along). The box is thinner than a jet particle's move in a substep.
    b2World level(b2Vec2(0, -9.81f));
    b2BodyDef wallsDef;
    b2Body* walls = level.CreateBody(&wallsDef);
    for (const auto& [c, h] : {std::pair<b2Vec2, b2Vec2>{{1.0f, -0.1f}, {1.2f, 0.1f}},
                               {{1.0f, 1.1f}, {1.2f, 0.1f}},
                               {{-0.1f, 0.5f}, {0.1f, 0.7f}},
                               {{2.1f, 0.5f}, {0.1f, 0.7f}}}) {
      b2PolygonShape box;
      box.SetAsBox(h.x, h.y, c, 0);
      walls->CreateFixture(&box, 0);
    }
    b2BodyDef boxDef;
    boxDef.type = b2_dynamicBody;
    boxDef.fixedRotation = true;
    boxDef.position.Set(1.2f, 0.2f);
    b2Body* box = level.CreateBody(&boxDef);
    b2PolygonShape shape;
    shape.SetAsBox(0.05f, 0.2f);
    box->CreateFixture(&shape, 3000.0f);
    SceneDef s;
    s.solver = solverDefaults(solver);
    s.solver.spacing = 0.02;
    EmitterDef jet;
    jet.position = Vec2d(0.1, 0.2);
    jet.direction = Vec2d(1, 0);
    jet.speed = 50;
    jet.rate = 1000;
    jet.stop = 0.3;
    s.effects.emitters.push_back(jet);
    World w(s, level, WorldOptions{2});
    std::size_t entered = 0, crossed = 0;
    std::map<std::uint32_t, Vec2d> last;  // each particle's position at the last frame
    double frontPrev = 1.15;
    for (int f = 0; f < 30; ++f) {
      w.stepFrame();
      level.Step(1.0f / 60, 8, 3);
      entered = std::max(entered, insideMoving(w));
      const double front = double(box->GetPosition().x) - 0.05, back = double(box->GetPosition().x) + 0.05;
      // Through the box: in front of it at the last frame, behind it now, and low enough both
      // times (under its top by 0.1 m) that the way over it is longer than a frame allows. Not
      // under it: Box2D rests a polygon on its skin (b2_polygonRadius, 1 cm) over the floor,
      // and a particle on the floor may pass that gap.
      for (std::size_t i = 0; i < w.particleCount(); ++i) {
        const Vec2d x = w.worldPosition(i);
        const auto it = last.find(w.particles().id[i]);
        auto through = [](double y) { return y > 0.03 && y < 0.3; };
        if (it != last.end() && it->second.x() < frontPrev && x.x() > back && through(it->second.y()) && through(x.y()))
          ++crossed;
        last[w.particles().id[i]] = x;
      }
      frontPrev = front;
    }
    MESSAGE(w.particleCount() << " jet particles; the box shoved from x = 1.2 to " << box->GetPosition().x << " m");
    CHECK(w.particleCount() == 300);
    CHECK(box->GetPosition().x > 1.25);  // the water pushed it
    CHECK(entered == 0);
    CHECK(crossed == 0);
    CHECK(test::outside(w, 2.0, 1.0) == 0);
  }
}

TEST_CASE(
    "moving bodies: a crate resting on the floor leaves no water under it, and none squeezed there, in the game solver") {
  // Box2D rests a polygon on the floor's polygon at two skins (b2_polygonRadius, 1 cm each)
  // less the slop: its core 1.5 cm over the floor's. Seen without its skin the crate left a
  // gap the water entered and was squeezed in; the fluid meets it at its skin, 0.5 cm over
  // the floor. A small dam break (a 1 m × 0.6 m tank, a 0.4 m × 0.5 m column) runs against a
  // 0.3 m × 0.2 m crate of density 2000 standing on the floor; over the second half second no
  // particle lies between the crate's core and the floor at spacing 0.02 (0.5 cm is less than
  // the two clearances of 0.25 spacing), at most a few at spacing 0.01 (where one layer kept
  // 2.5 mm off both just fits: 30 particles would fill it; without the skin 31 were there), none
  // is in the crate, and over the whole run none is compressed by more than the density
  // solve's tolerance, 10 %.
  for (const double dx : {0.01, 0.02}) {
    INFO("spacing " << dx);
    SceneDef s = test::tank("game", 1.0, 0.6, dx);
    s.blocks.push_back(test::block({0, 0}, {0.4, 0.5}));
    BodyDef crate;
    crate.type = BodyDef::Type::Dynamic;
    crate.position = Vec2d(0.7, 0.1);
    ShapeDef box = test::boxShape({0, 0}, {0.15, 0.1});
    box.density = 2000;
    crate.fixtures.push_back(box);
    s.bodies.push_back(crate);
    World w(s, WorldOptions{2});
    const b2Body* body = dynamicBody(w);
    REQUIRE(body);
    double worst = 0;
    std::size_t under = 0;
    for (int f = 0; f < 120; ++f) {
      w.stepFrame();
      worst = std::max(worst, w.densityStats().maxError);
      if (f < 90) continue;  // the last half second: the crate rests on the floor
      std::size_t n = 0;
      const double x = double(body->GetPosition().x), bottom = bottomOf(body);
      for (std::size_t i = 0; i < w.particleCount(); ++i) {
        const Vec2d q = w.worldPosition(i);
        if (std::fabs(q.x() - x) < 0.15 && q.y() < bottom) ++n;
      }
      under = std::max(under, n);
    }
    MESSAGE("spacing " << dx << ", resting crate: its core's bottom at " << bottomOf(body) << " m, at most " << under
                       << " particles under it, largest single-particle compression " << 100 * worst << " %");
    CHECK(bottomOf(body) < 0.02);  // on the floor
    CHECK(under <= (dx < 0.015 ? 5u : 0u));
    CHECK(insideMoving(w) == 0);
    CHECK(test::outside(w, 1.0, 0.6) == 0);
    CHECK(worst <= 0.10);
  }
}

TEST_CASE("moving bodies: crates stacked on each other in a game's b2World never hold a particle, in the game solver") {
  // Box2D rests a crate on another at two skins less the slop: the game solver's skins (1 cm
  // each) overlap by about 0.5 cm, and no point of the overlap is outside both crates. Until
  // 25 Nov a particle pushed out of one crate's skin by the other's was left inside the first
  // (one particle 3.6 mm into the top crate's core for 66 frames). A game's level: two heavy
  // crates 5 cm apart on the floor, a light one resting across them, a 0.6 m × 0.8 m column
  // breaking over them; the game steps its b2World after each frame. 2 s: after every frame
  // no particle deeper than 0.1 spacing inside any crate.
  b2World level(b2Vec2(0, -9.81f));
  test::addStaticBox(level, 1.0f, -0.1f, 1.2f, 0.1f);
  test::addStaticBox(level, -0.1f, 0.6f, 0.1f, 0.7f);
  test::addStaticBox(level, 2.1f, 0.6f, 0.1f, 0.7f);
  const float crates[3][3] = {{1.3f, 0.1f, 2000}, {1.55f, 0.1f, 2000}, {1.42f, 0.3f, 600}};
  b2Body* light = nullptr;
  for (const auto& c : crates) {
    b2BodyDef d;
    d.type = b2_dynamicBody;
    d.position.Set(c[0], c[1]);
    light = level.CreateBody(&d);  // the last: the light one
    b2PolygonShape box;
    box.SetAsBox(0.1f, 0.09f);
    light->CreateFixture(&box, c[2]);
  }
  SceneDef s;
  s.solver = solverDefaults("game");
  s.solver.spacing = 0.02;
  s.blocks.push_back(test::block({0, 0}, {0.6, 0.8}));
  World w(s, level, WorldOptions{2});
  std::size_t worst = 0;
  int worstFrame = -1;
  for (int f = 0; f < 120; ++f) {
    w.stepFrame();
    level.Step(1.0f / 60, 8, 3);
    const std::size_t n = insideMoving(w);
    if (n > worst) worst = n, worstFrame = f;
  }
  MESSAGE("stacked crates: at most " << worst << " particles inside a crate after a frame (frame " << worstFrame
                                     << ")");
  CHECK(worst == 0);
  CHECK(double(light->GetPosition().y) > 0.25);  // still resting across the heavy ones
}

TEST_CASE("moving bodies: a floating crate gives the same bits on 1, 2 and 3 threads, crate included, every solver") {
  for (const char* solver : {"game", "wcsph", "muller2003", "pbf", "dfsph"}) {
    INFO(solver);
    std::uint64_t first = 0;
    b2Vec2 pose0(0, 0);
    for (int threads = 1; threads <= 3; ++threads) {
      SceneDef s = crateScene(solver, 500, 0.62);
      s.solver.spacing = 0.02;
      World w(s, WorldOptions{threads});
      for (int f = 0; f < 30; ++f) w.stepFrame();
      const b2Vec2 pose = dynamicBody(w)->GetPosition();
      if (threads == 1) first = w.stateHash(), pose0 = pose;
      CHECK_MESSAGE(w.stateHash() == first, "threads " << threads);
      CHECK_MESSAGE((pose.x == pose0.x && pose.y == pose0.y), "threads " << threads);
    }
  }
}

TEST_CASE(
    "assets/scenes/floating_crates.json: the light crates float, the heavy one sinks, the turning bar stirs the water") {
  World w(test::scene("floating_crates.json"), WorldOptions{2});
  std::vector<const b2Body*> dyn;  // scene order: box 500, circle 300, box 800, box 2500
  for (const b2Body* b = w.box2d().GetBodyList(); b; b = b->GetNext())
    if (b->GetType() == b2_dynamicBody) dyn.insert(dyn.begin(), b);  // Box2D lists the newest first
  REQUIRE(dyn.size() == 4);
  // The heavy crate lands on the floor at about 1 m/s: within the fluid's step (which has no
  // contact between the crate and the floor; Box2D's next step has) it sinks into the floor,
  // and the water caught under it keeps to the floor, at the clearance over it, and is squeezed
  // out along the crate's bottom a spacing a substep (moving_bodies.cpp): for some frames a
  // few particles there are inside the crate's skin, or even its core (seen up to 2.7 cm deep,
  // 3.5 cm over the floor: a frame of the landing's travel, 1.7 cm, plus the skin). Above the
  // floor's two-spacing band no particle enters a crate, and at the end none is in one anywhere.
  const double band = 2 * double(w.spacing());
  std::size_t entered = 0;
  for (int f = 0; f < 150; ++f) {
    w.stepFrame();
    entered = std::max(entered, insideMoving(w, band));
  }
  for (const b2Body* b : dyn) MESSAGE("crate at (" << b->GetPosition().x << ", " << b->GetPosition().y << ")");
  CHECK(entered == 0);
  CHECK(insideMoving(w) == 0);
  CHECK(test::outside(w, 0, 0, 4, 2.2) == 0);
  CHECK(dyn[0]->GetPosition().y > 0.5);  // density 500 and 300: on the surface (0.6 m of water)
  CHECK(dyn[1]->GetPosition().y > 0.5);
  CHECK(dyn[2]->GetPosition().y > 0.3);   // density 800: mostly under, but afloat
  CHECK(dyn[3]->GetPosition().y < 0.15);  // density 2500: on the floor
  CHECK(test::meanSpeed(w) > 0.05);       // the bar keeps the water moving
}

TEST_CASE(
    "moving bodies: save, load and step a floating crate: the same state hashes and crate as the World not interrupted") {
  SceneDef s = crateScene("game", 500, 0.62);
  s.solver.spacing = 0.02;
  World a(s, WorldOptions{2});
  for (int f = 0; f < 20; ++f) a.stepFrame();  // the crate falls in and bobs
  std::ostringstream out;
  a.save(out);
  World b(s, WorldOptions{1});
  std::istringstream in(out.str());
  b.load(in);
  CHECK(b.stateHash() == a.stateHash());
  for (int f = 0; f < 15; ++f) {
    a.stepFrame();
    b.stepFrame();
    REQUIRE_MESSAGE(b.stateHash() == a.stateHash(), "frame " << f << " after the load");
    const b2Vec2 pa = dynamicBody(a)->GetPosition(), pb = dynamicBody(b)->GetPosition();
    REQUIRE_MESSAGE((pa.x == pb.x && pa.y == pb.y), "frame " << f << " after the load");
  }
}

TEST_CASE("moving bodies: a crate built of two overlapping boxes floats as deep as the one box it makes") {
  // 0.6 m × 0.2 m at density 500 as two 0.4 m × 0.2 m boxes overlapping by 0.2 m: the grid
  // scales the pressure to the fixtures' union's area (0.12 m², not 2 × 0.08 m²).
  SceneDef s = crateScene("game", 500, 0.62);
  s.bodies.back().fixtures.clear();
  for (const double cx : {-0.1, 0.1}) {
    ShapeDef box = test::boxShape({cx, 0}, {0.2, 0.1});
    box.density = 500 * 0.12 / 0.16;  // the same mass as the one box
    s.bodies.back().fixtures.push_back(box);
  }
  World w(s, WorldOptions{2});
  const b2Body* crate = dynamicBody(w);
  REQUIRE(crate);
  CHECK(crate->GetMass() == doctest::Approx(60.0).epsilon(1e-4));
  double draught = 0;
  int n = 0;
  for (int f = 0; f < 180; ++f) {
    w.stepFrame();
    if (f >= 120) draught += 0.5 * (surfaceIn(w, 0.05, 0.5) + surfaceIn(w, 1.5, 1.95)) - bottomOf(crate), ++n;
  }
  draught /= n;
  const double expected = archimedesDraught(500, 0.2);
  MESSAGE("two overlapping boxes: draught of the fixtures " << draught << " m (Archimedes " << expected << " m)");
  CHECK(std::fabs(draught - expected) <= 0.1 * expected);
}

TEST_CASE("moving bodies: a periodic scene with a moving body loads with one warning naming the body and the seam") {
  // Moving bodies do not wrap at a periodic seam (docs/SCENES.md, periodic); the user is told.
  const char* text = R"({"solver": {"quality": "game", "spacing": 0.04}, "periodic": {"x": [0, 2]},
      "boundaries": [{"fixtures": [{"shape": "box", "center": [1, -0.2], "half_size": [2, 0.2]}]},
                     {"type": "TYPE", "position": [1, 0.5], "fixtures": [{"shape": "box", "half_size": [0.1, 0.2]TAIL}]}],
      "fluid": [{"min": [0, 0], "max": [2, 0.4]}]})";
  auto warningsFor = [&](const std::string& type, const std::string& tail) {
    std::string t = text;
    t.replace(t.find("TYPE"), 4, type);
    t.replace(t.find("TAIL"), 4, tail);
    World w(parseScene(t, "periodic.json"));
    std::vector<std::string> seam;
    for (const std::string& m : w.takeWarnings())
      if (m.find("periodic seam") != std::string::npos) seam.push_back(m);
    return seam;
  };
  for (const auto& [type, tail] :
       {std::pair<std::string, std::string>{"kinematic", ""}, {"dynamic", R"(, "density": 500)"}}) {
    CAPTURE(type);
    const std::vector<std::string> seam = warningsFor(type, tail);
    REQUIRE(seam.size() == 1);
    CHECK(seam[0].find("boundaries[1] is " + type) != std::string::npos);
    CHECK(seam[0].find("x = 0 and 2") != std::string::npos);
  }
  CHECK(warningsFor("static", "").empty());
  // A game's b2World with a kinematic body, the scene periodic with no bodies of its own.
  b2World game(b2Vec2(0, -9.81f));
  b2BodyDef bd;
  bd.type = b2_kinematicBody;
  bd.position.Set(1, 0.5f);
  b2PolygonShape box;
  box.SetAsBox(0.1f, 0.2f);
  game.CreateBody(&bd)->CreateFixture(&box, 0);
  World w(parseScene(R"({"solver": {"quality": "game", "spacing": 0.04}, "periodic": {"x": [0, 2]},
      "fluid": [{"min": [0, 0], "max": [2, 0.4]}]})",
                     "periodic.json"),
          game);
  int seam = 0;
  for (const std::string& m : w.takeWarnings())
    seam += m.find("game's b2World has a kinematic body") != std::string::npos;
  CHECK(seam == 1);
}

TEST_CASE("moving bodies: setGravity turns the scene's own b2World's gravity too") {
  World w(crateScene("game", 500, 0.62));
  w.setGravity(Vec2d(-2.0, -9.0));
  CHECK(w.box2d().GetGravity().x == doctest::Approx(-2.0));
  CHECK(w.box2d().GetGravity().y == doctest::Approx(-9.0));
}
