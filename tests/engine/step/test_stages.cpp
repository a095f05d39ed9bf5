// The stages every solver shares (engine/src/step/stages.cpp): the neighbour lists on every
// SIMD path against a brute-force search, the tie-break direction
// of coincident pairs, integration and its displacement clamp, the periodic wrap
// and nearest images, reordering the particle arrays along the grid.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "sph2d/world.hpp"
#include "step/stages.hpp"
#include "support/fixture.hpp"

using namespace sph2d;

TEST_CASE("a uniform flow through a periodic box stays uniform across the seams (wcsph, pbf, dfsph)") {
  for (const std::string solver : {"wcsph", "pbf", "dfsph"}) {
    CAPTURE(solver);
    SceneDef s = loadScene(test::asset("scenes/validation/taylor_green.json"));
    s.solver.type = solver;
    s.solver.params.clear();
    if (solver == "wcsph") s.solver.params["expected_speed"] = 1.1;
    s.solver.clampNegativePressure = true;
    s.solver.spacing = 0.04;
    s.blocks[0].field.type = VelocityFieldDef::Type::None;
    s.effects.shifting = false;  // shifting a perfect lattice adds noise (docs/SCENES.md)
    const Vec2d u(1.0, 0.37);
    s.blocks[0].velocity = u;
    World w(s, WorldOptions{2});
    const std::size_t n = w.particleCount();
    double worst = 0, worstRho = 0;
    for (int f = 0; f < 90; ++f) {  // 1.5 s: every particle crosses the x seam once or twice
      w.stepFrame();
      for (std::size_t i = 0; i < n; ++i) {
        const Vec2d p = w.worldPosition(i);
        REQUIRE(p.x() >= 0);
        REQUIRE(p.x() < 1);
        REQUIRE(p.y() >= 0);
        REQUIRE(p.y() < 1);
        const Vec2 v = w.particles().v[i];
        worst = std::max(worst, std::hypot(double(v.x()) - u.x(), double(v.y()) - u.y()));
        worstRho = std::max(worstRho, std::fabs(double(w.particles().rho[i]) / 1000.0 - 1));
      }
    }
    MESSAGE(solver << ": largest velocity deviation " << worst << " m/s, largest density deviation " << 100 * worstRho
                   << " %");
    CHECK(w.particleCount() == n);
    CHECK(worst < 0.01);      // 1 % of the speed (dfsph's solve tolerance leaves ~0.3 %)
    CHECK(worstRho < 0.001);  // a lattice that moves as a whole keeps its density
  }
}

TEST_CASE("reordering changes physics by rounding only: every step vs never, 20 substeps, matched by id") {
  // The seed's solver: its step has no data-dependent branch. The game solver's
  // tolerance-driven iteration counts and active lists can turn a rounding
  // difference (sums in another slot order) into a discrete one.
  SceneDef s = test::scene("dam_break_muller2003.json");
  s.solver.reorderInterval = 1;
  World a(s, WorldOptions{2});
  s.solver.reorderInterval = 0;
  World b(s, WorldOptions{2});
  for (int i = 0; i < 20; ++i) {
    sph2d::bench::stepSubstep(a);
    sph2d::bench::stepSubstep(b);
  }
  REQUIRE(a.particleCount() == b.particleCount());
  std::map<std::uint32_t, Vec2d> pos;
  for (std::size_t i = 0; i < b.particleCount(); ++i) pos[b.particles().id[i]] = b.worldPosition(i);
  double worst = 0;
  bool anyDifferentSlot = false;
  for (std::size_t i = 0; i < a.particleCount(); ++i) {
    const std::uint32_t id = a.particles().id[i];
    worst = std::max(worst, (a.worldPosition(i) - pos.at(id)).norm());
    anyDifferentSlot = anyDifferentSlot || b.particles().id[i] != id;
  }
  MESSAGE("largest position difference " << worst << " m = " << worst / s.solver.spacing << " spacings");
  CHECK(anyDifferentSlot);  // the reordering really moved particles between slots
  CHECK(worst <= 1e-4 * s.solver.spacing);
  // And the particles did move: 20 substeps of the collapse are not a no-op.
  CHECK(a.kineticEnergy() > 0);
}

