// What readers ask of a World (engine/src/world/queries.cpp): searches by region,
// SPH samples of the fields, energy and density statistics, neighbour pairs,
// the state hash.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <box2d/box2d.h>

#include <stdexcept>

#include "sph2d/world.hpp"
#include "support/fixture.hpp"

using namespace sph2d;

namespace {

/// validation/taylor_green.json's fully periodic 1 m box filled by one block
/// moving at `u` (every particle has a full lattice neighbourhood), with `solver`.
SceneDef periodicBlock(const std::string& solver, const Vec2d& u, double spacing = 0.04) {
  SceneDef s = test::periodicShearLayer(solver, 0, spacing);
  s.blocks = {test::block({0, 0}, {1, 1}, u)};
  return s;
}

}  // namespace

TEST_CASE("slotsInRadius and slotsInBox return exactly the slots a brute-force scan finds, in slot order") {
  SceneDef s = test::scene("tests/small_dam_break.json");
  World w(s, WorldOptions{2});
  for (int f = 0; f < 20; ++f) w.stepFrame();  // a collapsing column: an irregular set
  int nonEmpty = 0;
  for (const Vec2d& c : {Vec2d(0.2, 0.2), Vec2d(1.0, 0.1), Vec2d(0.5, 1.5), Vec2d(3.0, 2.5)}) {
    for (double r : {0.05, 0.3, 1.0}) {
      std::vector<std::size_t> brute;
      for (std::size_t i = 0; i < w.particleCount(); ++i)
        if ((w.worldPosition(i) - c).squaredNorm() <= r * r) brute.push_back(i);
      CHECK(w.slotsInRadius(c, r) == brute);
      nonEmpty += !brute.empty();
      const Vec2d lo = c - Vec2d(r, 0.5 * r), hi = c + Vec2d(0.5 * r, r);
      std::vector<std::size_t> inBox;
      for (std::size_t i = 0; i < w.particleCount(); ++i) {
        const Vec2d p = w.worldPosition(i);
        if (p.x() >= lo.x() && p.y() >= lo.y() && p.x() <= hi.x() && p.y() <= hi.y()) inBox.push_back(i);
      }
      CHECK(w.slotsInBox(lo, hi) == inBox);
    }
  }
  CHECK(nonEmpty >= 6);  // the searches found particles, not only empty sets
}

TEST_CASE("searches see every change made between steps: a moved, an added and a removed particle") {
  // The searches go through a grid of the particles built on the first search after a change;
  // a grid kept across a change would miss these.
  World w(test::scene("tests/small_dam_break.json"), WorldOptions{1});
  for (int f = 0; f < 5; ++f) w.stepFrame();
  const Vec2d spot(3.5, 2.5);                    // empty air, far from the water
  REQUIRE(w.slotsInRadius(spot, 0.05).empty());  // builds the grid
  const std::uint32_t id = w.particles().id[0];
  REQUIRE(w.setParticle(id, spot, Vec2d(0, 0)));
  std::vector<std::size_t> found = w.slotsInRadius(spot, 0.05);
  REQUIRE(found.size() == 1);
  CHECK(w.particles().id[found[0]] == id);
  const IdRange added = w.addParticles({spot + Vec2d(0.2, 0)});
  REQUIRE(added.size() == 1);
  CHECK(w.slotsInBox(spot + Vec2d(0.1, -0.1), spot + Vec2d(0.3, 0.1)).size() == 1);
  CHECK(w.removeParticles({id}) == std::vector<std::uint32_t>{id});
  CHECK(w.slotsInRadius(spot, 0.05).empty());
  CHECK(w.slotsInRadius(spot, 0.25).size() == 1);  // the added one
}

