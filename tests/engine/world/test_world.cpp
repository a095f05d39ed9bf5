// The World's construction and public API (engine/src/world/world.cpp): the particle
// mass, the local frame, what a scene is refused for, and the effect switches.
#include <doctest/doctest.h>

#include <box2d/box2d.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "sph2d/world.hpp"
#include "support/fixture.hpp"

using namespace sph2d;

TEST_CASE("the particle mass makes a full square lattice exactly rho0 under each solver's own density kernel") {
  // A fully periodic box filled by one block at rest: every particle has a full
  // lattice neighbourhood, so its summation density is the lattice sum the mass
  // was chosen for (poly6 for muller2003, spiky for pbf, Wendland C2 for wcsph and
  // dfsph; the masses differ from ρ0 dx² by the kernels' lattice errors: pbf's by 12 %).
  for (const std::string& solver : test::solvers()) {
    for (double dx : {0.04, 0.05}) {
      CAPTURE(solver);
      CAPTURE(dx);
      SceneDef s = test::periodicShearLayer(solver, 0, dx);
      s.blocks = {test::block({0, 0}, {1, 1})};
      World w(s, WorldOptions{1});
      double lo = 1e300, hi = 0;
      for (std::size_t i = 0; i < w.particleCount(); ++i) {
        lo = std::min(lo, double(w.particles().rho[i]));
        hi = std::max(hi, double(w.particles().rho[i]));
      }
      MESSAGE(solver << " at dx = " << dx << ": density from " << lo << " to " << hi << " kg/m³, mass " << w.particleMass());
      CHECK(lo == doctest::Approx(1000.0).epsilon(1e-5));
      CHECK(hi == doctest::Approx(1000.0).epsilon(1e-5));
    }
  }
}

TEST_CASE("a scene 10 km from the origin runs in a local frame: the origin a multiple of 64 m near its centre") {
  SceneDef s = test::tank("wcsph", 1, 1, 0.05);
  s.blocks.push_back(test::block({0, 0}, {0.5, 0.5}));
  const Vec2d shift(10000.0, -3000.0);
  SceneDef far = s;
  for (auto& b : far.bodies) b.position += shift;
  for (auto& b : far.blocks) {
    b.min += shift;
    b.max += shift;
  }
  World near(s, WorldOptions{1}), away(far, WorldOptions{1});
  const Vec2d o = away.origin();
  CHECK(std::fmod(o.x(), 64.0) == 0);
  CHECK(std::fmod(o.y(), 64.0) == 0);
  CHECK((o - (shift + Vec2d(0.25, 0.25))).cwiseAbs().maxCoeff() <= 32);  // the scene's centre, rounded
  CHECK(near.origin() == Vec2d(0, 0));
  // The same particles, each within float rounding of the local frame's small numbers.
  REQUIRE(away.particleCount() == near.particleCount());
  double worst = 0;
  for (std::size_t i = 0; i < near.particleCount(); ++i) {
    const Vec2d local = Vec2d(away.particles().x[i].x(), away.particles().x[i].y());
    CHECK(local.norm() < 100);  // stored small, not as 10 km in a float
    worst = std::max(worst, (away.worldPosition(i) - shift - near.worldPosition(i)).norm());
  }
  MESSAGE("largest difference of a particle's position from the scene at the origin: " << worst << " m");
  CHECK(worst < 1e-5);
}

TEST_CASE("a periodic axis shorter than 3 support radii is refused, naming the axis and the length it needs") {
  SceneDef s = test::scene("validation/taylor_green.json");
  s.periodic.max.x() = s.periodic.min.x() + 2.9 * s.solver.supportRatio * s.solver.spacing;
  s.blocks = {test::block({0, 0}, {0.05, 1})};
  try {
    World w(s, WorldOptions{1});
    FAIL("a period of 2.9 support radii was accepted");
  } catch (const SceneError& e) {
    CHECK(e.key == "periodic.x");
    CHECK(e.message.find("at least 3 support radii") != std::string::npos);
  }
}

TEST_CASE("setEffectEnabled switches a scene's effect and refuses one the scene does not have, naming its effects") {
  SceneDef s = test::scene("tests/resting_column.json");  // viscosity
  s.effects.xsph = true;
  World w(s, WorldOptions{1});
  CHECK(w.effects() == std::vector<std::string>{"viscosity", "xsph"});
  try {
    w.setEffectEnabled("surface_tension", true);
    FAIL("an effect the scene does not have was switched on");
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    CHECK(what.find("surface_tension") != std::string::npos);
    CHECK(what.find("viscosity") != std::string::npos);
    CHECK(what.find("xsph") != std::string::npos);
  }
  w.setEffectEnabled("viscosity", false);
  const auto st = w.stages();
  CHECK(std::find(st.begin(), st.end(), "viscosity") == st.end());
  CHECK(std::find(st.begin(), st.end(), "xsph") != st.end());
}

TEST_CASE("a World in a game's b2World ignores the scene's own bodies and says so") {
  b2World game(b2Vec2(0, -9.81f));
  SceneDef s = test::tank("wcsph", 1, 1, 0.05);  // four bodies' worth of walls, ignored
  s.blocks.push_back(test::block({0.2, 0.2}, {0.4, 0.4}));
  World w(s, game, WorldOptions{1});
  const auto warnings = w.takeWarnings();
  REQUIRE(warnings.size() == 1);
  CHECK(warnings[0].find("1 boundary bodies are ignored") != std::string::npos);
  CHECK(w.colliders().empty());
  CHECK(&w.box2d() == &game);
}
