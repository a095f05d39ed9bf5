// The renderer's layout: depth shading along walls and under bumps, where the colour bar goes,
// and static solids a game moves.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>

#include <box2d/box2d.h>

#include "sph2d/hash.hpp"
#include "sph2d/render/image.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"
#include "support/frame_pixels.hpp"

using namespace sph2d;

namespace {

std::uint64_t hashOf(const Frame& f) { return xxh64(f.rgba.data(), f.rgba.size()); }

/// A pool 0.6 m deep from a wall at x = 0 to beyond the view's right edge, with a block 0.3 m
/// high and 0.2 m wide standing on its surface at x = 0.8 .. 1.0 (a bump), as a square lattice
/// at rest, seen at 240 px/m (spacing 3 px, like the dam break).
struct BumpPool {
  ParticleBuffer B;
  Particles P;  // B.view()
  std::vector<Collider> walls;
  RenderDef def;
  RenderInput in;
  static constexpr double dx = 0.0125;
  BumpPool() {
    std::uint32_t id = 0;
    auto fill = [&](double x0, double x1, double y0, double y1) {
      for (double y = y0 + dx / 2; y < y1; y += dx)
        for (double x = x0 + dx / 2; x < x1; x += dx) B.push(Vec2(Real(x), Real(y)), Vec2(0, 0), id++, Real(1000));
    };
    fill(0.0, 2.5, 0.0, 0.6);
    fill(0.8, 1.0, 0.6, 0.9);
    P = B.view();
    Collider wall;  // x −0.1 .. 0, y −0.1 .. 1.2, counter-clockwise
    wall.vertices = {Vec2(-0.1f, -0.1f), Vec2(0.0f, -0.1f), Vec2(0.0f, 1.2f), Vec2(-0.1f, 1.2f)};
    wall.normals = {Vec2(0, -1), Vec2(1, 0), Vec2(0, 1), Vec2(-1, 0)};
    wall.lo = Vec2(-0.1f, -0.1f);
    wall.hi = Vec2(0.0f, 1.2f);
    walls.push_back(wall);
    def.width = 480;
    def.height = 270;
    def.camera.automatic = false;
    def.camera.min = Vec2d(-0.2, -0.1);
    def.camera.max = Vec2d(1.8, 1.025);
    in.particles = P;
    in.spacing = dx;
    in.colliders = &walls;
  }
};

}  // namespace

TEST_CASE("liquid depth shading has no vertical seams under a bump and does not light the water along a wall") {
  BumpPool pool;
  Renderer r(pool.def);
  const Frame& f = r.render(pool.in);
  const auto cam = r.cameraRect();
  const double pxPerM = f.width / (cam[2] - cam[0]);
  auto px = [&](double x) { return int(std::floor((x - cam[0]) * pxPerM)); };
  auto py = [&](double y) { return int(std::floor((cam[3] - y) * pxPerM)); };
  auto at = [&](int x, int y) { return &f.rgba[(std::size_t(y) * std::size_t(f.width) + std::size_t(x)) * 4]; };
  // Rows 0.12 m to 0.45 m below the pool's surface (29 px or more from any edge of the water),
  // from 12 px right of the wall to the image's right edge (the pool goes on beyond it). The
  // old shading (each column's own depth, no sideways spread) stepped by 8 levels between two
  // pixels under the bump's sides; now the largest step is 2.
  int worst = 0, worstX = 0, worstY = 0;
  for (double depth = 0.12; depth <= 0.45; depth += 0.03) {
    const int y = py(0.6 - depth);
    for (int x = px(0.0) + 12; x + 1 < f.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const int d = std::abs(int(at(x + 1, y)[c]) - int(at(x, y)[c]));
        if (d > worst) {
          worst = d;
          worstX = x;
          worstY = y;
        }
      }
  }
  MESSAGE("largest step between neighbouring pixels inside the water: " << worst << " levels at x " << worstX << ", y "
                                                                        << worstY);
  CHECK(worst <= 3);
  // The shading is still there: deeper water is darker, and so is the water under the bump.
  const int yDeep = py(0.15), yShallow = py(0.55), xFar = px(1.6), xBump = px(0.9);
  MESSAGE("blue: shallow " << int(at(xFar, yShallow)[2]) << ", deep " << int(at(xFar, yDeep)[2])
                           << ", deep under the bump " << int(at(xBump, yDeep)[2]));
  CHECK(int(at(xFar, yShallow)[2]) - int(at(xFar, yDeep)[2]) >= 20);
  CHECK(int(at(xFar, yDeep)[2]) - int(at(xBump, yDeep)[2]) >= 8);
  // The wall neither passes light nor lends its own depth (none) to the water beside it: deep
  // down, the water 6 px from the wall (past the rim the fluid's edge draws there) is as dark as 40 px from it.
  const int nearWall = int(at(px(0.0) + 6, yDeep)[2]), awayFromWall = int(at(px(0.0) + 40, yDeep)[2]);
  MESSAGE("blue 6 px from the wall " << nearWall << ", 40 px from it " << awayFromWall);
  CHECK(std::abs(nearWall - awayFromWall) <= 2);
}

