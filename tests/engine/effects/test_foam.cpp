// Foam, spray and bubbles (effects.foam, sph2d/foam.hpp): none where the water is still, some
// after a dam break's impact, each gone within its lifetime, the same on any thread count, and
// nothing at all without the effect.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "sph2d/hash.hpp"
#include "sph2d/world.hpp"
#include "support/fixture.hpp"
#include "test_util.hpp"

using namespace sph2d;

namespace {

bool has(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

/// A 0.5 m × 1 m column collapsing in a 2 m × 1.2 m tank (the game preset, dx 0.02), foam on.
SceneDef damBreak() {
  SceneDef s = test::tank("game", 2.0, 1.2, 0.02);
  s.blocks = {test::block({0, 0}, {0.5, 1.0})};
  s.effects.foam = true;
  s.effects.foamDef.lifetime = Vec2d(0.3, 0.6);
  return s;
}

struct Counts {
  std::size_t spray = 0, foam = 0, bubble = 0;
  std::size_t total() const { return spray + foam + bubble; }
};

Counts countsOf(const DiffuseParticles& d) {
  Counts c;
  for (std::size_t k = 0; k < d.size(); ++k) {
    if (d.kind[k] == DiffuseKind::Spray) ++c.spray;
    if (d.kind[k] == DiffuseKind::Foam) ++c.foam;
    if (d.kind[k] == DiffuseKind::Bubble) ++c.bubble;
  }
  return c;
}

std::uint64_t hashOf(const DiffuseParticles& d) {
  Xxh64 h;
  if (d.size() == 0) return h.digest();
  h.update(d.x, d.size() * sizeof(Vec2));
  h.update(d.v, d.size() * sizeof(Vec2));
  h.update(d.age, d.size() * sizeof(Real));
  h.update(d.life, d.size() * sizeof(Real));
  h.update(d.kind, d.size() * sizeof(DiffuseKind));
  return h.digest();
}

}  // namespace

TEST_CASE("foam: none in a resting tank, none without the effect") {
  SceneDef s = test::tank("game", 1.0, 0.8, 0.02);
  s.blocks = {test::block({0, 0}, {1.0, 0.4})};
  s.effects.foam = true;
  World still(s, WorldOptions{2});
  std::size_t most = 0;
  for (int f = 0; f < 120; ++f) {
    still.stepFrame();
    most = std::max(most, still.diffuse().size());
  }
  CHECK(has(still.stages(), "foam"));
  CHECK(most == 0);

  // Without the effect: no stage, no field, no diffuse particle, after the same impact that
  // makes foam with it.
  SceneDef off = damBreak();
  off.effects.foam = false;
  World w(off, WorldOptions{2});
  for (int f = 0; f < 60; ++f) w.stepFrame();
  CHECK_FALSE(has(w.stages(), "foam"));
  CHECK(w.diffuse().size() == 0);
  CHECK(w.diffuse().x == nullptr);
  // The effect adds no particle field: the same fields with it and without.
  World on(damBreak(), WorldOptions{2});
  on.stepFrame();
  CHECK(on.particleFields() == w.particleFields());
}

TEST_CASE("foam: diffuse particles stay in a periodic box, a sand column sheds none") {
  // A periodic shear layer at ±2 m/s in zero gravity (the 1 m box of the Taylor–Green case):
  // its shear makes foam, which is carried across the seams and stays inside the box.
  SceneDef s = test::periodicShearLayer("game", 2.0, 0.02);
  s.effects.foam = true;
  World w(s, WorldOptions{2});
  std::size_t seen = 0, outside = 0;
  for (int f = 0; f < 60; ++f) {
    w.stepFrame();
    const DiffuseParticles d = w.diffuse();
    seen = std::max(seen, d.size());
    for (std::size_t k = 0; k < d.size(); ++k) {
      const Vec2d p = w.origin() + d.x[k].cast<double>();
      outside += p.x() < s.periodic.min.x() || p.x() >= s.periodic.max.x() || p.y() < s.periodic.min.y() ||
                 p.y() >= s.periodic.max.y();
    }
  }
  MESSAGE("periodic shear layer: up to " << seen << " diffuse particles");
  CHECK(seen > 0);
  CHECK(outside == 0);

  // Sand alone (one granular material: no per-particle material field) falling 0.5 m.
  SceneDef sand = test::tank("game", 1.0, 1.2, 0.02);
  MaterialDef grains;
  grains.name = "sand";
  grains.kind = MaterialDef::Kind::granular;
  grains.density = sand.solver.restDensity;  // the first material is the solver's
  grains.frictionAngle = 30;
  sand.materials = {grains};
  sand.blocks = {test::block({0.3, 0.5}, {0.6, 0.9})};
  sand.effects.foam = true;
  World g(sand, WorldOptions{2});
  std::size_t most = 0;
  for (int f = 0; f < 60; ++f) {
    g.stepFrame();
    most = std::max(most, g.diffuse().size());
  }
  CHECK(most == 0);
}

TEST_CASE("foam: with an emitter, lifetimes and a sink (particles added and removed each substep)") {
  // The fountain: a jet, per-particle ages, a sink and a budget, with foam: the foam stage reads
  // the neighbour lists before anything is removed; finite, and the same on 1 and 3 threads.
  SceneDef s = test::scene("fountain.json");
  s.effects.foam = true;
  std::uint64_t hashes[2] = {0, 0};
  std::size_t most = 0;
  for (int k = 0; k < 2; ++k) {
    World w(s, WorldOptions{k == 0 ? 1u : 3u});
    Xxh64 all;
    for (int f = 0; f < 120; ++f) {
      w.stepFrame();
      const std::uint64_t h = hashOf(w.diffuse());
      all.update(&h, sizeof h);
      most = std::max(most, w.diffuse().size());
    }
    REQUIRE(test::allFiniteState(w));
    hashes[k] = all.digest();
  }
  MESSAGE("fountain: up to " << most << " diffuse particles");
  CHECK(most > 0);
  CHECK(hashes[0] == hashes[1]);

  // A small cap: the foam fills it (each count rounded by its particle's hash when the room is
  // short, not all rounded down to none) and never exceeds it.
  SceneDef capped = damBreak();
  capped.effects.foamDef.maxParticles = 20;
  World w(capped, WorldOptions{2});
  std::size_t top = 0;
  for (int f = 0; f < 90; ++f) {
    w.stepFrame();
    top = std::max(top, w.diffuse().size());
  }
  MESSAGE("with max_particles 20: at most " << top);
  CHECK(top <= 20);
  CHECK(top >= 15);
}

TEST_CASE("foam: a dam break's impact makes spray, foam and bubbles, each gone within its lifetime") {
  const SceneDef s = damBreak();
  World w(s, WorldOptions{2});
  const double dt = 1.0 / s.fps;
  Counts most;
  double firstAt = -1, worstOver = -1;
  std::size_t peak = 0;
  for (int f = 0; f < 150; ++f) {  // 2.5 s: the surge hits the far wall at about 0.7 s
    w.stepFrame();
    const DiffuseParticles d = w.diffuse();
    const Counts c = countsOf(d);
    most.spray = std::max(most.spray, c.spray);
    most.foam = std::max(most.foam, c.foam);
    most.bubble = std::max(most.bubble, c.bubble);
    peak = std::max(peak, c.total());
    if (c.total() > 0 && firstAt < 0) firstAt = w.time();
    for (std::size_t k = 0; k < d.size(); ++k) {
      // Every one alive is younger than its lifetime (removed the substep its age reaches it),
      // and its lifetime is within the scene's bounds.
      worstOver = std::max(worstOver, double(d.age[k] - d.life[k]));
      CHECK(d.life[k] >= Real(0.3) - Real(1e-6));
      CHECK(d.life[k] <= Real(0.6) + Real(1e-6));
      CHECK(d.age[k] <= Real(0.6));
    }
  }
  MESSAGE("first diffuse particle at t = " << firstAt << " s; most spray " << most.spray << ", foam " << most.foam
                                           << ", bubbles " << most.bubble << ", at most " << peak
                                           << " at once; largest age − lifetime " << worstOver << " s");
  CHECK(firstAt > 0.1);  // the column starts from rest: nothing is fast at first
  CHECK(most.spray > 10);
  CHECK(most.foam > 10);
  CHECK(most.bubble > 0);
  CHECK(worstOver < 0);
  CHECK(worstOver > -dt);  // some reach the end of their lifetimes: they are not removed early
}

TEST_CASE("foam: the same diffuse particles on 1, 2 and 3 threads") {
  const SceneDef s = damBreak();
  std::vector<std::uint64_t> hashes;
  std::size_t n = 0;
  for (const unsigned threads : {1u, 2u, 3u}) {
    World w(s, WorldOptions{threads});
    Xxh64 all;
    for (int f = 0; f < 75; ++f) {
      w.stepFrame();
      const std::uint64_t h = hashOf(w.diffuse());
      all.update(&h, sizeof h);
    }
    n = w.diffuse().size();
    hashes.push_back(all.digest());
  }
  MESSAGE(n << " diffuse particles at 1.25 s");
  CHECK(n > 0);
  CHECK(hashes[0] == hashes[1]);
  CHECK(hashes[0] == hashes[2]);
}

TEST_CASE("foam: a scene's effects.foam is read, and bad values are refused at their key") {
  const SceneDef s = parseScene(R"({"fluid": [{"min": [0, 0], "max": [1, 1]}],
      "effects": {"foam": {"trapped_air": [2, 10], "lifetime": [0.5, 0.5], "rate": 80, "max_particles": 1000}}})",
                                "inline.json");
  CHECK(s.effects.foam);
  CHECK(s.effects.foamDef.trappedAir == Vec2d(2, 10));
  CHECK(s.effects.foamDef.lifetime == Vec2d(0.5, 0.5));
  CHECK(s.effects.foamDef.rate == 80);
  CHECK(s.effects.foamDef.maxParticles == 1000);
  CHECK(s.effects.foamDef.energy == Vec2d(1, 10));  // the default
  auto refused = [](const std::string& foam, const std::string& key) {
    try {
      (void)parseScene("{\"fluid\": [{\"min\": [0, 0], \"max\": [1, 1]}], \"effects\": {\"foam\": " + foam + "}}",
                       "inline.json");
      FAIL("accepted " << foam);
    } catch (const SceneError& e) {
      CHECK(e.key == key);
    }
  };
  refused(R"({"energy": [5, 5]})", "effects.foam.energy");
  refused(R"({"wave_crest": [8, 2]})", "effects.foam.wave_crest");
  refused(R"({"lifetime": [0, 1]})", "effects.foam.lifetime");
  refused(R"({"rate": -1})", "effects.foam.rate");
  refused(R"({"max_particles": 0})", "effects.foam.max_particles");
  refused(R"({"spray": 1})", "effects.foam.spray");
}
