// The game's calls about single particles (sph2d/particle_events.hpp,
// engine/src/world/particle_events.cpp): the destruction listener against the id sets before
// and after each step, each particle's own lifetime to within a substep, and ray casts
// against a brute-force scan of every particle on random clouds.
#include <doctest/doctest.h>

#include <box2d/box2d.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <vector>

#include "support/fixture.hpp"
#include "test_util.hpp"

using namespace sph2d;

namespace {

std::set<std::uint32_t> idSet(const World& w) {
  std::set<std::uint32_t> s;
  for (std::size_t i = 0; i < w.particleCount(); ++i) s.insert(w.particles().id[i]);
  return s;
}

bool hasStage(const World& w, const std::string& name) {
  const std::vector<std::string> s = w.stages();
  return std::find(s.begin(), s.end(), name) != s.end();
}

}  // namespace

TEST_CASE("particle events: the destruction listener hears exactly the ids that left, with their reason") {
  // Water flowing into a sink, a third of it with lifetimes of its own, an emitter, a game
  // call and a solid dropped onto the water.
  SceneDef s = test::tank("game", 1.0, 1.0, 0.02);
  s.blocks = {test::block({0.1, 0.1}, {0.6, 0.4})};
  s.effects.sinks = {RegionDef{{0.0, 0.0}, {0.15, 0.1}}};
  EmitterDef e;
  e.position = Vec2d(0.8, 0.8);
  e.direction = Vec2d(0, -1);
  e.rate = 200;
  e.speed = 1;
  s.effects.emitters = {e};
  World w(s);
  std::vector<Removal> heard;
  int calls = 0;
  w.setDestructionListener([&](const std::vector<Removal>& r) {
    ++calls;
    heard.insert(heard.end(), r.begin(), r.end());
  });
  CHECK_FALSE(hasStage(w, "particle_lifetimes"));  // nothing for lifetimes until one is set
  std::vector<std::uint32_t> mortal;
  for (std::size_t i = 0; i < w.particleCount(); i += 3) mortal.push_back(w.particles().id[i]);
  std::sort(mortal.begin(), mortal.end());
  CHECK(w.setLifetimes(mortal, 0.3) == mortal.size());
  CHECK(hasStage(w, "particle_lifetimes"));
  std::map<RemovalReason, std::size_t> byReason;
  for (int f = 0; f < 40; ++f) {
    const std::set<std::uint32_t> before = idSet(w);
    const std::uint64_t removedBefore = w.counters().removed;
    heard.clear();
    const int callsBefore = calls;
    w.stepFrame();
    const std::set<std::uint32_t> after = idSet(w);
    std::set<std::uint32_t> gone;
    for (const std::uint32_t id : before)
      if (!after.count(id)) gone.insert(id);
    std::set<std::uint32_t> told;
    for (const Removal& r : heard) {
      CHECK(told.insert(r.id).second);  // once each
      CHECK_FALSE(after.count(r.id));
      ++byReason[r.reason];
      if (r.reason == RemovalReason::lifetime) CHECK(std::binary_search(mortal.begin(), mortal.end(), r.id));
    }
    // Every particle of the step's start that left is heard; what else is heard was emitted
    // and removed within the step; the count is the World's.
    for (const std::uint32_t id : gone) CHECK(told.count(id));
    CHECK(told.size() == w.counters().removed - removedBefore);
    CHECK(calls - callsBefore == (told.empty() ? 0 : 1));  // once per step
  }
  // Every particle with a lifetime has left by 0.67 s (at 0.3 s, or into the sink before).
  const std::set<std::uint32_t> now = idSet(w);
  for (const std::uint32_t id : mortal) CHECK_FALSE(now.count(id));
  CHECK(byReason[RemovalReason::lifetime] > mortal.size() / 2);
  CHECK(byReason[RemovalReason::sink] > 0);
  // A game call: heard at once, the ids it returns.
  heard.clear();
  const std::vector<std::uint32_t> ids = {w.particles().id[0], w.particles().id[5]};
  const std::vector<std::uint32_t> removed = w.removeParticles(ids);
  REQUIRE(heard.size() == removed.size());
  for (std::size_t k = 0; k < removed.size(); ++k) {
    CHECK(heard[k].id == removed[k]);
    CHECK(heard[k].reason == RemovalReason::game);
  }
  // A static solid dropped onto the water: the particles it covers are heard as `solid`.
  heard.clear();
  b2BodyDef bd;
  b2Body* lid = w.box2d().CreateBody(&bd);
  b2PolygonShape box;
  box.SetAsBox(0.1f, 0.05f, b2Vec2(0.4f, 0.05f), 0);
  lid->CreateFixture(&box, 0);
  w.refreshBoundaries();
  REQUIRE_FALSE(heard.empty());
  for (const Removal& r : heard) CHECK(r.reason == RemovalReason::solid);
  // No listener: nothing is collected, so a listener set later hears nothing of before.
  w.setDestructionListener(nullptr);
  heard.clear();
  w.removeParticles({w.particles().id[0]});
  w.setDestructionListener([&](const std::vector<Removal>& r) { heard.insert(heard.end(), r.begin(), r.end()); });
  const std::uint32_t next = w.particles().id[1];
  w.removeParticles({next});
  REQUIRE(heard.size() == 1);
  CHECK(heard[0].id == next);
  // A listener may replace itself while it runs.
  int replaced = 0;
  w.setDestructionListener(
      [&](const std::vector<Removal>&) { w.setDestructionListener([&](const std::vector<Removal>&) { ++replaced; }); });
  w.removeParticles({w.particles().id[0]});
  w.removeParticles({w.particles().id[0]});
  CHECK(replaced == 1);
}

