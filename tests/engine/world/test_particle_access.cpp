// Particles by id (engine/src/world/particle_access.cpp): lookups that follow a particle
// through reordering and removal, writes of position and velocity one at a time and
// in bulk, particles added at given points and removed by id; checked on the physics
// they feed (momentum, free fall) and on determinism.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <box2d/box2d.h>

#include "support/fixture.hpp"

using namespace sph2d;

namespace {

/// A 1 m × 1 m tank with a 0.3 × 0.4 m column of the game solver at spacing 0.02.
SceneDef smallDamBreak() {
  SceneDef s = test::tank("game", 1.0, 1.0, 0.02);
  s.blocks.push_back(test::block({0, 0}, {0.3, 0.4}));
  return s;
}

bool everySlotFound(const World& w) {
  const Particles& P = w.particles();
  for (std::size_t i = 0; i < P.size(); ++i)
    if (w.slotOf(P.id[i]) != i) return false;
  return true;
}

}  // namespace

TEST_CASE("particle access: slotOf follows every particle through the grid's reordering and removals") {
  World w(smallDamBreak(), WorldOptions{2});
  REQUIRE(everySlotFound(w));
  const std::uint32_t watched = w.particles().id[w.particleCount() / 2];
  const std::size_t slot0 = w.slotOf(watched);
  for (int f = 0; f < 30; ++f) w.stepFrame();
  CHECK(w.slotOf(watched) != slot0);  // the grid reordered the particles: the slot moved
  CHECK(everySlotFound(w));
  const std::vector<std::uint32_t> removed = w.removeParticlesInBox({0, 0}, {0.2, 0.1});
  REQUIRE(!removed.empty());
  CHECK(everySlotFound(w));
  CHECK(w.slotOf(w.particles().id[w.particleCount() - 1] + 100000) == World::npos);  // never made
  Vec2d x(7, 7), v(7, 7);
  // An id removed above is not found, and its outputs are left as they were.
  std::uint32_t gone = 0;
  for (std::uint32_t id = 0;; ++id)
    if (w.slotOf(id) == World::npos) {
      gone = id;
      break;
    }
  CHECK_FALSE(w.getParticle(gone, x, v));
  CHECK(x == Vec2d(7, 7));
}

TEST_CASE("particle access: setVelocities gives a free block the momentum asked for, and the solver keeps it") {
  World w(test::freeMovingBlock(), WorldOptions{2});
  const Particles& P = w.particles();
  std::vector<std::uint32_t> ids(P.id.begin(), P.id.end());
  std::vector<Vec2d> vs(ids.size(), Vec2d(1.0, 0.5));
  ids.push_back(ids.back() + 1000);  // an id no particle has: skipped
  vs.push_back(Vec2d(99, 99));
  CHECK(w.setVelocities(ids, vs) == P.size());
  const double Nm = double(P.size()) * double(w.particleMass());
  const Vec2d m0 = test::momentum(w);
  CHECK((m0 - Nm * Vec2d(1.0, 0.5)).norm() <= 1e-6 * Nm);
  const Vec2d c0 = test::centroid(w);
  for (int i = 0; i < 30; ++i) sph2d::bench::stepSubstep(w);
  const Vec2d m1 = test::momentum(w);
  MESSAGE("momentum " << m0 << " -> " << m1);
  CHECK((m1 - m0).norm() <= 1e-5 * Nm);
  // The block moves as a whole at the velocity given: its centroid by (1, 0.5)·t.
  CHECK((test::centroid(w) - c0 - w.time() * Vec2d(1.0, 0.5)).norm() <= 0.01 * w.time());
  CHECK_THROWS_AS(w.setVelocities({P.id[0]}, {}), std::invalid_argument);
  CHECK_THROWS_AS(w.setParticleVelocity(P.id[0], Vec2d(std::numeric_limits<double>::quiet_NaN(), 0)),
                  std::invalid_argument);
}

