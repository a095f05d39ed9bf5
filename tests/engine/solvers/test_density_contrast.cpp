// Materials of different rest density in one pressure solve (Solenthaler & Pajarola 2008's
// number density: wcsph in engine/src/solvers/wcsph/wcsph.cpp; pbf and game weigh the
// projection by inverse mass, pbf.hpp, and game's grid takes β = ρ0/ρ per face,
// grid_projection.hpp): layers at rest under their hydrostatic pressure with a sharp, flat
// interface, and bodies of fluid that float or sink by their density, on each solver that
// takes a contrast.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "support/fixture.hpp"
#include "test_util.hpp"

using namespace sph2d;

namespace {

/// `solver` at `dx` in a closed tank [0, W] × [0, H] (free-slip walls; wcsph: c0 = 10 × 4 m/s),
/// viscosity `nu`, and the materials water (1000) and `name` (`density`).
SceneDef twoFluidTank(const std::string& solver, double W, double H, double dx, const std::string& name, double density,
                      double nu) {
  SceneDef s = test::tank(solver, W, H, dx);
  if (solver == "wcsph") s.solver.params["expected_speed"] = 4;
  s.solver.viscosity = nu;
  MaterialDef water;
  water.name = "water";
  water.density = s.solver.restDensity;
  MaterialDef other = water;
  other.name = name;
  other.density = density;
  other.color = {0.9, 0.7, 0.1};
  s.materials = {water, other};
  return s;
}

struct Layers {
  double interfaceRms = 0;    ///< RMS over the columns of the interface height about its mean [m]
  double interfaceMean = 0;   ///< mean interface height [m]
  std::size_t wrongSide = 0;  ///< particles more than a spacing on the other material's side of it
};

/// The interface between material 0 (below) and 1 (above), column by column (columns one
/// spacing wide): halfway between the column's highest particle of 0 and lowest of 1.
Layers layers(const World& w, double W, double dx) {
  const Particles& P = w.particles();
  const int columns = int(W / dx);
  std::vector<double> top(std::size_t(columns), -1e9), bottom(std::size_t(columns), 1e9);
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const Vec2d p = w.worldPosition(i);
    const int c = std::clamp(int(p.x() / dx), 0, columns - 1);
    if (P.material[i] == 0)
      top[std::size_t(c)] = std::max(top[std::size_t(c)], p.y());
    else
      bottom[std::size_t(c)] = std::min(bottom[std::size_t(c)], p.y());
  }
  std::vector<double> h;
  for (int c = 0; c < columns; ++c)
    if (top[std::size_t(c)] > -1e8 && bottom[std::size_t(c)] < 1e8)
      h.push_back(0.5 * (top[std::size_t(c)] + bottom[std::size_t(c)]));
  Layers L;
  for (const double y : h) L.interfaceMean += y / double(h.size());
  for (const double y : h) L.interfaceRms += (y - L.interfaceMean) * (y - L.interfaceMean) / double(h.size());
  L.interfaceRms = std::sqrt(L.interfaceRms);
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const double y = w.worldPosition(i).y();
    L.wrongSide += P.material[i] == 0 ? y > L.interfaceMean + dx : y < L.interfaceMean - dx;
  }
  return L;
}

}  // namespace

