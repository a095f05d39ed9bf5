// The liquid's splat summed on the CPU (engine/render/src/cpu_splat.hpp) against the GL's point
// sprites: the same frames, to float rounding, for every target the splat fills (the field,
// the materials' colours and transmissions, the groups' blobs), at every size of sprite (full
// and half resolution, and beyond the point-size limit, where the GL draws quads), frame after
// frame of a moving scene (rows the fluid has left are cleared).
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "../test_util.hpp"
#include "cpu_splat.hpp"
#include "sph2d/render/png_io.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

using namespace sph2d;

namespace {

/// How two frames differ: the largest change of a channel, and the share of pixels changed.
struct FrameDiff {
  int maxLevel = 0;
  double share = 0;
  bool glQuads = false;  ///< the GL path drew quads (sprites beyond its point-size limit)
};

FrameDiff compare(const Frame& a, const Frame& b) {
  REQUIRE(a.width == b.width);
  REQUIRE(a.height == b.height);
  FrameDiff d;
  std::size_t changed = 0;
  const std::size_t pixels = std::size_t(a.width) * std::size_t(a.height);
  for (std::size_t p = 0; p < pixels; ++p) {
    int m = 0;
    for (std::size_t c = 0; c < 3; ++c) m = std::max(m, std::abs(int(a.rgba[4 * p + c]) - int(b.rgba[4 * p + c])));
    d.maxLevel = std::max(d.maxLevel, m);
    changed += m > 0;
  }
  d.share = double(changed) / double(pixels);
  return d;
}

RenderOptions splatOn(SplatPath s) {
  RenderOptions o;
  o.splat = s;
  return o;
}

/// Renders `scene` by both paths `frames` times, stepping `every` frames after each (each
/// renderer kept from frame to frame, as a run keeps it), and returns the worst difference.
/// Each frame must show the fluid over a share of the image (against the same frame without
/// particles): a frame of background alone would compare equal whatever the splat did.
FrameDiff bothPaths(const SceneDef& scene, int frames, int every) {
  World world(scene, WorldOptions{2});
  Renderer gl(scene.render, splatOn(SplatPath::Gl));
  Renderer cpu(scene.render, splatOn(SplatPath::Cpu));
  Renderer empty(scene.render);
  REQUIRE(gl.splatPath() == "gl");
  REQUIRE(cpu.splatPath() == "cpu");
  FrameDiff worst;
  for (int f = 0; f < frames; ++f) {
    if (f) {
      for (int k = 0; k < every; ++k) world.stepFrame();
    }
    RenderInput none;
    ParticleBuffer noParticles;
    none.particles = noParticles.view();
    none.origin = world.origin();
    none.spacing = world.spacing();
    none.colliders = &world.colliders();
    const Frame background = empty.render(none);
    const Frame& a = gl.render(world);
    CHECK(compare(a, background).share > 0.02);
    const Frame& b = cpu.render(world);
    const FrameDiff d = compare(a, b);
    worst.maxLevel = std::max(worst.maxLevel, d.maxLevel);
    worst.share = std::max(worst.share, d.share);
    worst.glQuads = gl.usedQuads();
    if (const char* dump = std::getenv("SPH2D_TEST_DUMP")) {
      writePngAtomic(std::string(dump) + "_gl.png", a.width, a.height, a.rgba.data());
      writePngAtomic(std::string(dump) + "_cpu.png", b.width, b.height, b.rgba.data());
    }
  }
  return worst;
}

}  // namespace

TEST_CASE("liquid: the splat summed on the CPU draws the GL's frames, on a software GL by default") {
  const SceneDef s = test::scene("dam_break.json");
  Renderer automatic(s.render);
  // The tests run on OSMesa: llvmpipe (or softpipe), a software rasterizer, where the CPU sums.
  const bool software = softwareRasterizer(automatic.rendererString().c_str());
  CHECK(software);
  CHECK(automatic.splatPath() == (software ? "cpu" : "gl"));
  RenderOptions particles;
  particles.mode = "particles";
  CHECK(Renderer(s.render, particles).splatPath().empty());
  // The dam break as it falls and splashes (spray, lone drops, foam on fast water), frame
  // after frame: the rows the column leaves must be cleared, the new ones filled.
  const FrameDiff d = bothPaths(s, 12, 10);
  MESSAGE("dam break: worst channel difference " << d.maxLevel << " levels, " << 100 * d.share << " % of pixels");
  CHECK(d.maxLevel <= 2);
  CHECK(d.share < 0.01);
}

