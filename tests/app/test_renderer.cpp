// The renderer in process: numbers about pixels (coverage, hashes, pixel counts), not "it ran".
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

/// A 0.2 m × 0.2 m block of fluid (spacing 0.02: 100 particles) on a floor, seen through `cam`.
SceneDef blockScene(int w, int h, Vec2d camMin, Vec2d camMax) {
  SceneDef s;
  s.name = "block";
  s.solver.spacing = 0.02;
  BodyDef floor;
  ShapeDef box;
  box.type = ShapeDef::Type::Box;
  box.center = Vec2d(0.1, -0.05);
  box.halfSize = Vec2d(0.2, 0.05);
  floor.fixtures.push_back(box);
  s.bodies.push_back(floor);
  FluidBlockDef b;
  b.min = Vec2d(0, 0);
  b.max = Vec2d(0.2, 0.2);
  s.blocks.push_back(b);
  s.render.width = w;
  s.render.height = h;
  s.render.camera.automatic = false;
  s.render.camera.min = camMin;
  s.render.camera.max = camMax;
  return s;
}

/// Share of the pixels that are water: blue clearly above red.
double waterShare(const Frame& f) {
  std::size_t n = 0;
  for (std::size_t p = 0; p < f.rgba.size(); p += 4)
    if (f.rgba[p + 2] > f.rgba[p] + 60) ++n;
  return double(n) / double(f.width * f.height);
}

std::uint64_t hashOf(const Frame& f) { return xxh64(f.rgba.data(), f.rgba.size()); }

RenderInput inputOf(const World& w, const Particles& P) {
  RenderInput in;
  in.particles = P;
  in.origin = w.origin();
  in.spacing = w.spacing();
  in.colliders = &w.colliders();
  return in;
}

}  // namespace

TEST_CASE("the 5x7 font: glyph '0' sets 19 pixels per scale², every character of the overlay has a glyph") {
  Frame img;
  img.width = 20;
  img.height = 20;
  img.rgba.assign(20 * 20 * 4, 0);
  drawText(img, 1, 1, "0", 1, Rgba8{255, 255, 255, 255});
  int lit = 0;
  for (std::size_t p = 0; p < img.rgba.size(); p += 4) lit += img.rgba[p] == 255;
  CHECK(lit == 19);
  img.rgba.assign(20 * 20 * 4, 0);
  drawText(img, 0, 0, "0", 2, Rgba8{255, 255, 255, 255});
  lit = 0;
  for (std::size_t p = 0; p < img.rgba.size(); p += 4) lit += img.rgba[p] == 255;
  CHECK(lit == 19 * 4);
  for (char c : std::string("FRAME 0123456789 T . S PARTICLES SPEED M/S PRESSURE PA DENSITY KG/M3 AGE -+E"))
    CHECK_MESSAGE(hasGlyph(c), "no glyph for '" << c << "'");
  CHECK(textWidth("AB", 3) == (2 * 6 - 1) * 3);
  CHECK(formatLabel(1234.0) == "1234");
  CHECK(formatLabel(0.5) == "0.5");
  CHECK(formatLabel(2.5e5) == "2.50E+05");
}

TEST_CASE("liquid frames depend on particle values only, not on storage order, and fresh contexts agree") {
  const SceneDef s = blockScene(160, 120, Vec2d(-0.1, -0.1), Vec2d(0.3, 0.3));
  World world(s, WorldOptions{1});
  Renderer a(s.render);
  const std::uint64_t h0 = hashOf(a.render(world));
  // The same particles in reversed slots.
  const Particles P = world.particles();
  ParticleBuffer R;
  for (std::size_t k = P.size(); k-- > 0;) {
    R.push(P.x[k], P.v[k], P.id[k], P.rho[k]);
    R.p.back() = P.p[k];
  }
  const Particles reversed = R.view();
  const std::uint64_t h1 = hashOf(a.render(inputOf(world, reversed)));
  CHECK(h0 == h1);
  Renderer b(s.render);
  CHECK(hashOf(b.render(world)) == h0);
  // And the water covers the block: 0.2 m × 0.2 m of a 0.4 m × 0.3 m view (aspect-widened).
  const auto cam = a.cameraRect();
  const double expected = 0.04 / ((cam[2] - cam[0]) * (cam[3] - cam[1]));
  const double got = waterShare(a.render(world));
  MESSAGE("water share " << got << ", block share " << expected);
  CHECK(got == doctest::Approx(expected).epsilon(0.15));
}