namespace {

/// 0.3 m of a light fluid of `density` over 0.3 m of water in a 0.4 m tank, 10 s.
void layersAtRest(const std::string& solver, double density) {
  const double W = 0.4, dx = 0.02, hWater = 0.3, hOil = 0.3, g = 9.81;
  // Enough viscosity to settle: at ν = 0.002 a 0.6 m column of one fluid still rang after 10 s,
  // its floor pressure swinging ±10 %.
  SceneDef s = twoFluidTank(solver, W, 1.0, dx, "oil", density, 0.01);
  s.blocks = {test::block({0, 0}, {W, hWater}), test::block({0, hWater}, {W, hWater + hOil})};
  s.blocks[1].material = 1;
  World w(s, WorldOptions{2});
  REQUIRE(w.particles().material.size() == w.particleCount());
  const double expected = g * (density * hOil + 1000 * hWater);
  double worstRms = 0, pFloor = 0;
  std::size_t worstWrong = 0;
  for (int second = 1; second <= 10; ++second) {
    for (int f = 0; f < 60; ++f) w.stepFrame();
    REQUIRE(test::allFiniteState(w));
    if (second < 3) continue;  // settling
    const Layers L = layers(w, W, dx);
    worstRms = std::max(worstRms, L.interfaceRms);
    worstWrong = std::max(worstWrong, L.wrongSide);
    CHECK(L.interfaceMean == doctest::Approx(hWater).epsilon(0.1));
    // The floor's pressure: the particles of the bottom row, extrapolated to y = 0 with
    // ρ_water g; the mean of the eight seconds' samples.
    double pSum = 0, ySum = 0, n = 0;
    for (std::size_t i = 0; i < w.particleCount(); ++i) {
      const Vec2d p = w.worldPosition(i);
      if (p.y() < dx) pSum += double(w.particles().p[i]), ySum += p.y(), n += 1;
    }
    REQUIRE(n > 10);
    pFloor += (pSum / n + 1000 * g * ySum / n) / 8;
  }
  MESSAGE(solver << ", density " << density << " over water: floor pressure " << pFloor << " Pa (hydrostatic "
                 << expected << "), interface RMS " << worstRms << " m, at most " << worstWrong << " of "
                 << w.particleCount() << " particles on the wrong side, kinetic energy " << w.kineticEnergy()
                 << " J/m");
  // pbf reports −ρ0 λ/dt² as its pressure, not the hydrostatic one (2.1 times it in this tank
  // with one material): its layers are checked, not its pressure.
  if (solver != "pbf") CHECK(pFloor == doctest::Approx(expected).epsilon(0.03));
  CHECK(worstRms <= dx);
  CHECK(double(worstWrong) < 0.005 * double(w.particleCount()));
}

}  // namespace

// A density ratio of 1.25, and of 2.5, where summing neighbours' masses (Σ m_j W) smears the
// interface and pushes it apart (Solenthaler & Pajarola 2008, figure 2).
TEST_CASE("density contrast: oil (800) over water (1000) rests in layers with the hydrostatic floor pressure") {
  for (const std::string solver : {"wcsph", "game", "pbf"}) layersAtRest(solver, 800);
}
TEST_CASE("density contrast: a fluid of 400 over water rests in layers with the hydrostatic floor pressure") {
  for (const std::string solver : {"wcsph", "game", "pbf"}) layersAtRest(solver, 400);
}

TEST_CASE("density contrast: oil trapped under water in a corner overturns and ends on top, in layers") {
  // 0.2 m × 0.3 m of oil (800) in the lower left corner, water beside it and over both: the
  // layers invert (the test above starts stratified; this one must get there). At the start
  // half the particles are on the wrong side of the final interface (0.45 m). Measured at 12 s:
  // 6 % still are, single particles held in the other fluid's lattice (no surface tension
  // gathers them), and the interface's RMS is 2.5 spacings.
  for (const std::string solver : {"wcsph", "game"}) {
    const double W = 0.4, dx = 0.02;
    SceneDef s = twoFluidTank(solver, W, 1.0, dx, "oil", 800, 0.01);
    s.blocks = {test::block({0, 0}, {0.2, 0.3}), test::block({0.2, 0}, {W, 0.3}), test::block({0, 0.3}, {W, 0.6})};
    s.blocks[0].material = 1;
    World w(s, WorldOptions{2});
    for (int f = 0; f < 12 * 60; ++f) w.stepFrame();
    REQUIRE(test::allFiniteState(w));
    const Layers L = layers(w, W, dx);
    MESSAGE(solver << " after 12 s: interface at " << L.interfaceMean << " m (0.45 m when the oil is on top), RMS "
                   << L.interfaceRms << " m, " << L.wrongSide << " of " << w.particleCount()
                   << " particles on the wrong side");
    CHECK(L.interfaceMean == doctest::Approx(0.45).epsilon(0.1));
    CHECK(L.interfaceRms <= 3 * dx);
    CHECK(double(L.wrongSide) < 0.1 * double(w.particleCount()));
  }
}