TEST_CASE("the colour bar goes where it covers no solid or fluid: the right middle when clear, else a clear edge") {
  // A dark 400 × 300 frame; a grey wall over the right third, then also fluid blue over the
  // top third of the rest: the bar (ramp ends 128,0,0 and 0,0,128) must land on the dark part.
  auto frame = [] {
    Frame f;
    f.width = 400;
    f.height = 300;
    f.rgba.assign(std::size_t(f.width) * std::size_t(f.height) * 4, 0);
    for (std::size_t i = 0; i < f.rgba.size(); i += 4)
      f.rgba[i] = 14, f.rgba[i + 1] = 16, f.rgba[i + 2] = 22, f.rgba[i + 3] = 255;
    return f;
  };
  auto paint = [](Frame& f, int x0, int y0, int x1, int y1, std::array<std::uint8_t, 3> c) {
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x)
        for (int k = 0; k < 3; ++k)
          f.rgba[(std::size_t(y) * std::size_t(f.width) + std::size_t(x)) * 4 + std::size_t(k)] = c[std::size_t(k)];
  };
  auto barOver = [](const Frame& f, int x0, int y0, int x1, int y1) {  // ramp-end pixels in the box
    int n = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        const std::uint8_t* p = &f.rgba[(std::size_t(y) * std::size_t(f.width) + std::size_t(x)) * 4];
        n += (p[0] == 128 && p[1] == 0 && p[2] == 0) || (p[0] == 0 && p[1] == 0 && p[2] == 128);
      }
    return n;
  };
  Frame clear = frame();
  CHECK(drawColorBar(clear, 0, 1, "SPEED M/S", 1) > 200);  // clear: the right edge
  Frame wall = frame();
  paint(wall, 270, 0, 400, 300, {138, 128, 112});
  const int x = drawColorBar(wall, 0, 1, "SPEED M/S", 1);
  CHECK(x < 200);  // moved to the left edge
  CHECK(barOver(wall, 270, 0, 400, 300) == 0);
  CHECK(barOver(wall, 0, 0, 270, 300) > 0);
  Frame both = frame();
  paint(both, 270, 0, 400, 300, {138, 128, 112});
  paint(both, 0, 0, 270, 100, {47, 127, 216});  // the bar (half the height and its labels) fits below
  drawColorBar(both, 0, 1, "SPEED M/S", 1);
  CHECK(barOver(both, 270, 0, 400, 300) == 0);
  CHECK(barOver(both, 0, 0, 270, 100) == 0);
  CHECK(barOver(both, 0, 100, 270, 300) > 0);  // the clear bottom left
}

TEST_CASE("static solids a game moves are drawn where they are: a teleported wall, a slid one at rest") {
  // A game's level: a tank and a static shelf above the water. The game teleports the shelf,
  // then slides it back and stops it (a sliding static body is drawn as a moving one while
  // it moves, and is a static solid again once it rests). At each point the frame of the
  // renderer that drew every earlier frame equals a fresh renderer's, and the shelf's colour
  // is where the shelf is and gone from where it was.
  for (const char* mode : {"liquid", "particles"}) {
    INFO(mode);
    b2World level(b2Vec2(0, -9.81f));
    auto addBox = [&](float cx, float cy, float hx, float hy) {  // static boxes of the game's level
      b2BodyDef bd;
      bd.position.Set(cx, cy);
      b2Body* body = level.CreateBody(&bd);
      b2PolygonShape box;
      box.SetAsBox(hx, hy);
      body->CreateFixture(&box, 0);
      return body;
    };
    addBox(1, -0.1f, 1.2f, 0.1f);
    addBox(-0.1f, 0.5f, 0.1f, 0.7f);
    addBox(2.1f, 0.5f, 0.1f, 0.7f);
    b2Body* shelf = addBox(0.4f, 0.7f, 0.08f, 0.15f);
    SceneDef s;
    s.solver.spacing = 0.04;
    FluidBlockDef water;
    water.min = Vec2d(0, 0);
    water.max = Vec2d(2, 0.3);
    s.blocks.push_back(water);
    s.render.mode = mode;
    s.render.width = 200;
    s.render.height = 120;
    s.render.camera.min = Vec2d(-0.2, -0.2);
    s.render.camera.max = Vec2d(2.2, 1.2);
    World world(s, level, WorldOptions{1});
    Renderer seq(s.render);
    auto solidAround = [&](const Frame& f, double wx, double wy) {
      return test::solidAround(f, s.render, seq.cameraRect(), wx, wy);
    };
    auto sameAsFresh = [&](const Frame& f) {
      Renderer fresh(s.render);
      return hashOf(fresh.render(world)) == hashOf(f);
    };
    for (int f = 0; f < 5; ++f) {
      seq.render(world);
      world.stepFrame();
    }
    CHECK(solidAround(seq.render(world), 0.4, 0.7) == 35);
    // Teleported 1 m (no water up there): a static solid at once.
    shelf->SetTransform(b2Vec2(1.4f, 0.7f), 0);
    world.stepFrame();
    CHECK(world.colliders().size() == 4);
    const Frame& a = seq.render(world);
    CHECK(solidAround(a, 1.4, 0.7) == 35);
    CHECK(solidAround(a, 0.4, 0.7) == 0);
    CHECK(sameAsFresh(a));
    // Slid back 0.3 m at 1.2 m/s, then at rest for two frames.
    for (int f = 1; f <= 15; ++f) {
      shelf->SetTransform(b2Vec2(1.4f - 0.02f * float(f), 0.7f), 0);
      world.stepFrame();
      seq.render(world);
    }
    CHECK(world.movingColliders().size() == 1);
    for (int f = 0; f < 2; ++f) world.stepFrame();
    CHECK(world.colliders().size() == 4);
    CHECK(world.movingColliders().empty());
    const Frame& b = seq.render(world);
    CHECK(solidAround(b, 1.1, 0.7) == 35);
    CHECK(solidAround(b, 1.4, 0.7) == 0);
    CHECK(sameAsFresh(b));
  }
}