TEST_CASE("particle access: setParticle teleports a particle over a wall, and a position inside a solid is refused") {
  // Two compartments of one tank, split by a wall at x ∈ [0.45, 0.55].
  SceneDef s = test::tank("wcsph", 1.0, 1.0, 0.02);
  s.bodies[0].fixtures.push_back(test::boxShape({0.5, 0.5}, {0.05, 0.5}));
  s.blocks.push_back(test::block({0, 0}, {0.2, 0.2}));
  World w(s, WorldOptions{1});
  const std::uint32_t id = w.particles().id[0];
  Vec2d x0, v0;
  REQUIRE(w.getParticle(id, x0, v0));
  CHECK_FALSE(w.setParticle(id, Vec2d(0.5, 0.3), Vec2d(0, 0)));  // inside the wall
  Vec2d x, v;
  REQUIRE(w.getParticle(id, x, v));
  CHECK(x == x0);
  CHECK_THROWS_AS(w.setParticle(id, Vec2d(std::numeric_limits<double>::infinity(), 0), Vec2d(0, 0)),
                  std::invalid_argument);
  REQUIRE(w.setParticle(id, Vec2d(0.8, 0.5), Vec2d(-1.0, 0)));  // right compartment, moving at the wall
  for (int f = 0; f < 30; ++f) w.stepFrame();
  REQUIRE(w.getParticle(id, x, v));
  MESSAGE("teleported particle at " << x);
  CHECK(x.x() > 0.55);  // it stays on its side: the wall stops it
  CHECK(x.x() < 1.0);
}

TEST_CASE(
    "particle access: getParticles reads many ids as getParticle does one, and setPositions teleports many, refusing solids") {
  SceneDef s = test::tank("wcsph", 1.0, 1.0, 0.02);
  s.bodies[0].fixtures.push_back(test::boxShape({0.5, 0.5}, {0.05, 0.5}));  // a wall at x in [0.45, 0.55]
  s.blocks.push_back(test::block({0, 0}, {0.2, 0.2}));
  World w(s, WorldOptions{2});
  for (int f = 0; f < 3; ++f) w.stepFrame();  // moving, and reordered by the grid
  const std::uint32_t absent = 1000000;
  std::vector<std::uint32_t> ids = {w.particles().id[5], absent, w.particles().id[0], w.particles().id[17]};
  std::vector<Vec2d> x, v;
  CHECK(w.getParticles(ids, x, v) == 3);
  REQUIRE(x.size() == ids.size());
  REQUIRE(v.size() == ids.size());
  for (std::size_t k = 0; k < ids.size(); ++k) {
    Vec2d xk, vk;
    if (!w.getParticle(ids[k], xk, vk)) {
      CHECK(std::isnan(x[k].x()));
      CHECK(std::isnan(v[k].y()));
      continue;
    }
    CHECK(x[k] == xk);
    CHECK(v[k] == vk);
  }
  // Three moves: one into the right compartment, one into the wall (refused), one for an absent id.
  const std::vector<std::uint32_t> movers = {ids[0], ids[2], absent};
  const std::vector<Vec2d> to = {Vec2d(0.8, 0.3), Vec2d(0.5, 0.3), Vec2d(0.8, 0.5)};
  CHECK_THROWS_AS(w.setPositions(movers, {Vec2d(0.8, 0.3)}), std::invalid_argument);
  CHECK_THROWS_AS(w.setPositions(movers, {Vec2d(0.8, 0.3), Vec2d(std::nan(""), 0), Vec2d(0.8, 0.5)}),
                  std::invalid_argument);
  std::vector<Vec2d> before, vBefore;
  w.getParticles(movers, before, vBefore);
  CHECK(w.setPositions(movers, to) == 1);
  w.getParticles(movers, x, v);
  CHECK((x[0] - to[0]).norm() < 1e-6);  // stored in float, relative to the World's origin
  CHECK(v[0] == vBefore[0]);            // the velocity is kept
  CHECK(x[1] == before[1]);             // refused inside the wall
  for (int f = 0; f < 30; ++f) w.stepFrame();
  w.getParticles(movers, x, v);
  MESSAGE("the moved particle after 0.5 s at " << x[0].x() << ", " << x[0].y());
  CHECK(x[0].x() > 0.55);  // it stays on its side of the wall: the teleport started its swept path there
}

