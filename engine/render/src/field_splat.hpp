// field_splat.hpp — the liquid's field on the CPU: every particle adds its kernel
// w = (1 − q²)³ × its age fade, and w·|v|, into a float image, which also carries the field's
// gradient; the composite reads it as one RGBA32F texture.
//
// Design: llvmpipe spends about 0.2 µs setting up each point sprite whatever its size (measured,
// docs/RENDERING.md "Speed"), more than the whole kernel costs on the CPU, so the splat is a plain
// loop over the particles in id order and over the pixels whose centres lie within the sprite's
// radius — the pixels and the kernel argument the GPU's point sprite had (q = distance from the
// sprite's centre over its radius, at pixel centres). Each pixel receives its additions in id
// order and in single precision without contraction, so the field is the same on every machine.
// The gradient is the central difference at each texel (edge texels repeated, as a texture's
// clamp to edge would), so the composite needs one filtered sample where it took five (the
// field and four neighbours), and a bilinear read of it stays smooth from pixel to pixel.
// Rows run as the targets' do (row 0 is the world's top). Only the rows that particles reached
// this frame or the last (and one row beyond, for the gradient) are cleared and uploaded.
#pragma once

#include <vector>

namespace sph2d {

/// The liquid's field (see the design note above).
class FieldSplat {
 public:
  /// Sizes the field (w × h px) and clears it.
  void resize(int w, int h);
  /// Clears the field and adds every particle of `packed` (x, y, speed, weight per particle,
  /// engine local frame): the window position of (x, y) is ((x·sx + ox + 1) w/2,
  /// (y·sy + oy + 1) h/2), with (sx, sy, ox, oy) the targets' local → NDC transform; the
  /// sprites are `diameterPx` wide in field pixels. Then computes the gradient.
  void splat(const std::vector<float>& packed, const float scale[2], const float offset[2], float diameterPx);
  int width() const { return w_; }   ///< field width [px]
  int height() const { return h_; }  ///< field height [px]
  /// Per pixel, rows from the world's top: Σ w, Σ w·speed, and the gradient of Σ w per field
  /// pixel in world orientation: (right − left) / 2, (above − below) / 2.
  const std::vector<float>& data() const { return field_; }
  /// The rows [dirtyBegin, dirtyEnd) that changed in the last splat() (every row after
  /// resize()): the rows to upload.
  int dirtyBegin() const { return dirtyBegin_; }
  int dirtyEnd() const { return dirtyEnd_; }

 private:
  int w_ = 0, h_ = 0;
  int rowBegin_ = 0, rowEnd_ = 0;      // rows that may hold non-zero values
  int dirtyBegin_ = 0, dirtyEnd_ = 0;  // rows changed by the last splat (or resize)
  bool fresh_ = true;                  // resized since the last splat: every row is new
  std::vector<float> field_;           // RGBA per pixel
};

}  // namespace sph2d