TEST_CASE(
    "tieBreakDirection gives each coincident pair a unit direction, opposite for the two particles, spread over the circle") {
  int sectors[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  for (std::uint32_t i = 0; i < 40; ++i)
    for (std::uint32_t j = i + 1; j < 40; ++j) {
      const Vec2 d = tieBreakDirection(i, j), e = tieBreakDirection(j, i);
      CHECK(d.norm() == doctest::Approx(1.0f).epsilon(1e-6));
      CHECK(e == Vec2(-d));                 // antisymmetric: the pair forces built on it cancel
      CHECK(tieBreakDirection(i, j) == d);  // fixed
      const double a = std::atan2(double(d.y()), double(d.x())) + test::kPi;
      ++sectors[std::min(7, int(a / (2 * test::kPi) * 8))];
    }
  // 780 pairs: every octant gets its share (no preferred direction that would drift a clump).
  for (int k = 0; k < 8; ++k) {
    CAPTURE(k);
    CHECK(sectors[k] > 780 / 8 / 2);
  }
}

namespace {

/// Two particles and the parts a StepContext refers to (no neighbours needed).
struct TwoParticles {
  ParticleStore P;
  Grid grid;
  NeighbourLists nbr;
  BoundarySet boundary;
  ThreadPool pool{1};
  Scratch scratch;
  SolverDef def;
  StepContext c{P, grid, nbr, boundary, pool, scratch, def};
  TwoParticles() {
    P.push(Vec2(0, 0), Vec2(1, 0), 0, 1000);
    P.push(Vec2(1, 1), Vec2(0, 0), 1, 1000);
    c.R = 0.1f;
    c.dt = 0.01f;
    c.maxSpeed = 500;
  }
};

}  // namespace

TEST_CASE(
    "integration is symplectic Euler (v += a dt, then x += v dt) and moves no particle more than half a support") {
  TwoParticles t;
  t.P.a[0] = Vec2(0, -10);  // ordinary: Δv = (0, −0.1), |v dt| = 0.01 m < R/2
  t.P.a[1] = Vec2(0, 1e4);  // a jump: v = 100 m/s would move it 1 m
  REQUIRE(stageIntegrate(t.c) == kNone);
  CHECK(t.P.v[0].x() == doctest::Approx(1.0f));
  CHECK(t.P.v[0].y() == doctest::Approx(-0.1f));
  CHECK(t.P.x[0].x() == doctest::Approx(0.01f));  // with the new velocity
  CHECK(t.P.x[0].y() == doctest::Approx(-0.001f));
  CHECK(t.P.xPrev[0] == Vec2(0, 0));
  // The clamp: R/2 in this substep, along the velocity, and the velocity to match.
  CHECK((t.P.x[1] - t.P.xPrev[1]).norm() == doctest::Approx(0.5f * t.c.R));
  CHECK(t.P.v[1].y() == doctest::Approx(0.5f * t.c.R / t.c.dt));
  CHECK(t.P.v[1].x() == 0);
  // Beyond solver.max_speed the guard reports the particle instead.
  TwoParticles g;
  g.P.a[1] = Vec2(0, 1e7);  // 100,000 m/s
  CHECK(stageIntegrate(g.c) == 1);
}

TEST_CASE(
    "neighbour lists: every path (AVX-512 with up to four near slots of one row of cells searched together, SSE2, scalar) finds exactly the particles within R, in slot order") {
  // A lattice, a random cloud (groups of one to four slots of varied spread), a pile-up too
  // dense for the AVX-512 path's buffers (its slots are searched one at a time), and a few
  // isolated particles with no neighbour.
  ParticleStore P;
  Grid grid;
  NeighbourLists nbr;
  BoundarySet boundary;
  ThreadPool pool{2};
  Scratch scratch;
  SolverDef def;
  StepContext c{P, grid, nbr, boundary, pool, scratch, def};
  c.R = 0.1f;
  std::uint32_t id = 0;
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 40; ++x) P.push(Vec2(0.04f * x + 0.007f * (y % 3), 0.04f * y), Vec2(0, 0), id++, 1000);
  for (int k = 0; k < 700; ++k)  // 700 particles in a 0.03 m square: more candidates than a buffer holds
    P.push(Vec2(2.5f + 0.03f * float(k % 27) / 27.0f, 0.5f + 0.03f * float(k / 27) / 26.0f), Vec2(0, 0), id++, 1000);
  std::uint32_t seed = 12345;  // a fixed LCG: the same cloud every run
  const auto uniform = [&seed] {
    seed = seed * 1664525u + 1013904223u;
    return float(seed >> 8) / float(1u << 24);
  };
  for (int k = 0; k < 600; ++k) P.push(Vec2(0.5f + 1.2f * uniform(), 1.4f + 0.6f * uniform()), Vec2(0, 0), id++, 1000);
  for (int k = 0; k < 5; ++k) P.push(Vec2(4.0f + 0.5f * k, 2.0f), Vec2(0, 0), id++, 1000);
  stageGrid(c, true);
  REQUIRE(grid.inOrder);
  const std::size_t n = P.size();
  const Real R2 = c.R * c.R;
  std::vector<std::vector<std::uint32_t>> expected(n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      const Real dx = P.x[i].x() - P.x[j].x(), dy = P.x[i].y() - P.x[j].y();
      if (j != i && dx * dx + dy * dy < R2) expected[i].push_back(std::uint32_t(j));
    }
  std::size_t pileUp = 0;
  for (const auto& e : expected) pileUp = std::max(pileUp, e.size());
  CHECK(pileUp > 600);  // the pile-up's lists exceed the AVX-512 path's buffers
  for (int mode = 0; mode < 3; ++mode) {
    CAPTURE(mode);  // 0: the widest path, 1: SSE2, 2: scalar
    setBaselineSimdOnly(mode == 1);
    setScalarPairLoops(mode == 2);
    stageNeighbours(c);
    setBaselineSimdOnly(false);
    setScalarPairLoops(false);
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < n; ++i)
      wrong += !std::equal(expected[i].begin(), expected[i].end(), nbr.of(i), nbr.of(i) + nbr.count[i]) ||
               nbr.count[i] != expected[i].size();
    CHECK(wrong == 0);
  }
}