TEST_CASE("particle events: an emitter at a recycling budget removes the oldest, heard as budget") {
  SceneDef s = test::tank("game", 1.0, 1.0, 0.02);
  EmitterDef e;
  e.position = Vec2d(0.5, 0.8);
  e.rate = 600;
  e.speed = 1;
  s.effects.emitters = {e};
  s.effects.budget = 100;
  s.effects.budgetPolicy = BudgetPolicy::RecycleOldest;
  World w(s);
  std::vector<Removal> heard;
  w.setDestructionListener([&](const std::vector<Removal>& r) { heard.insert(heard.end(), r.begin(), r.end()); });
  for (int f = 0; f < 30; ++f) w.stepFrame();
  REQUIRE(w.counters().removed > 0);
  CHECK(heard.size() == w.counters().removed);
  for (const Removal& r : heard) CHECK(r.reason == RemovalReason::budget);
}

TEST_CASE("particle events: each particle's own lifetime removes it within one substep of its time") {
  SceneDef s = test::tank("game", 1.0, 1.0, 0.02);
  s.blocks = {test::block({0.1, 0.1}, {0.5, 0.3})};
  World w(s);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> life(0.01, 0.5);
  std::map<std::uint32_t, double> due;  // id → the World time it is due
  for (std::size_t i = 0; i < w.particleCount(); i += 2) {
    const std::uint32_t id = w.particles().id[i];
    due[id] = life(rng);
    w.setLifetimes({id}, due[id]);
  }
  CHECK(w.lifetimeLeft(w.particles().id[1]) == std::numeric_limits<double>::infinity());
  CHECK(w.lifetimeLeft(w.particles().id[0]) == doctest::Approx(due[w.particles().id[0]]));
  CHECK_THROWS_AS(w.setLifetimes({w.particles().id[0]}, -1), std::invalid_argument);
  // Steps of 1/600 s: one substep each, so "within one substep" is "in the step that passes it".
  const double dt = 1.0 / 600;
  double t = 0, worst = 0;
  for (int k = 0; k < 330; ++k) {
    const std::set<std::uint32_t> before = idSet(w);
    w.step(dt);
    const std::set<std::uint32_t> after = idSet(w);
    const double t1 = t + dt;
    for (const auto& [id, when] : due) {
      if (before.count(id) && !after.count(id)) worst = std::max(worst, std::fabs(when - t1));
      if (after.count(id)) CHECK(when > t1 - 1e-4);    // not overdue
      if (!after.count(id)) CHECK(when <= t1 + 1e-4);  // not early
    }
    t = t1;
  }
  MESSAGE("the latest or earliest removal: " << worst << " s from its time (substep " << dt << " s)");
  CHECK(worst <= dt + 1e-4);
  for (const auto& [id, when] : due) CHECK_FALSE(idSet(w).count(id));
}