TEST_CASE("particle access: addParticles places particles that fall freely, skips solids and holds the budget") {
  SceneDef s = test::tank("wcsph", 1.0, 2.0, 0.02);
  s.blocks.push_back(test::block({0, 0}, {1.0, 0.1}));
  World probe(s);
  s.maxParticles = probe.particleCount() + 3;
  World w(s, WorldOptions{2});
  const std::size_t n0 = w.particleCount();
  // Two points inside the floor, then four in the air: three fit the budget.
  const std::vector<Vec2d> pts = {{0.5, -0.1}, {0.3, -0.05}, {0.2, 1.8}, {0.5, 1.8}, {0.8, 1.8}, {0.6, 1.5}};
  const std::vector<Vec2d> vel = {{0, 0}, {0, 0}, {0, 0}, {0.5, 0}, {0, 0}, {0, 0}};
  const IdRange ids = w.addParticles(pts, vel);
  REQUIRE(ids.size() == 3);
  CHECK(w.particleCount() == n0 + 3);
  const std::vector<std::string> warn = w.takeWarnings();
  REQUIRE(warn.size() == 2);
  CHECK(warn[0] == "addParticles: skipped 2 points inside solids");
  CHECK(warn[1].find("particle budget of " + std::to_string(n0 + 3) +
                     " (max_particles) reached: addParticles added 3 and refused the last 1 points") == 0);
  Vec2d x, v;
  REQUIRE(w.getParticle(ids[1], x, v));
  CHECK((x - Vec2d(0.5, 1.8)).norm() <= 1e-6 * Vec2d(0.5, 1.8).norm());
  CHECK(v == Vec2d(0.5, 0));
  // Free fall from rest for 0.25 s: y = 1.8 − g t²/2 (alone, far above the water).
  for (int f = 0; f < 15; ++f) w.stepFrame();
  REQUIRE(w.getParticle(ids[0], x, v));
  const double t = w.time(), expected = 1.8 - 0.5 * 9.81 * t * t;
  MESSAGE("fell to " << x.y() << " (free fall: " << expected << ") in " << t << " s");
  CHECK(std::abs(x.y() - expected) < 0.02 * (1.8 - expected));
  CHECK(std::abs(v.y() + 9.81 * t) < 0.02 * 9.81 * t);
  CHECK_THROWS_AS(w.addParticles({{0.5, 1.0}}, {{0, 0}, {0, 0}}), std::invalid_argument);
  CHECK(w.particleCount() == n0 + 3);
}

TEST_CASE("particle access: removeParticles removes exactly the ids given, and the others keep their state") {
  World w(smallDamBreak(), WorldOptions{2});
  for (int f = 0; f < 5; ++f) w.stepFrame();
  const Particles& P = w.particles();
  std::vector<std::uint32_t> gone;
  for (std::size_t i = 0; i < P.size(); i += 7) gone.push_back(P.id[i]);
  const std::uint32_t keep = P.id[1];
  Vec2d xk, vk;
  REQUIRE(w.getParticle(keep, xk, vk));
  const std::size_t n0 = w.particleCount();
  std::vector<std::uint32_t> ask = gone;
  ask.push_back(4000000000u);  // no such particle
  std::vector<std::uint32_t> sorted = gone;
  std::sort(sorted.begin(), sorted.end());
  CHECK(w.removeParticles(ask) == sorted);  // exactly the ids a particle had, in increasing order
  CHECK(w.particleCount() == n0 - gone.size());
  Vec2d x, v;
  for (const std::uint32_t id : gone) CHECK_FALSE(w.getParticle(id, x, v));
  REQUIRE(w.getParticle(keep, x, v));
  CHECK(x == xk);
  CHECK(v == vk);
  CHECK(everySlotFound(w));
}

