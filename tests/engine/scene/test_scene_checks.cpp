// The scene checks (engine/src/scene_checks.*), called directly: Box2D's
// geometry rules, fluid blocks against the spacing and the solids, names and
// limits, each at its boundary. The same errors through whole scenes are in
// test_scene_errors.cpp.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "scene/json_reader.hpp"
#include "scene/scene_checks.hpp"
#include "scene/scene_reader.hpp"

using namespace sph2d;

namespace {

/// Runs `fn` with a Reader over an empty document; returns the message it
/// failed with ("" when it passed). `key` receives the key path of the failure.
template <class Fn>
std::string failure(Fn fn, std::string* key = nullptr) {
  const JsonDoc doc = parseJsonWithPositions("{}", "c.json");
  const Reader r(doc, "c.json");
  try {
    fn(r);
  } catch (const SceneError& e) {
    if (key) *key = e.key;
    return e.message;
  }
  return "";
}

std::string polygon(const std::vector<Vec2d>& v) {
  return failure([&](const Reader& r) { checkPolygon(r, v, "p.vertices"); });
}

}  // namespace

TEST_CASE("checkPolygon accepts convex polygons in either orientation and refuses what Box2D would assert on") {
  CHECK(polygon({{0, 0}, {1, 0}, {1, 1}, {0, 1}}) == "");
  CHECK(polygon({{0, 0}, {0, 1}, {1, 1}, {1, 0}}) == "");
  CHECK(polygon({{0, 0}, {0.5, 0}, {1, 0}, {1, 1}, {0, 1}}) == "");  // a straight vertex: Box2D's hull drops it
  CHECK(polygon({{0, 0}, {1, 0}, {0.5, 4e-6}}) == "");               // the thinnest Box2D takes
  std::string key;
  CHECK(failure(
            [](const Reader& r) {
              checkPolygon(r, {{0, 0}, {1, 0}}, "p.vertices");
            },
            &key) == "a polygon needs 3 to 8 vertices (Box2D 2.4.1), got 2");
  CHECK(key == "p.vertices");
  std::vector<Vec2d> nine;
  for (int k = 0; k < 9; ++k) nine.push_back(Vec2d(std::cos(k * 0.698), std::sin(k * 0.698)));
  CHECK(polygon(nine) == "a polygon needs 3 to 8 vertices (Box2D 2.4.1), got 9");
  CHECK(polygon({{0, 0}, {1, 0}, {1, 1}, {1.001, 1}}) ==
        "vertices [2] and [3] are closer than 0.005 m (Box2D's linear slop)");
  CHECK(polygon({{0, 0}, {2, 0}, {1, 0.2}, {2, 2}, {0, 2}}) ==
        "the polygon must be convex (split a concave shape into several fixtures)");
  CHECK(polygon({{0, 0}, {2, 0}, {1, 0}, {1, 1}}) ==
        "the polygon must be convex: its outline doubles back at vertex [1]");
  CHECK(polygon({{1, 0}, {-0.809, 0.588}, {0.309, -0.951}, {0.309, 0.951}, {-0.809, -0.588}}) ==
        "the polygon must be convex: its edges cross (the outline winds around more than once)");
  // Convex in double, but a sliver in Box2D's float arithmetic.
  CHECK(polygon({{0, 0}, {1, 0}, {0.5, 1e-6}})
            .rfind("the polygon is too thin: its area in Box2D's float arithmetic is 5e-07 m^2", 0) == 0);
  // 0.01 m apart in double, one float at 1e7: Box2D would weld them.
  CHECK(polygon({{1e7, 1e7}, {9999999.99, 1e7}, {1e7, 9999999.99}}) ==
        "vertices [0] and [1] are closer than 0.005 m (Box2D's linear slop)");
}

