// The pbf solver (Macklin & Müller 2013) at frame-sized substeps: a resting
// tank, a deep tank at any max_move, the small dam break, determinism across thread counts.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "sph2d/world.hpp"
#include "support/fixture.hpp"

using namespace sph2d;
using test::frontX;
using test::maxSpeed;
using test::meanSpeed;
using test::outside;
using test::sumY;

namespace {

/// A test scene switched to pbf. The explicit viscosity effect is off (it would
/// cap the substep at 0.03 R²/ν); pbf smooths velocities with XSPH instead.
SceneDef pbfScene(const std::string& rel) {
  SceneDef s = test::scene(rel);
  s.solver.type = "pbf";
  s.solver.params.clear();  // the World fills pbf's defaults
  s.solver.viscosity = 0;
  s.gravity = Vec2d(0, -9.81);
  return s;
}

}  // namespace

TEST_CASE(
    "pbf: a resting tank at the longest substep its limits allow settles within 2 % of rho0, at rest, nothing escapes") {
  const SceneDef s = pbfScene("tests/resting_column.json");
  World w(s, WorldOptions{2});
  const double H = 0.6, g = 9.81;
  for (int f = 0; f < 120; ++f) w.stepFrame();  // 2 s
  // At rest the depth limit 0.35 R/sqrt(g D) sets the substep (D < H: the deepest column).
  const double R = s.solver.spacing * s.solver.supportRatio;
  const int perFrame = int(std::ceil((1.0 / 60) / (0.35 * R / std::sqrt(g * H))));
  MESSAGE(w.counters().substeps << " substeps in 120 frames; the depth limit at D = H allows " << perFrame
                                << " a frame");
  CHECK(w.counters().substeps <= 120 * perFrame);
  REQUIRE(test::allFiniteState(w));
  const DensityStats d = w.densityStats();
  MESSAGE("mean compression " << d.meanError << ", max " << d.maxError << ", mean density " << d.meanDensity);
  // The solver iterates until the mean compression is at most solver.tolerance = 1 %.
  CHECK(d.meanError <= 0.02);
  CHECK(d.maxError <= 0.05);
  CHECK(std::fabs(d.meanDensity - 1000.0) / 1000.0 < 0.02);
  const double mean = meanSpeed(w), top = maxSpeed(w);
  MESSAGE("mean speed " << mean << " m/s, max " << top << " m/s, against sqrt(gH) = " << std::sqrt(g * H));
  CHECK(mean < 0.02 * std::sqrt(g * H));
  CHECK(top < 0.1 * std::sqrt(g * H));
  CHECK(outside(w, 0, 0, 0.6, 1.3) == 0);
}

TEST_CASE("pbf: a 1 m deep tank at 12,800 particles holds at rest whatever max_move it accepts") {
  // Without the depth limit, max_move 2 let the substep stay a frame long once single particles
  // burst at 2-4 m/s, the floor rows were crushed and then flung: 5 m/s at frame 20, 24 at
  // frame 40, 123 at frame 60. The hydrostatic stiffness limit (as dfsph's) holds it at any
  // max_move in its range.
  for (const double maxMove : {2.0, 10.0}) {
    SceneDef s = test::scene("validation/hydrostatic_tank.json");
    s.solver = solverDefaults("pbf");
    s.solver.spacing = 0.0125;
    s.solver.viscosity = 0;
    s.solver.params["max_move"] = maxMove;
    World w(s, WorldOptions{2});
    REQUIRE(w.particleCount() == 12800);
    double worst = 0;
    int worstFrame = 0;
    for (int f = 1; f <= 45; ++f) {
      w.stepFrame();
      REQUIRE(test::allFiniteState(w));
      if (f >= 10 && maxSpeed(w) > worst) {
        worst = maxSpeed(w);
        worstFrame = f;
      }
    }
    MESSAGE("max_move " << maxMove << ": fastest particle over frames 10-45 " << worst << " m/s (frame " << worstFrame
                        << "), " << w.counters().substeps << " substeps");
    CHECK(worst < 1.0);
    CHECK(outside(w, 0, 0, 2, 1.2) == 0);
  }
}

TEST_CASE("pbf: the small dam break runs 1 s at frame-sized steps: no NaN, nothing escapes, energy bounded") {
  const SceneDef s = pbfScene("tests/small_dam_break.json");
  World w(s, WorldOptions{2});
  const double front0 = frontX(w);
  const double y0 = sumY(w);
  const std::size_t n0 = w.particleCount();
  for (int f = 0; f < 60; ++f) w.stepFrame();
  CHECK(w.time() == doctest::Approx(1.0).epsilon(1e-6));
  MESSAGE(w.counters().substeps << " substeps for 60 frames");
  CHECK(w.counters().substeps <= 3 * 60);  // frame-sized while slow, max_move·R/v_max when fast
  REQUIRE(test::allFiniteState(w));
  CHECK(w.particleCount() == n0);
  CHECK(outside(w, 0, 0, 4, 3) == 0);
  const double front = frontX(w);
  MESSAGE("front moved from " << front0 << " to " << front << " m");
  CHECK(front > front0 + 1.5);
  const double released = double(w.particleMass()) * 9.81 * (y0 - sumY(w));
  MESSAGE("kinetic " << w.kineticEnergy() << " J/m, potential released " << released << " J/m");
  CHECK(released > 0);
  CHECK(w.kineticEnergy() <= released);
  const DensityStats d = w.densityStats();
  MESSAGE("mean compression " << d.meanError);
  CHECK(d.meanError <= 0.02);
}

TEST_CASE("pbf: the state hash is the same for 1, 2 and 3 threads and for two runs") {
  const SceneDef s = pbfScene("tests/small_dam_break.json");
  std::uint64_t hashes[4];
  const int threads[4] = {1, 2, 3, 2};
  for (int k = 0; k < 4; ++k) {
    World w(s, WorldOptions{threads[k]});
    for (int f = 0; f < 30; ++f) w.stepFrame();
    hashes[k] = w.stateHash();
  }
  CHECK(hashes[0] == hashes[1]);
  CHECK(hashes[0] == hashes[2]);
  CHECK(hashes[1] == hashes[3]);
  World w(s, WorldOptions{1});
  for (int f = 0; f < 31; ++f) w.stepFrame();
  CHECK(w.stateHash() != hashes[0]);
}

TEST_CASE("pbf: a sliver of a frame only advects (no projection turned into velocity)") {
  const SceneDef s = pbfScene("tests/resting_column.json");
  World w(s, WorldOptions{1});
  for (int f = 0; f < 30; ++f) w.stepFrame();
  const double before = maxSpeed(w);
  w.step(1e-9);  // what a float remainder of a frame looks like
  MESSAGE("max speed " << before << " m/s before, " << maxSpeed(w) << " m/s after");
  CHECK(maxSpeed(w) <= before + 1e-6);
  w.stepFrame();
  CHECK(maxSpeed(w) < 0.5);
}
