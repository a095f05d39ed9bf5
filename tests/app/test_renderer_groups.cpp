// The liquid mode's particle groups: solid blobs in their colour with a darker outline, over
// the water and in the air. Numbers about pixels: colours at the centres, the outline's width
// on both sides, the blobs' areas.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "sph2d/render/png_io.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

using namespace sph2d;

namespace {

/// Water 0.3 m × 0.3 m (dx 0.01) on a floor, a red rigid disc of radius 0.08 m against its
/// right side (a spacing from it), and a green elastic disc of radius 0.05 m in the air; 600 px per metre.
SceneDef groupsScene() {
  SceneDef s;
  s.name = "groups";
  s.solver.spacing = 0.01;
  BodyDef floor;
  ShapeDef box;
  box.type = ShapeDef::Type::Box;
  box.center = Vec2d(0.3, -0.05);
  box.halfSize = Vec2d(0.4, 0.05);
  floor.fixtures.push_back(box);
  s.bodies.push_back(floor);
  FluidBlockDef water;
  water.min = Vec2d(0, 0);
  water.max = Vec2d(0.3, 0.3);
  s.blocks.push_back(water);
  auto disc = [](Vec2d c, double r) {
    FluidBlockDef b;
    b.shape = FluidBlockDef::Shape::Circle;
    b.center = c;
    b.radius = r;
    b.min = c - Vec2d(r, r);
    b.max = c + Vec2d(r, r);
    return b;
  };
  GroupDef red;
  red.region = disc(Vec2d(0.385, 0.1), 0.08);
  red.color = 0xE63333u;  // (230, 51, 51)
  GroupDef green;
  green.region = disc(Vec2d(0.55, 0.33), 0.05);
  green.stiffness = 0.5;
  green.color = 0x33CC4Du;  // (51, 204, 77)
  s.groups = {red, green};
  s.render.width = 420;
  s.render.height = 300;
  s.render.camera.automatic = false;
  s.render.camera.min = Vec2d(-0.05, -0.05);
  s.render.camera.max = Vec2d(0.65, 0.45);
  return s;
}

}  // namespace

