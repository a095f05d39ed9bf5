// The coarse-grid pressure projection (engine/src/grid_projection.cpp), through
// the game solver that runs it: its κ = p/ρ0 is the hydrostatic pressure of a
// resting tank, and the velocity change it gives particles next to walls is the
// full one (the extrapolation into solid faces; without it the water beside a
// wall sank, was pushed back up by the constraint and pumped energy in).
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "sph2d/world.hpp"
#include "support/fixture.hpp"
#include "validation.hpp"

using namespace sph2d;
using test::boxShape;

TEST_CASE("grid projection: a resting 2 m x 1 m tank reports a hydrostatic pressure, and stays at rest beside the walls") {
  SceneDef s = test::wallScene(0.025, "game");
  BodyDef b;
  b.fixtures = {boxShape({1, -0.2}, {1.4, 0.2}), boxShape({-0.2, 0.8}, {0.2, 1.0}), boxShape({2.2, 0.8}, {0.2, 1.0})};
  s.bodies.push_back(b);
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
