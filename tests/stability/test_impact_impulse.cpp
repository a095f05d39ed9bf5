// The impulse of an impact against theory: a rectangular block of water moving at V meets a
// flat wall face-on, and the first substep's velocities are compared particle by particle with
// the pressure-impulse theory of Cooker & Peregrine (J. Fluid Mech. 297, 1995). It bounds what
// an impact can give a particle from the physics: the corner's fluid leaves faster than the
// block came (the theory's tangential velocity grows like (2V/π) ln(b/x) towards a corner), and
// no solver may throw a particle faster than the theory's fastest particle at the same spacing
// (docs/STABILITY.md). wcsph and muller2003 are left out: they meet the wall over the sound's
// crossing time, ringing, and the theory is their limit for c → ∞ only.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "sph2d/world.hpp"
#include "support/fixture.hpp"
#include "test_util.hpp"

using namespace sph2d;

namespace {

/// A block b wide (across the wall) and L long (along the wall's normal) that meets the wall
/// at V: in coordinates x across (0 … b) and y from the wall (0 … L), the pressure impulse
/// P = Σ_{k odd} 4ρVb/(k²π²) sin(kπx/b) sinh(kπ(L − y)/b)/cosh(kπL/b) is 0 on the three free
/// faces and stops the block's normal velocity at the wall (∂P/∂y = −ρV there). The velocity
/// after the impact is (0, −V) − ∇P/ρ.
struct ImpulseTheory {
  double b, L, V;
  static constexpr int kTerms = 4001;  ///< odd terms below this: the sums at y ≥ dx/2 converge long before
  /// (across, normal) velocity after the impact at (x, y).
  Vec2d velocity(double x, double y) const {
    double ux = 0, uy = -V;
    for (int k = 1; k < kTerms; k += 2) {
      const double a = k * test::kPi / b, c = 4 * V / (k * test::kPi);
      // sinh(a(L − y))/cosh(aL) and cosh(a(L − y))/cosh(aL) without overflow.
      const double e = std::exp(-a * y), far = std::exp(-2 * a * (L - y)), den = 1 + std::exp(-2 * a * L);
      ux -= c * std::cos(a * x) * e * (1 - far) / den;
      uy += c * std::sin(a * x) * e * (1 + far) / den;
    }
    return Vec2d(ux, uy);
  }
  /// The impulse the wall gives per unit depth over ρ: ∫₀ᵇ P(x, 0) dx / ρ.
  double wallImpulse() const {
    double s = 0;
    for (int k = 1; k < kTerms; k += 2)
      s += 8 * V * b * b / std::pow(k * test::kPi, 3) * std::tanh(k * test::kPi * L / b);
    return s;
  }
};

struct ImpactCase {
  int across, along;  ///< the block's particles across the wall and along its normal
  double speed;       ///< V [m/s]
  double dx;          ///< particle spacing [m]
  Vec2d normal;       ///< the wall's normal into the fluid: (0, 1) the floor, (−1, 0) the right wall, …
};

/// What the first substep left, against the theory: `rms` and `worst` of |v − v_theory|/V
/// over the particles, the fastest particle's speed and the theory's fastest (at the
/// particles' places) over V, the mean normal velocity against the theory's (over V), and the
/// kinetic energy over the block's before.
struct ImpactResult {
  double rms = 0, worst = 0, fastest = 0, theoryFastest = 0, meanNormal = 0, theoryMeanNormal = 0, energy = 0,
         theoryEnergy = 0;
};

ImpactResult flatImpact(const std::string& solver, const ImpactCase& ic) {
  const double dx = ic.dx, b = ic.across * dx, L = ic.along * dx, V = ic.speed;
  SceneDef s = test::wallScene(dx, solver);
  s.gravity = Vec2d(0, 0);
  s.solver.maxSpeed = 400;
  s.bodies.push_back(test::arena());  // the walls' faces at 0 and 4 m
  const Vec2d n = ic.normal, t(-n.y(), n.x());
  // The wall's face: the arena's, on the side n points away from.
  const Vec2d centre(2, 2), wallPoint = centre - n * 2;
  // The block's lattice sits (i + ½) dx from its corners: its first layer dx/2 off the face.
  const Vec2d c0 = wallPoint - t * (b / 2), c1 = wallPoint + t * (b / 2) + n * L;
  s.blocks.push_back(test::block(c0.cwiseMin(c1), c0.cwiseMax(c1), -n * V));
  World w(s, WorldOptions{2});
  const std::size_t count = w.particleCount();
  REQUIRE(count == std::size_t(ic.across * ic.along));
  std::vector<Vec2d> before(count);
  for (std::size_t i = 0; i < count; ++i) before[w.particles().id[i]] = w.worldPosition(i);
  bench::stepSubstep(w);
  REQUIRE(test::allFiniteState(w));
  const ImpulseTheory theory{b, L, V};
  ImpactResult r;
  double sq = 0, ke = 0, normal = 0;
  for (std::uint32_t id = 0; id < count; ++id) {
    const std::size_t i = w.slotOf(id);
    const Vec2d rel = before[id] - (wallPoint - t * (b / 2));
    const Vec2d th = theory.velocity(rel.dot(t), rel.dot(n));
    const Vec2d expected = t * th.x() + n * th.y();
    const Vec2d v = w.particles().v[i].cast<double>();
    const double e = (v - expected).norm() / V;
    sq += e * e;
    r.worst = std::max(r.worst, e);
    r.fastest = std::max(r.fastest, v.norm() / V);
    r.theoryFastest = std::max(r.theoryFastest, expected.norm() / V);
    ke += v.squaredNorm();
    normal += v.dot(n);
    r.theoryEnergy += expected.squaredNorm() / (V * V * double(count));
  }
  r.rms = std::sqrt(sq / double(count));
  r.energy = ke / (V * V * double(count));
  r.meanNormal = normal / (V * double(count));
  r.theoryMeanNormal = (-V * b * L + theory.wallImpulse()) / (V * b * L);
  MESSAGE(solver << " (" << ic.across << " x " << ic.along << " particles, " << V << " m/s, dx " << dx
                 << "): |v − theory|/V rms " << r.rms << ", worst " << r.worst << "; fastest " << r.fastest
                 << " V (theory " << r.theoryFastest << " V); mean normal velocity " << r.meanNormal << " V (theory "
                 << r.theoryMeanNormal << " V); kinetic energy " << r.energy << " of the block's (theory "
                 << r.theoryEnergy << ")");
  return r;
}

/// Four blocks: other widths, lengths, speeds, spacings and walls than one another.
const ImpactCase kCases[] = {
    {10, 20, 10, 0.03, Vec2d(0, 1)},  // onto the floor
    {8, 24, 6, 0.025, Vec2d(-1, 0)},  // into the right wall
    {16, 16, 20, 0.02, Vec2d(0, 1)},  // wide and short, fast
    {12, 30, 15, 0.03, Vec2d(1, 0)},  // into the left wall
};

/// A solver's bounds: the rms of |v − v_theory|/V, and how far the block's mean normal velocity
/// may be from the theory's (as a share of V). Measured over the four blocks: game 0.09–0.11 and
/// 0.03–0.07 (its grid stops the face a little harder: cells two spacings wide), dfsph
/// 0.12–0.21 and 0.00–0.03, pbf 0.19–0.29 and 0.06–0.10 (its position correction stops the
/// face harder still).
struct Bounds {
  double rms, normal;
};

void checkImpulse(const std::string& solver, const Bounds& bound) {
  for (const ImpactCase& ic : kCases) {
    const ImpactResult r = flatImpact(solver, ic);
    // The velocities are the theory's, within the spacing's resolution of its corner.
    CHECK(r.rms <= bound.rms);
    // No particle leaves faster than the theory lets the fastest one at the same spacing
    // (measured 0.67–0.87 of it).
    CHECK(r.fastest <= r.theoryFastest);
    // The wall's impulse: the block's mean normal velocity, and the kinetic energy left at most
    // the theory's + 0.05 of the block's (measured: game and pbf 0.83–0.94 of the theory's,
    // dfsph 0.99–1.02).
    CHECK(std::fabs(r.meanNormal - r.theoryMeanNormal) <= bound.normal);
    CHECK(r.energy <= r.theoryEnergy + 0.05);
  }
}

}  // namespace

TEST_CASE("a block meeting a wall face-on: the first substep is Cooker & Peregrine's pressure impulse (game)") {
  checkImpulse("game", Bounds{0.15, 0.1});
}
TEST_CASE("a block meeting a wall face-on: the first substep is Cooker & Peregrine's pressure impulse (dfsph)") {
  checkImpulse("dfsph", Bounds{0.3, 0.06});
}
TEST_CASE("a block meeting a wall face-on: the first substep is Cooker & Peregrine's pressure impulse (pbf)") {
  checkImpulse("pbf", Bounds{0.4, 0.14});
}