TEST_CASE("particle events: a ray cast finds the particles a brute-force scan finds, nearest first") {
  for (const unsigned seed : {1u, 2u, 3u}) {
    SceneDef s = test::tank("game", 2.0, 2.0, 0.02);
    World w(s);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.05, 1.95);
    std::vector<Vec2d> cloud;
    for (int k = 0; k < 3000; ++k) cloud.push_back(Vec2d(u(rng), u(rng)));
    w.addParticles(cloud);
    w.stepFrame();  // the particles moved: the search grid is rebuilt for their new places
    const double r = 0.01;
    for (int q = 0; q < 200; ++q) {
      const Vec2d p1(u(rng), u(rng)), p2(u(rng), u(rng));
      // Brute force: the entry of the segment into every disc the segment does not start in.
      std::vector<std::pair<double, std::uint32_t>> want;
      const Vec2d d = p2 - p1;
      for (std::size_t i = 0; i < w.particleCount(); ++i) {
        const Vec2d c = w.worldPosition(i);
        if ((p1 - c).norm() <= r) continue;
        // Solve |p1 + t d − c| = r for the smaller t.
        const double A = d.dot(d), B = 2 * (p1 - c).dot(d), C = (p1 - c).dot(p1 - c) - r * r;
        const double D = B * B - 4 * A * C;
        if (D < 0) continue;
        const double t = (-B - std::sqrt(D)) / (2 * A);
        if (t >= 0 && t <= 1) want.push_back({t, w.particles().id[i]});
      }
      std::sort(want.begin(), want.end());
      std::vector<RayHit> got;
      w.rayCast(p1, p2, [&](const RayHit& h) {
        got.push_back(h);
        return true;
      });
      REQUIRE(got.size() == want.size());
      for (std::size_t k = 0; k < got.size(); ++k) {
        CHECK(got[k].fraction == doctest::Approx(want[k].first).epsilon(1e-9));
        if (k + 1 < got.size() && want[k + 1].first - want[k].first > 1e-9) CHECK(got[k].id == want[k].second);
        CHECK(std::fabs((got[k].point - (p1 + d * got[k].fraction)).norm()) < 1e-9);
        CHECK(got[k].normal.norm() == doctest::Approx(1));
      }
      RayHit first;
      if (want.empty()) {
        CHECK_FALSE(w.rayCastFirst(p1, p2, first));
      } else {
        REQUIRE(w.rayCastFirst(p1, p2, first));
        CHECK(first.id == want.front().second);
      }
    }
    // A horizontal ray from far beyond the tank to far beyond it the other way: every disc
    // the line y = 0.7 crosses, nearest first.
    std::vector<std::pair<double, std::uint32_t>> line;
    for (std::size_t i = 0; i < w.particleCount(); ++i) {
      const Vec2d c = w.worldPosition(i);
      if (std::fabs(c.y() - 0.7) < r) line.push_back({c.x(), w.particles().id[i]});
    }
    std::sort(line.begin(), line.end());
    std::vector<std::uint32_t> far;
    w.rayCast(Vec2d(-1e7, 0.7), Vec2d(1e7, 0.7), [&](const RayHit& h) {
      far.push_back(h.id);
      return true;
    });
    REQUIRE(far.size() == line.size());
    for (std::size_t k = 0; k + 1 < line.size(); ++k)
      if (line[k + 1].first - line[k].first > 1e-6) CHECK(far[k] == line[k].second);
  }
}

TEST_CASE("particle events: lifetimes are kept by save and load, and a loaded World counts them down") {
  SceneDef s = test::tank("game", 1.0, 1.0, 0.02);
  s.blocks = {test::block({0.1, 0.1}, {0.3, 0.2})};
  World w(s);
  const std::uint32_t id = w.particles().id[3];
  w.setLifetimes({id}, 0.2);
  w.stepFrame();
  std::stringstream saved;
  w.save(saved);
  World fresh(s);
  CHECK_FALSE(hasStage(fresh, "particle_lifetimes"));
  fresh.load(saved);
  CHECK(hasStage(fresh, "particle_lifetimes"));
  CHECK(fresh.lifetimeLeft(id) == doctest::Approx(w.lifetimeLeft(id)));
  CHECK(fresh.lifetimeLeft(id) == doctest::Approx(0.2 - 1.0 / 60).epsilon(1e-4));
  for (int f = 0; f < 12; ++f) fresh.stepFrame();
  CHECK_FALSE(idSet(fresh).count(id));
  CHECK(fresh.particleCount() == w.particleCount() - 1);
}

TEST_CASE("particle events: a save taken before any lifetime or group loads into a World that has them") {
  SceneDef s = test::tank("game", 1.0, 1.0, 0.02);
  s.blocks = {test::block({0.1, 0.1}, {0.3, 0.2})};
  World w(s);
  std::stringstream before;
  w.save(before);
  const std::uint32_t id = w.particles().id[2];
  w.setLifetimes({id}, 0.5);
  GroupDef g;
  g.region = test::block({0.6, 0.6}, {0.7, 0.7});
  const std::uint32_t group = w.createGroup(g);
  w.stepFrame();
  CHECK_NOTHROW(w.load(before));  // the checkpoint of before: no lifetime, no group
  CHECK(w.lifetimeLeft(id) == std::numeric_limits<double>::infinity());
  GroupState st;
  CHECK_FALSE(w.groupState(group, st));
  for (int f = 0; f < 40; ++f) w.stepFrame();
  CHECK(idSet(w).count(id));
}