TEST_CASE(
    "shapes: slotsInShape matches b2Shape::TestPoint over every particle, and addShape and removeParticlesInShape fill and empty a rotated box") {
  SceneDef s = test::tank("wcsph", 2, 2, 0.02);
  s.gravity = Vec2d(0, 0);
  World w(s, WorldOptions{2});
  b2PolygonShape box;
  box.SetAsBox(0.3f, 0.15f, b2Vec2(0, 0), 0.6f);  // 0.6 m × 0.3 m, turned 0.6 rad
  const b2Transform xf(b2Vec2(1.0f, 1.0f), b2Rot(0.0f));
  const std::size_t n = w.addShape(box, xf, Vec2d(0.1, 0)).count;
  MESSAGE("a 0.18 m^2 box at spacing 0.02: " << n << " particles");
  CHECK(std::abs(double(n) - 0.18 / (0.02 * 0.02)) < 0.05 * 450);
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const Vec2d p = w.worldPosition(i);
    const b2Vec2 q(float(p.x()), float(p.y()));
    if (!box.TestPoint(xf, b2Vec2(q.x, q.y)) && !box.TestPoint(xf, b2Vec2(q.x + 1e-5f, q.y)) &&
        !box.TestPoint(xf, b2Vec2(q.x - 1e-5f, q.y)))
      FAIL("a particle of the box outside it at " << p);
  }
  b2CircleShape disc;
  disc.m_p = b2Vec2(0.1f, 0.05f);
  disc.m_radius = 0.2f;
  for (const b2Shape* shape : {static_cast<const b2Shape*>(&box), static_cast<const b2Shape*>(&disc)}) {
    std::vector<std::size_t> brute;
    for (std::size_t i = 0; i < w.particleCount(); ++i) {
      const Vec2d p = w.worldPosition(i);
      if (shape->TestPoint(xf, b2Vec2(float(p.x()), float(p.y())))) brute.push_back(i);
    }
    CHECK(!brute.empty());
    CHECK(w.slotsInShape(*shape, xf) == brute);
  }
  std::vector<std::uint32_t> inDisc;
  for (const std::size_t i : w.slotsInShape(disc, xf)) inDisc.push_back(w.particles().id[i]);
  std::sort(inDisc.begin(), inDisc.end());
  CHECK(w.removeParticlesInShape(disc, xf) == inDisc);  // exactly those ids, in increasing order
  CHECK(w.slotsInShape(disc, xf).empty());
  CHECK(w.particleCount() == n - inDisc.size());
  b2EdgeShape edge;
  edge.SetTwoSided(b2Vec2(0, 0), b2Vec2(1, 0));
  CHECK_THROWS_AS(w.addShape(edge, xf), std::invalid_argument);
  CHECK(w.slotsInShape(edge, xf).empty());
}

TEST_CASE(
    "sampleAt inside a uniform moving block returns rho0 and the block's velocity, with weight 1, and nothing far from it") {
  const Vec2d u(0.7, -0.3);
  World w(periodicBlock("wcsph", u), WorldOptions{1});
  for (const Vec2d& p : {Vec2d(0.5, 0.5), Vec2d(0.13, 0.71), Vec2d(0.021, 0.978)}) {
    CAPTURE(p.x());
    CAPTURE(p.y());
    const World::FieldSample f = w.sampleAt(p);
    CHECK(f.density == doctest::Approx(1000.0).epsilon(1e-5));
    CHECK(f.velocity.x() == doctest::Approx(u.x()).epsilon(1e-6));
    CHECK(f.velocity.y() == doctest::Approx(u.y()).epsilon(1e-6));
    // Σ V W of a full lattice under Wendland C2 at R = 2.5 dx is 1 to within the
    // kernel's lattice error; sampleAt does not wrap, so near a seam only one side counts.
    if (p.x() > 0.1 && p.y() < 0.9)
      CHECK(f.weight == doctest::Approx(1.0).epsilon(0.02));
    else
      CHECK(f.weight < 0.8);
  }
  // Beyond the support of every particle: no fluid there.
  const World::FieldSample far = w.sampleAt(Vec2d(5, 5));
  CHECK(far.weight == 0);
  CHECK(far.density == 0);
  CHECK(far.velocity == Vec2d(0, 0));
}

