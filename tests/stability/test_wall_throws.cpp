// The game preset at a wall: a slab of water thrown at the walls of a closed tank in zero
// gravity, head-on and obliquely, at several spacings and speeds, each from four starts.
// Every particle that reaches a wall within a substep stops there, so the pile-up the
// density solve inherits is as deep as the substep's move into the wall, in spacings:
// the preset's move limit (max_move 6 supports) keeps it within what the local iterations
// undo. Longer moves piled up (docs/notes/game-solver-rounds.md, "A step limit at walls"),
// which the second half of the test shows on the same throws.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "sph2d/world.hpp"
#include "support/fixture.hpp"
#include "test_util.hpp"

using namespace sph2d;

namespace {

struct Throw {
  double worstMax = 0;   ///< the largest single-particle compression at the end of any frame
  double worstMean = 0;  ///< the largest mean compression at the end of any frame
  std::size_t outside = 0;
  bool finite = true;
};

/// A slab [x0, x0 + 0.3] × [0.4, 0.8] thrown at `speed` m/s, `angle` degrees below the
/// horizontal, at the right wall (and the floor) of a closed 1.2 m × 1.2 m tank in zero
/// gravity: the game preset at spacing dx with max_move `maxMove`, 0.3 s (18 frames).
Throw throwSlab(double dx, double speed, double angle, double x0, double maxMove) {
  SceneDef s = test::tank("game", 1.2, 1.2, dx);
  s.gravity = Vec2d(0, 0);
  const double a = angle * M_PI / 180;
  s.blocks.push_back(test::block({x0, 0.4}, {x0 + 0.3, 0.8}, Vec2d(speed * std::cos(a), -speed * std::sin(a))));
  s.solver.params["max_move"] = maxMove;
  s.maxParticles = 100000;
  World w(s, WorldOptions{2});
  Throw r;
  for (int f = 0; f < 18; ++f) {
    w.stepFrame();
    const DensityStats d = w.densityStats();
    r.worstMax = std::max(r.worstMax, d.maxError);
    r.worstMean = std::max(r.worstMean, d.meanError);
    r.outside = std::max(r.outside, test::outside(w, 0, 0, 1.2, 1.2));
  }
  r.finite = test::allFiniteState(w);
  return r;
}

}  // namespace

TEST_CASE("stability: a slab thrown at the walls keeps its worst particle within the game preset's tolerance") {
  // Speeds just under 12·R·60 (R = 2 dx): at max_move 12 every substep would last a frame,
  // about 23 spacings a move; at the preset's 6 a frame takes two. Four starts each, since
  // how deep a front runs into a wall depends on where the substeps fall.
  struct Case {
    double dx, speed, angle;
  };
  double worst = 0;
  int piledLong = 0, throws = 0;
  for (const Case c : {Case{0.005, 7, 0}, Case{0.005, 7, 30}, Case{0.004, 5.5, 0}, Case{0.003, 4.2, 15}}) {
    CAPTURE(c.dx);
    CAPTURE(c.speed);
    CAPTURE(c.angle);
    for (double x0 : {0.05, 0.08, 0.11, 0.14}) {
      CAPTURE(x0);
      const Throw preset = throwSlab(c.dx, c.speed, c.angle, x0, 6), longer = throwSlab(c.dx, c.speed, c.angle, x0, 12);
      MESSAGE("worst particle compression " << 100 * preset.worstMax << " % (max_move 6), " << 100 * longer.worstMax
                                            << " % (12); worst mean " << 100 * preset.worstMean << " %");
      REQUIRE(preset.finite);
      // tolerance_max 8 %, and what the last local iteration leaves (up to 10.1 % measured).
      CHECK(preset.worstMax <= 0.125);
      CHECK(preset.worstMean <= 0.03);
      CHECK(preset.outside == 0);
      worst = std::max(worst, preset.worstMax);
      piledLong += longer.worstMax > 0.125;
      ++throws;
    }
  }
  // The same throws discriminate: at twice the move some leave a pile-up the iterations did not undo.
  MESSAGE("worst particle over the throws " << 100 * worst << " %; at max_move 12, " << piledLong << " of " << throws
                                            << " throws above 12.5 %");
  CHECK(piledLong >= 2);
}
