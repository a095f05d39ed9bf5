// The liquid's splat summed on the CPU (engine/render/src/cpu_splat.hpp) on its own: against a
// plain loop over every sprite and texel in order (the same arithmetic, so the same bits
// whatever the bands and threads), with sprites of every size, partly or wholly off the
// target, at non-finite positions and weights; and the rows it says to upload, which must
// keep a texture that receives only those rows equal to its texels, frame after frame.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "cpu_splat.hpp"

using namespace sph2d;

namespace {

/// The sums by the definition: every sprite in order, every texel of its square, q² < 1.
std::vector<float> reference(const std::vector<float>& packed, const float scale[2], const float offset[2], float d,
                             int w, int h, SplatSum kind) {
  const int C = splatChannels(kind);
  std::vector<float> out(std::size_t(w) * std::size_t(h) * std::size_t(C), 0.0f);
  const float r = 0.5f * d, inv = 2.0f / d;
  for (std::size_t i = 0; i + 3 < packed.size(); i += 4) {
    const float* p = &packed[i];
    if (!(p[3] != 0.0f)) continue;
    const float xw = (p[0] * scale[0] + offset[0] + 1.0f) * 0.5f * float(w);
    const float yw = (p[1] * scale[1] + offset[1] + 1.0f) * 0.5f * float(h);
    if (!(std::isfinite(xw) && std::isfinite(yw))) continue;
    float k[4] = {1.0f, p[2], 0.0f, 0.0f};
    if (C == 4) {
      const std::uint32_t c = std::uint32_t(p[2]);
      for (int s = 0; s < 3; ++s) {
        const float v = float((c >> (16 - 8 * s)) & 255u) / 255.0f;
        k[s] = kind == SplatSum::Absorb ? std::log(std::max(v, 1e-3f)) : v;
      }
      k[3] = 1.0f;
    }
    // A texel more each side than the disc can reach: q² < 1 alone decides.
    const float x0 = std::floor(xw - r - 0.5f) - 1.0f, x1 = std::ceil(xw + r - 0.5f) + 1.0f;
    const float y0 = std::floor(yw - r - 0.5f) - 1.0f, y1 = std::ceil(yw + r - 0.5f) + 1.0f;
    for (float fy = std::max(y0, 0.0f); fy <= std::min(y1, float(h - 1)); fy += 1.0f)
      for (float fx = std::max(x0, 0.0f); fx <= std::min(x1, float(w - 1)); fx += 1.0f) {
        const float u = (fx + 0.5f - xw) * inv, v = (fy + 0.5f - yw) * inv;
        const float q2 = u * u + v * v;
        if (!(q2 < 1.0f)) continue;
        const float a = 1.0f - q2;
        const float wk = a * a * a * p[3];
        float* t = &out[(std::size_t(fy) * std::size_t(w) + std::size_t(fx)) * std::size_t(C)];
        for (int c = 0; c < C; ++c) t[c] += wk * k[c];
      }
  }
  return out;
}

/// `n` sprites in [-1.3, 1.3]² of NDC (some off the target), random speeds or colours.
std::vector<float> sprites(std::mt19937& rng, std::size_t n, bool colours) {
  std::uniform_real_distribution<float> pos(-1.3f, 1.3f), unit(0.0f, 1.0f);
  std::vector<float> p;
  for (std::size_t i = 0; i < n; ++i) {
    const float value = colours ? float(rng() & 0xFFFFFFu) : 5.0f * unit(rng);
    p.insert(p.end(), {pos(rng), pos(rng), value, unit(rng) < 0.1f ? 0.0f : unit(rng)});
  }
  return p;
}

bool sameBits(const float* a, const std::vector<float>& b) {
  return std::memcmp(a, b.data(), b.size() * sizeof(float)) == 0;
}

}  // namespace

