// field_splat.cpp — the liquid's field on the CPU (see field_splat.hpp for the design).
#include "field_splat.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace sph2d {

void FieldSplat::resize(int w, int h) {
  w_ = w;
  h_ = h;
  field_.assign(std::size_t(w) * std::size_t(h) * 4, 0.0f);
  rowBegin_ = rowEnd_ = 0;
  fresh_ = true;
}

void FieldSplat::splat(const std::vector<float>& packed, const float scale[2], const float offset[2],
                       float diameterPx) {
  const std::size_t w = std::size_t(w_);
  // Clear what the last splat left.
  if (rowEnd_ > rowBegin_)
    std::memset(field_.data() + std::size_t(rowBegin_) * w * 4, 0,
                std::size_t(rowEnd_ - rowBegin_) * w * 4 * sizeof(float));
  int lo = h_, hi = 0;
  const double r = 0.5 * double(diameterPx);
  const float inv = float(1.0 / r);
  const std::size_t n = packed.size() / 4;
  for (std::size_t k = 0; k < n; ++k) {
    const float* p = &packed[4 * k];
    // The sprite's centre in window coordinates of the field (pixel centres at i + 0.5).
    const double cx = (double(p[0]) * scale[0] + offset[0] + 1.0) * 0.5 * w_;
    const double cy = (double(p[1]) * scale[1] + offset[1] + 1.0) * 0.5 * h_;
    const int x0 = std::max(0, int(std::ceil(cx - r - 0.5))), x1 = std::min(w_ - 1, int(std::floor(cx + r - 0.5)));
    const int y0 = std::max(0, int(std::ceil(cy - r - 0.5))), y1 = std::min(h_ - 1, int(std::floor(cy + r - 0.5)));
    if (x0 > x1 || y0 > y1) continue;
    lo = std::min(lo, y0);
    hi = std::max(hi, y1 + 1);
    const float speed = p[2], weight = p[3];
    const float fx0 = float((x0 + 0.5 - cx) * inv);
    for (int y = y0; y <= y1; ++y) {
      const float dy = float((y + 0.5 - cy) * inv);
      const float dy2 = dy * dy;
      float* row = field_.data() + (std::size_t(y) * w + std::size_t(x0)) * 4;
      for (int i = 0; i <= x1 - x0; ++i) {
        const float dx = fx0 + float(i) * inv;
        const float a = std::max(0.0f, 1.0f - (dx * dx + dy2));  // 0 outside the disc: adds nothing
        const float wk = a * a * a * weight;
        row[4 * i] += wk;
        row[4 * i + 1] += wk * speed;
      }
    }
  }
  // The gradient, on the rows written and one row beyond on each side.
  const int begin = lo < hi ? std::max(0, lo - 1) : 0, end = lo < hi ? std::min(h_, hi + 1) : 0;
  for (int y = begin; y < end; ++y) {
    const float* above = field_.data() + std::size_t(std::max(y - 1, 0)) * w * 4;
    const float* below = field_.data() + std::size_t(std::min(y + 1, h_ - 1)) * w * 4;
    float* row = field_.data() + std::size_t(y) * w * 4;
    for (std::size_t x = 0; x < w; ++x) row[4 * x + 3] = (above[4 * x] - below[4 * x]) * 0.5f;
    if (w < 2) continue;
    for (std::size_t x = 1; x + 1 < w; ++x) row[4 * x + 2] = (row[4 * x + 4] - row[4 * x - 4]) * 0.5f;
    row[2] = (row[4] - row[0]) * 0.5f;
    row[4 * (w - 1) + 2] = (row[4 * (w - 1)] - row[4 * (w - 2)]) * 0.5f;
  }
  // Changed rows: those written now and those cleared (written last time); all after resize().
  if (fresh_) {
    dirtyBegin_ = 0;
    dirtyEnd_ = h_;
  } else if (rowBegin_ >= rowEnd_ || begin >= end) {
    dirtyBegin_ = begin < end ? begin : rowBegin_;
    dirtyEnd_ = begin < end ? end : rowEnd_;
  } else {
    dirtyBegin_ = std::min(begin, rowBegin_);
    dirtyEnd_ = std::max(end, rowEnd_);
  }
  fresh_ = false;
  rowBegin_ = begin;
  rowEnd_ = end;
}

}  // namespace sph2d
