// The fluid's outline as curves (sph2d/surface.hpp, World::surfaceCurves): a resting tank is
// one closed curve of the fluid's area with a flat top, a drop in zero gravity a circle of its
// area, two drops two curves, a bubble a hole; bad options are refused.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "support/fixture.hpp"
#include "test_util.hpp"

using namespace sph2d;

namespace {

/// The curves with an area beyond a particle's square (leaves out a pair of spray particles' sliver).
std::vector<SurfaceCurve> regions(const std::vector<SurfaceCurve>& curves, double dx) {
  std::vector<SurfaceCurve> out;
  for (const SurfaceCurve& c : curves)
    if (std::fabs(c.area) > dx * dx) out.push_back(c);
  return out;
}

/// Zero gravity, no solids, the game solver at `dx`.
SceneDef emptySpace(double dx) {
  SceneDef s;
  s.solver = solverDefaults("game");
  s.solver.spacing = dx;
  s.gravity = Vec2d(0, 0);
  return s;
}

/// How far the points of `c` lie from a circle of its area about their centroid: the RMS and
/// the largest |r − r_eq| / r_eq.
struct Roundness {
  double rms = 0, worst = 0;
};
Roundness roundness(const SurfaceCurve& c) {
  Vec2d m(0, 0);
  for (const Vec2d& p : c.points) m += p / double(c.points.size());
  const double req = std::sqrt(std::fabs(c.area) / M_PI);
  Roundness r;
  for (const Vec2d& p : c.points) {
    const double d = std::fabs((p - m).norm() - req) / req;
    r.rms += d * d / double(c.points.size());
    r.worst = std::max(r.worst, d);
  }
  r.rms = std::sqrt(r.rms);
  return r;
}

}  // namespace

TEST_CASE("surface: a resting tank is one closed curve of the fluid's area with a flat top") {
  // Tanks of other sizes and spacings: the curve encloses particles × spacing² within 3 % and
  // its top, away from the walls' corners, is level within half a spacing.
  struct Case {
    double W, depth, dx;
  };
  for (const Case k : {Case{1.0, 0.4, 0.02}, Case{0.6, 0.5, 0.0125}}) {
    CAPTURE(k.W);
    CAPTURE(k.dx);
    SceneDef s = test::tank("game", k.W, 1.0, k.dx);
    s.blocks = {test::block({0, 0}, {k.W, k.depth})};
    World w(s, WorldOptions{2});
    for (int f = 0; f < 90; ++f) w.stepFrame();
    const std::vector<SurfaceCurve> curves = w.surfaceCurves();
    REQUIRE(curves.size() == 1);
    const SurfaceCurve& c = curves[0];
    CHECK_FALSE(c.hole());
    CHECK_FALSE(c.points.front() == c.points.back());  // closed without repeating its first point
    const double fluid = double(w.particleCount()) * k.dx * k.dx;
    double top = -1e9, low = 1e9, high = -1e9;
    for (const Vec2d& p : c.points) top = std::max(top, p.y());
    for (const Vec2d& p : c.points)
      if (p.y() > top - 4 * k.dx && p.x() > 4 * k.dx && p.x() < k.W - 4 * k.dx)
        low = std::min(low, p.y()), high = std::max(high, p.y());
    MESSAGE("area " << c.area << " m² against " << fluid << " (" << 100 * (c.area / fluid - 1) << " %), top from "
                    << low << " to " << high << " m, " << c.points.size() << " points");
    CHECK(std::fabs(c.area / fluid - 1) < 0.03);
    CHECK(high - low < 0.5 * k.dx);
    CHECK(std::fabs(high - k.depth) < 2 * k.dx);  // where the water stands
  }
}

TEST_CASE("surface: a drop in zero gravity is one curve within 2 % of a circle of its area") {
  // Drops of 12 and 30 spacings' radius, after a third of a second: the curve's RMS distance
  // from a circle of its area is within 2 % of the radius. The particles' own edge is a
  // lattice's, whose rows end in steps: the farthest point stands up to about 0.5/r of the
  // radius off the circle (r in spacings: 3.4 % at 12; bound 5 %).
  for (const double radius : {0.12, 0.3}) {
    CAPTURE(radius);
    const double dx = 0.01;
    World w(emptySpace(dx), WorldOptions{2});
    w.addDrop(Vec2d(0.7, -0.3), radius);
    for (int f = 0; f < 20; ++f) w.stepFrame();
    const std::vector<SurfaceCurve> curves = regions(w.surfaceCurves(), dx);
    REQUIRE(curves.size() == 1);
    const double fluid = double(w.particleCount()) * dx * dx;
    const Roundness round = roundness(curves[0]);
    MESSAGE("area " << curves[0].area << " m² against " << fluid << "; off a circle by " << 100 * round.rms
                    << " % of its radius (RMS), " << 100 * round.worst << " % at most");
    CHECK(std::fabs(curves[0].area / fluid - 1) < 0.03);
    CHECK(round.rms < 0.02);
    CHECK(round.worst < 0.05);
  }
}

