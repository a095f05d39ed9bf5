// Moving bodies and the fluid's momentum: a tank sloshing with and without a crate, the fluid's
// impulse on the walls and on the bodies against its momentum change.
#include <doctest/doctest.h>

#include <box2d/box2d.h>

#include <cmath>
#include <map>
#include <sstream>

#include "support/fixture.hpp"

using namespace sph2d;

namespace {

using test::dynamicBody;

/// The momentum balance of water in a 2 m × 1 m tank (0.4 m deep, spacing 0.02) over one
/// simulated second (what the tests below measure and print).
struct TankBalance {
  Vec2d p0{0, 0};        ///< P_fluid + P_crate at the start
  Vec2d dp{0, 0};        ///< Δ(P_fluid + P_crate)
  Vec2d gravity{0, 0};   ///< (M_fluid + M_crate) g T
  WallImpulse wall;      ///< World::wallImpulse() over the second
  Vec2d crate{0, 0};     ///< the crate's momentum at the end
  bool touched = false;  ///< the crate touched a static fixture (a Box2D contact) at a frame's end
  Vec2d residual() const { return dp - gravity - wall.total(); }
};

/// Runs the tank with `solver` on `threads` threads. With `slosh` the water starts in the
/// tank's first sloshing mode, u = U sin(πx/W), w = −U (π/W) y cos(πx/W) (divergence-free, no
/// flow through the floor or the walls), U = 0.4 m/s: it carries 0.25 m/s · M of horizontal
/// momentum that the walls turn back; else it starts at rest. With `crate`, a crate of density
/// 500 (0.6 m × 0.2 m) floats at Archimedes' draught (0.1 m) in the middle, 0.7 m from each
/// wall: it never reaches one (touched says whether Box2D saw a contact), so no contact impulse
/// between crate and walls enters the balance.
TankBalance tankBalance(const std::string& solver, bool slosh, bool crate, int threads = 2) {
  const double W = 2.0, depth = 0.4, U = slosh ? 0.4 : 0.0;
  // "NAME+no_slip": the solver with solver.no_slip (the viscosity effect's wall term).
  const bool noSlip = solver.size() > 8 && solver.compare(solver.size() - 8, 8, "+no_slip") == 0;
  SceneDef s = test::tank(noSlip ? solver.substr(0, solver.size() - 8) : solver, W, 1.0, 0.02);
  if (noSlip) {
    REQUIRE(s.solver.viscosity > 0);
    s.solver.noSlip = true;
  }
  s.blocks.push_back(test::block({0, 0}, {W, depth}));
  if (crate) {
    BodyDef b;
    b.type = BodyDef::Type::Dynamic;
    b.position = Vec2d(1.0, depth);
    ShapeDef box = test::boxShape({0, 0}, {0.3, 0.1});
    box.density = 500;
    b.fixtures.push_back(box);
    s.bodies.push_back(b);
  }
  World w(s, WorldOptions{threads});
  std::vector<std::uint32_t> ids;
  std::vector<Vec2d> vel;
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const Vec2d x = w.worldPosition(i);
    ids.push_back(w.particles().id[i]);
    vel.emplace_back(U * std::sin(test::kPi * x.x() / W), -U * test::kPi / W * x.y() * std::cos(test::kPi * x.x() / W));
  }
  w.setVelocities(ids, vel);
  const b2Body* body = dynamicBody(w);
  REQUIRE(bool(body) == crate);
  auto crateMomentum = [&] {
    return body ? Vec2d(Vec2d(body->GetLinearVelocity().x, body->GetLinearVelocity().y) * double(body->GetMass()))
                : Vec2d(0, 0);
  };
  const std::size_t n = w.particleCount();
  const double t0 = w.time();
  TankBalance r;
  r.p0 = test::momentum(w) + crateMomentum();
  w.resetWallImpulse();
  for (int f = 0; f < int(s.fps); ++f) {
    w.stepFrame();
    for (const b2ContactEdge* ce = body ? body->GetContactList() : nullptr; ce; ce = ce->next)
      if (ce->contact->IsTouching() && ce->other->GetType() == b2_staticBody) r.touched = true;
  }
  REQUIRE(w.particleCount() == n);  // the fluid's mass is constant
  r.crate = crateMomentum();
  r.dp = test::momentum(w) + r.crate - r.p0;
  const Vec2d g(w.box2d().GetGravity().x, w.box2d().GetGravity().y);
  r.gravity = (double(n) * double(w.particleMass()) + (body ? double(body->GetMass()) : 0.0)) * g * (w.time() - t0);
  r.wall = w.wallImpulse();
  return r;
}