TEST_CASE("checkEdge and checkChain refuse too few vertices and segments shorter than the slop, at the vertex") {
  CHECK(failure([](const Reader& r) { checkEdge(r, {{0, 0}, {0.0051, 0}}, "e"); }) == "");
  CHECK(failure([](const Reader& r) {
          checkEdge(r, {{0, 0}, {0.004, 0}}, "e");
        }) == "the edge is shorter than 0.005 m (Box2D's linear slop)");
  CHECK(failure([](const Reader& r) { checkEdge(r, {{0, 0}}, "e"); }) == "an edge needs exactly 2 vertices, got 1");
  CHECK(failure([](const Reader& r) { checkChain(r, {{0, 0}, {1, 0}}, false, "c"); }) == "");
  CHECK(failure([](const Reader& r) {
          checkChain(r, {{0, 0}}, false, "c");
        }) == "an open chain needs at least 2 vertices, got 1");
  CHECK(failure([](const Reader& r) {
          checkChain(r, {{0, 0}, {1, 0}}, true, "c");
        }) == "a looped chain needs at least 3 vertices, got 2");
  std::string key;
  CHECK(failure(
            [](const Reader& r) {
              checkChain(r, {{0, 0}, {1, 0}, {1.003, 0}, {2, 1}}, false, "c");
            },
            &key) == "chain vertices [1] and [2] are closer than 0.005 m (Box2D's linear slop)");
  CHECK(key == "c[2]");
  CHECK(failure(
            [](const Reader& r) {
              checkChain(r, {{0, 0}, {1, 0}, {1, 1}, {0, 0.001}}, true, "c");
            },
            &key)
            .rfind("the last vertex of a looped chain is closer than 0.005 m to the first", 0) == 0);
  CHECK(key == "c[3]");
}

TEST_CASE("box half sizes and circle radii are at least half of Box2D's linear slop") {
  std::string key;
  CHECK(failure([](const Reader& r) { checkBoxHalfSize(r, Vec2d(0.0025, 0.0025), "f"); }) == "");
  CHECK(failure([](const Reader& r) { checkBoxHalfSize(r, Vec2d(1, 0), "f"); }, &key) ==
        "both half sizes must be > 0, got [1, 0]");
  CHECK(key == "f.half_size");
  CHECK(failure([](const Reader& r) {
          checkBoxHalfSize(r, Vec2d(0.0024, 1), "f");
        }).rfind("both half sizes must be >= 0.0025", 0) == 0);
  CHECK(failure([](const Reader& r) { checkCircleRadius(r, 0.0025, "f"); }) == "");
  CHECK(
      failure([](const Reader& r) { checkCircleRadius(r, 0.0024, "f"); }, &key).rfind("value 0.0024 is too small", 0) ==
      0);
  CHECK(key == "f.radius");
}

TEST_CASE("checkBlock refuses a block thinner than a spacing or entirely inside one solid") {
  SceneDef s;
  s.solver.spacing = 0.1;
  BodyDef body;
  body.position = Vec2d(1, 1);
  body.angle = 0.3;
  ShapeDef box;
  box.halfSize = Vec2d(1, 1);
  body.fixtures.push_back(box);
  ShapeDef ring;  // a looped chain around everything: no inside
  ring.type = ShapeDef::Type::Chain;
  ring.loop = true;
  ring.vertices = {{-10, -10}, {10, -10}, {10, 10}, {-10, 10}};
  body.fixtures.push_back(ring);
  s.bodies.push_back(body);
  const auto block = [](Vec2d min, Vec2d max) {
    FluidBlockDef b;
    b.min = min;
    b.max = max;
    return b;
  };
  std::string key;
  CHECK(failure(
            [&](const Reader& r) {
              checkBlock(r, s, block({0.8, 0.8}, {1.2, 1.2}), "fluid[0]");
            },
            &key) ==
        "the block lies entirely inside boundaries[0].fixtures[0] (a box): every particle would be dropped");
  CHECK(key == "fluid[0]");
  CHECK(failure([&](const Reader& r) {
          checkBlock(r, s, block({0.5, 0.5}, {2.5, 2.5}), "fluid[0]");
        }) == "");  // partly inside
  CHECK(failure(
            [&](const Reader& r) {
              checkBlock(r, s, block({5, 5}, {5.09, 6}), "fluid[0]");
            },
            &key) ==
        "the block is 0.09 m x 1 m, less than one particle spacing (0.1 m) wide: it would hold no particle");
  CHECK(key == "fluid[0].max");
  CHECK(failure([&](const Reader& r) {
          checkBlock(r, s, block({5, 5}, {6, 5.09}), "fluid[0]");
        }).find(") high: it would") != std::string::npos);
  CHECK(failure([](const Reader& r) { checkMaxAboveMin(r, Vec2d(0, 0), Vec2d(1, 0), "b"); }, &key) ==
        "max must be greater than min in x and in y");
  CHECK(key == "b.max");
}

