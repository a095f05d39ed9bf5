// The liquid mode's water as a material: what is behind it (background, solids) is seen through
// it, absorbed per colour channel by its thickness (Beer–Lambert) and shifted where its surface
// tilts (refraction); foam, spray and bubbles drawn over it. Synthetic frames of still lattices
// of particles, rendered with and without what is behind, and a dam break with effects.foam.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "sph2d/render/png_io.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"
#include "support/liquid_pool.hpp"

using namespace sph2d;
using namespace sph2d::test;

TEST_CASE("liquid: a dark body behind the water shows through it by the water's transmission per channel") {
  // A grey background and a dark body x 0.4..0.7, y 0.1..0.4 behind a pool of water (0..1.2 ×
  // 0..0.6). Against opaque water (transmission 0, the same frame otherwise), each channel of
  // the water over the body changes by the share the water lets through of the body's
  // difference from the background: the transmission of a full layer.
  Pool pool;
  pool.def.background = {0.4, 0.4, 0.4};
  pool.def.water = {0.3, 0.5, 0.8};
  pool.def.solid = {0.02, 0.02, 0.02};
  pool.def.refraction = 1;
  pool.fill(0, 1.2, 0, 0.6, kDx);
  pool.solids = {boxCollider(0.4, 0.1, 0.7, 0.4)};
  pool.def.transmission = {0, 0, 0};
  const Frame opaque = pool.render(true, true), opaqueWithout = pool.render(true, false);
  pool.def.transmission = {0.2, 0.45, 0.7};
  const Frame with = pool.render(true, true);
  // The bulk over the body, 3 spacings inside its edges (the refraction's reach is 1).
  const double in = 3 * kDx;
  auto share = [&](double x0, double x1) {
    std::array<double, 3> s{};
    const auto lo = pixelOf(x0 + in, 0.4 - in), hi = pixelOf(x1 - in, 0.1 + in);
    int n = 0;
    for (int row = lo[1]; row <= hi[1]; ++row)
      for (int col = lo[0]; col <= hi[0]; ++col, ++n)
        for (int c = 0; c < 3; ++c) s[std::size_t(c)] += channel(with, col, row, c) - channel(opaque, col, row, c);
    for (int c = 0; c < 3; ++c)
      s[std::size_t(c)] /= n * 255 * (pool.def.solid[std::size_t(c)] - pool.def.background[std::size_t(c)]);
    return s;
  };
  const auto bulk = share(0.4, 0.7);
  MESSAGE("share passed: " << bulk[0] << " " << bulk[1] << " " << bulk[2]);
  for (int c = 0; c < 3; ++c) {
    CAPTURE(c);
    CHECK(std::fabs(bulk[std::size_t(c)] - pool.def.transmission[std::size_t(c)]) < 0.02);
  }
  // Opaque water hides the body: over it only the depth shading's light, which the body keeps
  // from spreading sideways, differs (a few levels).
  const auto lo = pixelOf(0.4 + in, 0.4 - in), hi = pixelOf(0.7 - in, 0.1 + in);
  int worst = 0;
  for (int row = lo[1]; row <= hi[1]; ++row)
    for (int col = lo[0]; col <= hi[0]; ++col)
      for (int c = 0; c < 3; ++c)
        worst = std::max(worst, std::abs(channel(opaque, col, row, c) - channel(opaqueWithout, col, row, c)));
  MESSAGE("opaque water over the body: at most " << worst << " levels from the water without it");
  CHECK(worst <= 4);
}