TEST_CASE("a liquid frame does not depend on the frames before it (the background comes back where water was)") {
  const SceneDef s = blockScene(160, 120, Vec2d(-0.1, -0.1), Vec2d(0.3, 0.3));
  World world(s, WorldOptions{1});
  // The same block lifted by 0.08 m: its rows of the image are others.
  ParticleBuffer raised;
  raised.assign(world.particles());
  for (auto& x : raised.x) x.y() += 0.08f;
  const Particles up = raised.view();
  Renderer seq(s.render);
  const std::uint64_t first = hashOf(seq.render(world));
  const std::uint64_t lifted = hashOf(seq.render(inputOf(world, up)));
  const std::uint64_t again = hashOf(seq.render(world));
  Renderer fresh(s.render);
  CHECK(hashOf(fresh.render(inputOf(world, up))) == lifted);
  CHECK(again == first);
  CHECK(lifted != first);
}

TEST_CASE("moving bodies are drawn where they are in each frame, with no trace where they were") {
  // A kinematic paddle above the water moving right at 1 m/s: after 0.5 s the frame of a
  // renderer that drew every earlier frame equals that of a fresh renderer, and the
  // paddle's colour is at its new place and gone from its old one.
  SceneDef s;
  s.solver = solverDefaults("wcsph");
  s.solver.spacing = 0.04;
  BodyDef tank;
  for (const auto& [c, h] :
       {std::pair<Vec2d, Vec2d>{{1, -0.1}, {1.2, 0.1}}, {{-0.1, 0.5}, {0.1, 0.7}}, {{2.1, 0.5}, {0.1, 0.7}}}) {
    ShapeDef box;
    box.center = c;
    box.halfSize = h;
    tank.fixtures.push_back(box);
  }
  s.bodies.push_back(tank);
  BodyDef paddle;
  paddle.type = BodyDef::Type::Kinematic;
  paddle.position = Vec2d(0.4, 0.7);
  paddle.velocity = Vec2d(1, 0);
  ShapeDef blade;
  blade.halfSize = Vec2d(0.08, 0.15);
  paddle.fixtures.push_back(blade);
  s.bodies.push_back(paddle);
  FluidBlockDef water;
  water.min = Vec2d(0, 0);
  water.max = Vec2d(2, 0.3);
  s.blocks.push_back(water);
  s.render.width = 200;
  s.render.height = 120;
  s.render.camera.min = Vec2d(-0.2, -0.2);
  s.render.camera.max = Vec2d(2.2, 1.2);
  World world(s, WorldOptions{1});
  Renderer seq(s.render);
  for (int f = 0; f < 30; ++f) {
    seq.render(world);
    world.stepFrame();
  }
  const Frame& a = seq.render(world);
  const std::uint64_t sequential = hashOf(a);
  auto solidAround = [&](const Frame& f, double wx, double wy) {
    return test::solidAround(f, s.render, seq.cameraRect(), wx, wy);
  };
  CHECK(solidAround(a, 0.9, 0.7) == 35);  // the paddle now (it moved 0.5 m)
  CHECK(solidAround(a, 0.4, 0.7) == 0);   // nothing left where it started
  Renderer fresh(s.render);
  CHECK(hashOf(fresh.render(world)) == sequential);
}