TEST_CASE("names, frame counts, periods and cameras are checked at their limits") {
  for (const char* bad : {"", ".", "..", "a/b", "a\\b", "tab\there"}) {
    INFO(bad);
    CHECK(failure([&](const Reader& r) { checkName(r, bad); }).find("the name names the output directory out/<name>") !=
          std::string::npos);
  }
  CHECK(failure([](const Reader& r) { checkName(r, std::string(200, 'x')); }) == "");
  CHECK(failure([](const Reader& r) {
          checkName(r, std::string(201, 'x'));
        }).rfind("the name is longer than 200 bytes", 0) == 0);

  std::string key;
  CHECK(failure([](const Reader& r) { checkFrameCount(r, 1000, 1000, "duration"); }) == "");
  CHECK(failure([](const Reader& r) { checkFrameCount(r, 1000.5, 1000, "fps"); }, &key)
            .rfind("duration x fps = 1000.5 s x 1000", 0) == 0);
  CHECK(key == "fps");

  CHECK(failure([](const Reader& r) { checkPeriod(r, Vec2d(0, 0.75), 0.25, "periodic.x"); }) == "");
  CHECK(failure([](const Reader& r) { checkPeriod(r, Vec2d(0, 0.74), 0.25, "periodic.x"); }, &key) ==
        "the period [0, 0.74] is 0.74 m long; it must be at least 3 support radii (3 x 0.25 m) long, min < max");
  CHECK(key == "periodic.x");
  CHECK(failure([](const Reader& r) { checkPeriod(r, Vec2d(1, 0), 0.25, "periodic.y"); }) != "");

  CameraDef cam;
  cam.min = Vec2d(0, 0);
  cam.max = Vec2d(4, 0.001);
  CHECK(failure([&](const Reader& r) { checkCamera(r, cam, "render.camera"); }) == "");
  cam.max = Vec2d(4, 0.0009);
  CHECK(failure([&](const Reader& r) { checkCamera(r, cam, "render.camera"); }, &key) ==
        "the camera shows 4 m x 0.0009 m; it must be at least 0.001 m wide and high");
  CHECK(key == "render.camera.max");
  cam.max = Vec2d(-1, 1);
  CHECK(failure([&](const Reader& r) { checkCamera(r, cam, "render.camera"); }) ==
        "max must be greater than min in x and in y");
}

TEST_CASE("the particle budget counts the blocks' lattice and the solids' samples, without overflow") {
  SceneDef s;
  s.solver.spacing = 0.1;
  FluidBlockDef wide, thin;
  wide.min = Vec2d(0, 0);
  wide.max = Vec2d(1, 0.5);
  thin.min = Vec2d(2, 0);
  thin.max = Vec2d(2.05, 1);  // thinner than a spacing: none
  s.blocks.push_back(wide);
  s.blocks.push_back(thin);
  CHECK(countBlockParticles(s) == 50);
  s.maxParticles = 50;
  CHECK(failure([&](const Reader& r) { checkParticleBudget(r, s); }) == "");
  s.maxParticles = 49;
  std::string key;
  CHECK(
      failure([&](const Reader& r) { checkParticleBudget(r, s); }, &key) ==
      "spacing 0.1 fills the fluid blocks with 50 particles, more than max_particles = 49; use a larger spacing or raise max_particles");
  CHECK(key == "solver.spacing");
  s.solver.spacing = 1e-300;
  CHECK(countBlockParticles(s) == std::numeric_limits<std::size_t>::max() / 2);
  CHECK(failure([&](const Reader& r) { checkParticleBudget(r, s); }).find("with too many particles") !=
        std::string::npos);

  // Samples: a 4 m box at 1e-5 m needs about 4.8 million, over the 4 million allowed
  // to any scene, within a max_particles of 5 million.
  SceneDef solid;
  solid.solver = solverDefaults("muller2003");  // support 2.5 spacings: three layers of samples
  solid.solver.spacing = 1e-5;
  BodyDef body;
  ShapeDef box;
  box.halfSize = Vec2d(2, 2);
  body.fixtures.push_back(box);
  solid.bodies.push_back(body);
  CHECK(
      failure([&](const Reader& r) { checkParticleBudget(r, solid); }) ==
      "spacing 1e-05 lines the solids with about 4800000 boundary samples, more than max(max_particles, 4000000) = 4000000; "
      "use a larger spacing or smaller solids");
  solid.maxParticles = 5000000;
  CHECK(failure([&](const Reader& r) { checkParticleBudget(r, solid); }) == "");
}
