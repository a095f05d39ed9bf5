// The muller2003 solver (Müller, Charypar & Gross 2003; the scenes' default):
// a resting column against Box2D walls, the dam break, determinism.
#include <doctest/doctest.h>

#include <cmath>

#include "sph2d/world.hpp"
#include "support/fixture.hpp"

using namespace sph2d;
using test::frontX;
using test::outside;

TEST_CASE("muller2003: a resting column settles: density within 5 % of rho0, its motion decays and stays small") {
  // muller2003 (the scene's default solver) with its single-term walls: the
  // column breathes as its wall rows settle (mean speed peaks near 0.09 m/s at
  // t = 0.7 s and falls to 0.02–0.05 m/s by 2 s, measured), so the check is on
  // the mean speed averaged over each second rather than on one instant.
  const SceneDef s = test::scene("tests/resting_column.json");
  World w(s, WorldOptions{2});
  const double H = 0.6, g = 9.81;
  double first = 0, second = 0;
  for (int f = 0; f < 120; ++f) {  // 2 s
    w.stepFrame();
    (f < 60 ? first : second) += test::meanSpeed(w) / 60;
  }
  REQUIRE(test::allFiniteState(w));
  const DensityStats d = w.densityStats();
  MESSAGE("mean density " << d.meanDensity << ", mean compression " << d.meanError);
  CHECK(std::fabs(d.meanDensity - 1000.0) / 1000.0 < 0.05);
  MESSAGE("mean speed " << first << " m/s over the first second, " << second
                        << " m/s over the second, against sqrt(gH) = " << std::sqrt(g * H));
  CHECK(second < first);                     // it settles
  CHECK(second < 0.025 * std::sqrt(g * H));  // to a small fraction of the collapse speed
  CHECK(outside(w, 0, 0, 0.6, 1.3) == 0);
}

TEST_CASE("muller2003: the dam break runs 1 s: no NaN, nothing leaves the tank, the front moves right") {
  const SceneDef s = test::scene("tests/small_dam_break.json");
  World w(s, WorldOptions{2});
  const double front0 = frontX(w);
  CHECK(w.kineticEnergy() == 0);
  const double sumY0 = test::sumY(w);
  const std::size_t n0 = w.particleCount();
  for (int f = 0; f < 60; ++f) w.stepFrame();
  CHECK(w.time() == doctest::Approx(1.0).epsilon(1e-6));
  REQUIRE(test::allFiniteState(w));
  CHECK(w.particleCount() == n0);
  CHECK(outside(w, 0, 0, 4, 3) == 0);
  const double front = frontX(w);
  MESSAGE("front moved from " << front0 << " to " << front << " m");
  // Shallow-water theory puts the front speed at 2·sqrt(g·2) ≈ 8.9 m/s; the tank is 4 m long.
  CHECK(front > front0 + 1.5);
  // Kinetic energy is bounded by the potential energy released (viscosity and walls only remove energy).
  const double released = double(w.particleMass()) * 9.81 * (sumY0 - test::sumY(w));
  MESSAGE("kinetic " << w.kineticEnergy() << " J/m, potential released " << released << " J/m");
  CHECK(released > 0);
  CHECK(w.kineticEnergy() <= released);
}

TEST_CASE("muller2003: the state hash is the same for 1, 2 and 3 threads and for two runs") {
  const SceneDef s = test::scene("tests/small_dam_break.json");
  std::uint64_t hashes[4];
  const int threads[4] = {1, 2, 3, 2};
  for (int k = 0; k < 4; ++k) {
    World w(s, WorldOptions{threads[k]});
    for (int f = 0; f < 20; ++f) w.stepFrame();
    hashes[k] = w.stateHash();
  }
  CHECK(hashes[0] == hashes[1]);
  CHECK(hashes[0] == hashes[2]);
  CHECK(hashes[1] == hashes[3]);
  // And the hash does see the state: one more frame changes it.
  World w(s, WorldOptions{1});
  for (int f = 0; f < 21; ++f) w.stepFrame();
  CHECK(w.stateHash() != hashes[0]);
}

TEST_CASE(
    "muller2003: a resting column's pressure grows by 2 rho0 g per metre (within 20 %) and vanishes at its surface") {
  // p = c²(ρ − ρ0) and the symmetric force m(p_i + p_j)/(2ρ_j)∇W recover ∇p/2
  // (muller2003.cpp), so at rest p = 2ρ0g(H − y), not ρ0g(H − y). Probed at x =
  // 0.3 ± 0.2 m in 5 cm bands over the second second, above the two rows at the
  // floor (the single-term walls leave them compressed: 2× and 1.4× the profile).
  // Measured: slope 1.12 × 2ρ0g, zero 1 mm above the surface.
  const SceneDef s = test::scene("tests/resting_column.json");
  REQUIRE(s.solver.type == "muller2003");
  World w(s, WorldOptions{2});
  test::PressureProbe probe{0.3, 0.2, 0.05};
  for (int f = 0; f < 120; ++f) {
    w.stepFrame();
    if (f >= 60) probe.add(w);
  }
  REQUIRE(test::allFiniteState(w));
  const double rho0 = 1000, g = 9.81, dx = s.solver.spacing, H = test::surfaceHeight(w, 0.3, 0.2);
  const auto bands = probe.profile(0.1, H - 3 * dx);
  REQUIRE(bands.size() >= 7);
  const test::Line l = test::fitLine(bands);
  MESSAGE("surface " << H << " m; over " << bands.size() << " bands dp/dy = " << l.slope
                     << " Pa/m = " << l.slope / (-2 * rho0 * g) << " × (−2 rho0 g), p = 0 at " << l.zero() << " m");
  CHECK(l.slope / (-2 * rho0 * g) == doctest::Approx(1.0).epsilon(0.2));
  CHECK(std::fabs(l.zero() - H) < 2 * dx);
}