TEST_CASE("at high zoom sprites wider than the point-size limit are drawn as quads and cover the right area") {
  // The camera shows 0.02 m × 0.02 m around the block's lower-left corner at 200×200 px: 10000 px/m,
  // a spacing of 200 px, liquid sprites 800 px wide (400 px in the half-resolution field, > 255), by
  // the GL's point sprites. Only the particle at (0.01, 0.01) has its centre in the image.
  const SceneDef s = blockScene(200, 200, Vec2d(-0.01, -0.01), Vec2d(0.01, 0.01));
  World world(s, WorldOptions{1});
  RenderOptions gl;
  gl.splat = SplatPath::Gl;  // llvmpipe's default, the CPU's sums, has no size limit (test_renderer_splat.cpp)
  Renderer liquid(s.render, gl);
  REQUIRE(liquid.maxPointSize() <= 256.0f);
  // The fluid fills x > 0, y > 0 (a quarter of the view); one particle per image rounds the corner out.
  const double share = waterShare(liquid.render(world));
  CHECK(liquid.usedQuads());
  MESSAGE("high zoom: water share " << share);
  CHECK(share > 0.20);
  CHECK(share < 0.40);
  // The same corner at a fifth of the zoom (guard band, points), and at a tenth.
  const SceneDef mid = blockScene(200, 200, Vec2d(-0.05, -0.05), Vec2d(0.05, 0.05));
  World w1(mid, WorldOptions{1});
  Renderer r1(mid.render);
  const double share1 = waterShare(r1.render(w1));
  CHECK_FALSE(r1.usedQuads());
  MESSAGE("fifth of the zoom: water share " << share1);
  CHECK(share1 > 0.20);
  CHECK(share1 < 0.30);
  const SceneDef wide = blockScene(200, 200, Vec2d(-0.1, -0.1), Vec2d(0.1, 0.1));
  World w2(wide, WorldOptions{1});
  Renderer r2(wide.render);
  const double share2 = waterShare(r2.render(w2));
  CHECK_FALSE(r2.usedQuads());
  CHECK(share2 == doctest::Approx(0.25).epsilon(0.2));
  // Particles mode at the high zoom: discs of 80 px are points; at 16× zoom they are quads.
  RenderOptions po;
  po.mode = "particles";
  const SceneDef closer = blockScene(200, 200, Vec2d(0.005, 0.005), Vec2d(0.015, 0.015));  // 20000 px/m
  World w3(closer, WorldOptions{1});
  Renderer discs(closer.render, po);
  const Frame& d = discs.render(w3);
  CHECK(discs.usedQuads());
  // One disc of 400 px diameter centred at (0.01, 0.01) covers the view but its own corners.
  std::size_t coloured = 0;
  for (std::size_t p = 0; p < d.rgba.size(); p += 4)
    if (d.rgba[p + 2] > 100 || d.rgba[p + 1] > 100 || d.rgba[p] > 100) ++coloured;
  const double discShare = double(coloured) / (200.0 * 200.0);
  MESSAGE("disc share " << discShare);
  CHECK(discShare > 0.7);
}

TEST_CASE("ages fade particles: age 0 changes nothing, past the fade end the fluid vanishes") {
  const SceneDef s = blockScene(160, 120, Vec2d(-0.1, -0.1), Vec2d(0.3, 0.3));
  World world(s, WorldOptions{1});
  Renderer r(s.render);
  const std::uint64_t plain = hashOf(r.render(world));
  const double plainShare = waterShare(r.render(world));
  std::vector<Real> age(world.particleCount(), 0.0f);
  CHECK(hashOf(r.render(world, age.data())) == plain);
  std::fill(age.begin(), age.end(), 3.5f);  // default fade: 1 s .. 3 s
  CHECK(waterShare(r.render(world, age.data())) == 0.0);
  std::fill(age.begin(), age.end(), 2.0f);  // half faded: the field halves, the surface shrinks
  const double half = waterShare(r.render(world, age.data()));
  MESSAGE("water share: " << plainShare << " fresh, " << half << " half faded");
  CHECK(half < plainShare);
  CHECK(half > 0.0);
  // Particles mode coloured by age: the range is 0 .. the oldest age.
  RenderOptions po;
  po.mode = "particles";
  po.colorBy = ColorField::Age;
  Renderer pr(s.render, po);
  for (std::size_t i = 0; i < age.size(); ++i) age[i] = 0.01f * float(i % 50);
  pr.render(world, age.data());
  CHECK(pr.lastRange()[0] == 0.0);
  CHECK(pr.lastRange()[1] == doctest::Approx(0.49));
  CHECK_THROWS(pr.render(world));  // colour by age without ages
}