TEST_CASE("particle events: the contact listener hears the pairs a brute-force scan finds, by material and group") {
  // Water beside oil in a tank, and a rigid group of oil dropped into the water.
  SceneDef s = test::tank("game", 1.0, 0.8, 0.02);
  MaterialDef water;
  water.name = "water";
  water.density = s.solver.restDensity;
  MaterialDef oil = water;
  oil.name = "oil";
  s.materials = {water, oil};
  s.blocks = {test::block({0, 0}, {0.5, 0.3}), test::block({0.5, 0}, {1.0, 0.3})};
  s.blocks[1].material = 1;
  World w(s, WorldOptions{2});
  GroupDef g;
  g.region = test::block({0.2, 0.35}, {0.3, 0.45});
  g.region.material = 1;
  IdRange blobIds;
  const std::uint32_t blob = w.createGroup(g, &blobIds);
  const std::vector<std::uint32_t> blobList = blobIds.ids();
  const std::set<std::uint32_t> inBlob(blobList.begin(), blobList.end());
  using Pair = std::pair<std::uint32_t, std::uint32_t>;
  // Every touching pair (centres less than 1.5 spacings apart) that `take` keeps, by brute force.
  auto scan = [&](const std::function<bool(std::size_t, std::size_t)>& take) {
    std::set<Pair> out;
    const Particles& P = w.particles();
    for (std::size_t i = 0; i < w.particleCount(); ++i)
      for (std::size_t j = 0; j < w.particleCount(); ++j) {
        if (P.id[i] >= P.id[j] || (w.worldPosition(i) - w.worldPosition(j)).norm() >= 0.03) continue;
        if (take(i, j) || take(j, i)) out.insert(Pair(P.id[i], P.id[j]));
      }
    return out;
  };
  std::vector<std::vector<ParticleContact>> heard;
  auto listen = [&](const std::vector<ParticleContact>& c) { heard.push_back(c); };
  auto asSet = [](const std::vector<ParticleContact>& c) {
    std::set<Pair> out;
    for (const ParticleContact& k : c) out.insert(Pair(k.a, k.b));
    return out;
  };
  // Water against oil (either order).
  ParticleContactFilter f;
  f.materialA = 0;
  f.materialB = 1;
  w.setParticleContactListener(f, listen);
  for (int step = 0; step < 3; ++step) {
    w.stepFrame();
    REQUIRE(heard.size() == std::size_t(step + 1));
    const std::vector<ParticleContact>& c = heard.back();
    const std::set<Pair> expected = scan(
        [&](std::size_t i, std::size_t j) { return w.particles().material[i] == 0 && w.particles().material[j] == 1; });
    CHECK(expected.size() > 20);
    CHECK(asSet(c) == expected);
    CHECK(std::is_sorted(c.begin(), c.end(), [](const ParticleContact& x, const ParticleContact& y) {
      return std::make_pair(x.a, x.b) < std::make_pair(y.a, y.b);
    }));
    std::size_t began = 0;
    for (const ParticleContact& k : c) began += k.began;
    if (step == 0)
      CHECK(began == c.size());  // none touched before the listener
    else
      CHECK(began < c.size() / 2);  // most pairs along the interface touched a step ago too
  }
  // The blob against particles in no group: no pair inside the blob.
  f = ParticleContactFilter{};
  f.groupA = blob;
  f.groupB = ParticleContactFilter::kNoGroup;
  heard.clear();
  w.setParticleContactListener(f, listen);
  for (int step = 0; step < 30 && heard.empty(); ++step) w.stepFrame();  // until it reaches the water
  REQUIRE_FALSE(heard.empty());
  const std::set<Pair> expected = scan([&](std::size_t i, std::size_t j) {
    return inBlob.count(w.particles().id[i]) && !inBlob.count(w.particles().id[j]);
  });
  const std::set<Pair> got = asSet(heard.back());
  CHECK(got.size() > 5);
  CHECK(got == expected);
  // Cleared: no call.
  heard.clear();
  w.setParticleContactListener(f, nullptr);
  w.stepFrame();
  CHECK(heard.empty());
}