TEST_CASE("cpu splat: the sums are a plain loop's, bit for bit, at every size and on two threads") {
  std::mt19937 rng(7);
  const float scale[2] = {1.0f, 1.0f}, offset[2] = {0.0f, 0.0f};
  for (const SplatSum kind : {SplatSum::Field, SplatSum::Tint, SplatSum::Absorb}) {
    // Few small sprites (one thread) and many wide ones (work enough for two).
    for (const float d : {1.0f, 2.5f, 7.3f, 18.0f, 300.0f}) {
      const std::size_t n = d < 5 ? 400 : d < 100 ? 6000 : 600;
      std::vector<float> p = sprites(rng, n, kind != SplatSum::Field);
      CpuSplatTarget t;
      const auto rows = t.sum(p, n, scale, offset, d, 203, 157, kind);
      CHECK(rows == std::pair<int, int>{0, 157});  // a new target: every row
      CHECK_MESSAGE(sameBits(t.texels(), reference(p, scale, offset, d, 203, 157, kind)),
                    "kind " << int(kind) << ", diameter " << d);
    }
  }
  // Non-finite positions are skipped; a NaN or infinite weight or value spoils only the disc's
  // texels (as the GL's blending would), not the square around it.
  std::vector<float> p = {0.0f, 0.0f, 1.0f, 1.0f};
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  p.insert(p.end(), {nan, 0.1f, 1.0f, 1.0f, 0.2f, inf, 1.0f, 1.0f, 0.5f, 0.5f, inf, 1.0f, -0.5f, -0.5f, 1.0f, nan});
  CpuSplatTarget t;
  t.sum(p, p.size() / 4, scale, offset, 12.0f, 64, 64, SplatSum::Field);
  CHECK(sameBits(t.texels(), reference(p, scale, offset, 12.0f, 64, 64, SplatSum::Field)));
  std::size_t nonFinite = 0;
  for (std::size_t i = 0; i < 64 * 64 * 2; ++i) nonFinite += !std::isfinite(t.texels()[i]);
  // A disc 12 px wide holds about 113 texel centres, its square 144: the infinite speed spoils
  // one channel of a disc, the NaN weight both of another (3 × 113 ≈ 339; squares: 432).
  MESSAGE("non-finite channels " << nonFinite);
  CHECK(nonFinite > 300);
  CHECK(nonFinite < 400);
}

TEST_CASE("cpu splat: a texture that takes only the rows to upload stays equal to the sums") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const float offset[2] = {0.0f, 0.0f};
  CpuSplatTarget t;
  std::vector<float> texture;  // what the GL texture would hold: garbage when (re)made
  int w = 0, h = 0;
  for (int frame = 0; frame < 300; ++frame) {
    // Now and then a new size (a new texture, reset() as liquid_pass.cpp does), an empty frame,
    // sprites all off the target, or a band of rows far from the last one.
    if (frame % 37 == 0) {
      w = 40 + int(rng() % 200);
      h = 30 + int(rng() % 150);
      texture.assign(std::size_t(w) * std::size_t(h) * 2, 12345.0f);
      t.reset();
    }
    const int what = int(rng() % 10);
    const std::size_t n = what == 0 ? 0 : 1 + rng() % 400;
    const float scale[2] = {what == 1 ? 0.01f : 0.3f, 0.3f};
    const float shift = what == 1 ? 50.0f : 2.5f * unit(rng) - 1.25f;  // a band somewhere, or far off
    std::vector<float> p;
    for (std::size_t i = 0; i < n; ++i)
      p.insert(p.end(), {6.0f * unit(rng) - 3.0f, 6.0f * unit(rng) - 3.0f, 1.0f, 1.0f});
    const float off[2] = {shift, offset[1] + (what == 1 ? 50.0f : shift)};
    const float d = 1.0f + 12.0f * unit(rng);
    const auto [y0, y1] = t.sum(p, n, scale, off, d, w, h, SplatSum::Field);
    REQUIRE(0 <= y0);
    REQUIRE(y1 <= h);
    if (y0 < y1)
      std::memcpy(&texture[std::size_t(y0) * std::size_t(w) * 2], t.texels() + std::size_t(y0) * std::size_t(w) * 2,
                  std::size_t(y1 - y0) * std::size_t(w) * 2 * sizeof(float));
    REQUIRE_MESSAGE(sameBits(t.texels(), texture), "frame " << frame);
    REQUIRE(sameBits(t.texels(), reference(p, scale, off, d, w, h, SplatSum::Field)));
  }
}

TEST_CASE("cpu splat: a software rasterizer is told by its GL_RENDERER") {
  CHECK(softwareRasterizer("llvmpipe (LLVM 15.0.6, 256 bits)"));
  CHECK(softwareRasterizer("softpipe"));
  CHECK(softwareRasterizer("Mesa X11 Software Rasterizer"));
  CHECK_FALSE(softwareRasterizer("NVIDIA GeForce RTX 3060/PCIe/SSE2"));
  CHECK_FALSE(softwareRasterizer("AMD Radeon RX 6600 (radeonsi, navi23, LLVM 15.0.6, DRM 3.49)"));
  CHECK_FALSE(softwareRasterizer(nullptr));
}