TEST_CASE(
    "kineticEnergy is half m v squared summed, densityStats the mean and largest compression and the mean density") {
  const Vec2d u(0.7, -0.3);
  World w(periodicBlock("wcsph", u), WorldOptions{1});
  const double N = double(w.particleCount()), m = double(w.particleMass());
  REQUIRE(N == 625);
  // Every particle moves at u: E = ½ N m |u|² (float velocities: to 1e-6).
  CHECK(w.kineticEnergy() == doctest::Approx(0.5 * N * m * u.squaredNorm()).epsilon(1e-6));
  const DensityStats rest = w.densityStats();  // a full lattice: ρ0 everywhere (test_world.cpp)
  CHECK(rest.meanError <= 1e-5);
  CHECK(rest.maxError <= 1e-5);
  // A second block on the lower half of the box, every new particle on top of an old one:
  // 2 ρ0 there, ρ0 above, a row or two between.
  const std::size_t added = w.addBlock(test::block({0, 0}, {1, 0.5})).count;
  sph2d::bench::stepSubstep(w);  // the densities of the new state
  const DensityStats d = w.densityStats();
  const double doubled = 2.0 * double(added) / double(w.particleCount());  // the share of particles in the overlap
  MESSAGE(added << " added; mean compression " << d.meanError << ", largest " << d.maxError << ", mean density "
                << d.meanDensity << " (" << doubled << " of the particles in the overlap)");
  CHECK(d.maxError == doctest::Approx(1.0).epsilon(0.01));      // 2 ρ0: compression 1
  CHECK(d.meanError == doctest::Approx(doubled).epsilon(0.1));  // ≈ 1 × the overlap's share
  CHECK(d.meanDensity == doctest::Approx(1000.0 * (1 + doubled)).epsilon(0.1));
}

TEST_CASE("neighbourPairs counts each particle's 20 lattice neighbours within 2.5 dx, from both sides") {
  // On a full square lattice the points within R = 2.5 dx of a particle are the 20
  // with i² + j² ≤ 5 (i² + j² = 6.25 has no integer solution; √8 = 2.83 dx is out).
  World w(periodicBlock("wcsph", Vec2d(0, 0)), WorldOptions{2});
  sph2d::bench::stepSubstep(w);
  CHECK(w.counters().neighbourPairs == 20 * w.particleCount());
}

TEST_CASE("the state hash is the same for the same state and changes with any particle's motion or removal") {
  const SceneDef s = test::scene("tests/small_dam_break.json");
  World a(s, WorldOptions{1}), b(s, WorldOptions{3});
  CHECK(a.stateHash() == b.stateHash());
  sph2d::bench::stepSubstep(a);
  CHECK(a.stateHash() != b.stateHash());  // one substep moved the particles
  sph2d::bench::stepSubstep(b);
  CHECK(a.stateHash() == b.stateHash());
  // Removing one particle changes it, and removing the same one in the other world agrees again.
  const Vec2d p = a.worldPosition(0);
  CHECK(a.removeParticlesInBox(p, p).size() == 1);
  CHECK(a.stateHash() != b.stateHash());
  CHECK(b.removeParticlesInBox(p, p).size() == 1);
  CHECK(a.stateHash() == b.stateHash());
}

