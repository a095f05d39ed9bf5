// World::save and World::load (engine/src/save_load.cpp): a saved and reloaded World
// steps on to exactly the state hashes of the World that was not interrupted, for every
// solver, with emitters, lifetimes, effects, user forces and moved gravity; and a save
// that is not this scene's, truncated or inflated is refused without changing the World.
#include <doctest/doctest.h>

#include <sstream>
#include <string>

#include "support/fixture.hpp"

using namespace sph2d;

namespace {

/// A 1.2 m × 1.2 m tank with a column, a jittered emitter, lifetimes, XSPH and a turning bar.
SceneDef busyScene(const std::string& solver) {
  SceneDef s = test::tank(solver, 1.2, 1.2, 0.03);
  s.blocks.push_back(test::block({0, 0}, {0.3, 0.5}));
  EmitterDef e;
  e.position = Vec2d(0.8, 1.0);
  e.direction = Vec2d(0, -1);
  e.rate = 120;
  e.speed = 1.5;
  e.spread = 0.3;
  e.jitter = 0.2;
  e.seed = 7;
  s.effects.emitters.push_back(e);
  s.effects.lifetime = true;
  s.effects.maxAge = 0.4;
  s.effects.xsph = true;
  BodyDef bar;  // a kinematic bar turning in the open water
  bar.type = BodyDef::Type::Kinematic;
  bar.position = Vec2d(0.7, 0.25);
  bar.angularVelocity = 3;
  bar.fixtures.push_back(test::boxShape({0, 0}, {0.15, 0.02}));
  s.bodies.push_back(bar);
  return s;
}

std::string saved(const World& w) {
  std::ostringstream o;
  w.save(o);
  return o.str();
}

}  // namespace

TEST_CASE("save and load: every solver steps on to the same state hashes as the World that was not interrupted") {
  for (const char* solver : {"muller2003", "wcsph", "pbf", "dfsph", "game"}) {
    INFO(solver);
    const SceneDef s = busyScene(solver);
    World a(s, WorldOptions{2});
    for (int f = 0; f < 12; ++f) a.stepFrame();
    // State a scene does not hold: moved gravity, a user force, a switched effect, a moved emitter.
    a.setGravity(Vec2d(1.0, -9.0));
    a.setUserForces({UserForce{Vec2d(0.3, 0.3), 0.3, -20.0}});
    a.setEffectEnabled("xsph", false);
    a.moveEmitter(0, Vec2d(0.7, 1.0), Vec2d(0.2, -1));
    for (int f = 0; f < 3; ++f) a.stepFrame();
    const std::string bytes = saved(a);
    World b(s, WorldOptions{1});  // another thread count: the same bits
    std::istringstream in(bytes);
    b.load(in);
    CHECK(b.stateHash() == a.stateHash());
    CHECK(b.time() == a.time());
    CHECK(b.particleCount() == a.particleCount());
    CHECK(b.stages() == a.stages());
    for (int f = 0; f < 15; ++f) {
      a.stepFrame();
      b.stepFrame();
      REQUIRE_MESSAGE(b.stateHash() == a.stateHash(), "frame " << f << " after the load");
    }
    CHECK(b.emittedCount(0) == a.emittedCount(0));
    CHECK(b.removedCount() == a.removedCount());
    CHECK(saved(b) == saved(a));
  }
}