TEST_CASE("liquid: the CPU's splat draws the GL's frames at every sprite size, sparse and dense") {
  // The dam break's column, without gravity, seen ever closer around its top right particle:
  // sprites of 3.6 px (the field at full resolution), of 9 and 30 px (half resolution), and of
  // 900 px (450 in the half-resolution field: beyond llvmpipe's 255 px point limit, where the
  // GL draws quads).
  SceneDef s = test::scene("dam_break.json");
  s.gravity = Vec2d(0, 0);
  s.render.width = 320;
  s.render.height = 240;
  s.render.camera.automatic = false;
  Vec2d corner(-1e9, -1e9);
  {
    World w(s, WorldOptions{1});
    const Particles P = w.particles();
    for (std::size_t i = 0; i < P.size(); ++i) {
      const Vec2d x = w.origin() + P.x[i].cast<double>();
      if (x.x() + x.y() > corner.x() + corner.y()) corner = x;
    }
  }
  struct View {
    double x0, y0, x1, y1;  // around the corner [m]
  };
  for (const View v : {View{-1.5, -2.5, 3.5, 1.25}, View{-1.1, -2.1, 0.9, -0.6}, View{-0.2, -0.4, 0.4, 0.05},
                       View{-0.01, -0.01, 0.01, 0.005}}) {
    s.render.camera.min = corner + Vec2d(v.x0, v.y0);
    s.render.camera.max = corner + Vec2d(v.x1, v.y1);
    const FrameDiff d = bothPaths(s, 3, 1);
    MESSAGE("view " << v.x1 - v.x0 << " m wide: " << d.maxLevel << " levels, " << 100 * d.share << " % of pixels");
    CHECK(d.maxLevel <= 2);
    CHECK(d.share < 0.01);
    CHECK(d.glQuads == (v.x1 - v.x0 < 0.1));
  }
  // Sprites narrower than a pixel (splat_radius 0.25 and 0.4 at 0.95 px per spacing): the GL
  // draws a point at least its smallest size (1 px), and so does the CPU.
  s.render.camera.min = corner + Vec2d(-1.5, -2.5);
  s.render.camera.max = corner + Vec2d(3.5, 1.25);
  for (const double radius : {0.25, 0.4}) {
    s.render.splatRadius = radius;
    const FrameDiff d = bothPaths(s, 2, 1);
    MESSAGE("splat_radius " << radius << ": " << d.maxLevel << " levels, " << 100 * d.share << " % of pixels");
    CHECK(d.maxLevel <= 2);
    CHECK(d.share < 0.01);
  }
}

TEST_CASE("liquid: the CPU's splat draws the GL's materials, transmissions, grains and blobs") {
  // Oil on water, each in its colour, seen through by transmissions that differ (the tint and
  // the absorption targets); the sandbox's sand (grains: no splat) and its rigid and jelly
  // groups (the blob target).
  SceneDef oil = test::scene("oil_and_water.json");
  REQUIRE(oil.materials.size() >= 2);
  oil.materials[1].transmission = {0.8, 0.6, 0.1};
  const FrameDiff a = bothPaths(oil, 3, 20);
  MESSAGE("oil and water: " << a.maxLevel << " levels, " << 100 * a.share << " % of pixels");
  CHECK(a.maxLevel <= 2);
  CHECK(a.share < 0.01);
  const FrameDiff b = bothPaths(test::scene("sandbox.json"), 3, 30);
  MESSAGE("sandbox: " << b.maxLevel << " levels, " << 100 * b.share << " % of pixels");
  CHECK(b.maxLevel <= 2);
  CHECK(b.share < 0.01);
}
