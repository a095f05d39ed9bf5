// The wcsph solver (Tait equation of state, Becker & Teschner 2007): hydrostatics
// against Box2D walls, momentum, the Taylor–Green vortex.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "bench/validation.hpp"
#include "sph2d/world.hpp"
#include "support/fixture.hpp"
#include "support/taylor_green.hpp"

using namespace sph2d;
using test::boxShape;

TEST_CASE("hydrostatic tank 2 m x 1 m (wcsph): linear pressure, no gap at the floor, density within 1 %") {
  SceneDef s = test::wallScene(0.025);
  BodyDef b;
  b.fixtures = {boxShape({1, -0.2}, {1.4, 0.2}), boxShape({-0.2, 0.8}, {0.2, 1.0}), boxShape({2.2, 0.8}, {0.2, 1.0})};
  s.bodies.push_back(b);
  FluidBlockDef blk;
  blk.min = Vec2d(0, 0);
  blk.max = Vec2d(2, 1);
  s.blocks.push_back(blk);
  s.solver.params["alpha"] = 0.1;
  World w(s, WorldOptions{2});
  // Settle for 1 s, then probe the pressure at x = 1 m in 5 cm slabs, averaged
  // over the last 0.5 s (a probe averages the column's slow sloshing out).
  const double rho0 = 1000, g = 9.81, dx = s.solver.spacing;
  validation::PressureProfile profile;
  for (int f = 0; f < 90; ++f) {
    w.stepFrame();
    if (f < 60) continue;
    profile.add(w);
  }
  REQUIRE(test::allFiniteState(w));
  const double H = validation::PressureProfile::surface(w, 1.0, dx);  // free surface
  int checked = 0, empty = 0;
  const double worst = profile.worstError(H, rho0, g, dx, 1.0, checked, empty);
  CHECK(empty == 0);
  MESSAGE("surface at " << H << " m, worst pressure error " << 100 * worst << " % of rho0 g H over " << checked
                        << " bands");
  CHECK(checked >= 15);
  CHECK(worst <= 0.05);
  double minY = 1e9, maxBottom = 0;
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const Vec2d q = w.worldPosition(i);
    minY = std::min(minY, q.y());
  }
  // The bottom row: particles below one spacing; each must be within [dx/3, dx] of the floor.
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const Vec2d q = w.worldPosition(i);
    if (q.y() < 0.8 * dx && q.x() > 0.2 && q.x() < 1.8) maxBottom = std::max(maxBottom, q.y());
  }
  MESSAGE("lowest particle " << minY / dx << " dx above the floor, bottom row up to " << maxBottom / dx << " dx");
  CHECK(minY >= dx / 3);
  CHECK(maxBottom <= dx);
  CHECK(std::fabs(w.densityStats().meanDensity - rho0) / rho0 <= 0.01);
}

TEST_CASE("wcsph: its pressure force conserves linear momentum to rounding (no walls, no gravity)") {
  SceneDef s = test::freeMovingBlock();
  const test::MomentumRun r = test::momentumOver(s, 30);
  MESSAGE("pressure: momentum change " << r.change << " of " << r.scale);
  CHECK(r.change <= 1e-5 * r.scale);
  CHECK(r.finite);
}

TEST_CASE("Taylor-Green vortex at Re = 100 (wcsph, 2500 particles): the decay rate within 10 % of -8 pi^2 / Re") {
  test::taylorGreenRe100("wcsph");
}

TEST_CASE("wcsph: a resting column's pressure is rho0 g (H - y) at every depth (within 3 % of rho0 g H)") {
  // The Tait pressure with the lattice-renormalised gradient (wcsph.cpp) and
  // mirrored wall pressure: the hydrostatic profile down to the floor row. The
  // resting column (0.6 m, dx = 0.02) with wcsph; probed at x = 0.3 ± 0.2 m in
  // 5 cm bands over the second second. Measured: every band within 1.2 % of
  // rho0 g H, slope 0.997 × rho0 g, zero 1 mm above the surface.
  SceneDef s = test::scene("tests/resting_column.json");
  s.solver.type = "wcsph";
  s.solver.params.clear();
  World w(s, WorldOptions{2});
  test::PressureProbe probe{0.3, 0.2, 0.05};
  for (int f = 0; f < 120; ++f) {
    w.stepFrame();
    if (f >= 60) probe.add(w);
  }
  REQUIRE(test::allFiniteState(w));
  const double rho0 = 1000, g = 9.81, dx = s.solver.spacing, H = test::surfaceHeight(w, 0.3, 0.2);
  const auto bands = probe.profile(0, H - 3 * dx);
  REQUIRE(bands.size() >= 10);
  double worst = 0;
  for (const auto& [y, p] : bands) worst = std::max(worst, std::fabs(p - rho0 * g * (H - y)) / (rho0 * g * H));
  const test::Line l = test::fitLine(bands);
  MESSAGE("surface " << H << " m; worst band " << 100 * worst << " % of rho0 g H; dp/dy = " << l.slope / (-rho0 * g)
                     << " × (−rho0 g), p = 0 at " << l.zero() << " m");
  CHECK(worst <= 0.03);
  CHECK(l.slope / (-rho0 * g) == doctest::Approx(1.0).epsilon(0.03));
  CHECK(std::fabs(l.zero() - H) < dx);
}