TEST_CASE("particle access: every removal returns exactly the ids that left, in increasing order") {
  World w(smallDamBreak(), WorldOptions{2});
  for (int f = 0; f < 20; ++f) w.stepFrame();
  auto ids = [&] {
    std::vector<std::uint32_t> out(w.particles().id.begin(), w.particles().id.end());
    std::sort(out.begin(), out.end());
    return out;
  };
  auto gone = [](const std::vector<std::uint32_t>& before, const std::vector<std::uint32_t>& after) {
    std::vector<std::uint32_t> out;
    std::set_difference(before.begin(), before.end(), after.begin(), after.end(), std::back_inserter(out));
    return out;
  };
  // By box: the ids of the particles that were in it.
  std::vector<std::uint32_t> before = ids();
  const std::vector<std::uint32_t> inBox = w.removeParticlesInBox({0.0, 0.0}, {0.1, 0.1});
  CHECK(inBox.size() > 10);
  CHECK(inBox == gone(before, ids()));
  CHECK(std::is_sorted(inBox.begin(), inBox.end()));
  // By shape.
  b2CircleShape disc;
  disc.m_radius = 0.06f;
  const b2Transform at(b2Vec2(0.2f, 0.1f), b2Rot(0));
  before = ids();
  const std::vector<std::uint32_t> inDisc = w.removeParticlesInShape(disc, at);
  CHECK(inDisc.size() > 10);
  CHECK(inDisc == gone(before, ids()));
  // By id: repeats, ids removed before and ids never made are not in the answer.
  before = ids();
  const std::vector<std::uint32_t> ask = {before[40], before[3], before[40], inBox[0], 4000000000u, before[7]};
  const std::vector<std::uint32_t> byId = w.removeParticles(ask);
  CHECK(byId == std::vector<std::uint32_t>{before[3], before[7], before[40]});
  CHECK(byId == gone(before, ids()));
  // Nothing to remove: empty, and the World unchanged.
  const std::uint64_t hash = w.stateHash();
  CHECK(w.removeParticlesInBox({5, 5}, {6, 6}).empty());
  CHECK(w.removeParticles({inBox[0]}).empty());
  CHECK(w.stateHash() == hash);
}

TEST_CASE("particle access: writes by id give the same state hash for 1, 2 and 3 threads") {
  std::uint64_t first = 0;
  for (int threads = 1; threads <= 3; ++threads) {
    World w(smallDamBreak(), WorldOptions{threads});
    for (int f = 0; f < 5; ++f) w.stepFrame();
    std::vector<std::uint32_t> ids;
    std::vector<Vec2d> vs;
    for (std::size_t i = 0; i < w.particleCount(); i += 3) {
      ids.push_back(w.particles().id[i]);
      vs.push_back(Vec2d(0.5, 1.0));
    }
    w.setVelocities(ids, vs);
    w.addParticles({{0.6, 0.8}, {0.62, 0.8}}, {{-1, 0}, {-1, 0}});
    w.removeParticles({ids[0], ids[1]});
    for (int f = 0; f < 10; ++f) w.stepFrame();
    if (threads == 1) first = w.stateHash();
    CHECK_MESSAGE(w.stateHash() == first, "threads " << threads);
  }
}