TEST_CASE("save and load: a save of another scene, a damaged or an inflated save is refused and the World is unchanged") {
  const SceneDef s = busyScene("game");
  World a(s, WorldOptions{1});
  for (int f = 0; f < 10; ++f) a.stepFrame();
  const std::string good = saved(a);
  World b(s, WorldOptions{1});
  for (int f = 0; f < 3; ++f) b.stepFrame();
  const std::uint64_t before = b.stateHash();
  const std::string beforeBytes = saved(b);
  auto refusal = [&](const std::string& bytes) -> std::string {
    std::istringstream in(bytes);
    try {
      b.load(in);
    } catch (const SaveError& e) {
      return e.what();
    }
    return "";
  };
  CHECK(refusal("hello, world").find("not an sph2d saved state") != std::string::npos);
  SceneDef other = s;
  other.solver.spacing = 0.025;
  CHECK(refusal(saved(World(other))).find("belongs to another scene") != std::string::npos);
  // Truncated anywhere: refused, never read past the end.
  for (std::size_t cut = 8; cut < good.size(); cut += good.size() / 37 + 1) {
    const std::string r = refusal(good.substr(0, cut));
    INFO("cut at " << cut << " of " << good.size());
    CHECK(r.find("the saved state is") != std::string::npos);
  }
  CHECK(refusal(good + "x").find("bytes follow") != std::string::npos);
  // The particle count inflated past the budget (it follows the effects; found by value).
  std::string big = good;
  const std::uint64_t n = a.particleCount();
  const std::size_t at = big.find(std::string(reinterpret_cast<const char*>(&n), sizeof n));
  REQUIRE(at != std::string::npos);
  const std::uint64_t huge = std::uint64_t(1) << 40;
  big.replace(at, sizeof huge, std::string(reinterpret_cast<const char*>(&huge), sizeof huge));
  CHECK(refusal(big).find("beyond the scene's budget") != std::string::npos);
  // Nothing changed by any refusal: the World steps on as it would have.
  CHECK(b.stateHash() == before);
  CHECK(saved(b) == beforeBytes);
  std::istringstream in(good);
  b.load(in);
  CHECK(b.stateHash() == a.stateHash());
}

TEST_CASE("save and load: crates resting on each other and on the floor follow the uninterrupted run to a millimetre") {
  // Box2D 2.4 warm-starts each contact from the impulses of its last step and orders its
  // contacts by its broad phase's history; neither is public state, so a reloaded World
  // (a fresh b2World, the bodies set to their saved poses and velocities) solves the crates'
  // first contacts from zero. The fluid steps on bit for bit until the crates' contacts act;
  // after that the run stays close, not equal: each crate within a millimetre of where it is
  // in the uninterrupted World, 20 frames on.
  for (const char* solver : {"game", "wcsph"}) {
    INFO(solver);
    SceneDef s = test::tank(solver, 1.2, 1.2, 0.03);
    s.blocks.push_back(test::block({0, 0}, {1.2, 0.25}));
    for (const Vec2d& at : {Vec2d(0.4, 0.1), Vec2d(0.4, 0.3), Vec2d(0.8, 0.1)}) {
      BodyDef crate;
      crate.type = BodyDef::Type::Dynamic;
      crate.position = at;
      crate.fixtures.push_back(test::boxShape({0, 0}, {0.1, 0.08}));
      crate.fixtures.back().density = 2500;  // heavier than the water: they rest on the floor and on each other
      s.bodies.push_back(crate);
    }
    World a(s, WorldOptions{2});
    for (int f = 0; f < 40; ++f) a.stepFrame();
    World b(s, WorldOptions{1});
    std::istringstream in(saved(a));
    b.load(in);
    REQUIRE(b.stateHash() == a.stateHash());
    // The crates come back exactly where and as fast as they were saved (not where the scene put them).
    int crates = 0;
    for (const b2Body *qa = a.box2d().GetBodyList(), *qb = b.box2d().GetBodyList(); qa && qb;
         qa = qa->GetNext(), qb = qb->GetNext()) {
      if (qa->GetType() != b2_dynamicBody) continue;
      ++crates;
      CHECK(qb->GetPosition() == qa->GetPosition());
      CHECK(qb->GetAngle() == qa->GetAngle());
      CHECK(qb->GetLinearVelocity() == qa->GetLinearVelocity());
    }
    CHECK(crates == 3);
    a.stepFrame();
    b.stepFrame();
    // The game solver's first step after the load is the same bits (Box2D steps after the
    // fluid); wcsph, sampling the bodies, steps Box2D with every substep.
    if (std::string(solver) == "game") CHECK(b.stateHash() == a.stateHash());
    for (int f = 1; f < 20; ++f) {
      a.stepFrame();
      b.stepFrame();
    }
    double worst = 0;
    const b2Body* qa = a.box2d().GetBodyList();
    const b2Body* qb = b.box2d().GetBodyList();
    for (; qa && qb; qa = qa->GetNext(), qb = qb->GetNext())
      if (qa->GetType() == b2_dynamicBody) worst = std::max(worst, double((qa->GetPosition() - qb->GetPosition()).Length()));
    MESSAGE(std::string(solver) << ": the crates 20 frames after the load, at most " << 1000 * worst << " mm from the uninterrupted run");
    CHECK(worst < 1e-3);
  }
}

