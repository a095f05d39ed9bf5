// cpu_splat.cpp — the liquid's splat on the CPU (see cpu_splat.hpp for the design).
#include "cpu_splat.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <system_error>
#include <thread>

namespace sph2d {
namespace {

using Sprite = CpuSplatTarget::Sprite;

/// The factors of a sprite's kernel weight in each of its C channels (what splat.frag and
/// tint.frag multiply w by).
void channelsOf(SplatSum kind, float value, float k[4]) {
  if (kind == SplatSum::Field) {
    k[0] = 1.0f;
    k[1] = value;
    k[2] = k[3] = 0.0f;
    return;
  }
  const std::uint32_t c = std::uint32_t(value);  // 0xRRGGBB, exact in a float
  const float rgb[3] = {float((c >> 16) & 255u) / 255.0f, float((c >> 8) & 255u) / 255.0f, float(c & 255u) / 255.0f};
  for (int i = 0; i < 3; ++i) k[i] = kind == SplatSum::Absorb ? std::log(std::max(rgb[i], 1e-3f)) : rgb[i];
  k[3] = 1.0f;
}

/// Adds the sprites `ids` (in order) into rows [r0, r1) of `out` (w texels a row); `dx2` holds
/// at least w floats.
template <int C>
void splatRows(const std::vector<Sprite>& sprites, const std::vector<std::uint32_t>& ids, float d, int w, int r0,
               int r1, float* dx2, float* out) {
  const float inv = 2.0f / d;
  for (const std::uint32_t id : ids) {
    const Sprite& s = sprites[id];
    const int y0 = std::max(s.y0, r0), y1 = std::min(s.y1, r1 - 1);
    const int span = s.x1 - s.x0 + 1;
    for (int j = 0; j < span; ++j) {
      const float u = (float(s.x0 + j) + 0.5f - s.xw) * inv;
      dx2[j] = u * u;
    }
    for (int iy = y0; iy <= y1; ++iy) {
      const float v = (float(iy) + 0.5f - s.yw) * inv;
      const float dy2 = v * v;
      if (!(dy2 < 1.0f)) continue;
      float* row = out + (std::size_t(iy) * std::size_t(w) + std::size_t(s.x0)) * C;
      for (int j = 0; j < span; ++j) {
        const float q2 = dx2[j] + dy2;
        if (!(q2 < 1.0f)) continue;  // the fragment the GL discards
        const float a = 1.0f - q2;
        const float wk = a * a * a * s.weight;
        for (int c = 0; c < C; ++c) row[j * C + c] += wk * s.k[c];
      }
    }
  }
}

}  // namespace

bool softwareRasterizer(const char* glRenderer) {
  if (!glRenderer) return false;
  for (const char* name : {"llvmpipe", "softpipe", "Software Rasterizer"})
    if (std::strstr(glRenderer, name)) return true;
  return false;
}

std::pair<int, int> CpuSplatTarget::sum(const std::vector<float>& packed, std::size_t n, const float scale[2],
                                        const float offset[2], float diameterPx, int w, int h, SplatSum kind) {
  try {
    return sumAll(packed, n, scale, offset, diameterPx, w, h, kind);
  } catch (...) {
    reset();  // the texels are not what was uploaded: the next sum uploads them all
    throw;
  }
}

std::pair<int, int> CpuSplatTarget::sumAll(const std::vector<float>& packed, std::size_t n, const float scale[2],
                                           const float offset[2], float diameterPx, int w, int h, SplatSum kind) {
  const int C = splatChannels(kind);
  w = std::max(w, 0);
  h = std::max(h, 0);
  std::pair<int, int> upload{0, h};
  if (w != w_ || h != h_ || C != channels_) {
    w_ = 0;  // until the texels are whole
    texels_.assign(std::size_t(w) * std::size_t(h) * std::size_t(C), 0.0f);
    w_ = w;
    h_ = h;
    channels_ = C;
  } else {
    std::fill(texels_.begin() + std::ptrdiff_t(std::size_t(rows_.first) * std::size_t(w) * std::size_t(C)),
              texels_.begin() + std::ptrdiff_t(std::size_t(rows_.second) * std::size_t(w) * std::size_t(C)), 0.0f);
    upload = rows_;
  }
  rows_ = {0, 0};
  n = std::min(n, packed.size() / 4);
  if (w == 0 || h == 0 || !(diameterPx > 0.0f)) return upload;
  const float r = 0.5f * diameterPx;
  // Each sprite's window position (the vertex shader's NDC, then the viewport) and the texels
  // whose centres its disc can cover (q² < 1 lies inside the point's square); then, per band
  // of rows, the sprites that reach it, in their order.
  constexpr int kBand = 32;
  const int bands = (h + kBand - 1) / kBand;
  sprites_.clear();
  inBand_.resize(std::size_t(bands));
  for (auto& v : inBand_) v.clear();
  for (auto& v : scratch_) v.resize(std::size_t(w));
  int lo = h, hi = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const float* p = &packed[4 * i];
    if (!(p[3] != 0.0f)) continue;
    const float nx = p[0] * scale[0] + offset[0], ny = p[1] * scale[1] + offset[1];
    const float xw = (nx + 1.0f) * 0.5f * float(w), yw = (ny + 1.0f) * 0.5f * float(h);
    if (!(std::isfinite(xw) && std::isfinite(yw))) continue;
    const float fx0 = std::ceil(xw - r - 0.5f), fx1 = std::floor(xw + r - 0.5f);
    const float fy0 = std::ceil(yw - r - 0.5f), fy1 = std::floor(yw + r - 0.5f);
    if (!(fx0 <= fx1 && fy0 <= fy1) || fx1 < 0.0f || fy1 < 0.0f || fx0 > float(w - 1) || fy0 > float(h - 1)) continue;
    Sprite s{};
    s.xw = xw;
    s.yw = yw;
    s.weight = p[3];
    channelsOf(kind, p[2], s.k);
    s.x0 = int(std::max(fx0, 0.0f));
    s.x1 = int(std::min(fx1, float(w - 1)));
    s.y0 = int(std::max(fy0, 0.0f));
    s.y1 = int(std::min(fy1, float(h - 1)));
    const std::uint32_t id = std::uint32_t(sprites_.size());
    sprites_.push_back(s);
    for (int b = s.y0 / kBand; b <= s.y1 / kBand; ++b) inBand_[std::size_t(b)].push_back(id);
    lo = std::min(lo, s.y0);
    hi = std::max(hi, s.y1 + 1);
  }
  if (lo < hi) {
    rows_ = {lo, hi};
    upload = upload.first < upload.second ? std::pair<int, int>{std::min(upload.first, lo), std::max(upload.second, hi)}
                                          : rows_;
  }
  // From here nothing allocates: the bands are summed by this thread and, when the work is
  // worth a thread's start (tens of µs), a helper, each with its own scratch row.
  float* out = texels_.data();
  auto run = [&](int b0, int b1, float* dx2) {
    for (int b = b0; b < b1; ++b) {
      const int r0 = b * kBand, r1 = std::min(h, r0 + kBand);
      if (C == 2)
        splatRows<2>(sprites_, inBand_[std::size_t(b)], diameterPx, w, r0, r1, dx2, out);
      else
        splatRows<4>(sprites_, inBand_[std::size_t(b)], diameterPx, w, r0, r1, dx2, out);
    }
  };
  // Bands hold their own texels: split where half the sprites' band entries are on each side.
  const double work = double(sprites_.size()) * double(diameterPx) * double(diameterPx);
  std::size_t total = 0;
  for (const auto& v : inBand_) total += v.size();
  int split = 0;
  for (std::size_t acc = 0; split < bands && 2 * acc < total; ++split) acc += inBand_[std::size_t(split)].size();
  if (work < 2e5 || split <= 0 || split >= bands) {
    run(0, bands, scratch_[0].data());
    return upload;
  }
  std::thread helper;
  try {
    helper = std::thread(run, split, bands, scratch_[1].data());
  } catch (const std::system_error&) {  // no thread to be had: this one sums them all
    run(0, bands, scratch_[0].data());
    return upload;
  }
  run(0, split, scratch_[0].data());
  helper.join();
  return upload;
}

}  // namespace sph2d