TEST_CASE(
    "particle colour and user data: allocated by the first set, kept by id through steps, removals and save/load") {
  SceneDef s = test::tank("game", 1.0, 1.0, 0.02);
  s.blocks.push_back(test::block({0, 0}, {1, 0.4}));
  World w(s, WorldOptions{2});
  REQUIRE(w.particleCount() > 500);
  auto has = [&](const char* name) {
    const auto f = w.particleFields();
    return std::find(f.begin(), f.end(), name) != f.end();
  };
  CHECK_FALSE(has("color"));
  CHECK_FALSE(has("user_data"));
  CHECK(w.particleColor(w.particles().id[0]) == 0u);  // nothing set: 0, and still no field
  CHECK_FALSE(has("color"));
  // Colour the left half red, tag every third particle with its id times 7.
  std::vector<std::uint32_t> left, red;
  for (std::size_t i = 0; i < w.particleCount(); ++i)
    if (w.worldPosition(i).x() < 0.5) {
      left.push_back(w.particles().id[i]);
      red.push_back(0xFF0000u);
    }
  const std::uint64_t before = w.stateHash();
  CHECK(w.setParticleColors(left, red) == left.size());
  for (std::size_t k = 0; k < w.particleCount(); k += 3)
    CHECK(w.setParticleUserData(w.particles().id[k], w.particles().id[k] * 7u));
  CHECK(has("color"));
  CHECK(has("user_data"));
  CHECK(w.stateHash() == before);                   // not part of the state hash
  CHECK_FALSE(w.setParticleColor(0xFFFFFFF0u, 1));  // no such id
  CHECK_THROWS_AS(w.setParticleColors(left, {}), std::invalid_argument);
  // Steps reorder the slots; removals compact them; new particles hold 0.
  for (int f = 0; f < 30; ++f) w.stepFrame();
  const std::vector<std::uint32_t> gone(left.begin(), left.begin() + 10);
  CHECK(w.removeParticles(gone).size() == 10);
  const IdRange added = w.addParticles({Vec2d(0.5, 0.9)});
  REQUIRE(added.size() == 1);
  CHECK(w.particleColor(added[0]) == 0u);
  CHECK(w.particleUserData(added[0]) == 0u);
  std::size_t redLeft = 0;
  for (std::size_t k = 10; k < left.size(); ++k) redLeft += w.particleColor(left[k]) == 0xFF0000u;
  CHECK(redLeft == left.size() - 10);
  CHECK(w.particleColor(left[0]) == 0u);  // removed
  std::size_t tagged = 0, right = 0;
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const std::uint32_t id = w.particles().id[i];
    const std::uint32_t u = w.particleUserData(id);
    tagged += u != 0;
    CHECK((u == 0 || u == id * 7u));
    right += std::find(left.begin(), left.end(), id) == left.end() && w.particleColor(id) == 0u;
  }
  CHECK(tagged > w.particleCount() / 4);
  CHECK(right + (left.size() - 10) == w.particleCount());
  // Save and load into a World that never set either: both fields come back, by id.
  std::stringstream saved;
  w.save(saved);
  World v(s, WorldOptions{1});
  v.load(saved);
  CHECK(v.stateHash() == w.stateHash());
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const std::uint32_t id = w.particles().id[i];
    CHECK(v.particleColor(id) == w.particleColor(id));
    CHECK(v.particleUserData(id) == w.particleUserData(id));
  }
  // The other way: a World that set colours after a save loads it back (a rewind): no colours.
  World r(s, WorldOptions{1});
  std::stringstream early;
  r.save(early);
  CHECK(r.setParticleColor(r.particles().id[0], 0x123456u));
  r.load(early);
  CHECK(r.particleColor(r.particles().id[0]) == 0u);
}

