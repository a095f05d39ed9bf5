// field_splat.hpp — the liquid's field on the CPU: every particle adds its kernel
// w = (1 − q²)³ × its age fade, and w·|v|, into an RG float image (the field the composite reads).
//
// Design: llvmpipe spends about 0.2 µs setting up each point sprite whatever its size (measured,
// docs/RENDERING.md "Speed"), more than the whole kernel costs on the CPU, so the splat is a plain
// loop over the particles in id order and over the pixels whose centres lie within the sprite's
// radius — the pixels and the kernel argument the GPU's point sprite had (q = distance from the
// sprite's centre over its radius, at pixel centres). Each pixel receives its additions in id
// order and in single precision without contraction, so the field is the same on every machine.
// Rows run as the targets' do (row 0 is the world's top). Only the rows that particles reached
// this frame or the last are cleared and uploaded.
#pragma once

#include <vector>

namespace sph2d {

/// The RG32F field of the liquid (see the design note above).
class FieldSplat {
 public:
  /// Sizes the field (w × h px) and clears it.
  void resize(int w, int h);
  /// Clears the field and adds every particle of `packed` (x, y, speed, weight per particle,
  /// engine local frame): the window position of (x, y) is ((x·sx + ox + 1) w/2,
  /// (y·sy + oy + 1) h/2), with (sx, sy, ox, oy) the targets' local → NDC transform; the
  /// sprites are `diameterPx` wide in field pixels.
  void splat(const std::vector<float>& packed, const float scale[2], const float offset[2], float diameterPx);
  int width() const { return w_; }   ///< field width [px]
  int height() const { return h_; }  ///< field height [px]
  /// R = Σ w, G = Σ w·speed per pixel, rows from the world's top.
  const std::vector<float>& data() const { return field_; }
  /// The rows [dirtyBegin, dirtyEnd) that changed in the last splat() (cleared or written;
  /// every row after resize()): the rows to upload.
  int dirtyBegin() const { return dirtyBegin_; }
  int dirtyEnd() const { return dirtyEnd_; }

 private:
  int w_ = 0, h_ = 0;
  int rowBegin_ = 0, rowEnd_ = 0;      // rows written by the last splat
  int dirtyBegin_ = 0, dirtyEnd_ = 0;  // rows changed by the last splat (or resize)
  bool fresh_ = true;                  // resized since the last splat: every row is new
  std::vector<float> field_;
};

}  // namespace sph2d