TEST_CASE("particles mode: the colour range is the field's min..max and the colour bar is drawn") {
  const SceneDef s = blockScene(240, 180, Vec2d(-0.1, -0.1), Vec2d(0.3, 0.3));
  World world(s, WorldOptions{1});
  for (int k = 0; k < 3; ++k) world.stepFrame();
  const Particles& P = world.particles();
  const auto [rlo, rhi] = std::minmax_element(P.rho.begin(), P.rho.end());
  const auto [plo, phi] = std::minmax_element(P.p.begin(), P.p.end());
  RenderOptions po;
  po.mode = "particles";
  po.colorBy = ColorField::Density;
  Renderer dr(s.render, po);
  const Frame& f = dr.render(world);
  CHECK(dr.lastRange()[0] == doctest::Approx(*rlo));
  CHECK(dr.lastRange()[1] == doctest::Approx(*rhi));
  // The bar's top row is the ramp's dark-red end, its bottom row the dark-blue end: find both
  // in the right half of the image.
  bool red = false, blue = false;
  for (int y = 0; y < f.height; ++y)
    for (int x = f.width / 2; x < f.width; ++x) {
      const std::uint8_t* p = &f.rgba[(std::size_t(y) * std::size_t(f.width) + std::size_t(x)) * 4];
      red = red || (p[0] == 128 && p[1] == 0 && p[2] == 0);    // colorRamp(1) = (0.5, 0, 0)
      blue = blue || (p[0] == 0 && p[1] == 0 && p[2] == 128);  // colorRamp(0) = (0, 0, 0.5)
    }
  CHECK(red);
  CHECK(blue);
  po.colorBy = ColorField::Pressure;
  Renderer pr(s.render, po);
  pr.render(world);
  CHECK(pr.lastRange()[0] == doctest::Approx(*plo));
  CHECK(pr.lastRange()[1] == doctest::Approx(*phi));
  po.range = std::array<double, 2>{0.0, 1000.0};
  Renderer fixed(s.render, po);
  fixed.render(world);
  CHECK(fixed.lastRange()[0] == 0.0);
  CHECK(fixed.lastRange()[1] == 1000.0);
}