TEST_CASE(
    "queries: idsTouching finds the particles within one spacing of a fixture, and forEachContact visits the fixtures the water touches") {
  SceneDef s = test::tank("game", 1.0, 1.0, 0.02);
  s.blocks.push_back(test::block({0, 0}, {1, 0.4}));
  BodyDef pole;  // a submerged circle, r = 0.06 m, at (0.5, 0.2)
  ShapeDef c;
  c.type = ShapeDef::Type::Circle;
  c.center = Vec2d(0.5, 0.2);
  c.radius = 0.06;
  pole.fixtures.push_back(c);
  s.bodies.push_back(pole);
  World w(s, WorldOptions{2});
  for (int f = 0; f < 30; ++f) w.stepFrame();
  const double dx = double(w.spacing());
  // The fixtures by where they are: floor, ceiling, the pole.
  const b2Fixture *floor = nullptr, *ceiling = nullptr, *circle = nullptr;
  for (const b2Body* b = w.box2d().GetBodyList(); b; b = b->GetNext())
    for (const b2Fixture* fx = b->GetFixtureList(); fx; fx = fx->GetNext()) {
      const b2AABB a = fx->GetAABB(0);
      if (fx->GetShape()->GetType() == b2Shape::e_circle)
        circle = fx;
      else if (a.upperBound.y < 0.02f)
        floor = fx;  // AABBs hold the polygon skin (0.01 m)
      else if (a.lowerBound.y > 0.98f)
        ceiling = fx;
    }
  REQUIRE(floor);
  REQUIRE(ceiling);
  REQUIRE(circle);
  // Against a scan of every particle with the exact distance to each shape.
  auto scan = [&](auto dist) {
    std::vector<std::uint32_t> ids;
    for (std::size_t i = 0; i < w.particleCount(); ++i)
      if (dist(w.worldPosition(i)) <= dx) ids.push_back(w.particles().id[i]);
    return ids;
  };
  const std::vector<std::uint32_t> onFloor = w.idsTouching(*floor);
  const std::vector<std::uint32_t> floorScan = scan([](const Vec2d& p) { return std::max(0.0, p.y()); });
  const std::vector<std::uint32_t> onPole = w.idsTouching(*circle);
  const std::vector<std::uint32_t> poleScan =
      scan([](const Vec2d& p) { return std::max(0.0, (p - Vec2d(0.5, 0.2)).norm() - 0.06); });
  MESSAGE(onFloor.size() << " particles on the floor, " << onPole.size() << " around the pole");
  CHECK(onFloor == floorScan);
  CHECK(onPole == poleScan);
  CHECK(onFloor.size() >= std::size_t(0.9 / dx));                // the whole bottom layer
  CHECK(onPole.size() >= std::size_t(2 * 3.14159 * 0.06 / dx));  // a ring around it
  CHECK(w.idsTouching(*ceiling).empty());
  // forEachContact: the floor, the side walls and the pole, never the ceiling; the same lists.
  int visited = 0;
  bool sawCeiling = false, sawPole = false;
  w.forEachContact([&](const b2Fixture& fx, const std::vector<std::uint32_t>& ids) {
    ++visited;
    sawCeiling = sawCeiling || &fx == ceiling;
    if (&fx == circle) {
      sawPole = true;
      CHECK(ids == onPole);
    }
    CHECK_FALSE(ids.empty());
  });
  CHECK(visited == 4);
  CHECK(sawPole);
  CHECK_FALSE(sawCeiling);
}

TEST_CASE(
    "queries: with contact tracking a particle that passed a fixture during the step is reported, without it only those touching at its end") {
  // One particle shot at 8 m/s along a line 1 cm above a circle (r = 0.05 m at (0.5, 0.3)),
  // static or a kinematic body at rest: within one frame (wcsph: many substeps) it passes the
  // circle and ends 5 cm beyond it. The snapshot at the frame's end misses it; the contacts
  // stage, which looks at the end of every substep, records it, for that step only.
  for (const bool kinematic : {false, true}) {
    INFO(std::string(kinematic ? "kinematic" : "static"));
    auto run = [kinematic](bool tracking, std::vector<std::uint32_t>& touching, std::vector<std::uint32_t>& after,
                           double& endGap, std::uint32_t& id, int& visits, bool& stagePresent) {
      SceneDef s = test::tank("wcsph", 1.0, 1.0, 0.02);
      BodyDef pole;
      ShapeDef c;
      c.type = ShapeDef::Type::Circle;
      c.center = Vec2d(0.5, 0.3);
      c.radius = 0.05;
      if (kinematic) {
        pole.type = BodyDef::Type::Kinematic;
        pole.position = c.center;
        c.center = Vec2d(0, 0);
      }
      pole.fixtures.push_back(c);
      s.bodies.push_back(pole);
      World w(s, WorldOptions{2});
      w.setContactTracking(tracking);
      CHECK(w.contactTracking() == tracking);
      const auto names = w.stages();
      stagePresent = std::find(names.begin(), names.end(), "contacts") != names.end();
      const b2Fixture* circle = nullptr;
      for (const b2Body* b = w.box2d().GetBodyList(); b; b = b->GetNext())
        for (const b2Fixture* fx = b->GetFixtureList(); fx; fx = fx->GetNext())
          if (fx->GetShape()->GetType() == b2Shape::e_circle) circle = fx;
      REQUIRE(circle);
      const auto ids = w.addParticles({Vec2d(0.45, 0.36)}, {Vec2d(8, 0)});
      REQUIRE(ids.size() == 1);
      id = ids[0];
      w.stepFrame();
      REQUIRE(w.counters().substeps > 5);
      endGap = (w.worldPosition(0) - Vec2d(0.5, 0.3)).norm() - 0.05;
      touching = w.idsTouching(*circle);
      visits = 0;
      w.forEachContact([&](const b2Fixture& fx, const std::vector<std::uint32_t>& l) {
        if (&fx == circle) visits += l == touching;
      });
      w.stepFrame();  // on, far from the circle: this step's record is empty
      after = w.idsTouching(*circle);
    };
    std::vector<std::uint32_t> offNow, offAfter, onNow, onAfter;
    double gapOff = 0, gapOn = 0;
    std::uint32_t idOff = 0, idOn = 0;
    int visitsOff = 0, visitsOn = 0;
    bool stageOff = true, stageOn = false;
    run(false, offNow, offAfter, gapOff, idOff, visitsOff, stageOff);
    run(true, onNow, onAfter, gapOn, idOn, visitsOn, stageOn);
    MESSAGE("the particle ends the frame " << gapOn << " m from the circle");
    CHECK(gapOff == gapOn);  // tracking changes nothing of the motion
    CHECK(gapOn > 0.04);     // it passed and left (the reach is one spacing, 0.02 m)
    CHECK(offNow.empty());   // the snapshot misses it
    CHECK(visitsOff == 0);
    CHECK(onNow == std::vector<std::uint32_t>{idOn});  // the stage saw it pass
    CHECK(visitsOn == 1);
    CHECK(onAfter.empty());
    CHECK_FALSE(stageOff);
    CHECK(stageOn);
  }
}