TEST_CASE("liquid: thinner water lets more of what is behind it through") {
  // Tiles behind a dense pool (the lattice spacing) and a sparse one (1.25 times the spacing:
  // a fill of 0.64). The share of a joint's brightness the water passes (the frames with and
  // without the tiles, with and without the water) is the transmission of a full layer in the
  // dense pool and about its 0.64th power in the sparse one.
  Pool pool;
  pool.def.transmission = {0.2, 0.45, 0.7};
  pool.def.refraction = 0;
  pool.fill(-0.1, 0.85, 0, 0.6, kDx);
  pool.fill(0.95, 1.9, 0, 0.6, 1.25 * kDx);
  const Frame water = pool.render(true, false), nothing = pool.render(false, false);
  pool.def.tiles = 0.1;
  const Frame waterTiles = pool.render(true, false), tiles = pool.render(false, false);
  auto share = [&](double x0, double x1, int c) {
    // Along the joint y = 0.3 (a row of pixels on each side), between vertical joints.
    double num = 0, den = 0;
    for (double x = x0; x < x1; x += 1.0 / 240) {
      if (std::fabs(x / 0.1 - std::round(x / 0.1)) < 0.15) continue;
      const auto p = pixelOf(x, 0.3);
      for (int row = p[1] - 1; row <= p[1] + 1; ++row) {
        num += channel(waterTiles, p[0], row, c) - channel(water, p[0], row, c);
        den += channel(tiles, p[0], row, c) - channel(nothing, p[0], row, c);
      }
    }
    REQUIRE(den > 1000);
    return num / den;
  };
  for (int c = 0; c < 3; ++c) {
    CAPTURE(c);
    const double t = pool.def.transmission[std::size_t(c)];
    const double dense = share(0.1, 0.75, c), sparse = share(1.05, 1.8, c);
    MESSAGE("channel " << c << ": dense water passes " << dense << ", sparse " << sparse);
    CHECK(std::fabs(dense - t) < 0.05);
    CHECK(sparse > dense + 0.05);
    CHECK(std::fabs(sparse - std::pow(t, 0.64)) < 0.08);
  }
}

TEST_CASE("liquid: the water's fringe along a body leaves the body's edge as it is drawn") {
  // Water beside a body (the particles end at its face, as a solver leaves them): the body is
  // drawn to its edge, every pixel inside it its own colour, whatever the field's fringe over
  // it (the field reaches two spacings past the particles).
  Pool beside;
  beside.def.solid = {0.9, 0.3, 0.2};
  beside.fill(0, 0.4, 0, 0.6, kDx);
  beside.fill(0.7, 1.2, 0, 0.6, kDx);
  beside.fill(0.4, 0.7, 0.4, 0.6, kDx);
  beside.solids = {boxCollider(0.4, 0.0, 0.7, 0.4)};
  const Frame f = beside.render(true, true);
  const auto blo = pixelOf(0.4, 0.4), bhi = pixelOf(0.7, 0.0);
  int wrong = 0, inside = 0;
  for (int row = blo[1] + 1; row < bhi[1]; ++row)
    for (int col = blo[0] + 1; col < bhi[0]; ++col, ++inside)
      for (int c = 0; c < 3; ++c)
        wrong += std::abs(channel(f, col, row, c) - int(std::lround(beside.def.solid[std::size_t(c)] * 255))) > 1;
  CHECK(inside > 5000);
  CHECK(wrong == 0);
}

TEST_CASE("liquid: refraction shifts what is behind the water where its surface tilts, and nowhere else") {
  // Tiles behind a pool whose surface is at y = 0.6: a joint one spacing below the surface
  // (where the water's thickness falls towards the air) and one deep in the bulk. The joint is
  // found in the difference of the frames with and without the tiles (what the water lets
  // through of them, its own shading removed). Seen through the water the near joint appears
  // shifted towards the thinner water (up), by at most the refraction's spacings; the deep one
  // stays where it is.
  auto jointRow = [](const Frame& a, const Frame& b, double x, double y) {
    // The centroid of the difference's brightness within 4 px of the joint's true row, to a
    // fraction of a pixel.
    const auto p = pixelOf(x, y);
    double m = 0, w = 0;
    for (int row = p[1] - 4; row <= p[1] + 4; ++row) {
      double e = 0;
      for (int c = 0; c < 3; ++c) e += channel(a, p[0], row, c) - channel(b, p[0], row, c);
      e = std::max(0.0, e);
      m += e * row;
      w += e;
    }
    CAPTURE(x);
    CAPTURE(y);
    REQUIRE(w > 10);
    return m / w;
  };
  const double tile = (0.6 - kDx) / 5;  // joints at y = k·tile: 0.5875 (near) and 0.235 (deep)
  double shiftNear[2] = {0, 0}, shiftDeep[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    Pool pool;
    pool.def.transmission = {0.6, 0.6, 0.6};
    pool.def.water = {0.1, 0.2, 0.3};  // dark: the surface's highlight stays below white
    pool.def.refraction = k == 0 ? 0 : 0.75;
    pool.fill(-0.1, 1.9, 0, 0.6, kDx);
    const Frame water = pool.render(true, false), nothing = pool.render(false, false);
    pool.def.tiles = tile;
    const Frame waterTiles = pool.render(true, false), tiles = pool.render(false, false);
    for (const double x : {0.3, 0.9, 1.5}) {  // columns between the vertical joints
      shiftNear[k] += (jointRow(waterTiles, water, x, 5 * tile) - jointRow(tiles, nothing, x, 5 * tile)) / 3;
      shiftDeep[k] += (jointRow(waterTiles, water, x, 2 * tile) - jointRow(tiles, nothing, x, 2 * tile)) / 3;
    }
  }
  MESSAGE("joint one spacing under the surface moved " << shiftNear[0] << " px without refraction, " << shiftNear[1]
                                                       << " px with 0.75 spacings; deep joint " << shiftDeep[0] << ", "
                                                       << shiftDeep[1] << " px");
  CHECK(std::fabs(shiftNear[0]) < 0.2);
  CHECK(std::fabs(shiftDeep[0]) < 0.2);
  CHECK(std::fabs(shiftDeep[1]) < 0.2);
  CHECK(shiftNear[1] < -0.5);             // up (rows run top-down), towards the thinner water
  CHECK(shiftNear[1] > -0.75 * 3 - 0.3);  // at most the refraction's 0.75 spacings of 3 px
}