TEST_CASE(
    "particles mode: color_by color draws each particle in its own colour, the rest in the fluid's, and no colour bar") {
  const SceneDef s = blockScene(240, 180, Vec2d(-0.1, -0.1), Vec2d(0.3, 0.3));
  World world(s, WorldOptions{1});
  // Left half of the block red, right half green, the top rows (y > 0.15) left uncoloured.
  for (std::size_t i = 0; i < world.particleCount(); ++i) {
    const Vec2d p = world.worldPosition(i);
    if (p.y() > 0.15) continue;
    world.setParticleColor(world.particles().id[i], p.x() < 0.1 ? 0xFF0000u : 0x00FF00u);
  }
  RenderOptions po;
  po.mode = "particles";
  po.colorBy = ColorField::Color;
  Renderer r(s.render, po);
  const Frame& f = r.render(world);
  // The first pixel (row-major, rows top-down) of a colour class: red, green or the fluid's blue.
  auto find = [&](const Frame& fr, int cls) -> const std::uint8_t* {
    for (std::size_t k = 0; k + 3 < fr.rgba.size(); k += 4) {
      const std::uint8_t* p = &fr.rgba[k];
      if (cls == 0 && p[0] > 150 && p[1] < 60 && p[2] < 60) return p;
      if (cls == 1 && p[1] > 150 && p[0] < 60 && p[2] < 60) return p;
      if (cls == 2 && p[2] > 120 && p[2] > p[0] + 60 && p[1] > 60) return p;
    }
    return nullptr;
  };
  auto count = [&](const Frame& fr, int cls) {
    std::size_t n = 0;
    for (std::size_t k = 0; k + 3 < fr.rgba.size(); k += 4) {
      const std::uint8_t* p = &fr.rgba[k];
      n += (cls == 0 && p[0] > 150 && p[1] < 60 && p[2] < 60) || (cls == 1 && p[1] > 150 && p[0] < 60 && p[2] < 60) ||
           (cls == 2 && p[2] > 120 && p[2] > p[0] + 60 && p[1] > 60);
    }
    return n;
  };
  // The three colours cover areas in proportion to their particles: red and green 8 rows of 5
  // each, the fluid's blue the 2 top rows of 10 (y = 0.17, 0.19); red left of green.
  const std::size_t nr = count(f, 0), ng = count(f, 1), nb = count(f, 2);
  MESSAGE("red " << nr << " px, green " << ng << " px, fluid blue " << nb << " px");
  CHECK(nr > 500);
  CHECK(ng > 500);
  CHECK(nb > 200);
  CHECK(double(nr) / double(ng) == doctest::Approx(1.0).epsilon(0.2));
  CHECK(double(nb) / double(nr) == doctest::Approx(0.5).epsilon(0.2));
  const std::uint8_t* a = find(f, 0);
  REQUIRE(a != nullptr);
  const std::size_t ax = std::size_t(a - f.rgba.data()) / 4 % std::size_t(f.width);
  std::size_t gx = 0;
  for (std::size_t k = 0; k + 3 < f.rgba.size(); k += 4)
    if (f.rgba[k + 1] > 150 && f.rgba[k] < 60 && f.rgba[k + 2] < 60) gx = std::max(gx, k / 4 % std::size_t(f.width));
  CHECK(ax < gx);
  // No colour bar: nothing on the ramp's dark-red end anywhere.
  bool barRed = false;
  for (std::size_t k = 0; k + 3 < f.rgba.size(); k += 4)
    barRed = barRed || (f.rgba[k] == 128 && f.rgba[k + 1] == 0 && f.rgba[k + 2] == 0);
  CHECK_FALSE(barRed);
  // Without any colour set, every particle is the fluid's colour.
  World plain(s, WorldOptions{1});
  Renderer r2(s.render, po);
  const Frame& g = r2.render(plain);
  CHECK(count(g, 0) == 0);
  CHECK(count(g, 1) == 0);
  CHECK(count(g, 2) > nr + ng);
  // Odd colours at and above 0x800000 come out as given (white, magenta), not rounded to a neighbour.
  for (std::size_t i = 0; i < plain.particleCount(); ++i)
    plain.setParticleColor(plain.particles().id[i], plain.worldPosition(i).x() < 0.1 ? 0xFFFFFFu : 0xFF00FFu);
  Renderer r3(s.render, po);
  const Frame& h = r3.render(plain);
  std::size_t white = 0, magenta = 0;
  for (std::size_t k = 0; k + 3 < h.rgba.size(); k += 4) {
    const std::uint8_t* p = &h.rgba[k];
    white += p[0] > 200 && p[1] > 200 && p[2] > 200;
    magenta += p[0] > 180 && p[1] < 60 && p[2] > 180;
  }
  MESSAGE("white " << white << " px, magenta " << magenta << " px");
  CHECK(white > 1000);
  CHECK(magenta > 1000);
}