namespace {

/// A game's level: a b2World of its own with a tank and a floating crate (density 500).
struct GameLevel {
  b2World world{b2Vec2(0, -9.81f)};
  b2Body* crate = nullptr;
  explicit GameLevel(int crates = 1) {
    test::addStaticBox(world, 1.0f, -0.1f, 1.2f, 0.1f);
    test::addStaticBox(world, -0.1f, 0.6f, 0.1f, 0.7f);
    test::addStaticBox(world, 2.1f, 0.6f, 0.1f, 0.7f);
    for (int k = 0; k < crates; ++k) {
      b2BodyDef d;
      d.type = b2_dynamicBody;
      d.position.Set(1.0f + 0.5f * float(k), 0.52f);
      crate = world.CreateBody(&d);
      b2PolygonShape box;
      box.SetAsBox(0.3f, 0.1f);
      crate->CreateFixture(&box, 500.0f);
    }
  }
  /// Steps the game's world after the fluid, as a game does.
  void step() { world.Step(1.0f / 60, 8, 3); }
};

SceneDef gameLevelFluid(const char* solver) {
  SceneDef s;
  s.solver = solverDefaults(solver);
  s.solver.spacing = 0.03;
  s.blocks.push_back(test::block({0, 0}, {2, 0.4}));
  return s;
}

}  // namespace

TEST_CASE("save and load: with a game's own b2World and a dynamic crate, every solver steps on to the same state hashes") {
  // The game saves and restores its own bodies; the save holds where the particles last saw
  // each of them (the first substep after the load sweeps the particles from there).
  for (const char* solver : {"muller2003", "wcsph", "pbf", "dfsph", "game"}) {
    INFO(solver);
    const SceneDef s = gameLevelFluid(solver);
    GameLevel la;
    World a(s, la.world, WorldOptions{2});
    for (int f = 0; f < 20; ++f) {
      a.stepFrame();
      la.step();
    }
    const std::string bytes = saved(a);
    GameLevel lb;  // the game rebuilds its level and puts its crate back
    lb.crate->SetTransform(la.crate->GetPosition(), la.crate->GetAngle());
    lb.crate->SetLinearVelocity(la.crate->GetLinearVelocity());
    lb.crate->SetAngularVelocity(la.crate->GetAngularVelocity());
    World b(s, lb.world, WorldOptions{1});
    std::istringstream in(bytes);
    b.load(in);
    REQUIRE(b.stateHash() == a.stateHash());
    for (int f = 0; f < 15; ++f) {
      a.stepFrame();
      la.step();
      b.stepFrame();
      lb.step();
      REQUIRE_MESSAGE(b.stateHash() == a.stateHash(), "frame " << f << " after the load");
    }
    CHECK(lb.crate->GetPosition() == la.crate->GetPosition());
  }
}

TEST_CASE("save and load: a save of a game's b2World is refused by a World with other bodies or with the scene's own") {
  const SceneDef s = gameLevelFluid("game");
  GameLevel la;
  World a(s, la.world, WorldOptions{1});
  for (int f = 0; f < 5; ++f) a.stepFrame();
  const std::string bytes = saved(a);
  auto refusal = [&](World& w) -> std::string {
    const std::uint64_t before = w.stateHash();
    std::istringstream in(bytes);
    try {
      w.load(in);
    } catch (const SaveError& e) {
      CHECK(w.stateHash() == before);
      return e.what();
    }
    return "";
  };
  GameLevel two(2);
  World b(s, two.world, WorldOptions{1});
  CHECK(refusal(b).find("has 1 moving bodies, but the game's b2World has 2") != std::string::npos);
  World own(s, WorldOptions{1});
  CHECK(refusal(own).find("taken with a game's b2World") != std::string::npos);
}