TEST_CASE("liquid: foam, spray and bubbles are drawn where they are, light over the water and the air") {
  // A dam break with effects.foam after its impact: the frame with the diffuse particles against
  // the same frame without them. Every pixel that changes lies within a spacing of one of them,
  // and most get lighter.
  SceneDef s;
  s.solver.spacing = 0.02;
  BodyDef tank;
  for (const auto& box : {std::array<double, 4>{1.0, -0.1, 1.2, 0.1}, std::array<double, 4>{-0.1, 0.6, 0.1, 0.8},
                          std::array<double, 4>{2.1, 0.6, 0.1, 0.8}}) {
    ShapeDef b;
    b.type = ShapeDef::Type::Box;
    b.center = Vec2d(box[0], box[1]);
    b.halfSize = Vec2d(box[2], box[3]);
    tank.fixtures.push_back(b);
  }
  s.bodies.push_back(tank);
  FluidBlockDef column;
  column.min = Vec2d(0, 0);
  column.max = Vec2d(0.5, 1.0);
  s.blocks.push_back(column);
  s.effects.foam = true;
  s.render.width = 480;
  s.render.height = 270;
  World world(s, WorldOptions{2});
  for (int f = 0; f < 75; ++f) world.stepFrame();
  const DiffuseParticles d = world.diffuse();
  REQUIRE(d.size() > 20);
  RenderInput in;
  in.particles = world.particles();
  in.origin = world.origin();
  in.spacing = world.spacing();
  in.colliders = &world.colliders();
  Renderer plainR(s.render), foamR(s.render);
  const Frame plain = plainR.render(in);
  in.diffuse = d;
  const Frame foamy = foamR.render(in);
  if (const char* dump = std::getenv("SPH2D_TEST_DUMP"))
    writePngAtomic(dump, foamy.width, foamy.height, foamy.rgba.data());
  const std::vector<double> cam = foamR.cameraRect();
  const double pxPerM = foamy.width / (cam[2] - cam[0]);
  int changed = 0, lighter = 0, far = 0;
  for (int row = 0; row < foamy.height; ++row)
    for (int col = 0; col < foamy.width; ++col) {
      int before = 0, after = 0;
      for (int c = 0; c < 3; ++c) {
        before += channel(plain, col, row, c);
        after += channel(foamy, col, row, c);
      }
      if (before == after && channel(plain, col, row, 0) == channel(foamy, col, row, 0)) continue;
      ++changed;
      lighter += after > before;
      const double x = cam[0] + (col + 0.5) / pxPerM - in.origin.x(), y = cam[3] - (row + 0.5) / pxPerM - in.origin.y();
      double nearest = 1e9;
      for (std::size_t k = 0; k < d.size(); ++k)
        nearest = std::min(nearest, std::hypot(double(d.x[k].x()) - x, double(d.x[k].y()) - y));
      far += nearest > in.spacing + 1.5 / pxPerM;
    }
  MESSAGE(d.size() << " diffuse particles change " << changed << " pixels, " << lighter << " lighter, " << far
                   << " farther than a spacing from them");
  CHECK(changed > int(d.size()) / 2);
  CHECK(lighter > changed * 8 / 10);
  CHECK(far == 0);
  // The next frame without them, on the same renderer: what they covered (in the air too, where
  // the composite does not draw) is back to the backdrop, the frame a fresh renderer draws.
  in.diffuse = DiffuseParticles{};
  const Frame after = foamR.render(in);
  CHECK(after.rgba == plain.rgba);
}

