// Granular materials (effects/granular.cpp): a viscoplastic continuum whose shear stress is
// bounded by c + tan(friction_angle)·p, measured against the angle of repose of a slowly
// poured pile, the 2D column collapse of Lajeunesse, Mangeney-Castelnau & Vilotte 2005
// ("Granular slumping on a horizontal surface", Phys. Fluids 17, 103302), the critical
// height of a cohesive vertical cut, and sand settling in water.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "support/fixture.hpp"

namespace sph2d {
namespace {

/// The game solver's closed tank [0, W] × [0, H] at `dx`, inviscid, with one granular material.
SceneDef sandTank(double W, double H, double dx, double angle, double cohesion = 0) {
  SceneDef s = test::tank("game", W, H, dx);
  s.solver.viscosity = 0;
  MaterialDef sand;
  sand.name = "sand";
  sand.density = s.solver.restDensity;
  sand.kind = MaterialDef::Kind::granular;
  sand.frictionAngle = angle;
  sand.cohesion = cohesion;
  sand.color = {0.85, 0.72, 0.45};
  s.materials = {sand};
  return s;
}

/// The top of the material in columns `width` wide over [0, W] (0 where a column is empty).
std::vector<double> surface(const World& w, double W, double width, double dx) {
  std::vector<double> top(std::size_t(W / width) + 1, 0.0);
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const Vec2d p = w.worldPosition(i);
    const std::size_t c = std::size_t(std::clamp(p.x() / width, 0.0, double(top.size() - 1)));
    top[c] = std::max(top[c], p.y() + dx / 2);
  }
  return top;
}

/// The mean slope [degrees] of each side of a pile centred at W/2: least squares of the
/// surface height against |x − W/2| over the columns between 20 % and 80 % of its height.
std::pair<double, double> pileSlopes(const World& w, double W, double dx, double& height) {
  const std::vector<double> top = surface(w, W, dx, dx);
  height = *std::max_element(top.begin(), top.end());
  double slope[2] = {0, 0};
  for (int side = 0; side < 2; ++side) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    for (std::size_t c = 0; c < top.size(); ++c) {
      const double x = (double(c) + 0.5) * dx - W / 2;
      if ((side == 0) != (x < 0) || top[c] < 0.2 * height || top[c] > 0.8 * height) continue;
      const double ax = std::fabs(x);
      sx += ax, sy += top[c], sxx += ax * ax, sxy += ax * top[c];
      ++n;
    }
    if (n > 2) slope[side] = std::atan(-(n * sxy - sx * sy) / (n * sxx - sx * sx)) * 180 / test::kPi;
  }
  return {slope[0], slope[1]};
}

/// A pile of 0.06 m² of sand poured from a nozzle 0.3 m above the floor's middle at 0.002 m²/s
/// (30 s), then 3 s to settle.
std::unique_ptr<World> pour(double angle, double dx, double W) {
  SceneDef s = sandTank(W, 0.8, dx, angle);
  EmitterDef e;
  e.position = Vec2d(W / 2, 0.3);
  e.direction = Vec2d(0, -1);
  e.width = 4 * dx;
  e.speed = 0.5;
  e.rate = 0.002 / (dx * dx);
  e.stop = 30;
  s.effects.emitters = {e};
  auto w = std::make_unique<World>(s, WorldOptions{2});
  for (int f = 0; f < 33 * 60; ++f) w->stepFrame();
  return w;
}

/// The deposit's end: the first empty column (1 cm wide) from the wall at x = 0.
double runout(const World& w, double W, double dx) {
  const std::vector<double> top = surface(w, W, 0.01, dx);
  std::size_t c = 0;
  while (c < top.size() && top[c] > 0) ++c;
  return double(c) * 0.01;
}

}  // namespace

TEST_CASE("granular: a slowly poured pile stands at its friction angle, and without friction it spreads flat") {
  const double dx = 0.005, W = 1.6;
  for (const double angle : {25.0, 35.0}) {
    const std::unique_ptr<World> pw = pour(angle, dx, W);
    const World& w = *pw;
    REQUIRE(test::allFiniteState(w));
    double height = 0;
    const auto [left, right] = pileSlopes(w, W, dx, height);
    MESSAGE("friction angle " << angle << "°: slopes " << left << "° and " << right << "°, height " << height << " m, "
                              << w.particleCount() << " grains");
    CHECK(std::fabs(0.5 * (left + right) - angle) <= 3.0);
    CHECK(std::fabs(left - angle) <= 4.0);
    CHECK(std::fabs(right - angle) <= 4.0);
    CHECK(test::maxSpeed(w) < 0.05);  // at rest
  }
  const std::unique_ptr<World> flatWorld = pour(0, dx, W);
  const World& flat = *flatWorld;
  double height = 0;
  const auto [left, right] = pileSlopes(flat, W, dx, height);
  const double depth = double(flat.particleCount()) * dx * dx / W;  // spread over the floor
  MESSAGE("friction angle 0°: slopes " << left << "° and " << right << "°, height " << height << " m (flat " << depth
                                       << " m)");
  CHECK(std::fabs(left) < 2.0);
  CHECK(std::fabs(right) < 2.0);
  CHECK(height < 1.5 * depth);
}

