// Particles added and removed at run time: emitters a game adds and removes, the ids every
// add and removal returns, and the emitter index a tracked particle carries.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <set>
#include <sstream>
#include <stdexcept>

#include "sph2d/world.hpp"
#include "support/fixture.hpp"

using namespace sph2d;

namespace {

bool has(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

/// The closed tank [0, 2]² (wcsph, no viscosity), no fluid.
SceneDef box(double spacing = 0.04) {
  SceneDef s = test::tank("wcsph", 2, 2, spacing);
  s.solver.viscosity = 0.0;
  return s;
}

}  // namespace

TEST_CASE(
    "emitters added and removed at run time: nothing owed for the past, seeded, saved, and the emit stage only while one exists") {
  const SceneDef s = box();
  EmitterDef e;
  e.position = Vec2d(1.0, 1.8);
  e.direction = Vec2d(0, -2);  // normalised by addEmitter
  e.rate = 200;
  e.speed = 1.0;
  e.spread = 0.2;
  e.jitter = 0.1;
  e.seed = 7;
  auto run = [&](int threads, std::uint64_t seed, std::stringstream* save) {
    World w(s, WorldOptions{threads});
    CHECK_FALSE(has(w.stages(), "emit"));
    for (int f = 0; f < 30; ++f) w.stepFrame();  // 0.5 s with no emitter
    EmitterDef d = e;
    d.seed = seed;
    CHECK(w.addEmitter(d) == 0);  // start 0 is in the past: it starts now
    CHECK(has(w.stages(), "emit"));
    CHECK(w.emitter(0).direction.y() == doctest::Approx(-1.0));
    for (int f = 0; f < 30; ++f) w.stepFrame();  // 0.5 s more
    const double expected = e.rate * 0.5;
    CHECK(std::fabs(double(w.emittedCount(0)) - expected) <= 1.0);
    CHECK(w.particleCount() == w.emittedCount(0));
    if (save) w.save(*save);
    return w.stateHash();
  };
  const std::uint64_t a = run(1, 7, nullptr);
  std::stringstream saved;
  CHECK(run(3, 7, &saved) == a);  // seeded: the same bits on any thread count
  CHECK(run(2, 8, nullptr) != a);
  // A World of the same scene (no emitters) loads the save with the added emitter, and both go on alike.
  World w(s, WorldOptions{2});
  w.load(saved);
  CHECK(w.emitterCount() == 1);
  CHECK(has(w.stages(), "emit"));
  CHECK(w.stateHash() == a);
  World again(s, WorldOptions{1});
  saved.clear();
  saved.seekg(0);
  again.load(saved);
  for (int f = 0; f < 10; ++f) {
    w.stepFrame();
    again.stepFrame();
  }
  CHECK(w.stateHash() == again.stateHash());
  CHECK(w.emittedCount(0) > 100);
  // Removal: indices move down; the particles stay; the stage goes with the last emitter.
  EmitterDef second = e;
  second.position = Vec2d(0.5, 1.8);
  CHECK(w.addEmitter(second) == 1);
  const std::size_t before = w.particleCount();
  w.removeEmitter(0);
  CHECK(w.emitterCount() == 1);
  CHECK(w.emitter(0).position.x() == doctest::Approx(0.5));
  CHECK(w.particleCount() == before);
  w.removeEmitter(0);
  CHECK_FALSE(has(w.stages(), "emit"));
  w.stepFrame();
  CHECK(w.particleCount() == before);
  CHECK_THROWS_AS(w.removeEmitter(0), std::out_of_range);
  // Bad definitions are refused, naming the field.
  EmitterDef bad = e;
  bad.rate = -1;
  CHECK_THROWS_WITH_AS(w.addEmitter(bad), doctest::Contains("rate"), std::invalid_argument);
  bad = e;
  bad.direction = Vec2d(0, 0);
  CHECK_THROWS_WITH_AS(w.addEmitter(bad), doctest::Contains("direction"), std::invalid_argument);
  bad = e;
  bad.position = Vec2d(std::nan(""), 0);
  CHECK_THROWS_WITH_AS(w.addEmitter(bad), doctest::Contains("position"), std::invalid_argument);
  CHECK(w.emitterCount() == 0);
}

namespace {

/// The ids of every particle of `w`, in increasing order.
std::vector<std::uint32_t> allIds(const World& w) {
  std::vector<std::uint32_t> ids(w.particles().id.begin(), w.particles().id.end());
  std::sort(ids.begin(), ids.end());
  return ids;
}

/// The ids in `after` that are not in `before` (both in increasing order).
std::vector<std::uint32_t> newIds(const std::vector<std::uint32_t>& before, const std::vector<std::uint32_t>& after) {
  std::vector<std::uint32_t> out;
  std::set_difference(after.begin(), after.end(), before.begin(), before.end(), std::back_inserter(out));
  return out;
}

}  // namespace

TEST_CASE(
    "every add returns the ids it made: addBlock, addDrop, addShape, addParticles, the budget cutting a block short too") {
  SceneDef s = box();
  s.blocks.push_back(test::block({0.1, 0.1}, {0.5, 0.5}));
  EmitterDef e;  // emitted particles take ids between the adds
  e.position = Vec2d(1.5, 1.8);
  e.direction = Vec2d(0, -1);
  e.rate = 100;
  e.speed = 1;
  s.effects.emitters.push_back(e);
  World w(s, WorldOptions{2});
  // Each add: the ids new in the World are exactly the range returned, and the range is what it says.
  auto expectAdded = [&](const std::vector<std::uint32_t>& before, const IdRange& r) {
    const std::vector<std::uint32_t> made = newIds(before, allIds(w));
    CHECK(made == r.ids());
    CHECK(made.size() == r.count);
    for (const std::uint32_t id : made) CHECK(r.contains(id));
    CHECK_FALSE(r.contains(r.first - 1));
    CHECK_FALSE(r.contains(r.first + std::uint32_t(r.count)));
    CHECK(std::vector<std::uint32_t>(r.begin(), r.end()) == made);
  };
  for (int f = 0; f < 10; ++f) w.stepFrame();
  std::vector<std::uint32_t> before = allIds(w);
  const IdRange block = w.addBlock(test::block({1.0, 0.1}, {1.3, 0.3}));
  CHECK(block.count == 35);            // 7 × 5 lattice points at spacing 0.04 (the floor's face left out: none here)
  CHECK(block.first > before.back());  // after every id given out, the emitted ones included
  expectAdded(before, block);
  for (int f = 0; f < 5; ++f) w.stepFrame();
  before = allIds(w);
  const IdRange drop = w.addDrop(Vec2d(1.0, 1.0), 0.1, Vec2d(0, -1));
  CHECK(drop.count > 0);
  expectAdded(before, drop);
  before = allIds(w);
  b2PolygonShape tri;
  const b2Vec2 corners[3] = {b2Vec2(0.6f, 1.2f), b2Vec2(0.9f, 1.2f), b2Vec2(0.75f, 1.45f)};
  tri.Set(corners, 3);
  const IdRange shape = w.addShape(tri, b2Transform(b2Vec2(0, 0), b2Rot(0)));
  CHECK(shape.count > 10);
  expectAdded(before, shape);
  // addParticles: points inside a solid take no id, so the ids stay consecutive.
  before = allIds(w);
  const IdRange points =
      w.addParticles({Vec2d(0.3, 1.0), Vec2d(0.3, -0.1), Vec2d(0.4, 1.0), Vec2d(-0.1, 1.0), Vec2d(0.5, 1.0)});
  CHECK(points.count == 3);
  expectAdded(before, points);
  CHECK(w.takeWarnings().size() == 1);  // the two points in the walls
  // Removed ids are never given again: the next add starts after the last id given.
  const std::vector<std::uint32_t> removed = w.removeParticles(points.ids());
  CHECK(removed == points.ids());
  before = allIds(w);
  const IdRange again = w.addParticles({Vec2d(0.3, 1.0)});
  CHECK(again.first == points.first + 3);
  expectAdded(before, again);
  // The budget cuts a block short: the ids it did add are still one range, and a full World adds none.
  SceneDef small = box();
  small.maxParticles = 50;
  World full(small, WorldOptions{1});
  const IdRange cut = full.addBlock(test::block({0.1, 0.1}, {1.9, 1.9}));
  CHECK(cut.count == 50);
  CHECK(cut.first == 0);
  CHECK(allIds(full) == cut.ids());
  full.takeWarnings();
  const IdRange none = full.addDrop(Vec2d(1, 1), 0.2);
  CHECK(none.empty());
  CHECK(none.first == 50);  // the id the next particle would take
  CHECK(none.begin() == none.end());
  CHECK(allIds(full) == cut.ids());
}

TEST_CASE(
    "emitter tracking: each particle an emitter makes carries its index, only when asked, with no cost or change when off") {
  SceneDef s = box();
  s.blocks.push_back(test::block({0.1, 0.1}, {0.5, 0.3}));
  EmitterDef left;
  left.position = Vec2d(0.6, 1.6);
  left.direction = Vec2d(0, -1);
  left.rate = 150;
  left.speed = 1;
  EmitterDef right = left;
  right.position = Vec2d(1.4, 1.6);
  right.start = 0.25;  // the first 15 frames: only the left one
  right.seed = 3;
  s.effects.emitters = {left, right};
  World off(s, WorldOptions{2}), on(s, WorldOptions{2});
  CHECK_FALSE(on.emitterTracking());
  on.setEmitterTracking(true);
  CHECK(on.emitterTracking());
  const std::vector<std::uint32_t> blockIds = allIds(on);
  for (const std::uint32_t id : blockIds) CHECK(on.particleEmitter(id) == World::npos);  // there before: none
  // Frame by frame: the particles new in the World are tagged with the emitter whose count grew.
  for (int f = 0; f < 40; ++f) {
    const std::vector<std::uint32_t> before = allIds(on);
    const std::uint64_t e0 = on.emittedCount(0), e1 = on.emittedCount(1);
    off.stepFrame();
    on.stepFrame();
    std::size_t by0 = 0, by1 = 0;
    for (const std::uint32_t id : newIds(before, allIds(on))) {
      const std::size_t e = on.particleEmitter(id);
      REQUIRE((e == 0 || e == 1));
      (e == 0 ? by0 : by1) += 1;
    }
    CHECK(by0 == on.emittedCount(0) - e0);
    CHECK(by1 == on.emittedCount(1) - e1);
    if (f < 14) CHECK(by1 == 0);
    REQUIRE(on.stateHash() == off.stateHash());  // the tag changes nothing that moves
  }
  CHECK(on.emittedCount(1) > 50);
  // The view shows 1 + the index; the World that did not ask has no such field.
  const Particles& P = on.particles();
  REQUIRE(P.emitter.size() == P.size());
  for (std::size_t i = 0; i < P.size(); ++i)
    CHECK(P.emitter[i] ==
          (on.particleEmitter(P.id[i]) == World::npos ? 0u : std::uint32_t(on.particleEmitter(P.id[i]) + 1)));
  CHECK(off.particles().emitter.empty());
  CHECK_FALSE(has(off.particleFields(), "emitter"));
  CHECK(has(on.particleFields(), "emitter"));
  CHECK(off.particleEmitter(P.id[P.size() - 1]) == World::npos);
  // An emitter added at run time tags with its index; removing one renumbers the tags with the indices.
  EmitterDef third = left;
  third.position = Vec2d(1.0, 1.8);
  third.seed = 9;
  REQUIRE(on.addEmitter(third) == 2);
  for (int f = 0; f < 10; ++f) on.stepFrame();
  std::vector<std::size_t> tagOf;
  const std::vector<std::uint32_t> ids = allIds(on);
  std::size_t count[3] = {0, 0, 0};
  for (const std::uint32_t id : ids) {
    tagOf.push_back(on.particleEmitter(id));
    if (tagOf.back() != World::npos) ++count[tagOf.back()];
  }
  CHECK(count[2] > 0);
  on.removeEmitter(0);
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const std::size_t expected = tagOf[k] == 0 || tagOf[k] == World::npos ? World::npos : tagOf[k] - 1;
    CHECK(on.particleEmitter(ids[k]) == expected);
  }
  // Saved and loaded with the particles: a World that had it off loads it on.
  std::stringstream saved;
  on.save(saved);
  World loaded(s, WorldOptions{1});
  loaded.load(saved);  // (the save holds the emitters, the one added at run time too)
  CHECK(loaded.emitterTracking());
  for (const std::uint32_t id : ids) CHECK(loaded.particleEmitter(id) == on.particleEmitter(id));
  // Off again: the field is gone, the state unchanged.
  const std::uint64_t hash = on.stateHash();
  on.setEmitterTracking(false);
  CHECK_FALSE(on.emitterTracking());
  CHECK(on.particles().emitter.empty());
  CHECK(on.particleEmitter(ids.back()) == World::npos);
  CHECK_FALSE(has(on.particleFields(), "emitter"));
  CHECK(on.stateHash() == hash);
}