TEST_CASE("liquid: a surface whose particles are out of line by a fraction of a spacing is drawn flat") {
  // A pool at 8 px per spacing whose top row of particles is displaced up and down by 0.3
  // spacing, at random (fixed seed): the drawn edge (the first row down each column whose blue
  // channel is closer to the water's than to the background's) stays within a fraction of a
  // spacing of a straight line.
  ParticleBuffer B;
  const double dx = 0.0125;
  std::uint32_t id = 0, seed = 12345;
  for (double y = dx / 2; y < 0.3; y += dx)
    for (double x = dx / 2; x < 0.75; x += dx) {
      double yy = y;
      if (y + dx > 0.3) {
        seed = seed * 1664525u + 1013904223u;
        yy += 0.3 * dx * (double(seed >> 8) / double(1u << 24) * 2 - 1);
      }
      B.push(Vec2(Real(x), Real(yy)), Vec2(0, 0), id++, 1000);
    }
  RenderDef def;
  def.width = 480;
  def.height = 270;
  def.camera.automatic = false;
  def.camera.min = Vec2d(0, 0);
  def.camera.max = Vec2d(0.75, 0.421875);  // 640 px per metre: 8 px per spacing
  RenderInput in;
  in.particles = B.view();
  in.spacing = dx;
  Renderer r(def);
  const Frame f = r.render(in);
  if (const char* dump = std::getenv("SPH2D_TEST_DUMP")) writePngAtomic(dump, f.width, f.height, f.rgba.data());
  const int bgBlue = int(std::lround(def.background[2] * 255)), waterBlue = int(std::lround(def.water[2] * 255));
  std::vector<double> edge;
  for (int col = 40; col < 440; ++col) {
    int row = 0;
    while (row < f.height && 2 * channel(f, col, row, 2) < bgBlue + waterBlue) ++row;
    edge.push_back(row);
  }
  double mean = 0;
  for (const double e : edge) mean += e / double(edge.size());
  double rms = 0;
  for (const double e : edge) rms += (e - mean) * (e - mean) / double(edge.size());
  rms = std::sqrt(rms);
  MESSAGE("edge at row " << mean << ", RMS " << rms << " px (8 px per spacing)");
  CHECK(std::fabs(mean - (0.421875 - 0.3) * 640) < 8);
  CHECK(rms < 0.1 * 8);
}

TEST_CASE("liquid: a lone particle in the air is drawn as a droplet of its own area") {
  // Five lone particles a metre apart above nothing, at 4, 6 and 8 px per spacing: each is a
  // drop whose drawn area (pixels that differ from the background by more than 30 levels in
  // some channel) is about the particle's own area, a spacing squared (the area the fluid's
  // particles stand for), not a dot of a pixel or two.
  for (const double pxPerSpacing : {4.0, 6.0, 8.0}) {
    CAPTURE(pxPerSpacing);
    const double dx = 0.01, pxPerM = pxPerSpacing / dx;
    ParticleBuffer B;
    for (std::uint32_t k = 0; k < 5; ++k) B.push(Vec2(Real(0.1 + 0.15 * k), Real(0.1)), Vec2(0, 0), k, 1000);
    RenderDef def;
    def.width = 480;
    def.height = 270;
    def.camera.automatic = false;
    def.camera.min = Vec2d(0, 0);
    def.camera.max = Vec2d(480 / pxPerM, 270 / pxPerM);
    RenderInput in;
    ParticleBuffer none;
    in.spacing = dx;
    in.particles = none.view();
    Renderer r0(def), r1(def);
    const Frame empty = r0.render(in);
    in.particles = B.view();
    const Frame drops = r1.render(in);
    int covered = 0;
    for (int row = 0; row < drops.height; ++row)
      for (int col = 0; col < drops.width; ++col) {
        int worst = 0;
        for (int c = 0; c < 3; ++c)
          worst = std::max(worst, std::abs(channel(drops, col, row, c) - channel(empty, col, row, c)));
        covered += worst > 30;
      }
    const double area = covered / 5.0 / (pxPerSpacing * pxPerSpacing);
    MESSAGE(pxPerSpacing << " px per spacing: a lone drop covers " << area << " spacings squared");
    CHECK(area > 0.7);
    CHECK(area < 1.6);
  }
}