TEST_CASE("granular: 2D column collapses run out as Lajeunesse et al.'s law") {
  // Their 2D law: (L∞ − L0)/L0 ≈ 1.2 a for a ≲ 3, ≈ 1.9 a^(2/3) beyond (a = H0/L0), for glass
  // beads; 22° is such beads' angle of repose. The column stands against the wall at x = 0.
  const double dx = 0.005, W = 2.0;
  for (const double a : {0.5, 3.0}) {
    const double L0 = a < 1 ? 0.2 : 0.1, H0 = a * L0;
    SceneDef s = sandTank(W, 1.0, dx, 22);
    s.blocks = {test::block({0, 0}, {L0, H0})};
    World w(s, WorldOptions{2});
    for (int f = 0; f < 3 * 60; ++f) w.stepFrame();
    REQUIRE(test::allFiniteState(w));
    const double L = runout(w, W, dx), law = a <= 3 ? 1.2 * a : 1.9 * std::pow(a, 2.0 / 3.0);
    const double rel = (L - L0) / L0;
    MESSAGE("a = " << a << ": (L - L0)/L0 = " << rel << ", law " << law << " (" << 100 * (rel / law - 1) << " %)");
    CHECK(std::fabs(rel / law - 1) <= 0.2);
    CHECK(test::maxSpeed(w) < 0.1);  // the deposit has stopped
    // Most of the column came down: the deposit is lower than the column and no thinner than
    // its volume spread over the runout.
    const std::vector<double> top = surface(w, W, 0.01, dx);
    CHECK(*std::max_element(top.begin(), top.end()) < (a < 1 ? 1.05 : 0.8) * H0);
  }
}

TEST_CASE("granular: a cohesive column stands below its critical height and falls above it") {
  // Without friction the bound is the cohesion c alone (a Tresca material): a free-standing
  // column much narrower than its height is in uniaxial compression, ρ g H at its foot, and
  // stands while that is below the material's unconfined strength 2c.
  const double dx = 0.005, H = 0.2, rho = 1000, g = 9.81;
  for (const double ratio : {0.5, 2.0}) {  // ρ g H / 2c
    SceneDef s = sandTank(1.0, 0.5, dx, 0, rho * g * H / (2 * ratio));
    s.blocks = {test::block({0.45, 0}, {0.55, H})};  // two free faces
    World w(s, WorldOptions{2});
    for (int f = 0; f < 2 * 60; ++f) w.stepFrame();
    REQUIRE(test::allFiniteState(w));
    double height = 0, lo = 1, hi = 0;
    for (std::size_t i = 0; i < w.particleCount(); ++i) {
      const Vec2d p = w.worldPosition(i);
      height = std::max(height, p.y() + dx / 2);
      lo = std::min(lo, p.x() - dx / 2);
      hi = std::max(hi, p.x() + dx / 2);
    }
    MESSAGE("rho g H / 2c = " << ratio << ": height " << height << " m of " << H << ", width " << hi - lo
                              << " m of 0.1");
    if (ratio < 1) {
      CHECK(height > 0.97 * H);
      CHECK(hi - lo < 0.12);
    } else {
      CHECK(height < 0.8 * H);
      CHECK(hi - lo > 0.2);
    }
  }
}

TEST_CASE("granular: sand sinks in water and piles on the floor, where a liquid as heavy spreads") {
  // Sand of 1600 kg/m³ released 0.2 m under the surface of 0.4 m of water; the same material
  // without friction is a heavy liquid, which spreads into a layer along the floor.
  const double dx = 0.01, W = 1.2;
  double heights[2] = {0, 0};
  for (const double angle : {35.0, 0.0}) {
    SceneDef s = test::tank("game", W, 1.0, dx);
    s.solver.viscosity = 0;
    MaterialDef water;
    water.name = "water";
    water.density = s.solver.restDensity;
    MaterialDef sand = water;
    sand.name = "sand";
    sand.density = 1600;
    sand.kind = MaterialDef::Kind::granular;
    sand.frictionAngle = angle;
    s.materials = {water, sand};
    s.blocks = {test::block({0, 0}, {W, 0.4})};
    World w(s, WorldOptions{2});
    w.removeParticlesInBox(Vec2d(0.5, 0.1), Vec2d(0.7, 0.25));
    FluidBlockDef b = test::block({0.5, 0.1}, {0.7, 0.25});
    b.material = 1;
    w.addBlock(b);
    for (int f = 0; f < 5 * 60; ++f) w.stepFrame();
    REQUIRE(test::allFiniteState(w));
    std::vector<double> ys;
    for (std::size_t i = 0; i < w.particleCount(); ++i)
      if (w.particles().material[i] == 1) ys.push_back(w.worldPosition(i).y());
    std::sort(ys.begin(), ys.end());
    double mean = 0;
    for (const double y : ys) mean += y / double(ys.size());
    const double top = ys[ys.size() * 95 / 100];  // the pile's top, a grain thrown up aside
    heights[angle > 0 ? 0 : 1] = top;
    MESSAGE("friction angle " << angle << "°: sand's top (95th percentile) " << top << " m, mean height " << mean
                              << " m, " << ys.size() << " grains");
    CHECK(mean < 0.1);  // on the floor
  }
  CHECK(heights[0] > 1.8 * heights[1]);  // a pile, not a layer
}

