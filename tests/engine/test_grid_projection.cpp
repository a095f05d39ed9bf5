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
  std::vector<double> sum(30, 0.0);
  std::vector<int> count(30, 0);
  double vmaxWall = 0;
  for (int f = 0; f < 90; ++f) {
    w.stepFrame();
    if (f < 60) continue;
    for (std::size_t i = 0; i < w.particleCount(); ++i) {
      const Vec2d q = w.worldPosition(i);
      const int band = int(std::lround(q.y() / 0.05));
      if (std::fabs(q.x() - 1.0) < 0.2 && band >= 0 && band < 30) {
        sum[std::size_t(band)] += w.particles().p[i];
        ++count[std::size_t(band)];
      }
      if (q.x() < 2 * dx || q.x() > 2 - 2 * dx) vmaxWall = std::max(vmaxWall, double(w.particles().v[i].norm()));
    }
  }
  REQUIRE(test::allFiniteState(w));
  double top = 0, H = 0;
  int n = 0;
  for (std::size_t i = 0; i < w.particleCount(); ++i) top = std::max(top, w.worldPosition(i).y());
  for (std::size_t i = 0; i < w.particleCount(); ++i)
    if (w.worldPosition(i).y() > top - dx && std::fabs(w.worldPosition(i).x() - 1) < 0.5) {
      H += w.worldPosition(i).y();
      ++n;
    }
  H = H / n + 0.5 * dx;
  int checked = 0;
  double worst = 0;
  for (int band = 1; 0.05 * band < H - 3 * dx; ++band) {  // below the top layer
    REQUIRE(count[std::size_t(band)] > 0);
    const double y = 0.05 * band, p = sum[std::size_t(band)] / count[std::size_t(band)];
    worst = std::max(worst, std::fabs(p - rho0 * g * (H - y)) / (rho0 * g * H));
    ++checked;
  }
  MESSAGE("surface at " << H << " m, worst pressure error " << 100 * worst << " % of rho0 g H over " << checked
                        << " bands; fastest particle beside the side walls " << vmaxWall << " m/s");
  CHECK(checked >= 15);
  CHECK(std::fabs(H - 1.0) < 2 * dx);  // incompressible: the surface where it started
  CHECK(worst <= 0.10);
  // At rest beside the walls: 0.002 m/s measured; 1.5 m/s without the extrapolation.
  CHECK(vmaxWall < 0.05);
}