TEST_CASE("liquid: each material is seen through by its own transmission") {
  // Two materials side by side over one dark body: water (transmission 0.2 0.45 0.7) and an ink
  // that lets nothing through (0 0 0). Over the body the water's pixels change by its share of
  // the body's contrast and the ink's not at all (against the same frame without the body).
  Pool pool;
  pool.def.background = {0.4, 0.4, 0.4};
  pool.def.water = {0.3, 0.5, 0.8};
  pool.def.solid = {0.02, 0.02, 0.02};
  pool.fill(0, 0.6, 0, 0.6, kDx);
  const std::size_t waterCount = pool.B.size();
  pool.fill(0.6, 1.2, 0, 0.6, kDx);
  pool.B.material.assign(pool.B.size(), 0);
  for (std::size_t k = waterCount; k < pool.B.size(); ++k) pool.B.material[k] = 1;
  pool.solids = {boxCollider(0.15, 0.1, 1.05, 0.4)};
  auto render = [&](bool body, bool particles = true) {
    RenderInput in;
    ParticleBuffer empty;
    in.particles = particles ? pool.B.view() : empty.view();
    in.spacing = kDx;
    std::vector<Collider> none;
    in.colliders = body ? &pool.solids : &none;
    in.materialColors = {0x4D80CCu, 0x4D80CCu};  // the same colour: only the transmissions differ
    in.materialTransmission = {{0.2f, 0.45f, 0.7f}, {0.0f, 0.0f, 0.0f}};
    Renderer r(pool.def);
    return Frame(r.render(in));
  };
  const Frame with = render(true), without = render(false);
  const Frame body = render(true, false), plain = render(false, false);  // what is behind
  auto meanChange = [&](double x0, double x1, int c) {
    double change = 0, contrast = 0;
    const auto lo = pixelOf(x0, 0.35), hi = pixelOf(x1, 0.15);
    for (int row = lo[1]; row <= hi[1]; ++row)
      for (int col = lo[0]; col <= hi[0]; ++col) {
        change += channel(with, col, row, c) - channel(without, col, row, c);
        contrast += channel(body, col, row, c) - channel(plain, col, row, c);
      }
    return change / contrast;
  };
  for (int c = 0; c < 3; ++c) {
    CAPTURE(c);
    const double water = meanChange(0.2, 0.5, c), ink = meanChange(0.7, 1.0, c);
    MESSAGE("channel " << c << ": the water passes " << water << " of the body's contrast, the ink " << ink);
    CHECK(std::fabs(water - std::array<double, 3>{0.2, 0.45, 0.7}[std::size_t(c)]) < 0.03);
    CHECK(std::fabs(ink) < 0.01);
  }
}

TEST_CASE("liquid: a scene's materials take their transmission, or the render's") {
  const SceneDef s = parseScene(R"({"fluid": [{"min": [0, 0], "max": [1, 1]}],
      "render": {"transmission": [0.1, 0.2, 0.3]},
      "materials": [{"name": "water"}, {"name": "ink", "transmission": [0, 0, 0.05]}]})",
                                "inline.json");
  REQUIRE(s.materials.size() == 2);
  CHECK(s.materials[0].transmission == std::array<double, 3>{0.1, 0.2, 0.3});
  CHECK(s.materials[1].transmission == std::array<double, 3>{0, 0, 0.05});
  World w(s, WorldOptions{1});
  const std::vector<std::array<float, 3>> t = materialTransmission(w);
  REQUIRE(t.size() == 2);
  CHECK(t[1][2] == 0.05f);
  // Without a materials table the one material is the render's: its transmission too.
  const SceneDef plain = parseScene(R"({"fluid": [{"min": [0, 0], "max": [1, 1]}],
      "render": {"transmission": [0, 0, 0]}})",
                                    "inline.json");
  World one(plain, WorldOptions{1});
  const std::vector<std::array<float, 3>> t1 = materialTransmission(one);
  REQUIRE(t1.size() == 1);
  CHECK(t1[0] == std::array<float, 3>{0, 0, 0});
  MaterialDef bad;
  bad.name = "glass";
  bad.transmission = {0, 0, 1.5};
  CHECK_THROWS_WITH_AS(one.addMaterial(bad), doctest::Contains("transmission components must be in 0..1"),
                       std::invalid_argument);
  try {
    (void)parseScene(R"({"fluid": [{"min": [0, 0], "max": [1, 1]}],
        "materials": [{"name": "water", "transmission": [0, 0, 2]}]})",
                     "inline.json");
    FAIL("a transmission above 1 was accepted");
  } catch (const SceneError& e) {
    CHECK(e.key == "materials[0].transmission");
  }
}