TEST_CASE("liquid mode: a particle group is a solid blob in its colour with a darker outline") {
  const SceneDef s = groupsScene();
  World world(s, WorldOptions{1});
  REQUIRE(world.groupCount() == 2);
  REQUIRE(world.particles().group.size() == world.particleCount());
  RenderOptions lo;
  lo.mode = "liquid";
  Renderer r(s.render, lo);
  const Frame& f = r.render(world);
  if (const char* dump = std::getenv("SPH2D_TEST_DUMP")) writePngAtomic(dump, f.width, f.height, f.rgba.data());
  const std::vector<double> cam = r.cameraRect();
  auto col = [&](double x) { return int((x - cam[0]) / (cam[2] - cam[0]) * f.width); };
  auto row = [&](double y) { return int((cam[3] - y) / (cam[3] - cam[1]) * f.height); };
  auto px = [&](int c, int rr) { return &f.rgba[4 * (std::size_t(rr) * std::size_t(f.width) + std::size_t(c))]; };
  auto near = [](const std::uint8_t* p, int r0, int g0, int b0) {
    return std::abs(p[0] - r0) <= 3 && std::abs(p[1] - g0) <= 3 && std::abs(p[2] - b0) <= 3;
  };
  // Centres: the group's own colour (the field is flat there: no shading).
  const std::uint8_t* redCentre = px(col(0.385), row(0.1));
  const std::uint8_t* greenCentre = px(col(0.55), row(0.33));
  MESSAGE("centres: red " << int(redCentre[0]) << "," << int(redCentre[1]) << "," << int(redCentre[2]) << "; green "
                          << int(greenCentre[0]) << "," << int(greenCentre[1]) << "," << int(greenCentre[2]));
  CHECK(near(redCentre, 230, 51, 51));
  CHECK(near(greenCentre, 51, 204, 77));
  // The water beside the red blob stays water.
  const std::uint8_t* w = px(col(0.15), row(0.15));
  CHECK(w[2] > w[0] + 60);

  // Along the red blob's middle row: from its centre to the air (right) and to the water (left),
  // the fill, then an outline of the colour darkened (R below 160 and still red), then the rest.
  auto outline = [&](int dir) {
    int c = col(0.385), dark = 0, firstDark = -1;
    for (int k = 0; k < 120; ++k, c += dir) {
      const std::uint8_t* p = px(c, row(0.1));
      const bool red = p[0] > p[1] + 40 && p[0] > p[2] + 40;
      if (!red) break;
      if (p[0] < 160) {
        ++dark;
        if (firstDark < 0) firstDark = k;
      }
    }
    return std::pair<int, int>{dark, firstDark};
  };
  const auto [airSide, airAt] = outline(+1);
  const auto [waterSide, waterAt] = outline(-1);
  MESSAGE("outline: " << airSide << " px on the air side (from " << airAt << " px), " << waterSide
                      << " px on the water side (from " << waterAt << " px); spacing 6 px");
  CHECK((airSide >= 1 && airSide <= 5));
  CHECK((waterSide >= 1 && waterSide <= 5));
  // The outline is at the blob's edge, about its radius (0.08 m: 48 px) out.
  CHECK(std::abs(airAt - 48) <= 4);
  CHECK(std::abs(waterAt - 48) <= 4);

  // Areas: red and green pixels against the discs, within 10 %.
  std::size_t redPx = 0, greenPx = 0;
  for (std::size_t p = 0; p < f.rgba.size(); p += 4) {
    const int R = f.rgba[p], G = f.rgba[p + 1], B = f.rgba[p + 2];
    redPx += R > G + 40 && R > B + 40;
    greenPx += G > R + 40 && G > B + 40;
  }
  const double pxPerM = f.width / (cam[2] - cam[0]);
  const double redArea = kPi<double> * std::pow(0.08 * pxPerM, 2), greenArea = kPi<double> * std::pow(0.05 * pxPerM, 2);
  MESSAGE("areas: red " << redPx << " px (disc " << redArea << "), green " << greenPx << " px (disc " << greenArea
                        << ")");
  CHECK(double(redPx) == doctest::Approx(redArea).epsilon(0.10));
  CHECK(double(greenPx) == doctest::Approx(greenArea).epsilon(0.10));
}

TEST_CASE("liquid mode: a group without a colour of its own is a blob in its material's colour") {
  // The red disc without a colour, of the water; the green one of a material coloured (0.2, 0.4, 0.9).
  SceneDef s = groupsScene();
  for (GroupDef& g : s.groups) g.color = 0;
  MaterialDef water, blue;
  water.name = "water";
  water.color = s.render.water;
  blue.name = "blue";
  blue.color = {0.2, 0.4, 0.9};
  s.materials = {water, blue};
  s.groups[1].region.material = 1;
  World world(s, WorldOptions{1});
  RenderOptions lo;
  lo.mode = "liquid";
  Renderer r(s.render, lo);
  const Frame& f = r.render(world);
  const std::vector<double> cam = r.cameraRect();
  const int c = int((0.55 - cam[0]) / (cam[2] - cam[0]) * f.width),
            rr = int((cam[3] - 0.33) / (cam[3] - cam[1]) * f.height);
  const std::uint8_t* p = &f.rgba[4 * (std::size_t(rr) * std::size_t(f.width) + std::size_t(c))];
  // The material's colour at the centre of the second disc, the water's at the first's.
  for (int k = 0; k < 3; ++k) CHECK(std::abs(int(p[k]) - int(std::lround(s.materials[1].color[k] * 255))) <= 3);
  const int c2 = int((0.385 - cam[0]) / (cam[2] - cam[0]) * f.width),
            r2 = int((cam[3] - 0.1) / (cam[3] - cam[1]) * f.height);
  const std::uint8_t* q = &f.rgba[4 * (std::size_t(r2) * std::size_t(f.width) + std::size_t(c2))];
  for (int k = 0; k < 3; ++k) CHECK(std::abs(int(q[k]) - int(std::lround(s.render.water[k] * 255))) <= 3);
}