TEST_CASE("particles mode: color_by material draws each particle in its material's colour, own colours first") {
  const SceneDef s = loadScene(std::string(SPH2D_ASSETS) + "/scenes/tests/two_materials.json");  // water below y = 1
  World world(s, WorldOptions{1});
  RenderOptions po;
  po.mode = "particles";
  po.colorBy = ColorField::Material;
  // Water (0.10, 0.45, 0.85) and dye (0.85, 0.20, 0.25): the rows where each is the most.
  auto rows = [](const Frame& f, bool dye) {
    double sum = 0, n = 0;
    for (std::size_t k = 0; k + 3 < f.rgba.size(); k += 4) {
      const std::uint8_t* p = &f.rgba[k];
      const bool isDye = p[0] > 150 && p[1] < 90 && p[2]<110, isWater = p[2]> 150 && p[0] < 90 && p[1] < 160;
      if (dye ? isDye : isWater) sum += double(k / 4 / std::size_t(f.width)), n += 1;
    }
    return std::make_pair(n, n > 0 ? sum / n : 0.0);
  };
  Renderer r(s.render, po);
  const Frame& f = r.render(world);
  const auto [nDye, yDye] = rows(f, true);
  const auto [nWater, yWater] = rows(f, false);
  MESSAGE("dye " << nDye << " px about row " << yDye << ", water " << nWater << " px about row " << yWater);
  CHECK(nDye > 300);
  CHECK(double(nDye) / double(nWater) == doctest::Approx(1.0).epsilon(0.15));  // 625 particles each
  CHECK(yDye < yWater);  // the dye above (image rows run top-down)
  // color_by color: a particle's own colour wins, the others keep their material's.
  for (std::size_t i = 0; i < world.particleCount(); ++i)
    if (world.worldPosition(i).y() > 1.5) world.setParticleColor(world.particles().id[i], 0x00FF00u);
  po.colorBy = ColorField::Color;
  Renderer rc(s.render, po);
  const Frame& fc = rc.render(world);
  std::size_t green = 0;
  for (std::size_t k = 0; k + 3 < fc.rgba.size(); k += 4)
    green += fc.rgba[k + 1] > 150 && fc.rgba[k] < 60 && fc.rgba[k + 2] < 60;
  const auto [nDye2, yDye2] = rows(fc, true);
  const auto [nWater2, yWater2] = rows(fc, false);
  CHECK(double(green) / double(nDye2) == doctest::Approx(1.0).epsilon(0.2));  // the dye's upper half green
  CHECK(double(nWater2) / double(nWater) == doctest::Approx(1.0).epsilon(0.05));
  CHECK(yDye2 > yDye);  // what is left of the dye is its lower half
}

TEST_CASE("liquid mode: each material in its own colour, and without materials none of the dye's") {
  const SceneDef s = loadScene(std::string(SPH2D_ASSETS) + "/scenes/tests/two_materials.json");  // dye above water
  World world(s, WorldOptions{1});
  RenderOptions lo;
  lo.mode = "liquid";
  Renderer r(s.render, lo);
  const Frame& f = r.render(world);
  // Pixels whose hue is the dye's (red) or the water's (blue), and their mean image row.
  auto hue = [](const Frame& fr, bool red) {
    double n = 0, rows = 0;
    for (std::size_t k = 0; k + 3 < fr.rgba.size(); k += 4) {
      const int R = fr.rgba[k], G = fr.rgba[k + 1], B = fr.rgba[k + 2];
      if (red ? (R > G + 40 && R > B + 40) : (B > R + 40 && B > G + 20))
        n += 1, rows += double(k / 4 / std::size_t(fr.width));
    }
    return std::make_pair(n, n > 0 ? rows / n : 0.0);
  };
  const auto [nRed, rowRed] = hue(f, true);
  const auto [nBlue, rowBlue] = hue(f, false);
  MESSAGE("dye " << nRed << " px about row " << rowRed << ", water " << nBlue << " px about row " << rowBlue);
  CHECK(nRed > 500);
  CHECK(double(nRed) / double(nBlue) == doctest::Approx(1.0).epsilon(0.25));  // 625 particles each
  CHECK(rowRed < rowBlue);                                                    // the dye above
  // The same particles as one material: every pixel of the fluid the render's water colour, as
  // a World without materials draws it.
  SceneDef one = s;
  one.materials.clear();
  for (FluidBlockDef& b : one.blocks) b.material = 0;
  for (EmitterDef& e : one.effects.emitters) e.material = 0;
  World plain(one, WorldOptions{1});
  Renderer rp(one.render, lo);
  const Frame& fp = rp.render(plain);
  CHECK(hue(fp, true).first == 0);
}