TEST_CASE("density contrast: a disc of oil released at the floor rises through the water, one of 3000 sinks") {
  const double W = 0.5, dx = 0.0125, depth = 0.5, r = 0.06;
  for (const std::string solver : {"wcsph", "game"})
    for (const double density : {800.0, 3000.0}) {
      SceneDef s = twoFluidTank(solver, W, 0.8, dx, density < 1000 ? "oil" : "sand_slurry", density, 0.002);
      const bool light = density < 1000;
      const Vec2d centre(0.5 * W, light ? r + 2 * dx : depth - r - 2 * dx);
      // The water with a round hole where the disc is (a polygon ring, the hole a 32-gon).
      s.blocks = {test::block({0, 0}, {W, depth})};
      World w(s, WorldOptions{2});
      const std::vector<std::uint32_t> hole = w.removeParticles([&] {
        std::vector<std::uint32_t> ids;
        for (std::size_t i = 0; i < w.particleCount(); ++i)
          if ((w.worldPosition(i) - centre).norm() < r) ids.push_back(w.particles().id[i]);
        return ids;
      }());
      REQUIRE(hole.size() > 50);
      const IdRange disc = w.addDrop(centre, r - 0.25 * dx, Vec2d(0, 0), 1);
      REQUIRE(disc.size() > 50);
      for (int f = 0; f < 5 * 60; ++f) w.stepFrame();
      REQUIRE(test::allFiniteState(w));
      double yDisc = 0, nDisc = 0, topDisc = 0, topWater = 0, xlo = W, xhi = 0;
      for (std::size_t i = 0; i < w.particleCount(); ++i) {
        const Vec2d p = w.worldPosition(i);
        if (w.particles().material[i] == 1) {
          yDisc += p.y(), nDisc += 1, topDisc = std::max(topDisc, p.y());
          xlo = std::min(xlo, p.x()), xhi = std::max(xhi, p.x());
        } else {
          topWater = std::max(topWater, p.y());
        }
      }
      yDisc /= nDisc;
      std::size_t waterOver = 0;  // water above the disc's top, within its width
      for (std::size_t i = 0; i < w.particleCount(); ++i) {
        const Vec2d p = w.worldPosition(i);
        waterOver += w.particles().material[i] == 0 && p.y() > topDisc && p.x() > xlo && p.x() < xhi;
      }
      MESSAGE(solver << ", density " << density << ": the disc's mean height " << yDisc << " m from " << centre.y()
                     << ", its top " << topDisc << " m, the water's surface " << topWater << " m, " << waterOver
                     << " water particles over it");
      // On top: at the surface, water over it no more than the stratified test's bound on
      // particles on the wrong side (0.5 %: single particles held in the other fluid's lattice).
      if (light) {
        CHECK(topDisc > topWater - dx);
        CHECK(double(waterOver) < 0.005 * double(w.particleCount()));
        CHECK(yDisc > depth - 3 * r);
      } else {
        CHECK(yDisc < r);  // on the floor (spread there: a fluid)
      }
    }
}

TEST_CASE("density contrast: dfsph and muller2003 refuse it, as do the effects that weigh by one mass") {
  SceneDef s = twoFluidTank("wcsph", 0.4, 0.4, 0.02, "oil", 800, 0.01);
  s.blocks = {test::block({0, 0}, {0.4, 0.2})};
  CHECK_NOTHROW(World{s});
  for (const char* solver : {"game", "pbf"}) {
    SceneDef other = s;
    other.solver = solverDefaults(solver);
    other.solver.spacing = 0.02;
    CHECK_NOTHROW(World{other});
  }
  for (const char* solver : {"dfsph", "muller2003"}) {
    SceneDef other = s;
    other.solver = solverDefaults(solver);
    other.solver.spacing = 0.02;
    CHECK_THROWS_WITH_AS(World{other}, doctest::Contains("takes materials of one density"), SceneError);
  }
  SceneDef xsph = s;
  xsph.effects.xsph = true;
  CHECK_THROWS_WITH_AS(World{xsph}, doctest::Contains("effects.xsph does not take materials of different density"),
                       SceneError);
  // A World of one density runs no rest-ratio field; a lighter material added later brings it.
  SceneDef one = s;
  one.materials.resize(1);
  World w(one);
  for (const std::string& f : w.particleFields()) CHECK(f != "rest_ratio");
  MaterialDef oil = s.materials[1];
  w.addMaterial(oil);
  const std::vector<std::string> fields = w.particleFields();
  CHECK(std::find(fields.begin(), fields.end(), "rest_ratio") != fields.end());
}
