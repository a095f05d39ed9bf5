// World::save and World::load (engine/src/world/save_load.cpp): a saved and reloaded World
// steps on to exactly the state hashes of the World that was not interrupted, for every
// solver, with emitters, lifetimes, effects, user forces and moved gravity; and a save
// that is not this scene's, truncated or inflated is refused without changing the World.
// With Box2D bodies: what of a b2World's state no save holds (warm-start impulses, sleep
// timers), that save() reports it, and that a game's replay without them is bit-identical.
#include <doctest/doctest.h>

#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "sph2d/hash.hpp"
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
    CHECK(b.counters().removed == a.counters().removed);
    CHECK(saved(b) == saved(a));
  }
}

TEST_CASE(
    "save and load: a save of another scene, a damaged or an inflated save is refused and the World is unchanged") {
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
      if (qa->GetType() == b2_dynamicBody)
        worst = std::max(worst, double((qa->GetPosition() - qb->GetPosition()).Length()));
    MESSAGE(std::string(solver) << ": the crates 20 frames after the load, at most " << 1000 * worst
                                << " mm from the uninterrupted run");
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

TEST_CASE(
    "save and load: with a game's own b2World and a dynamic crate, every solver steps on to the same state hashes") {
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

namespace {

/// A game's level in a b2World of its own: a 2 m tank, 1.2 m × 0.4 m of water at its left, and
/// crates (x, y, half width, half height, density), each at rest where it is put. The game
/// saves its bodies itself; restore() puts another level's back (pose, velocity, awake).
struct CrateLevel {
  struct Crate {
    float x, y, hx, hy, density;
  };
  b2World world{b2Vec2(0, -9.81f)};
  std::vector<b2Body*> crates;
  CrateLevel(const std::vector<Crate>& specs, bool warmStarting, bool allowSleeping) {
    world.SetWarmStarting(warmStarting);
    world.SetAllowSleeping(allowSleeping);
    test::addStaticBox(world, 1.0f, -0.1f, 1.2f, 0.1f);
    test::addStaticBox(world, -0.1f, 0.8f, 0.1f, 0.9f);
    test::addStaticBox(world, 2.1f, 0.8f, 0.1f, 0.9f);
    for (const Crate& c : specs) {
      b2BodyDef d;
      d.type = b2_dynamicBody;
      d.position.Set(c.x, c.y);
      b2Body* b = world.CreateBody(&d);
      b2PolygonShape box;
      box.SetAsBox(c.hx, c.hy);
      b->CreateFixture(&box, c.density);
      crates.push_back(b);
    }
  }
  void step() { world.Step(1.0f / 60, 8, 3); }
  void restore(const CrateLevel& from) {
    for (std::size_t k = 0; k < crates.size(); ++k) {
      const b2Body* b = from.crates[k];
      crates[k]->SetTransform(b->GetPosition(), b->GetAngle());
      crates[k]->SetLinearVelocity(b->GetLinearVelocity());
      crates[k]->SetAngularVelocity(b->GetAngularVelocity());
      crates[k]->SetAwake(b->IsAwake());
    }
  }
  /// XXH64 of every crate's pose and velocity bits.
  std::uint64_t hash() const {
    Xxh64 h;
    for (const b2Body* b : crates) {
      const float v[6] = {b->GetPosition().x,       b->GetPosition().y,       b->GetAngle(),
                          b->GetLinearVelocity().x, b->GetLinearVelocity().y, b->GetAngularVelocity()};
      h.update(v, sizeof v);
    }
    return h.digest();
  }
  /// How far the crates are from `other`'s, at most [m].
  double farthest(const CrateLevel& other) const {
    double d = 0;
    for (std::size_t k = 0; k < crates.size(); ++k)
      d = std::max(d, double((crates[k]->GetPosition() - other.crates[k]->GetPosition()).Length()));
    return d;
  }
};

/// A heavy crate on the floor in the water with another on it, and a light one floating.
const std::vector<CrateLevel::Crate> kStack = {
    {0.3f, 0.1f, 0.1f, 0.08f, 2500}, {0.32f, 0.28f, 0.1f, 0.08f, 2500}, {0.9f, 0.45f, 0.2f, 0.08f, 500}};
/// Three heavy crates on the floor, apart: they come to rest.
const std::vector<CrateLevel::Crate> kApart = {
    {0.3f, 0.1f, 0.1f, 0.08f, 2500}, {0.9f, 0.1f, 0.1f, 0.08f, 2500}, {1.6f, 0.1f, 0.1f, 0.08f, 2500}};

/// The game's loop to frame `saveAt`, a save of the fluid (its report in `report`) and of the
/// game's bodies, a fresh level and World loaded from them, then both on to frame 300. Returns
/// the first frame at which the fluid's state hash or a crate's bits differ (0: none); `sleepParts`:
/// whether a crate was asleep in one level and awake in the other at that frame.
int replayFrom(const std::vector<CrateLevel::Crate>& crates, bool warmStarting, bool allowSleeping, int saveAt,
               SaveReport& report, double* farthest = nullptr, bool* sleepParts = nullptr) {
  SceneDef s;
  s.solver = solverDefaults("game");
  s.solver.spacing = 0.03;
  s.blocks.push_back(test::block({0, 0}, {1.2, 0.4}));
  CrateLevel la(crates, warmStarting, allowSleeping);
  World a(s, la.world, WorldOptions{2});
  for (int f = 0; f < saveAt; ++f) {
    a.stepFrame();
    la.step();
  }
  std::ostringstream out;
  report = a.save(out);
  CrateLevel lb(crates, warmStarting, allowSleeping);  // the game rebuilds its level from its own save
  lb.restore(la);
  World b(s, lb.world, WorldOptions{1});
  std::istringstream in(out.str());
  b.load(in);
  REQUIRE(b.stateHash() == a.stateHash());
  REQUIRE(lb.hash() == la.hash());
  int first = 0;
  for (int f = saveAt + 1; f <= 300; ++f) {
    a.stepFrame();
    la.step();
    b.stepFrame();
    lb.step();
    if (!first && (b.stateHash() != a.stateHash() || lb.hash() != la.hash())) {
      first = f;
      for (std::size_t k = 0; k < crates.size() && sleepParts; ++k)
        *sleepParts = *sleepParts || la.crates[k]->IsAwake() != lb.crates[k]->IsAwake();
    }
  }
  if (farthest) *farthest = la.farthest(lb);
  return first;
}

}  // namespace

TEST_CASE(
    "save and load: in a game's b2World without warm starting, a replay from frame 100 is bit-identical through frame 300") {
  // Crates in contact with the floor and with each other, moving: with SetWarmStarting(false)
  // on the saved and the rebuilt b2World, nothing Box2D keeps privately carries over from one
  // step to the next, and save() says the save is complete.
  SaveReport report;
  CHECK(replayFrom(kStack, false, true, 100, report) == 0);
  CHECK(report.complete());
  CHECK(report.warning.empty());
}

TEST_CASE(
    "save and load: with warm starting on, save() says the contact state cannot be restored, and the replay parts at once") {
  // Box2D's default: each contact warm-starts from its impulses of the last step, which no
  // save holds; the rebuilt b2World solves its first step from zero, and the crates part at
  // the first Box2D step after the load (frame 101).
  SceneDef s;
  s.solver = solverDefaults("game");
  s.solver.spacing = 0.03;
  s.blocks.push_back(test::block({0, 0}, {1.2, 0.4}));
  CrateLevel level(kStack, true, true);
  World w(s, level.world, WorldOptions{2});
  for (int f = 0; f < 100; ++f) {
    w.stepFrame();
    level.step();
  }
  std::size_t touching = 0;  // counted here as the report should: touching, a dynamic body on a side
  for (const b2Contact* c = level.world.GetContactList(); c; c = c->GetNext())
    touching += c->IsTouching() && (c->GetFixtureA()->GetBody()->GetType() == b2_dynamicBody ||
                                    c->GetFixtureB()->GetBody()->GetType() == b2_dynamicBody);
  REQUIRE(touching == 2);  // the floor and the lower crate, the two crates
  w.takeWarnings();
  std::ostringstream out;
  const SaveReport first = w.save(out);
  CHECK_FALSE(first.complete());
  CHECK(first.warmStartedContacts == touching);
  CHECK(first.warmStartedJoints == 0);
  CHECK(first.sleepTimers == 0);  // every crate moves faster than the sleep tolerances
  CHECK(first.warning.find(std::to_string(touching) + " touching contacts of dynamic bodies warm-start") !=
        std::string::npos);
  CHECK(first.warning.find("SetWarmStarting(false)") != std::string::npos);
  const std::vector<std::string> warnings = w.takeWarnings();
  REQUIRE(warnings.size() == 1);
  CHECK(warnings[0] == first.warning);
  std::ostringstream again;
  CHECK(w.save(again).warning == first.warning);  // every save reports it, the warnings once
  CHECK(w.takeWarnings().empty());
  // A joint of a dynamic body is reported too; and with warm starting off, nothing is.
  b2RevoluteJointDef hinge;
  hinge.Initialize(level.crates[1], level.crates[2], level.crates[2]->GetPosition());
  level.world.CreateJoint(&hinge);
  std::ostringstream withJoint;
  CHECK(w.save(withJoint).warmStartedJoints == 1);
  level.world.SetWarmStarting(false);
  std::ostringstream cold;
  CHECK(w.save(cold).complete());
  // What the report says is so: the same replay as the test above, warm-started, parts at frame 101.
  SaveReport report;
  double farthest = 0;
  CHECK(replayFrom(kStack, true, true, 100, report, &farthest) == 101);
  CHECK(report.warmStartedContacts == 2);
  MESSAGE("warm-started replay from frame 100: the crates " << 1000 * farthest << " mm apart at frame 300");
}

TEST_CASE(
    "save and load: bodies at rest have sleep timers no save holds: save() says so, and without sleeping the replay is bit-identical") {
  // Three crates come to rest on the floor: slower than Box2D's sleep tolerances, their sleep
  // timers run, and a rebuilt body's starts at 0, so it falls asleep later than the saved one.
  // Saved at frame 200, when the dam break's water has let all three rest (at frame 100 one
  // still rocked in the waves).
  constexpr int kRestFrame = 200;
  SaveReport report;
  bool sleepParts = false;
  const int parted = replayFrom(kApart, false, true, kRestFrame, report, nullptr, &sleepParts);
  CHECK(report.sleepTimers == 3);
  CHECK(report.warmStartedContacts == 0);
  CHECK(report.warning.find("3 bodies at rest have sleep timers running") != std::string::npos);
  CHECK(report.warning.find("SetAllowSleeping(false)") != std::string::npos);
  CHECK(report.warning.find("SetWarmStarting") == std::string::npos);
  MESSAGE("sleeping allowed: the replay parts at frame " << parted);
  CHECK(parted > kRestFrame + 1);
  CHECK(sleepParts);  // they part when a crate falls asleep in one world and not in the other
  // With sleeping off on both b2Worlds the report is complete and the replay the same bits.
  CHECK(replayFrom(kApart, false, false, kRestFrame, report) == 0);
  CHECK(report.complete());
}

TEST_CASE("save and load: the scene's own b2World's switches and its bodies' sleep come back with the load") {
  // A crate of the scene's own world at rest on a shelf above the water falls asleep; the game
  // turned warm starting off on that world. The save holds both: the loaded World's crate
  // sleeps, its world does not warm-start, and it steps on bit for bit.
  SceneDef s = test::tank("game", 1.2, 1.2, 0.03);
  s.blocks.push_back(test::block({0, 0}, {1.2, 0.2}));
  BodyDef shelf;
  shelf.position = Vec2d(0.9, 0.6);
  shelf.fixtures.push_back(test::boxShape({0, 0}, {0.25, 0.03}));
  s.bodies.push_back(shelf);
  BodyDef crate;
  crate.type = BodyDef::Type::Dynamic;
  crate.position = Vec2d(0.9, 0.72);
  crate.fixtures.push_back(test::boxShape({0, 0}, {0.08, 0.08}));
  crate.fixtures.back().density = 800;
  s.bodies.push_back(crate);
  World a(s, WorldOptions{2});
  a.box2d().SetWarmStarting(false);
  for (int f = 0; f < 90; ++f) a.stepFrame();
  const b2Body* ca = test::dynamicBody(a);
  REQUIRE(ca);
  REQUIRE_FALSE(ca->IsAwake());  // at rest long enough: asleep
  std::ostringstream out;
  CHECK(a.save(out).complete());
  World b(s, WorldOptions{1});
  REQUIRE(b.box2d().GetWarmStarting());
  std::istringstream in(out.str());
  b.load(in);
  const b2Body* cb = test::dynamicBody(b);
  CHECK_FALSE(cb->IsAwake());
  CHECK_FALSE(b.box2d().GetWarmStarting());
  for (int f = 0; f < 60; ++f) {
    a.stepFrame();
    b.stepFrame();
    REQUIRE_MESSAGE(b.stateHash() == a.stateHash(), "frame " << f << " after the load");
    REQUIRE(cb->GetPosition() == ca->GetPosition());
    REQUIRE(cb->GetAngle() == ca->GetAngle());
  }
}

TEST_CASE("save and load: version-4 and 5 saves still load, and older and newer versions are refused by number") {
  const SceneDef s = busyScene("game");
  SceneDef still = s;
  still.bodies.clear();  // no moving bodies and no emitters: a version-4 or 5 save had these very bytes
  still.bodies.push_back(test::tankWalls(1.2, 1.2));
  still.effects.emitters.clear();
  World a(still, WorldOptions{1});
  for (int f = 0; f < 10; ++f) a.stepFrame();
  std::string bytes = saved(a);
  auto withVersion = [&](std::uint32_t v) {
    std::string b = bytes;
    std::memcpy(&b[8], &v, sizeof v);  // after the 8 magic bytes
    return b;
  };
  for (const std::uint32_t v : {4u, 5u}) {
    World b(still, WorldOptions{1});
    std::istringstream in(withVersion(v));
    b.load(in);
    CHECK(b.stateHash() == a.stateHash());
  }
  World b(still, WorldOptions{1});
  for (const std::uint32_t v : {3u, 7u}) {
    std::istringstream in(withVersion(v));
    try {
      b.load(in);
      FAIL("version " << v << " loaded");
    } catch (const SaveError& e) {
      CHECK(std::string(e.what()) ==
            "the saved state has version " + std::to_string(v) + "; this sph2d reads versions 4 to 6");
    }
  }
}
