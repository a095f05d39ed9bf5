// Particle groups (sph2d/groups.hpp, engine/src/world/groups.cpp): a rigid group keeps its
// shape while the water throws it about, floats at its Archimedes draught or sinks by its
// density, and takes a game's impulse as a rigid body does.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "support/fixture.hpp"
#include "test_util.hpp"

using namespace sph2d;

namespace {

/// The game solver in a tank W × H at `dx` with water `depth` deep, and a second material.
SceneDef tankWith(double W, double H, double dx, double depth, double density) {
  SceneDef s = test::tank("game", W, H, dx);
  MaterialDef water;
  water.name = "water";
  water.density = s.solver.restDensity;
  MaterialDef solid = water;
  solid.name = "solid";
  solid.density = density;
  s.materials = {water, solid};
  s.blocks = {test::block({0, 0}, {W, depth})};
  return s;
}

std::vector<Vec2d> groupPositions(const World& w, const std::vector<std::uint32_t>& ids) {
  std::vector<Vec2d> xs, vs;
  w.getParticles(ids, xs, vs);
  return xs;
}

}  // namespace

TEST_CASE("groups: a rigid group keeps every pairwise distance within 0.1 % while sloshing water tumbles it") {
  const double dx = 0.01;
  SceneDef s = tankWith(1.0, 0.8, dx, 0.3, 700);
  World w(s, WorldOptions{2});
  GroupDef g;
  g.region = test::block({0.42, 0.36}, {0.58, 0.44}, Vec2d(0.5, -1.0));
  g.region.material = 1;
  IdRange range;
  const std::uint32_t index = w.createGroup(g, &range);
  const std::vector<std::uint32_t> ids = range.ids();
  REQUIRE(ids.size() > 100);
  const std::vector<Vec2d> x0 = groupPositions(w, ids);
  double worst = 0, angleMin = 0, angleMax = 0;
  for (int f = 0; f < 300; ++f) {  // 5 s, the tank tilting ±0.35 rad every 1.5 s
    const double t = f / 60.0, tilt = 0.35 * std::sin(2 * kPi<double> * t / 1.5);
    w.setGravity(Vec2d(9.81 * std::sin(tilt), -9.81 * std::cos(tilt)));
    w.stepFrame();
    const std::vector<Vec2d> x = groupPositions(w, ids);
    for (std::size_t a = 0; a < x.size(); a += 3)
      for (std::size_t b = a + 1; b < x.size(); b += 2) {
        const double d0 = (x0[a] - x0[b]).norm(), d = (x[a] - x[b]).norm();
        worst = std::max(worst, std::fabs(d / d0 - 1));
      }
    GroupState st;
    REQUIRE(w.groupState(index, st));
    angleMin = std::min(angleMin, st.angle);
    angleMax = std::max(angleMax, st.angle);
  }
  REQUIRE(test::allFiniteState(w));
  MESSAGE(ids.size() << " particles: largest change of a pairwise distance " << worst * 100 << " %, angle from "
                     << angleMin << " to " << angleMax << " rad");
  CHECK(worst < 1e-3);
  CHECK(angleMax - angleMin > 0.2);  // it did tumble
}

TEST_CASE("groups: a rigid group of 500 kg/m3 floats at its Archimedes draught, one of 2000 sinks") {
  // A block 0.3 m × 0.16 m (wide enough to float flat at half the water's density), let go
  // with its bottom at the water's surface; the water with ν = 0.01 so that the waves of
  // its entry die down. The draught: the water's surface away from the block (the highest
  // water particle of each column within 0.2 m of the walls, plus half a spacing) less the
  // block's bottom (its lowest particle less half a spacing), averaged over seconds 3 to 6.
  const double dx = 0.01, W = 1.0, depth = 0.4, h = 0.16;
  for (const double density : {500.0, 2000.0}) {
    SceneDef s = tankWith(W, 1.0, dx, depth, density);
    s.solver.viscosity = 0.01;
    World w(s, WorldOptions{2});
    GroupDef g;
    g.region = test::block({0.35, depth}, {0.65, depth + h});
    g.region.material = 1;
    IdRange range;
    const std::uint32_t index = w.createGroup(g, &range);
    const std::vector<std::uint32_t> ids = range.ids();
    double draught = 0, bottomMean = 0, tilt = 0;
    int samples = 0;
    for (int f = 1; f <= 6 * 60; ++f) {
      w.stepFrame();
      if (f <= 3 * 60) continue;
      const std::vector<Vec2d> x = groupPositions(w, ids);
      double bottom = 1e9;
      for (const Vec2d& p : x) bottom = std::min(bottom, p.y() - 0.5 * dx);
      std::vector<double> top(std::size_t(W / dx), -1e9);
      for (std::size_t i = 0; i < w.particleCount(); ++i) {
        if (w.particles().material[i] != 0) continue;
        const Vec2d p = w.worldPosition(i);
        const std::size_t c = std::min(top.size() - 1, std::size_t(p.x() / dx));
        top[c] = std::max(top[c], p.y() + 0.5 * dx);
      }
      double surface = 0, n = 0;
      for (std::size_t c = 0; c < top.size(); ++c)
        if ((double(c) + 0.5) * dx < 0.2 || (double(c) + 0.5) * dx > W - 0.2) surface += top[c], n += 1;
      draught += surface / n - bottom;
      bottomMean += bottom;
      GroupState st;
      REQUIRE(w.groupState(index, st));
      tilt = std::max(tilt, std::fabs(st.angle));
      ++samples;
    }
    REQUIRE(test::allFiniteState(w));
    draught /= samples;
    bottomMean /= samples;
    const double expected = h * density / 1000;
    MESSAGE("density " << density << ": mean bottom " << bottomMean << " m, mean draught " << draught
                       << " m (Archimedes " << expected << "), largest tilt " << tilt << " rad");
    if (density < 1000) {
      CHECK(draught == doctest::Approx(expected).epsilon(0.1));
      CHECK(tilt < 0.2);
    } else {
      CHECK(bottomMean < 1.5 * dx);  // on the floor
    }
  }
}