TEST_CASE("surface: two drops are two curves, a bubble is a hole") {
  const double dx = 0.01;
  {
    World w(emptySpace(dx), WorldOptions{2});
    w.addDrop(Vec2d(0, 0), 0.1);
    w.addDrop(Vec2d(0.35, 0.1), 0.08);
    w.stepFrame();
    const std::vector<SurfaceCurve> curves = regions(w.surfaceCurves(), dx);
    REQUIRE(curves.size() == 2);
    CHECK_FALSE(curves[0].hole());
    CHECK_FALSE(curves[1].hole());
    CHECK(std::fabs(curves[0].area + curves[1].area - double(w.particleCount()) * dx * dx) <
          0.03 * double(w.particleCount()) * dx * dx);
  }
  {
    // A square of water 0.6 m wide with a round bubble of radius 0.15 m off its centre.
    World w(emptySpace(dx), WorldOptions{2});
    std::vector<Vec2d> points;
    const Vec2d bubble(0.35, 0.27);
    for (int j = 0; j < 60; ++j)
      for (int i = 0; i < 60; ++i) {
        const Vec2d p((i + 0.5) * dx, (j + 0.5) * dx);
        if ((p - bubble).norm() > 0.15) points.push_back(p);
      }
    w.addParticles(points);
    const std::vector<SurfaceCurve> curves = regions(w.surfaceCurves(), dx);
    REQUIRE(curves.size() == 2);
    const SurfaceCurve& outer = curves[0].hole() ? curves[1] : curves[0];
    const SurfaceCurve& hole = curves[0].hole() ? curves[0] : curves[1];
    REQUIRE(hole.hole());
    REQUIRE_FALSE(outer.hole());
    const Roundness round = roundness(hole);
    MESSAGE("outline " << outer.area << " m² (square 0.36), hole " << hole.area << " m² (circle " << -M_PI * 0.0225
                       << "), off a circle by " << 100 * round.rms << " % (RMS), " << 100 * round.worst
                       << " % at most");
    CHECK(std::fabs(outer.area - 0.36) < 0.03 * 0.36);
    CHECK(std::fabs(-hole.area / (M_PI * 0.0225) - 1) < 0.05);
    CHECK(round.rms < 0.02);
    CHECK(round.worst < 0.05);
    CHECK(std::fabs(outer.area + hole.area - double(points.size()) * dx * dx) < 0.03 * double(points.size()) * dx * dx);
  }
}

TEST_CASE("surface: a material's own outline, an empty world and bad options") {
  SceneDef s = emptySpace(0.01);
  MaterialDef water, dyed;
  water.name = "water";
  dyed.name = "dyed";
  water.density = dyed.density = s.solver.restDensity;
  s.materials = {water, dyed};
  World w(s, WorldOptions{1});
  CHECK(w.surfaceCurves().empty());
  w.addDrop(Vec2d(0, 0), 0.1, Vec2d(0, 0), 0);
  w.addDrop(Vec2d(0.3, 0), 0.1, Vec2d(0, 0), 1);
  SurfaceOptions only;
  CHECK(regions(w.surfaceCurves(only), 0.01).size() == 2);
  only.material = 1;
  const std::vector<SurfaceCurve> dyedOnly = regions(w.surfaceCurves(only), 0.01);
  REQUIRE(dyedOnly.size() == 1);
  CHECK(dyedOnly[0].points[0].x() > 0.15);
  CHECK_THROWS_WITH_AS(surfaceCurves({Vec2d(0, 0)}, 0.0), doctest::Contains("spacing must be a positive length"),
                       std::invalid_argument);
  SurfaceOptions bad;
  bad.level = 1;
  CHECK_THROWS_WITH_AS(surfaceCurves({Vec2d(0, 0)}, 0.01, bad), doctest::Contains("level"), std::invalid_argument);
  bad = SurfaceOptions{};
  bad.cell = 0.5;  // finer than the particles: each would be an island
  CHECK_THROWS_WITH_AS(surfaceCurves({Vec2d(0, 0)}, 0.01, bad), doctest::Contains("cell"), std::invalid_argument);
  bad.cell = 100;
  CHECK_THROWS_WITH_AS(surfaceCurves({Vec2d(0, 0)}, 0.01, bad), doctest::Contains("cell"), std::invalid_argument);
  bad = SurfaceOptions{};
  bad.smoothing = 0;
  CHECK_THROWS_WITH_AS(surfaceCurves({Vec2d(0, 0)}, 0.01, bad), doctest::Contains("smoothing"), std::invalid_argument);
  CHECK_THROWS_WITH_AS(surfaceCurves({Vec2d(0, std::nan(""))}, 0.01), doctest::Contains("not finite"),
                       std::invalid_argument);
  CHECK_THROWS_WITH_AS(surfaceCurves({Vec2d(0, 0), Vec2d(1e8, 0)}, 0.01), doctest::Contains("span"),
                       std::invalid_argument);
  only.material = 7;
  CHECK_THROWS_WITH_AS(w.surfaceCurves(only), doctest::Contains("material 7 does not exist"), std::invalid_argument);
}