TEST_CASE("both modes draw mixed particles in their mixed colour") {
  // blockScene's block in zero gravity: its left half red, its right half blue, miscible at a
  // diffusion fast enough to mix it through in a second.
  SceneDef s = blockScene(160, 120, Vec2d(-0.1, -0.1), Vec2d(0.3, 0.3));
  s.gravity = Vec2d(0, 0);
  MaterialDef red;
  red.name = "red";
  red.density = s.solver.restDensity;
  red.color = {1, 0, 0};
  red.diffusion = 0.05;
  MaterialDef blue = red;
  blue.name = "blue";
  blue.color = {0, 0, 1};
  blue.miscibleWith = {"red"};
  s.materials = {red, blue};
  FluidBlockDef right = s.blocks[0];
  s.blocks[0].max.x() = 0.1;
  right.min.x() = 0.1;
  right.material = 1;
  s.blocks.push_back(right);
  auto count = [](const Frame& f) {  // pure red, pure blue, purple pixels
    std::array<std::size_t, 3> n{0, 0, 0};
    for (std::size_t k = 0; k + 3 < f.rgba.size(); k += 4) {
      const int R = f.rgba[k], G = f.rgba[k + 1], B = f.rgba[k + 2];
      if (G > 60) continue;
      n[0] += R > 100 && B < 40;
      n[1] += B > 100 && R < 40;
      n[2] += R > 50 && B > 50;
    }
    return n;
  };
  for (const char* mode : {"particles", "liquid"}) {
    RenderOptions o;
    o.mode = mode;
    o.colorBy = ColorField::Material;
    Renderer r(s.render, o);
    World w(s, WorldOptions{1});
    const std::array<std::size_t, 3> before = count(r.render(w));
    for (int f = 0; f < 60; ++f) w.stepFrame();
    const std::array<std::size_t, 3> after = count(r.render(w));
    MESSAGE(std::string(mode) << ": red, blue, purple pixels " << before[0] << ", " << before[1] << ", " << before[2]
                              << " -> " << after[0] << ", " << after[1] << ", " << after[2]);
    CHECK(before[0] > 200);
    CHECK(before[1] > 200);
    CHECK(after[0] < before[0] / 10);
    CHECK(after[1] < before[1] / 10);
    CHECK(after[2] > before[0]);
  }
}

TEST_CASE("the overlay changes only the pixels of its box in the top-left corner") {
  const SceneDef s = blockScene(320, 240, Vec2d(-0.1, -0.1), Vec2d(0.3, 0.3));
  World world(s, WorldOptions{1});
  Renderer plain(s.render);
  RenderOptions o;
  o.overlay = true;
  Renderer over(s.render, o);
  const Frame a = plain.render(world);
  const Frame& b = over.render(world);
  const int scale = 1;  // 240 px high: scale max(1, 240/270)
  const std::string line = "FRAME 0  T 0.000 S  100 PARTICLES";
  const int boxW = textWidth(line, scale) + 6 * scale, boxH = textHeight(scale) + 6 * scale;
  int inside = 0, outside = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const std::size_t p = (std::size_t(y) * std::size_t(a.width) + std::size_t(x)) * 4;
      const bool diff = a.rgba[p] != b.rgba[p] || a.rgba[p + 1] != b.rgba[p + 1] || a.rgba[p + 2] != b.rgba[p + 2];
      if (diff) (x < boxW && y < boxH ? inside : outside)++;
    }
  CHECK(outside == 0);
  CHECK(inside > boxW * boxH / 2);  // the translucent box darkens every pixel it covers (but black ones)
}

