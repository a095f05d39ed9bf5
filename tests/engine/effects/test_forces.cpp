// Force fields and user forces (engine/src/effects/forces.cpp).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "sph2d/world.hpp"
#include "support/fixture.hpp"

using namespace sph2d;

namespace {

bool has(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

}  // namespace

TEST_CASE("a region-limited force field accelerates only the particles inside it") {
  SceneDef s;
  s.solver = solverDefaults("wcsph");
  s.solver.spacing = 0.05;
  s.solver.viscosity = 0;
  s.gravity = Vec2d(0, 0);
  for (double x0 : {0.0, 3.0}) {
    FluidBlockDef blk;
    blk.min = Vec2d(x0, 0);
    blk.max = Vec2d(x0 + 0.5, 0.5);
    s.blocks.push_back(blk);
  }
  ForceFieldDef f;
  f.acceleration = Vec2d(2.0, 0);
  f.everywhere = false;
  f.region.min = Vec2d(-1, -1);
  f.region.max = Vec2d(1, 1);
  s.effects.forceFields.push_back(f);
  World w(s, WorldOptions{1});
  for (int k = 0; k < 6; ++k) w.stepFrame();  // 0.1 s
  double vIn = 0, vOut = 0;
  int nIn = 0, nOut = 0;
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const double vx = w.particles().v[i].x();
    if (w.worldPosition(i).x() < 2) {
      vIn += vx;
      ++nIn;
    } else {
      vOut += vx;
      ++nOut;
    }
  }
  CHECK(vIn / nIn == doctest::Approx(0.2).epsilon(0.02));  // a·t = 2 m/s² × 0.1 s
  CHECK(std::fabs(vOut / nOut) < 1e-6);
}

TEST_CASE("a user force pulls particles towards the point, and a NaN strength stops the run at the user_force stage") {
  SceneDef s = test::scene("tests/resting_column.json");
  World w(s, WorldOptions{2});
  for (int f = 0; f < 10; ++f) w.stepFrame();
  CHECK_FALSE(has(w.stages(), "user_force"));
  UserForce u;
  u.point = Vec2d(0.3, 0.9);
  u.radius = 0.6;
  u.strength = 100;  // 100 m/s² at the point: beats gravity within ~0.5 m of it
  w.setUserForces({u});
  double y0 = 0;
  for (std::size_t i = 0; i < w.particleCount(); ++i) y0 += w.worldPosition(i).y();
  for (int f = 0; f < 10; ++f) w.stepFrame();
  double y1 = 0;
  for (std::size_t i = 0; i < w.particleCount(); ++i) y1 += w.worldPosition(i).y();
  CHECK(has(w.stages(), "user_force"));
  MESSAGE("mean height " << y0 / double(w.particleCount()) << " -> " << y1 / double(w.particleCount()) << " m");
  CHECK(y1 > y0 + 0.01 * double(w.particleCount()));  // mean height rose by more than 1 cm
  u.strength = std::nan("");
  w.setUserForces({u});
  try {
    w.stepFrame();
    FAIL("expected SimulationError");
  } catch (const SimulationError& e) {
    CHECK(e.stage == "user_force");
  }
}

TEST_CASE("a force field everywhere alone accelerates a free block's mean velocity by a t (momentum to rounding)") {
  // Zero gravity, no walls: pressure forces are pairwise and cancel, so the mean
  // velocity is exactly the field's a·t. Measured: (1.500000, −0.500002) m/s at 0.5 s.
  SceneDef s;
  s.solver = solverDefaults("wcsph");
  s.solver.spacing = 0.05;
  s.solver.viscosity = 0;
  s.gravity = Vec2d(0, 0);
  s.blocks.push_back(test::block({0, 0}, {0.5, 0.5}));
  const Vec2d a(3.0, -1.0);
  s.effects.forceFields.push_back(ForceFieldDef{a, true, RegionDef{}});
  World w(s, WorldOptions{2});
  for (int f = 0; f < 30; ++f) w.stepFrame();
  const Vec2d mean = test::momentum(w) / (double(w.particleMass()) * double(w.particleCount()));
  const Vec2d expected = a * w.time();
  MESSAGE("mean velocity (" << mean.x() << ", " << mean.y() << ") m/s at t = " << w.time() << " s, a t = ("
                            << expected.x() << ", " << expected.y() << ")");
  CHECK(w.time() == doctest::Approx(0.5));
  CHECK((mean - expected).norm() <= 1e-4 * expected.norm());
  CHECK(test::allFiniteState(w));
}