TEST_CASE("granular: same bits on 1, 2 and 3 threads, and a scene without grains runs no granular stage") {
  const double dx = 0.01;
  std::uint64_t h[3] = {0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    SceneDef s = sandTank(1.0, 0.6, dx, 30, 10);
    s.blocks = {test::block({0, 0}, {0.2, 0.3})};
    World w(s, WorldOptions{k + 1});
    for (int f = 0; f < 30; ++f) w.stepFrame();
    h[k] = w.stateHash();
    if (k == 0) {
      const std::vector<std::string> st = w.stages();
      CHECK(std::find(st.begin(), st.end(), "granular") != st.end());
      CHECK(std::find(st.begin(), st.end(), "pressure_now") != st.end());
    }
  }
  CHECK(h[0] == h[1]);
  CHECK(h[0] == h[2]);
  SceneDef plain = test::tank("game", 1.0, 0.6, dx);
  plain.blocks = {test::block({0, 0}, {0.2, 0.3})};
  World w(plain, WorldOptions{1});
  w.stepFrame();
  const std::vector<std::string> st = w.stages();
  CHECK(std::find(st.begin(), st.end(), "granular") == st.end());
  CHECK(std::find(st.begin(), st.end(), "pressure_now") == st.end());
}

TEST_CASE(
    "granular: a scene names the material's kind, friction angle and cohesion, and bad ones are refused at their key") {
  const auto scene = [](const std::string& solver, const std::string& sand) {
    return "{\"solver\": {\"type\": \"" + solver + "\", \"spacing\": 0.05},\n\"materials\": [{\"name\": \"water\"},\n" +
           sand +
           "],\n\"boundaries\": [{\"fixtures\": [{\"shape\": \"box\", \"center\": [1, -0.1], \"half_size\": [1.2, "
           "0.1]}]}],\n\"fluid\": [{\"min\": [0, 0], \"max\": [0.5, 0.5]}]}";
  };
  const SceneDef s = parseScene(
      scene("game", "{\"name\": \"sand\", \"kind\": \"granular\", \"friction_angle\": 33, \"cohesion\": 5}"), "t.json");
  REQUIRE(s.materials.size() == 2);
  CHECK(s.materials[1].granular());
  CHECK(s.materials[1].frictionAngle == 33);
  CHECK(s.materials[1].cohesion == 5);
  CHECK_FALSE(s.materials[0].granular());
  const std::vector<std::string> effects = World(s).effects();
  CHECK(std::find(effects.begin(), effects.end(), "granular") != effects.end());
  auto refused = [&](const std::string& solver, const std::string& sand, const std::string& key,
                     const std::string& why) {
    try {
      parseScene(scene(solver, sand), "t.json");
      FAIL("accepted " << sand);
    } catch (const SceneError& e) {
      CHECK(e.key == key);
      CHECK(e.line == 3);
      CHECK(e.message.find(why) != std::string::npos);
    }
  };
  refused("game", "{\"name\": \"sand\", \"kind\": \"gravel\"}", "materials[1].kind", "granular");
  refused("game", "{\"name\": \"sand\", \"kind\": \"granular\", \"friction_angle\": 75}", "materials[1].friction_angle",
          "60");
  refused("game", "{\"name\": \"sand\", \"kind\": \"granular\", \"cohesion\": -1}", "materials[1].cohesion", "");
  refused("game", "{\"name\": \"oil\", \"friction_angle\": 30}", "materials[1].friction_angle",
          "\"kind\": \"granular\"");
  refused("wcsph", "{\"name\": \"sand\", \"kind\": \"granular\"}", "materials[1].kind", "needs solver.type");
  SolverDef noGrid = solverDefaults("game");  // the game solver without its grid projection
  noGrid.params["grid_cell"] = 0;
  MaterialDef grains;
  grains.name = "grains";
  grains.kind = MaterialDef::Kind::granular;
  CHECK(materialProblem({}, grains, noGrid).find("grid projection") != std::string::npos);
  CHECK(materialProblem({}, grains, solverDefaults("game")).empty());
  // Run time: a World built without grains takes none; one built with them takes more.
  World plain(parseScene(scene("game", "{\"name\": \"oil\"}"), "t.json"));
  MaterialDef sand;
  sand.name = "sand";
  sand.kind = MaterialDef::Kind::granular;
  CHECK_THROWS_WITH_AS(plain.addMaterial(sand), doctest::Contains("granular"), std::invalid_argument);
  World w(s);
  sand.name = "gravel";
  sand.frictionAngle = 40;
  CHECK(w.addMaterial(sand) == 2);
}

}  // namespace sph2d