TEST_CASE(
    "particle access: the b2Vec2 overloads do what the Vec2d calls do, and braced pairs still pick the Vec2d calls") {
  SceneDef s = smallDamBreak();
  World a(s, WorldOptions{1}), b(s, WorldOptions{1});
  const std::uint32_t id = a.particles().id[3];
  // The same edits, once with Vec2d (braced pairs) and once with b2Vec2 (values exact in a float).
  a.setGravity({0.5, -9.8125});
  b.setGravity(b2Vec2(0.5f, -9.8125f));
  a.addDrop({0.625, 0.75}, 0.0625, {0.0, -1.0});
  b.addDrop(b2Vec2(0.625f, 0.75f), 0.0625, b2Vec2(0.0f, -1.0f));
  a.setParticle(id, {0.5, 0.5}, {0.25, 0.5});
  b.setParticle(id, b2Vec2(0.5f, 0.5f), b2Vec2(0.25f, 0.5f));
  a.setParticleVelocity(a.particles().id[4], {1.0, 0.0});
  b.setParticleVelocity(b.particles().id[4], b2Vec2(1.0f, 0.0f));
  a.addParticles(std::vector<Vec2d>{{0.8125, 0.875}}, std::vector<Vec2d>{{0.0, 0.0}});
  b.addParticles(std::vector<b2Vec2>{b2Vec2(0.8125f, 0.875f)}, std::vector<b2Vec2>{b2Vec2(0.0f, 0.0f)});
  // At rest: addDrop without a velocity, addParticles without velocities.
  CHECK(b.addDrop(b2Vec2(0.375f, 0.8125f), 0.0625) == a.addDrop({0.375, 0.8125}, 0.0625));
  CHECK(b.addParticles(std::vector<b2Vec2>{b2Vec2(0.6875f, 0.875f), b2Vec2(0.75f, 0.875f)}) ==
        a.addParticles(std::vector<Vec2d>{{0.6875, 0.875}, {0.75, 0.875}}));
  // The structs' vectors from b2Vec2s: a user force and an emitter's position and direction.
  a.setUserForces({UserForce{Vec2d(0.25, 0.3125), 0.25, -10.0}});
  b.setUserForces({UserForce{b2Vec2(0.25f, 0.3125f), 0.25, -10.0}});
  EmitterDef hose;
  hose.rate = 120;
  hose.speed = 1.5;
  hose.position = Vec2d(0.5, 0.875);
  hose.direction = Vec2d(0.5, -1.0);
  EmitterDef hoseB2 = hose;
  hoseB2.position = b2Vec2(0.5f, 0.875f);
  hoseB2.direction = b2Vec2(0.5f, -1.0f);
  CHECK(b.addEmitter(hoseB2) == a.addEmitter(hose));
  CHECK(b.emitter(0).position == a.emitter(0).position);
  CHECK(b.emitter(0).direction == a.emitter(0).direction);
  for (int f = 0; f < 5; ++f) {
    a.stepFrame();
    b.stepFrame();
  }
  CHECK(a.stateHash() == b.stateHash());
  CHECK(b.emittedCount(0) > 0);
  for (std::size_t i = 0; i < a.particleCount(); ++i) {
    const b2Vec2 q = b.worldPosition<b2Vec2>(i);
    const Vec2d p = a.worldPosition(i);
    REQUIRE(q.x == float(p.x()));
    REQUIRE(q.y == float(p.y()));
  }
  Vec2d pa, va;
  b2Vec2 pb, vb;
  REQUIRE(a.getParticle(id, pa, va));
  REQUIRE(b.getParticle(id, pb, vb));
  CHECK(pb.x == float(pa.x()));
  CHECK(vb.y == float(va.y()));
  CHECK(b.slotsInRadius(b2Vec2(0.125f, 0.1875f), 0.1) == a.slotsInRadius({0.125, 0.1875}, 0.1));
  CHECK(b.slotsInBox(b2Vec2(0.0f, 0.0f), b2Vec2(0.1875f, 0.1875f)) == a.slotsInBox({0.0, 0.0}, {0.1875, 0.1875}));
  CHECK(b.sampleAt(b2Vec2(0.125f, 0.125f)).density == a.sampleAt({0.125, 0.125}).density);
  CHECK(b.slotsInRadius(b2Vec2(0.125f, 0.1875f), 0.1).size() > 10);
  // The bulk calls, the box removal and the shape fill.
  const std::vector<std::uint32_t> ids = {a.particles().id[5], a.particles().id[6], 999999};
  a.setVelocities(ids, std::vector<Vec2d>{{0.5, 0.25}, {-0.5, 0.0}, {0.0, 0.0}});
  CHECK(b.setVelocities(ids, std::vector<b2Vec2>{b2Vec2(0.5f, 0.25f), b2Vec2(-0.5f, 0.0f), b2Vec2(0.0f, 0.0f)}) == 2);
  a.setPositions(ids, std::vector<Vec2d>{{0.75, 0.5}, {0.75, 0.5625}, {0.0, 0.0}});
  CHECK(b.setPositions(ids, std::vector<b2Vec2>{b2Vec2(0.75f, 0.5f), b2Vec2(0.75f, 0.5625f), b2Vec2(0.0f, 0.0f)}) == 2);
  CHECK(b.removeParticlesInBox(b2Vec2(0.0f, 0.0f), b2Vec2(0.125f, 0.125f)) ==
        a.removeParticlesInBox({0.0, 0.0}, {0.125, 0.125}));
  CHECK(a.counters().removed > 0);
  b2CircleShape disc;
  disc.m_radius = 0.0625f;
  b2Transform at;
  at.Set(b2Vec2(0.75f, 0.25f), 0.0f);
  CHECK(b.addShape(disc, at, b2Vec2(0.0f, -0.5f)) == a.addShape(disc, at, {0.0, -0.5}));
  a.stepFrame();
  b.stepFrame();
  CHECK(a.stateHash() == b.stateHash());
  std::vector<Vec2d> pa2, va2;
  std::vector<b2Vec2> pb2, vb2;
  CHECK(b.getParticles(ids, pb2, vb2) == a.getParticles(ids, pa2, va2));
  REQUIRE(pb2.size() == 3);
  CHECK(pb2[0].x == float(pa2[0].x()));
  CHECK(vb2[1].y == float(va2[1].y()));
  CHECK(std::isnan(pb2[2].x));
}