TEST_CASE(
    "queries: idsTouching a kinematic box measures from where the fluid meets it: the skin for the game solver, the fixture for wcsph") {
  // A 0.3 m × 0.1 m kinematic box at rest in the water. The game solver meets a moving polygon
  // at Box2D's skin (1 cm out), wcsph at the fixture itself (its moving samples stand for it):
  // the particles touching it are those within one spacing of that surface.
  for (const char* solver : {"game", "wcsph"}) {
    INFO(solver);
    SceneDef s = test::tank(solver, 1.0, 1.0, 0.02);
    s.blocks.push_back(test::block({0, 0}, {1, 0.5}));
    BodyDef box;
    box.type = BodyDef::Type::Kinematic;
    box.position = Vec2d(0.5, 0.25);
    box.fixtures.push_back(test::boxShape({0, 0}, {0.15, 0.05}));
    s.bodies.push_back(box);
    World w(s, WorldOptions{2});
    for (int f = 0; f < 10; ++f) w.stepFrame();
    const double dx = double(w.spacing()), skin = std::string(solver) == "game" ? double(b2_polygonRadius) : 0.0;
    const b2Fixture* fixture = nullptr;
    for (const b2Body* b = w.box2d().GetBodyList(); b; b = b->GetNext())
      if (b->GetType() == b2_kinematicBody) fixture = b->GetFixtureList();
    REQUIRE(fixture);
    // Against a scan: the distance from the box's fixture (0.3 × 0.1 at (0.5, 0.25)), less the skin.
    std::vector<std::uint32_t> scan;
    for (std::size_t i = 0; i < w.particleCount(); ++i) {
      const Vec2d p = w.worldPosition(i);
      const double ox = std::max(0.0, std::fabs(p.x() - 0.5) - 0.15),
                   oy = std::max(0.0, std::fabs(p.y() - 0.25) - 0.05);
      if (std::sqrt(ox * ox + oy * oy) - skin <= dx) scan.push_back(w.particles().id[i]);
    }
    const std::vector<std::uint32_t> touching = w.idsTouching(*fixture);
    MESSAGE(solver << ": " << touching.size() << " particles touch the box");
    CHECK(touching.size() >= std::size_t(0.6 / dx));  // a layer around it
    CHECK(touching == scan);
  }
}
