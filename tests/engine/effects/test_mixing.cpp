// Mixing of miscible materials (engine/src/effects/mixing.cpp): concentrations diffuse at the
// materials' D across an interface as the diffusion equation says, their sum is conserved, a
// closed box of two colours goes to the mean, and immiscible materials have no mixing at all.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "support/fixture.hpp"
#include "test_util.hpp"

using namespace sph2d;

namespace {

/// A W × H tank in zero gravity (the fluid at rest), game preset at dx, left half of material
/// "red", right half "blue" (one density), miscible when `miscible`, diffusion D each.
SceneDef twoColours(double W, double H, double dx, bool miscible, double D) {
  SceneDef s = test::tank("game", W, H, dx);
  s.gravity = Vec2d(0, 0);
  MaterialDef red;
  red.name = "red";
  red.density = s.solver.restDensity;
  red.color = {1, 0, 0};
  red.diffusion = D;
  MaterialDef blue = red;
  blue.name = "blue";
  blue.color = {0, 0, 1};
  if (miscible) blue.miscibleWith = {"red"};
  s.materials = {red, blue};
  s.blocks = {test::block({0, 0}, {0.5 * W, H}), test::block({0.5 * W, 0}, {W, H})};
  s.blocks[1].material = 1;
  return s;
}

/// Σ of every particle's blue share as its mixed colour shows it (rounded to 1/255 each).
double totalBlue(const World& w) {
  double sum = 0;
  for (std::size_t i = 0; i < w.particleCount(); ++i) sum += double(w.particles().mixedColor[i] & 0xFFu) / 255.0;
  return sum;
}

}  // namespace

TEST_CASE("mixing: two miscible colours diffuse across their interface as c = erfc(x / 2 sqrt(Dt)) / 2") {
  const double W = 1.0, H = 0.4, dx = 0.02, D = 2e-3, T = 2.0;
  World w(twoColours(W, H, dx, true, D), WorldOptions{2});
  const std::vector<std::string> effects = w.effects();
  REQUIRE(std::find(effects.begin(), effects.end(), "mixing") != effects.end());
  const double before = totalBlue(w);
  for (int f = 0; f < int(T * 60); ++f) w.stepFrame();
  REQUIRE(test::allFiniteState(w));
  // Each particle's blue share against the exact profile (the walls 0.5 m away do not reach in 2 s).
  double se = 0, n = 0, worst = 0;
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const Vec2d p = w.worldPosition(i);
    const double c = double(w.particles().mixedColor[i] & 0xFFu) / 255.0;
    const double exact = 0.5 * std::erfc(-(p.x() - 0.5 * W) / (2 * std::sqrt(D * T)));
    se += (c - exact) * (c - exact), n += 1;
    worst = std::max(worst, std::fabs(c - exact));
  }
  const double rms = std::sqrt(se / n), after = totalBlue(w);
  MESSAGE("RMS " << rms << " against the exact profile (worst " << worst << "), diffusion length " << std::sqrt(D * T)
                 << " m; blue in all: " << before << " -> " << after);
  CHECK(rms < 0.03);
  CHECK(after == doctest::Approx(before).epsilon(2e-3));  // through the colour's 1/255 rounding
  // A diffusion four times slower is visibly narrower: the check above is of D, not of any spreading.
  World slow(twoColours(W, H, dx, true, D / 4), WorldOptions{2});
  for (int f = 0; f < int(T * 60); ++f) slow.stepFrame();
  double seSlow = 0;
  for (std::size_t i = 0; i < slow.particleCount(); ++i) {
    const Vec2d p = slow.worldPosition(i);
    const double c = double(slow.particles().mixedColor[i] & 0xFFu) / 255.0;
    const double exact = 0.5 * std::erfc(-(p.x() - 0.5 * W) / (2 * std::sqrt(D * T)));
    seSlow += (c - exact) * (c - exact);
  }
  CHECK(std::sqrt(seSlow / n) > 2 * rms);
}

TEST_CASE("mixing: a closed box of two miscible colours goes to the mean, its total conserved to 1e-6") {
  World w(twoColours(0.4, 0.4, 0.02, true, 0.05), WorldOptions{2});
  const double before = totalBlue(w), exactBefore = w.totalConcentration(1);
  CHECK(exactBefore == double(w.particleCount() / 2));
  for (int f = 0; f < 3 * 60; ++f) w.stepFrame();
  double lo = 1, hi = 0;
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const double c = double(w.particles().mixedColor[i] & 0xFFu) / 255.0;
    lo = std::min(lo, c), hi = std::max(hi, c);
  }
  MESSAGE("after 3 s the blue share is " << lo << " to " << hi << " (mean 0.5); total " << before << " -> "
                                         << totalBlue(w));
  CHECK(lo > 0.45);
  CHECK(hi < 0.55);
  CHECK(totalBlue(w) == doctest::Approx(before).epsilon(2e-3));
  MESSAGE("the field's total: " << exactBefore << " -> " << w.totalConcentration(1));
  CHECK(w.totalConcentration(1) == doctest::Approx(exactBefore).epsilon(1e-6));
  // One particle's share, by id.
  const std::uint32_t id = w.particles().id[0];
  CHECK(w.concentrationOf(id, 0) + w.concentrationOf(id, 1) == doctest::Approx(1.0).epsilon(1e-5));
}

TEST_CASE("mixing: immiscible materials have no mixing stage, no field, and keep their colours") {
  World w(twoColours(0.4, 0.4, 0.02, false, 0.05), WorldOptions{2});
  const std::vector<std::string> effects = w.effects();
  CHECK(std::find(effects.begin(), effects.end(), "mixing") == effects.end());
  for (const std::string& f : w.particleFields()) {
    CHECK(f.rfind("concentration", 0) != 0);
    CHECK(f != "mixed_color");
  }
  CHECK(w.particles().mixedColor.empty());
}

TEST_CASE("mixing: a save holds the concentrations, and a World that mixes takes no more materials") {
  const SceneDef s = twoColours(0.4, 0.4, 0.04, true, 0.01);
  World a(s);
  for (int f = 0; f < 20; ++f) a.stepFrame();
  std::stringstream buf;
  a.save(buf);
  World b(s);
  b.load(buf);
  CHECK(b.stateHash() == a.stateHash());
  for (int f = 0; f < 10; ++f) a.stepFrame(), b.stepFrame();
  CHECK(b.stateHash() == a.stateHash());
  MaterialDef green = s.materials[0];
  green.name = "green";
  CHECK_THROWS_WITH_AS(a.addMaterial(green), doctest::Contains("takes no more materials"), std::invalid_argument);
}
