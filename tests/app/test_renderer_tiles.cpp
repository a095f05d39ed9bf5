// The liquid composite's tiles (engine/render/src/depth_grid.hpp): the cells deep in the water
// take the interior program, which draws there what the full program draws; with the field
// summed on the CPU, a lone drop takes a few cells, not the sprite's reach around it. Variants
// of shaders/composite.frag (SPH2D_SHADER_DIR) show where each program ran.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <string>

#include "sph2d/render/renderer.hpp"
#include "sph2d/world.hpp"
#include "support/liquid_pool.hpp"

using namespace sph2d;
using namespace sph2d::test;

namespace {

/// Pixels of frame f painted magenta (a variant's mark).
bool magenta(const Frame& f, int col, int row) {
  return channel(f, col, row, 0) == 255 && channel(f, col, row, 1) == 0 && channel(f, col, row, 2) == 255;
}

/// A frame drawn three ways by `render` (a new Renderer each call): as built; with the interior
/// tiles drawn by the full program (INTERIOR undefined); with the interior program painting
/// magenta.
struct ThreeWays {
  Frame built, full, marked;
};
template <class Render>
ThreeWays threeWays(const Render& render) {
  ThreeWays t;
  t.built = render();
  {
    const ShaderDir dir(compositeVariant("composite_one_program", "void main() {", "#undef INTERIOR\nvoid main() {"));
    t.full = render();
  }
  {
    const ShaderDir dir(compositeVariant("composite_marked", "void main() {",
                                         "void main() {\n#ifdef INTERIOR\n  outColor = vec4(1.0, 0.0, 1.0, 1.0);\n"
                                         "  return;\n#endif"));
    t.marked = render();
  }
  return t;
}

}  // namespace

TEST_CASE("liquid: deep water takes the interior program, which draws it as the full program does") {
  // A pool (surface at y = 0.6) whose particles are out of line by up to 0.3 spacings (a
  // rippled field), tiles behind it and a dark body in it. Drawn three times: as built; with
  // the interior tiles drawn by the full program (INTERIOR undefined); and with the interior
  // program painting magenta. The first two are the same to the bit; the magenta covers most
  // of the deep water and none of it near the surface or the body.
  Pool pool;
  pool.def.tiles = 0.1;
  pool.def.solid = {0.02, 0.02, 0.02};
  pool.solids = {boxCollider(0.8, 0.1, 1.0, 0.3)};
  std::uint32_t h = 12345;
  auto jitter = [&] {
    h = h * 1664525u + 1013904223u;
    return (double(h >> 8) / double(1u << 24) - 0.5) * 0.6 * kDx;
  };
  for (double y = kDx / 2; y < 0.6; y += kDx)
    for (double x = -0.1 + kDx / 2; x < 1.9; x += kDx) {
      if (x > 0.8 - kDx / 2 && x < 1.0 + kDx / 2 && y > 0.1 - kDx / 2 && y < 0.3 + kDx / 2) continue;
      const double jx = jitter(), jy = jitter();
      pool.B.push(Vec2(Real(x + jx), Real(y + jy)), Vec2(0, 0), pool.nextId++, 1000);
    }
  const auto [built, full, marked] = threeWays([&] { return pool.render(true, true); });
  CHECK(built.rgba == full.rgba);
  // Magenta where the interior program drew; the pixels deeper than 8 spacings, away from the
  // body and the image's sides by as much, that it covered.
  int deep = 0, deepMarked = 0, nearMarked = 0;
  for (int row = 0; row < marked.height; ++row)
    for (int col = 0; col < marked.width; ++col) {
      const bool mark = magenta(marked, col, row);
      const double x = -0.1 + (col + 0.5) / 240, y = 1.025 - (row + 0.5) / 240;
      const double toBody = std::max({0.8 - x, x - 1.0, 0.1 - y, y - 0.3});  // > 0: outside the body
      const double m = 8 * kDx;
      if (y < 0.6 - m && y > m && x > -0.1 + m && x < 1.9 - m && toBody > m) {
        ++deep;
        deepMarked += mark;
      }
      if (y > 0.6 - 2 * kDx || toBody < 2 * kDx) nearMarked += mark;
    }
  MESSAGE("interior program over " << deepMarked << " of " << deep << " deep pixels; " << nearMarked
                                   << " within two spacings of the surface or the body");
  CHECK(deepMarked > deep / 2);
  CHECK(nearMarked == 0);
}