/// One line of figures for MESSAGE.
std::string describe(const TankBalance& b) {
  const Vec2d r = b.residual(), w = b.wall.total();
  std::ostringstream o;
  o << "Δp (" << b.dp.x() << ", " << b.dp.y() << "), gravity (" << b.gravity.x() << ", " << b.gravity.y() << "), wall ("
    << w.x() << ", " << w.y() << ") = samples (" << b.wall.samples.x() << ", " << b.wall.samples.y() << ") + grid ("
    << b.wall.grid.x() << ", " << b.wall.grid.y() << ") + collision (" << b.wall.collision.x() << ", "
    << b.wall.collision.y() << ") kg m/s; residual (" << r.x() << ", " << r.y()
    << ") = " << 100 * r.norm() / b.gravity.norm() << " % of |gravity|";
  if (w.x() != 0) o << ", x: " << 100 * std::fabs(r.x()) / std::fabs(w.x()) << " % of the walls' x";
  return o.str();
}

}  // namespace

TEST_CASE(
    "moving bodies: over a second of a crate in a sloshing tank, the change of water-plus-crate momentum is gravity's impulse plus the walls' within 5 %") {
  // Issue 16: Δ(P_fluid + P_crate) = Σ m g T + World::wallImpulse() (the crate never touches a
  // wall, so no Box2D contact impulse enters). The residual is normalised by |gravity's impulse|
  // (both axes), and the horizontal balance, where gravity does not act, separately by the
  // walls' horizontal impulse. The game solver's grid figures are grid-level (its particle ↔ grid
  // transfer does not conserve momentum): 1.3 % measured, held to the 5 %. The other
  // solvers count each wall term where they apply it and close to rounding (≤ 1e-8 of |gravity|
  // for wcsph and dfsph, 5e-6 for pbf, whose XSPH sum is not exactly antisymmetric): they are
  // held to 1e-6 and 1e-4, so that a lost part shows (wcsph's collision, 4e-6 of it, is the
  // smallest). muller2003 counts its wall pressure and, with no_slip, the viscosity's wall term
  // (folded into its pressure force; wcsph+no_slip: the viscosity effect's own stage).
  // docs/STABILITY.md, "Momentum balance", has the figures.
  for (const std::string solver :
       {"game", "wcsph", "dfsph", "pbf", "muller2003", "muller2003+no_slip", "wcsph+no_slip"}) {
    INFO(solver);
    const TankBalance b = tankBalance(solver, true, true);
    const Vec2d r = b.residual(), w = b.wall.total();
    const double G = b.gravity.norm();
    MESSAGE(solver << ": " << describe(b) << "; crate (" << b.crate.x() << ", " << b.crate.y() << ")");
    CHECK_FALSE(b.touched);
    CHECK(std::fabs(w.x()) > std::fabs(b.p0.x()));  // the walls turned the slosh back
    CHECK(b.crate.norm() > 5.0);                    // the water moved the crate
    const double tol = solver == "game" ? 0.05 : solver == "pbf" ? 1e-4 : 1e-6;
    CHECK(r.norm() <= tol * G);
    CHECK(std::fabs(r.x()) <= tol * std::fabs(w.x()));
    CHECK(std::fabs(r.y()) <= tol * std::fabs(b.gravity.y()));
  }
}

TEST_CASE(
    "moving bodies: water at rest in a tank: over a second the walls' impulse is the water's weight, within 1 % for the game solver") {
  // At rest the game solver's grid attribution is exact but for the particles' density
  // (0.19 % measured); it holds the two grid parts apart: without the closed faces' own
  // velocity change (the half cell between the floor and the lowest cell centres) it is 4.9 %
  // short (measured), without the cells' pressure on the faces all but that.
  for (const std::string solver : {"game", "wcsph", "dfsph", "pbf"}) {
    INFO(solver);
    const TankBalance b = tankBalance(solver, false, false);
    MESSAGE(solver << " at rest: " << describe(b));
    const double tol = solver == "game" ? 0.01 : 1e-4;
    CHECK(b.residual().norm() <= tol * b.gravity.norm());
    CHECK(b.wall.total().y() == doctest::Approx(-b.gravity.y()).epsilon(0.01));  // the floor holds the water up
  }
}

TEST_CASE("moving bodies: the walls' impulse on a sloshing tank with a crate has the same bits on 1, 2 and 3 threads") {
  for (const std::string solver : {"game", "wcsph", "dfsph", "pbf", "muller2003+no_slip"}) {
    INFO(solver);
    const TankBalance ref = tankBalance(solver, true, true, 1);
    for (int threads = 2; threads <= 3; ++threads) {
      const TankBalance b = tankBalance(solver, true, true, threads);
      const WallImpulse &a = ref.wall, &c = b.wall;
      CHECK_MESSAGE((a.samples == c.samples && a.grid == c.grid && a.collision == c.collision), "threads " << threads);
    }
  }
}
