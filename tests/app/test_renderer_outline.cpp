// The renderer's --outline: the fluid's outline (surfaceCurves) drawn over the water. A block
// of water on a floor, rendered with and without it: every pixel the outline changes lies
// within two pixels of where the particles' squares end, and it runs along the block's top.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>

#include "app_util.hpp"
#include "sph2d/render/png_io.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

using namespace sph2d;
using namespace sph2d::apptest;

TEST_CASE("--outline draws the fluid's outline where its particles end, in both modes") {
  // Water 0.4 m × 0.2 m (dx 0.01) resting on a floor, 700 px per metre.
  SceneDef s;
  s.name = "outline";
  s.solver.spacing = 0.01;
  BodyDef floor;
  ShapeDef box;
  box.type = ShapeDef::Type::Box;
  box.center = Vec2d(0.3, -0.05);
  box.halfSize = Vec2d(0.4, 0.05);
  floor.fixtures.push_back(box);
  s.bodies.push_back(floor);
  FluidBlockDef water;
  water.min = Vec2d(0.1, 0);
  water.max = Vec2d(0.5, 0.2);
  s.blocks.push_back(water);
  s.render.width = 420;
  s.render.height = 280;
  s.render.camera.automatic = false;
  s.render.camera.min = Vec2d(0, -0.05);
  s.render.camera.max = Vec2d(0.6, 0.35);
  World world(s, WorldOptions{1});
  for (const std::string mode : {"liquid", "particles"}) {
    CAPTURE(mode);
    RenderOptions plain;
    plain.mode = mode;
    RenderOptions lined = plain;
    lined.outline = true;
    Renderer r0(s.render, plain), r1(s.render, lined);
    const Frame& a = r0.render(world);
    const Frame& b = r1.render(world);
    if (const char* dump = std::getenv("SPH2D_TEST_DUMP")) writePngAtomic(dump, b.width, b.height, b.rgba.data());
    const std::vector<double> cam = r1.cameraRect();
    const double pxPerM = a.width / (cam[2] - cam[0]);
    // The outline's place: the block's edges (its particles' squares end on them), the top
    // y = 0.2, the sides x = 0.1 and 0.5 and the floor y = 0, rounded within two and a half
    // spacings of the corners (the field is smoothed over about a spacing); pixel centres in
    // world coordinates.
    int changed = 0, stray = 0, onTop = 0;
    for (int row = 0; row < a.height; ++row)
      for (int col = 0; col < a.width; ++col) {
        const std::size_t k = 4 * (std::size_t(row) * std::size_t(a.width) + std::size_t(col));
        if (a.rgba[k] == b.rgba[k] && a.rgba[k + 1] == b.rgba[k + 1] && a.rgba[k + 2] == b.rgba[k + 2]) continue;
        ++changed;
        const double x = cam[0] + (col + 0.5) / pxPerM, y = cam[3] - (row + 0.5) / pxPerM;
        const double tol = 2.0 / pxPerM;
        const bool top = std::fabs(y - 0.2) < tol && x > 0.1 - tol && x < 0.5 + tol;
        const bool side = (std::fabs(x - 0.1) < tol || std::fabs(x - 0.5) < tol) && y > -tol && y < 0.2 + tol;
        const bool bottom = std::fabs(y) < tol && x > 0.1 - tol && x < 0.5 + tol;
        bool corner = false;
        for (const double cx : {0.1, 0.5})
          for (const double cy : {0.0, 0.2}) corner = corner || std::hypot(x - cx, y - cy) < 0.025;
        if (top) ++onTop;
        if (!top && !side && !bottom && !corner) ++stray;
      }
    MESSAGE(changed << " pixels changed, " << onTop << " along the top, " << stray << " elsewhere");
    CHECK(onTop > int(0.35 * pxPerM));  // most of the 0.4 m top (280 px)
    CHECK(stray == 0);
  }
}

TEST_CASE("--outline is recorded in the manifest: sph2d check redraws it, and without it the frames differ") {
  const std::string dir = freshDir("outline_check");
  const std::string scene = asset("scenes/tests/small_dam_break.json");
  REQUIRE(run("run " + q(scene) + " --frames 11 --every 5 --outline --quiet --out " + q(dir)).code == 0);
  const std::string manifest = readText(dir + "/manifest.json");
  REQUIRE(manifest.find("\"outline\": true") != std::string::npos);
  CHECK(run("check " + q(scene) + " --against " + q(dir + "/manifest.json") + " --out " + q(dir + "_check")).code == 0);
  // The same manifest saying no outline: the rerun's first frame differs.
  std::string plain = manifest;
  plain.replace(plain.find("\"outline\": true"), std::string("\"outline\": true").size(), "\"outline\": false");
  std::ofstream(dir + "/plain.json") << plain;
  CHECK(run("check " + q(scene) + " --against " + q(dir + "/plain.json") + " --out " + q(dir + "_plain")).code != 0);
}