TEST_CASE("surface: stray particles far away cost their own region only, and far from the origin precision holds") {
  // A block of water 0.5 m × 0.2 m (dx 0.01) and particles of spray 20 m, 300 m and 5 km away
  // (each alone, then a pair): the block's curve keeps its area as without them, and a level
  // 1e6 m from the origin gives the same block.
  const double dx = 0.01;
  std::vector<Vec2d> block;
  for (int j = 0; j < 20; ++j)
    for (int i = 0; i < 50; ++i) block.push_back(Vec2d((i + 0.5) * dx, (j + 0.5) * dx));
  const std::vector<SurfaceCurve> alone = regions(surfaceCurves(block, dx), dx);
  REQUIRE(alone.size() == 1);
  CHECK(std::fabs(alone[0].area / 0.1 - 1) < 0.02);
  for (const double far : {20.0, 300.0, 5000.0}) {
    CAPTURE(far);
    std::vector<Vec2d> points = block;
    points.push_back(Vec2d(far, far / 2));
    points.push_back(Vec2d(-far, 0.1));
    points.push_back(Vec2d(-far + 0.5 * dx, 0.1));
    const std::vector<SurfaceCurve> curves = regions(surfaceCurves(points, dx), dx);
    REQUIRE(curves.size() == 1);
    CHECK(curves[0].area == doctest::Approx(alone[0].area).epsilon(1e-9));
  }
  std::vector<Vec2d> shifted = block;
  for (Vec2d& p : shifted) p += Vec2d(1e6, -1e6);
  const std::vector<SurfaceCurve> there = regions(surfaceCurves(shifted, dx), dx);
  REQUIRE(there.size() == 1);
  CHECK(there[0].area == doctest::Approx(alone[0].area).epsilon(1e-6));
}

TEST_CASE("surface: the same curves on 1 and 3 threads, and a tilted surface is straight") {
  // Water sloshing in a tank, stepped on 1 and 3 threads (the same bits): the curves agree
  // point for point. A block rotated by 25 degrees: its long top edge, away from the corners,
  // stays within a fifth of a spacing of a straight line.
  const double dx = 0.02;
  SceneDef s = test::tank("game", 1.0, 1.0, dx);
  s.blocks = {test::block({0, 0}, {0.4, 0.6})};
  World one(s, WorldOptions{1}), three(s, WorldOptions{3});
  for (int f = 0; f < 40; ++f) one.stepFrame(), three.stepFrame();
  REQUIRE(one.stateHash() == three.stateHash());
  const std::vector<SurfaceCurve> a = one.surfaceCurves(), b = three.surfaceCurves();
  REQUIRE(a.size() == b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    REQUIRE(a[k].points.size() == b[k].points.size());
    for (std::size_t i = 0; i < a[k].points.size(); ++i) CHECK(a[k].points[i] == b[k].points[i]);
  }
  const double angle = 25 * M_PI / 180, c = std::cos(angle), sn = std::sin(angle);
  std::vector<Vec2d> tilted;
  for (int j = 0; j < 20; ++j)
    for (int i = 0; i < 80; ++i) {
      const double x = (i + 0.5) * dx, y = (j + 0.5) * dx;
      tilted.push_back(Vec2d(c * x - sn * y, sn * x + c * y));
    }
  const std::vector<SurfaceCurve> t = regions(surfaceCurves(tilted, dx), dx);
  REQUIRE(t.size() == 1);
  // The top edge: points whose coordinate along the block lies away from its ends, on its upper side.
  double worst = 0;
  int counted = 0;
  for (const Vec2d& p : t[0].points) {
    const double along = c * p.x() + sn * p.y(), across = -sn * p.x() + c * p.y();
    if (along > 3 * dx && along < 77 * dx && across > 10 * dx) {
      worst = std::max(worst, std::fabs(across - 20 * dx));
      ++counted;
    }
  }
  MESSAGE("tilted top: " << counted << " points, farthest " << worst / dx << " spacings off the line");
  CHECK(counted > 40);
  CHECK(worst < 0.2 * dx);
}