TEST_CASE(
    "particles(): views of the World own arrays, colour and user data appear once set, a ParticleBuffer copy keeps a frame") {
  World w(smallDamBreak(), WorldOptions{1});
  const std::size_t n = w.particleCount();
  {
    const Particles P = w.particles();
    REQUIRE(P.size() == n);
    CHECK(P.v.size() == n);
    CHECK(P.rho.size() == n);
    CHECK(P.p.size() == n);
    CHECK(P.id.size() == n);
    CHECK(P.age.empty());  // no lifetimes in this scene
    CHECK(P.color.empty());
    CHECK(P.userData.empty());
    CHECK(P.x.data() == w.particles().x.data());  // a view, not a copy
  }
  const std::uint32_t painted = w.particles().id[n / 3];
  REQUIRE(w.setParticleColor(painted, 0x20a0ff));
  REQUIRE(w.setParticleUserData(painted, 77));
  const Particles& held = w.particles();  // a game keeps this reference for the World's life
  ParticleBuffer before;
  {
    const Particles P = w.particles();
    REQUIRE(P.color.size() == n);
    REQUIRE(P.userData.size() == n);
    std::size_t coloured = 0;
    for (std::size_t i = 0; i < n; ++i) coloured += P.color[i] != 0;
    CHECK(coloured == 1);
    CHECK(P.color[w.slotOf(painted)] == 0x20a0ffu);
    CHECK(P.userData[w.slotOf(painted)] == 77u);
    before.assign(P);
  }
  for (int f = 0; f < 10; ++f) w.stepFrame();  // the column falls and spreads
  // The step itself brought the held views up to date (particles() need not be called again).
  const Vec2* heldX = held.x.data();
  const std::uint32_t* heldColor = held.color.data();
  const Particles now = w.particles();
  CHECK(heldX == held.x.data());
  CHECK(heldColor == held.color.data());
  // The reference taken before the steps shows the arrays as they are now (the grid reordered
  // them into other storage meanwhile).
  CHECK(held.x.data() == now.x.data());
  CHECK(held.id.data() == now.id.data());
  CHECK(held.color.data() == now.color.data());
  const Particles kept = before.view();
  REQUIRE(kept.size() == n);
  CHECK(kept.x.data() == before.x.data());
  CHECK(kept.color.size() == n);
  // The copy still holds the frame it was taken at: the painted particle's old height, while the
  // World's has it lower (falling water) and the colour followed it through the reordering.
  std::size_t oldSlot = n;
  for (std::size_t i = 0; i < n; ++i)
    if (kept.id[i] == painted) oldSlot = i;
  REQUIRE(oldSlot < n);
  CHECK(kept.color[oldSlot] == 0x20a0ffu);
  const std::size_t s = w.slotOf(painted);
  REQUIRE(s != World::npos);
  CHECK(now.color[s] == 0x20a0ffu);
  double fell = 0;
  for (std::size_t i = 0; i < n; ++i) fell += double(kept.x[i].y()) - double(now.x[w.slotOf(kept.id[i])].y());
  MESSAGE("mean drop of the column over 10 frames: " << fell / double(n) << " m");
  CHECK(fell / double(n) > 0.005);
}