TEST_CASE("liquid: a lone drop's tiles cover a few cells around it, and the drops are drawn as before") {
  // Forty lone particles in the air, 0.1 m apart. A variant paints magenta where the composite
  // ran and drew no water (its edge's cover is 0): the tiles' waste. The GL's splat takes the
  // tiles of the particles' cells dilated by the sprite's reach; with the field summed on the
  // CPU (the default on llvmpipe) only the cells where the field can show water. Both draw the
  // same frame to float rounding.
  Pool pool;
  for (int k = 0; k < 40; ++k) {
    const double x = 0.1 + 0.1 * (k % 10) + 0.013 * (k / 10), y = 0.3 + 0.15 * (k / 10) + 0.004 * (k % 10);
    pool.B.push(Vec2(Real(x), Real(y)), Vec2(0, 0), pool.nextId++, 1000);
  }
  RenderInput in;
  in.particles = pool.B.view();
  in.spacing = kDx;
  const std::vector<Collider> none;
  in.colliders = &none;
  RenderOptions cpu, gl;
  cpu.splat = SplatPath::Cpu;
  gl.splat = SplatPath::Gl;
  auto waste = [&](const RenderOptions& o) {
    const ShaderDir dir(compositeVariant("composite_waste", "  if (cover <= 0.0) {\n    outColor = vec4(bg, 1.0);",
                                         "  if (cover <= 0.0) {\n    outColor = vec4(1.0, 0.0, 1.0, 1.0);"));
    Renderer r(pool.def, o);
    const Frame& f = r.render(in);
    int n = 0;
    for (int row = 0; row < f.height; ++row)
      for (int col = 0; col < f.width; ++col) n += magenta(f, col, row);
    return n / 40.0;
  };
  const double byField = waste(cpu), byReach = waste(gl);
  MESSAGE("the composite ran on " << byField << " px a drop that show no water (" << byReach
                                  << " with the tiles by the sprite's reach)");
  CHECK(byField < 0.5 * byReach);
  Renderer cpuRenderer(pool.def, cpu), glRenderer(pool.def, gl);
  const Frame a = cpuRenderer.render(in), b = glRenderer.render(in);
  int worst = 0;
  for (std::size_t p = 0; p < a.rgba.size(); ++p) worst = std::max(worst, std::abs(int(a.rgba[p]) - int(b.rgba[p])));
  CHECK(worst <= 2);
}

TEST_CASE("liquid: a sand pile beside the water is no deep water: the interior program stays in the water") {
  // Water (x 0 .. 0.8) and sand (a granular material, x 1.0 .. 1.8) side by side, both 0.6 m
  // deep. Grains add nothing to the liquid's field: under the sand the full program draws the
  // backdrop between the grains, and the interior program must not draw water there. The frame
  // as built against the one with the interior tiles drawn by the full program: the same to the
  // bit; the magenta variant marks the water's depths and none of the sand.
  Pool pool;
  pool.fill(0.0, 0.8, 0.0, 0.6, kDx);
  const std::size_t water = pool.B.size();
  pool.fill(1.0, 1.8, 0.0, 0.6, kDx);
  pool.B.material.assign(pool.B.size(), 0);
  for (std::size_t k = water; k < pool.B.size(); ++k) pool.B.material[k] = 1;
  auto render = [&] {
    RenderInput in;
    in.particles = pool.B.view();
    in.spacing = kDx;
    const std::vector<Collider> none;
    in.colliders = &none;
    in.materialColors = {0x3080D0u, 0xC8A870u};
    in.materialGranular = {0, 1};
    Renderer r(pool.def);
    return Frame(r.render(in));
  };
  const auto [built, full, marked] = threeWays(render);
  CHECK(built.rgba == full.rgba);
  int inWater = 0, inSand = 0;
  for (int row = 0; row < marked.height; ++row)
    for (int col = 0; col < marked.width; ++col) {
      const double x = -0.1 + (col + 0.5) / 240;
      if (!magenta(marked, col, row)) continue;
      (x < 0.9 ? inWater : inSand) += 1;
    }
  MESSAGE("interior program over " << inWater << " px of the water and " << inSand << " of the sand");
  CHECK(inWater > 10000);
  CHECK(inSand == 0);
}

TEST_CASE("liquid: the tiles by the field draw the frame of the tiles by reach, to the bit") {
  // Jittered pools with a body and background tiles behind, 600 spray particles scattered
  // over the image, at odd and even image sizes and three spacings (the field at full and half
  // resolution). One grain far off screen makes the same renderer take the tiles by reach (a
  // frame with grains keeps them); it adds nothing on screen.
  for (const int width : {480, 483})
    for (const int height : {270, 271})
      for (const double step : {kDx, 0.6 * kDx, 2.2 * kDx}) {
        Pool pool;
        pool.def.width = width;
        pool.def.height = height;
        pool.def.tiles = 0.1;
        pool.solids = {boxCollider(0.8, 0.1, 1.0, 0.3)};
        std::uint32_t h = 777u + std::uint32_t(width * 7 + height * 13 + int(step * 1e4));
        auto rnd = [&] {
          h = h * 1664525u + 1013904223u;
          return double(h >> 8) / double(1u << 24);
        };
        for (double y = step / 2; y < 0.5; y += step)
          for (double x = -0.1 + step / 2; x < 0.7; x += step)
            pool.B.push(Vec2(Real(x + (rnd() - 0.5) * 0.6 * step), Real(y + (rnd() - 0.5) * 0.6 * step)), Vec2(0, 0),
                        pool.nextId++, 1000);
        for (int k = 0; k < 600; ++k)
          pool.B.push(Vec2(Real(-0.1 + 2.0 * rnd()), Real(-0.1 + 1.125 * rnd())), Vec2(Real(3 * rnd()), 0),
                      pool.nextId++, 1000);
        auto render = [&](bool offscreenGrain) {
          ParticleBuffer B = pool.B;
          B.material.assign(B.size(), 0);
          if (offscreenGrain) {
            B.push(Vec2(Real(50), Real(50)), Vec2(0, 0), 999999u, 1000);
            B.material.back() = 1;
          }
          RenderInput in;
          in.particles = B.view();
          in.spacing = step;
          in.colliders = &pool.solids;
          in.materialGranular = {0, 1};
          Renderer r(pool.def);
          return Frame(r.render(in));
        };
        const Frame a = render(false), b = render(true);
        CAPTURE(width);
        CAPTURE(height);
        CAPTURE(step);
        CHECK(a.rgba == b.rgba);
      }
}
