// The coarse-grid pressure projection (engine/src/grid_projection.cpp), through
// the game solver that runs it: its κ = p/ρ0 is the hydrostatic pressure of a
// resting tank, and the velocity change it gives particles next to walls is the
// full one (the extrapolation into solid faces; without it the water beside a
// wall sank, was pushed back up by the constraint and pumped energy in).
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include <box2d/box2d.h>

#include "sph2d/world.hpp"
#include "support/fixture.hpp"
#include "validation.hpp"

using namespace sph2d;
using test::boxShape;

TEST_CASE("grid projection: a resting 2 m x 1 m tank reports a hydrostatic pressure, and stays at rest beside the walls") {
  SceneDef s = test::wallScene(0.025, "game");
  s.bodies.push_back(test::tankWalls(2, 1.6));
  FluidBlockDef blk;
  blk.min = Vec2d(0, 0);
  blk.max = Vec2d(2, 1);
  s.blocks.push_back(blk);
  World w(s, WorldOptions{2});
  // Settle for 1 s, then average the pressure in 5 cm slabs around x = 1 m over 0.5 s.
  const double rho0 = 1000, g = 9.81, dx = s.solver.spacing;
  validation::PressureProfile profile;
  double vmaxWall = 0;
  for (int f = 0; f < 90; ++f) {
    w.stepFrame();
    if (f < 60) continue;
    profile.add(w);
    for (std::size_t i = 0; i < w.particleCount(); ++i) {
      const double x = w.worldPosition(i).x();
      if (x < 2 * dx || x > 2 - 2 * dx) vmaxWall = std::max(vmaxWall, double(w.particles().v[i].norm()));
    }
  }
  REQUIRE(test::allFiniteState(w));
  const double H = validation::PressureProfile::surface(w, 1.0, dx);
  int checked = 0, empty = 0;
  const double worst = profile.worstError(H, rho0, g, dx, 1.0, checked, empty);
  CHECK(empty == 0);
  MESSAGE("surface at " << H << " m, worst pressure error " << 100 * worst << " % of rho0 g H over " << checked
                        << " bands; fastest particle beside the side walls " << vmaxWall << " m/s");
  CHECK(checked >= 15);
  CHECK(std::fabs(H - 1.0) < 2 * dx);  // incompressible: the surface where it started
  CHECK(worst <= 0.10);
  // At rest beside the walls: 0.002 m/s measured; 1.5 m/s without the extrapolation.
  CHECK(vmaxWall < 0.05);
}

TEST_CASE("grid projection: a wall the game replaces (same body, a new fixture in the old one's memory) stops holding water") {
  // A gate at x = 0.5 m holds a column on the left of a 2 m tank; the game destroys it and
  // creates a small box under the floor on the same body (Box2D's allocator hands the new
  // fixture the gate's block), then refreshes the boundaries. The water must flow as if the
  // gate had never been there: the grid's solid cells and closed faces are read again.
  auto build = [](bool gate) {
    SceneDef s = test::wallScene(0.025, "game");
    BodyDef b = test::tankWalls(2, 1.6);
    if (gate) b.fixtures.push_back(boxShape({0.55, 0.5}, {0.05, 0.5}));
    s.bodies.push_back(b);
    FluidBlockDef blk;
    blk.min = Vec2d(0, 0);
    blk.max = Vec2d(0.5, 0.8);
    s.blocks.push_back(blk);
    return s;
  };
  auto rightOf = [](const World& w) {
    int n = 0;
    for (std::size_t i = 0; i < w.particleCount(); ++i) n += w.worldPosition(i).x() > 0.6;
    return n;
  };
  World gated(build(true), WorldOptions{2});
  for (int f = 0; f < 20; ++f) gated.stepFrame();  // the projection caches the gate
  REQUIRE(rightOf(gated) == 0);
  b2Body* body = gated.box2d().GetBodyList();
  b2Fixture* gate = nullptr;
  for (b2Fixture* fx = body->GetFixtureList(); fx; fx = fx->GetNext()) {
    const b2AABB bb = fx->GetAABB(0);
    if (bb.lowerBound.x > 0.45f && bb.upperBound.x < 0.65f) gate = fx;
  }
  REQUIRE(gate != nullptr);
  const void* old = gate;
  body->DestroyFixture(gate);
  b2PolygonShape small;
  small.SetAsBox(0.05f, 0.05f, b2Vec2(1.0f, -0.1f), 0);  // inside the floor: no effect on the water
  const b2Fixture* replaced = body->CreateFixture(&small, 0);
  gated.refreshBoundaries();
  // A 0.8 m column released at x = 0.5 m: its front moves at ~2 sqrt(g h) ≈ 5.6 m/s, so a
  // quarter of the water is past x = 0.6 m within 0.5 s.
  for (int f = 0; f < 30; ++f) gated.stepFrame();
  MESSAGE("new fixture at the old one's address: " << (static_cast<const void*>(replaced) == old) << "; particles past the gate "
                                                   << rightOf(gated) << " of " << gated.particleCount());
  CHECK(rightOf(gated) > int(gated.particleCount() / 4));
}
