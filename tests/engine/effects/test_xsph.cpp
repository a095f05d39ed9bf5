// XSPH velocity smoothing (engine/src/effects/xsph.cpp).
#include <doctest/doctest.h>

#include <string>

#include "sph2d/world.hpp"
#include "support/fixture.hpp"

using namespace sph2d;

TEST_CASE(
    "xsph alone smooths a shear layer: less velocity variance than without it, and a smaller velocity difference") {
  // dfsph, U = 0.1 m/s, XSPH's default c = 0.05; 1 s. Measured: variance 1.25 U²
  // with XSPH, 3.33 U² without (the sliding layers' noise); the halves' velocity
  // difference 0.887 and 1.007 of the start.
  const double U = 0.1;
  double variance[2], difference[2];
  for (int on = 0; on < 2; ++on) {
    SceneDef s = test::periodicShearLayer("dfsph", U, 0.04);
    s.effects.xsph = on == 1;
    World w(s, WorldOptions{2});
    std::uint32_t firstUpper = 0;
    for (std::size_t i = 0; i < w.particleCount(); ++i) firstUpper += w.worldPosition(i).y() < 0.5;
    for (int f = 0; f < 60; ++f) w.stepFrame();
    REQUIRE(test::allFiniteState(w));
    variance[on] = test::velocityVariance(w) / (U * U);
    difference[on] = test::layerVelocityDifference(w, firstUpper) / (2 * U);
    MESSAGE(std::string(on ? "with" : "without") << " xsph: velocity variance " << variance[on]
                                                 << " U², velocity difference " << difference[on] << " of the start");
  }
  CHECK(variance[1] < 0.5 * variance[0]);
  CHECK(difference[1] < 0.95);
  CHECK(difference[1] < difference[0] - 0.05);
}

TEST_CASE("xsph conserves linear momentum to rounding (no walls, no gravity)") {
  SceneDef s = test::freeMovingBlock();
  s.effects.xsph = true;
  const test::MomentumRun r = test::momentumOver(s, 30);
  MESSAGE("xsph: momentum change " << r.change << " of " << r.scale);
  CHECK(r.change <= 1e-5 * r.scale);
  CHECK(r.finite);
}
