// Granular materials and Box2D bodies: sand holds up a body a liquid of its density lets sink
// (it pushes back by friction, not only by buoyancy), and a moving blade pushes sand into a
// heap that stands where the same material without friction flows level.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "support/fixture.hpp"

namespace sph2d {
namespace {

/// A bed of sand `depth` deep over the game solver's closed tank [0, W] × [0, 0.8] at dx 0.01,
/// inviscid, of 1000 kg/m³ and friction angle `angle` (0: a heavy liquid).
SceneDef sandBed(double W, double depth, double angle) {
  SceneDef s = test::tank("game", W, 0.8, 0.01);
  s.solver.viscosity = 0;
  MaterialDef sand;
  sand.name = "sand";
  sand.density = s.solver.restDensity;
  sand.kind = MaterialDef::Kind::granular;
  sand.frictionAngle = angle;
  s.materials = {sand};
  s.blocks = {test::block({0, 0}, {W, depth})};
  return s;
}

/// The top of the sand over [x0, x1]: the highest particle's centre plus half a spacing.
double topIn(const World& w, double x0, double x1) {
  double top = 0;
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const Vec2d p = w.worldPosition(i);
    if (p.x() >= x0 && p.x() < x1) top = std::max(top, p.y() + 0.005);
  }
  return top;
}

}  // namespace

TEST_CASE("granular: sand bears a box 2.5 times as dense on its surface, the more the steeper its angle") {
  // A box 0.16 m × 0.08 m of 2500 kg/m³ set on a 0.25 m bed. Its pressure on the sand, 0.08 ρ_b g
  // = 200 g Pa, is below the bed's bearing capacity (½ γ B N_γ: N_γ ≈ 5, 20, 200 at 20°, 30°,
  // 45°, Terzaghi): it presses in a little, less the larger the angle, and stops. Without
  // friction the bed is a liquid of 1000 kg/m³ and the box sinks to the floor.
  std::vector<double> bottoms, speeds;
  const std::vector<double> angles{20, 30, 45, 0};
  for (const double angle : angles) {
    SceneDef s = sandBed(1.0, 0.25, angle);
    BodyDef box;
    box.type = BodyDef::Type::Dynamic;
    box.position = Vec2d(0.5, 0.25 + 0.04 + 0.005);
    ShapeDef shape = test::boxShape({0, 0}, {0.08, 0.04});
    shape.density = 2500;
    box.fixtures.push_back(shape);
    s.bodies.push_back(box);
    World w(s, WorldOptions{2});
    for (int f = 0; f < 3 * 60; ++f) w.stepFrame();
    REQUIRE(test::allFiniteState(w));
    const b2Body* b = test::dynamicBody(w);
    REQUIRE(b);
    bottoms.push_back(test::bottomOf(b));
    speeds.push_back(b->GetLinearVelocity().Length());
    MESSAGE("friction angle " << angle << "°: the box's bottom at " << bottoms.back()
                              << " m after 3 s (bed top 0.25), speed " << speeds.back() << " m/s");
  }
  for (std::size_t k = 0; k < 3; ++k) {
    CHECK(bottoms[k] > 0.25 - 0.08);  // in by less than its height
    CHECK(speeds[k] < 0.005);         // at rest
  }
  CHECK(bottoms[0] < bottoms[1]);  // the steeper the angle, the less it presses in
  CHECK(bottoms[1] < bottoms[2]);
  CHECK(bottoms[3] < 0.05);  // through the liquid to the floor
}

TEST_CASE("granular: a box pressing into sand gives the same bits on 1, 2 and 3 threads") {
  std::uint64_t h[3] = {0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    SceneDef s = sandBed(0.6, 0.15, 30);
    BodyDef box;
    box.type = BodyDef::Type::Dynamic;
    box.position = Vec2d(0.3, 0.2);
    box.angle = 0.3;
    ShapeDef shape = test::boxShape({0, 0}, {0.06, 0.03});
    shape.density = 2500;
    box.fixtures.push_back(shape);
    s.bodies.push_back(box);
    World w(s, WorldOptions{k + 1});
    for (int f = 0; f < 40; ++f) w.stepFrame();
    h[k] = w.stateHash();
  }
  CHECK(h[0] == h[1]);
  CHECK(h[0] == h[2]);
}

TEST_CASE("granular: a moving blade pushes sand into a heap that stands, and without friction it flows level") {
  // A kinematic blade 0.04 m thick, from the floor to above the 0.1 m bed, moves right at
  // 0.25 m/s for 2 s (0.5 m), then stops. Ahead of it the sand is a heap that falls off to
  // the bed beyond, and stands from 0.5 s to 2.5 s after the stop; behind it the bed falls
  // off into the trench the blade left. The frictionless material flows level on each side.
  // Relief: the top next to the blade less the top 0.3 m from it (ahead), the top by the left
  // wall less the top in the trench (behind).
  double ahead[2] = {0, 0}, behind[2] = {0, 0};
  for (const double angle : {30.0, 0.0}) {
    SceneDef s = sandBed(1.2, 0.1, angle);
    s.blocks = {test::block({0, 0}, {0.175, 0.1}), test::block({0.225, 0}, {1.2, 0.1})};  // none in the blade
    BodyDef blade;
    blade.type = BodyDef::Type::Kinematic;
    blade.position = Vec2d(0.2, 0.155);
    blade.velocity = Vec2d(0.25, 0);
    blade.fixtures.push_back(test::boxShape({0, 0}, {0.02, 0.15}));
    s.bodies.push_back(blade);
    World w(s, WorldOptions{2});
    const std::size_t n = w.particleCount();
    double x0 = 0;  // Σ x over the grains: the blade pushes them along
    for (std::size_t i = 0; i < n; ++i) x0 += w.worldPosition(i).x();
    for (int f = 0; f < 2 * 60; ++f) w.stepFrame();
    for (b2Body* b = w.box2d().GetBodyList(); b; b = b->GetNext())
      if (b->GetType() == b2_kinematicBody) b->SetLinearVelocity(b2Vec2(0, 0));
    for (int f = 0; f < 30; ++f) w.stepFrame();
    const double early = topIn(w, 0.72, 0.82) - topIn(w, 1.05, 1.15);  // the blade's face at 0.72
    for (int f = 0; f < 120; ++f) w.stepFrame();
    REQUIRE(test::allFiniteState(w));
    double x1 = 0;
    for (std::size_t i = 0; i < w.particleCount(); ++i) x1 += w.worldPosition(i).x();
    const int k = angle > 0 ? 0 : 1;
    ahead[k] = topIn(w, 0.72, 0.82) - topIn(w, 1.05, 1.15);
    behind[k] = topIn(w, 0.02, 0.12) - topIn(w, 0.45, 0.55);
    MESSAGE("friction angle " << angle << "°: relief ahead " << early << " m 0.5 s after the stop, " << ahead[k]
                              << " m 2.5 s after; behind " << behind[k] << " m; the grains' mean x moved "
                              << (x1 - x0) / double(n) << " m");
    CHECK(x1 > x0);                             // pushed along
    if (k == 0) CHECK(ahead[0] > 0.9 * early);  // the heap stands
  }
  CHECK(ahead[0] > 0.05);                       // a heap ahead, half the bed's depth above the bed beyond
  CHECK(behind[0] > 0.05);                      // a trench behind
  CHECK(std::fabs(ahead[1]) < 0.3 * ahead[0]);  // the liquid flows level
  CHECK(std::fabs(behind[1]) < 0.3 * behind[0]);
}

}  // namespace sph2d
