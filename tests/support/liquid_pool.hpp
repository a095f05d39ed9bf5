// tests/support/liquid_pool.hpp — shared by the liquid mode's tests (tests/app/
// test_renderer_water.cpp, tests/app/test_renderer_tiles.cpp): square lattices of still particles
// and what is behind them, seen by a fixed camera (Pool), and variants of the composite program
// loaded through SPH2D_SHADER_DIR.
#pragma once

#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "sph2d/render/png_io.hpp"
#include "sph2d/render/renderer.hpp"

namespace sph2d::test {

inline constexpr double kDx = 0.0125;  // 3 px at 240 px/m, like the dam break

/// A box collider x0..x1 × y0..y1 (counter-clockwise).
inline Collider boxCollider(double x0, double y0, double x1, double y1) {
  Collider c;
  c.vertices = {Vec2(Real(x0), Real(y0)), Vec2(Real(x1), Real(y0)), Vec2(Real(x1), Real(y1)), Vec2(Real(x0), Real(y1))};
  c.normals = {Vec2(0, -1), Vec2(1, 0), Vec2(0, 1), Vec2(-1, 0)};
  c.lo = c.vertices[0];
  c.hi = c.vertices[2];
  return c;
}

/// Square lattices of still particles (spacing `step` each) and what is behind them, seen by a
/// fixed camera at 240 px per metre: x −0.1 .. 1.9, y −0.1 .. 1.025 in 480 × 270 px.
struct Pool {
  ParticleBuffer B;
  std::vector<Collider> solids;
  RenderDef def;
  std::uint32_t nextId = 0;
  Pool() {
    def.width = 480;
    def.height = 270;
    def.camera.automatic = false;
    def.camera.min = Vec2d(-0.1, -0.1);
    def.camera.max = Vec2d(1.9, 1.025);
  }
  void fill(double x0, double x1, double y0, double y1, double step) {
    for (double y = y0 + step / 2; y < y1; y += step)
      for (double x = x0 + step / 2; x < x1; x += step) B.push(Vec2(Real(x), Real(y)), Vec2(0, 0), nextId++, 1000);
  }
  /// The frame with the particles (or none) and the solids (or none).
  Frame render(bool particles, bool withSolids) const {
    RenderInput in;
    ParticleBuffer none;
    in.particles = particles ? B.view() : none.view();
    in.spacing = kDx;
    std::vector<Collider> noSolids;
    in.colliders = withSolids ? &solids : &noSolids;
    Renderer r(def);
    Frame f = r.render(in);
    if (const char* dump = std::getenv("SPH2D_TEST_DUMP")) writePngAtomic(dump, f.width, f.height, f.rgba.data());
    return f;
  }
};

/// Pixel (column, row) of world point (x, y) in the Pool's camera.
inline std::array<int, 2> pixelOf(double x, double y) {
  const double pxPerM = 240;
  return {int(std::floor((x + 0.1) * pxPerM)), int(std::floor((1.025 - y) * pxPerM))};
}

inline int channel(const Frame& f, int col, int row, int c) {
  return f.rgba[4 * (std::size_t(row) * std::size_t(f.width) + std::size_t(col)) + std::size_t(c)];
}

/// A folder for SPH2D_SHADER_DIR holding composite.frag as built with `before` replaced by
/// `after` once (a test's variant of the program).
inline std::string compositeVariant(const std::string& name, const std::string& before, const std::string& after) {
  std::ifstream in(std::string(SPH2D_SOURCE_DIR) + "/shaders/composite.frag");
  std::stringstream text;
  text << in.rdbuf();
  std::string src = text.str();
  const std::size_t at = src.find(before);
  REQUIRE(at != std::string::npos);
  src.replace(at, before.size(), after);
  const std::string dir = std::string(SPH2D_TEST_TMP) + "/" + name;
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/composite.frag") << src;
  return dir;
}

/// SPH2D_SHADER_DIR set to `dir` while it lives (a Renderer compiles its programs when made).
struct ShaderDir {
  explicit ShaderDir(const std::string& dir) { setenv("SPH2D_SHADER_DIR", dir.c_str(), 1); }
  ~ShaderDir() { unsetenv("SPH2D_SHADER_DIR"); }
  ShaderDir(const ShaderDir&) = delete;
  ShaderDir& operator=(const ShaderDir&) = delete;
};

}  // namespace sph2d::test