TEST_CASE("100k particles render: a 2 m x 1 m lattice covers its share of a 960x540 image, both modes") {
  // 100,352 particles at 0.0044 m (about 1.07 px at 240 px/m): sprites of 4.3 px, full-resolution field.
  ParticleBuffer B;
  const double dx = 0.0044;
  std::uint32_t id = 0;
  for (int j = 0; j < 224; ++j)
    for (int i = 0; i < 448; ++i)
      B.push(Vec2(Real(0.5 + (i + 0.5) * dx), Real(0.5 + (j + 0.5) * dx)), Vec2(Real(i % 7), 0), id++, Real(1000));
  const Particles P = B.view();
  REQUIRE(P.size() == 100352);
  RenderDef def;
  def.width = 960;
  def.height = 540;
  def.camera.automatic = false;
  def.camera.min = Vec2d(0, 0);
  def.camera.max = Vec2d(4, 2.25);
  RenderInput in;
  in.particles = P;
  in.spacing = dx;
  const double block = (448 * dx) * (224 * dx) / (4.0 * 2.25);
  Renderer liquid(def);
  const double share = waterShare(liquid.render(in));
  MESSAGE("100k liquid: water share " << share << ", block " << block);
  CHECK(share == doctest::Approx(block).epsilon(0.03));
  RenderOptions po;
  po.mode = "particles";
  Renderer discs(def, po);
  const Frame& f = discs.render(in);
  CHECK(discs.lastRange()[1] == doctest::Approx(6.0));
  // Discs of 3 px on a 1.07 px lattice cover the block; count non-background pixels left of the bar.
  std::size_t lit = 0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width * 3 / 4; ++x) {
      const std::uint8_t* p = &f.rgba[(std::size_t(y) * std::size_t(f.width) + std::size_t(x)) * 4];
      lit += (p[0] > 40 || p[1] > 40 || p[2] > 60);
    }
  const double litShare = double(lit) / (f.width * 0.75 * f.height);
  MESSAGE("100k discs: lit share " << litShare << ", block " << block / 0.75);
  CHECK(litShare == doctest::Approx(block / 0.75).epsilon(0.05));
}

TEST_CASE("liquid mode: a granular material is drawn as grains, a liquid of the same colour as a surface") {
  // blockScene's block as sand and as a liquid of its colour: grains are discs one spacing wide
  // with gaps between them, each its own shade; the liquid covers the block.
  SceneDef s = blockScene(320, 320, Vec2d(-0.04, -0.04), Vec2d(0.24, 0.24));
  MaterialDef sand;
  sand.name = "sand";
  sand.density = s.solver.restDensity;
  sand.color = {0.85, 0.70, 0.40};
  s.render.water = sand.color;  // one material: the liquid is drawn in the render's water colour
  std::array<double, 2> cover{0, 0}, shades{0, 0};
  for (const bool granular : {true, false}) {
    sand.kind = granular ? MaterialDef::Kind::granular : MaterialDef::Kind::fluid;
    s.materials = {sand};
    World world(s, WorldOptions{1});
    RenderOptions lo;
    lo.mode = "liquid";
    Renderer r(s.render, lo);
    const Frame& f = r.render(world);
    // Over the block's middle, the share of sand-hued pixels (R > G > B) and their distinct reds.
    const int W = f.width;
    auto px = [&](double x) { return int((x + 0.04) / 0.28 * W); };
    std::size_t n = 0, hued = 0;
    std::vector<int> seen(256, 0);
    for (int row = W - px(0.15); row < W - px(0.05); ++row)
      for (int col = px(0.05); col < px(0.15); ++col) {
        const std::uint8_t* p = &f.rgba[4 * (std::size_t(row) * std::size_t(W) + std::size_t(col))];
        ++n;
        if (p[0] > 120 && p[0] > p[1] && p[1] > p[2] + 20) {
          ++hued;
          seen[p[0]] = 1;
        }
      }
    cover[granular ? 0 : 1] = double(hued) / double(n);
    for (const int v : seen) shades[granular ? 0 : 1] += v;
  }
  MESSAGE("sand-hued share: grains " << cover[0] << ", liquid " << cover[1] << "; reds " << shades[0] << ", "
                                     << shades[1]);
  CHECK(cover[1] > 0.99);                      // a surface covers it
  CHECK((cover[0] > 0.6 && cover[0] < 0.97));  // grains, with gaps between them
  CHECK(shades[0] > 20);                       // each grain its own shade
}