TEST_CASE("groups: an impulse moves a rigid group as a rigid body, and bad definitions are refused") {
  SceneDef s = tankWith(2.0, 2.0, 0.02, 0.0, 1000);
  s.blocks.clear();
  s.gravity = Vec2d(0, 0);
  World w(s);
  GroupDef g;
  g.region = test::block({0.8, 0.8}, {1.2, 1.0});
  IdRange range;
  const std::uint32_t index = w.createGroup(g, &range);
  GroupState before;
  REQUIRE(w.groupState(index, before));
  CHECK(before.velocity.norm() < 1e-12);
  CHECK(before.particles == range.size());
  // I = Σ m r² of its particles, from their positions.
  std::vector<Vec2d> xs, vs;
  w.getParticles(range.ids(), xs, vs);
  double I = 0;
  for (const Vec2d& x : xs) I += before.mass / double(xs.size()) * (x - before.centre).squaredNorm();
  const double L = 0.5 * I;  // 0.5 rad/s
  CHECK(w.applyGroupImpulse(index, Vec2d(0.3 * before.mass, 0), L));
  GroupState after;
  REQUIRE(w.groupState(index, after));
  CHECK(after.velocity.x() == doctest::Approx(0.3).epsilon(1e-5));
  CHECK(std::fabs(after.velocity.y()) < 1e-6);
  CHECK(after.angularVelocity == doctest::Approx(0.5).epsilon(1e-4));
  w.getParticles(range.ids(), xs, vs);
  for (std::size_t k = 0; k < xs.size(); ++k) {  // each particle: v = V + ω × r
    const Vec2d r = xs[k] - after.centre;
    CHECK((vs[k] - Vec2d(0.3 - 0.5 * r.y(), 0.5 * r.x())).norm() < 1e-5);
  }
  w.stepFrame();  // one frame: it moves and turns as one body
  GroupState later;
  REQUIRE(w.groupState(index, later));
  MESSAGE("one frame: centre moved " << (later.centre - before.centre).x() << " m (0.3/60 = " << 0.3 / 60
                                     << "), turned " << later.angle << " rad (0.5/60 = " << 0.5 / 60 << ")");
  CHECK((later.centre - before.centre).x() == doctest::Approx(0.3 / 60).epsilon(0.05));
  CHECK(later.angle == doctest::Approx(0.5 / 60).epsilon(0.05));
  CHECK_FALSE(w.applyGroupImpulse(index + 1, Vec2d(1, 0), 0));
  GroupState none;
  CHECK_FALSE(w.groupState(index + 1, none));
  GroupDef bad = g;
  bad.stiffness = 0;
  CHECK_THROWS_AS(w.createGroup(bad), std::invalid_argument);
  bad.stiffness = 1.5;
  CHECK_THROWS_AS(w.createGroup(bad), std::invalid_argument);
  bad.stiffness = 1;
  bad.region = test::block({0.5, -0.15}, {0.7, -0.05});  // inside the floor: no particle
  CHECK_THROWS_AS(w.createGroup(bad), std::invalid_argument);
}

TEST_CASE("groups: the same bits on 1, 2 and 3 threads, and through save and load") {
  SceneDef s = tankWith(1.0, 0.8, 0.02, 0.3, 600);
  GroupDef rigid, jelly;
  rigid.region = test::block({0.2, 0.4}, {0.36, 0.5}, Vec2d(0.4, 0));
  rigid.region.material = 1;
  jelly.region = test::block({0.6, 0.4}, {0.76, 0.5});
  jelly.stiffness = 0.3;
  std::uint64_t hashes[3] = {0, 0, 0};
  for (int threads = 1; threads <= 3; ++threads) {
    World w(s, WorldOptions{threads});
    w.createGroup(rigid);
    w.createGroup(jelly);
    for (int f = 0; f < 40; ++f) w.stepFrame();
    hashes[threads - 1] = w.stateHash();
  }
  CHECK(hashes[0] == hashes[1]);
  CHECK(hashes[0] == hashes[2]);
  World a(s);
  a.createGroup(rigid);
  a.createGroup(jelly);
  for (int f = 0; f < 20; ++f) a.stepFrame();
  std::stringstream saved;
  a.save(saved);
  World b(s);
  b.load(saved);
  for (int f = 0; f < 20; ++f) {
    a.stepFrame();
    b.stepFrame();
  }
  CHECK(b.stateHash() == a.stateHash());
  CHECK(b.stateHash() == hashes[0]);
  GroupState ga, gb;
  REQUIRE(b.groupState(1, gb));
  REQUIRE(a.groupState(1, ga));
  CHECK(gb.particles == ga.particles);
}
