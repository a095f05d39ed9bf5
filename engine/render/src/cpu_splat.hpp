// cpu_splat.hpp — the liquid's splat on the CPU: the same sums the GL point sprites of
// shaders/splat.frag and shaders/tint.frag add into their float targets, computed in one loop.
//
// Design: a software rasterizer (llvmpipe) spends most of the splat on each point's own set-up
// (a wide point becomes a quad, clipped, binned: 3 ms for 20,000 points even when each covers
// one pixel, on the development machine) and on blending float fragments. The sum itself is a
// few multiply-adds a texel. A texel (ix, iy) of a w × h target (iy from the bottom, as the
// GL's window rows) takes a sprite of diameter D centred at window position (xw, yw) when
// q² = |2 (ix + ½ − xw, iy + ½ − yw) / D|² < 1, with w = (1 − q²)³ × the particle's weight: the
// point sprite's gl_PointCoord and discard (the caller gives D at least the GL's smallest point
// size, as the GL clamps it). The sprites are added in their order (id order, as the GL draws
// them), so each texel's sum runs in the same order as the GL's blending; the frames of the two
// paths differ by float rounding and by llvmpipe's fixed-point sprite sizes (at most 2 levels
// of a channel in under 1 % of the pixels, tests/app/test_renderer_splat.cpp). Unlike a GL
// point, a sprite whose centre is off the target still adds its part; the targets' guard band
// (camera.hpp) keeps every centre that reaches the image inside them, so the frames agree.
// The target is cut into bands of 32 rows, each summed from the sprites that reach it (kept
// in their order); two threads take a half of the bands each when the frame is large enough.
// A texel's sum is the same whichever band or thread makes it. Only rows that held or now hold
// a sprite are cleared and uploaded.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace sph2d {

/// What a sprite adds into its texels (the shaders the GL path runs).
enum class SplatSum {
  Field,   ///< RG: w, w × value (the speed; shaders/splat.frag)
  Tint,    ///< RGBA: w × colour, w (value = 0xRRGGBB; shaders/tint.frag)
  Absorb,  ///< RGBA: w × ln(max(colour / 255, 1e-3)), w (shaders/tint.frag with ABSORB)
};

/// True when `glRenderer` (GL_RENDERER) names a software rasterizer: Mesa's llvmpipe or softpipe,
/// or its classic "Software Rasterizer" (RenderOptions::splat's auto takes the CPU there).
bool softwareRasterizer(const char* glRenderer);

/// Channels of a target of `sum` (2 or 4).
inline int splatChannels(SplatSum sum) { return sum == SplatSum::Field ? 2 : 4; }

/// One float target summed on the CPU, kept between frames.
class CpuSplatTarget {
 public:
  /// Sums the first `n` sprites of `packed` (x, y, value, weight per sprite, the engine's local
  /// frame; weight 0 adds nothing) into w × h texels of splatChannels(kind) floats, rows from the
  /// bottom: local → NDC by `scale` and `offset`, each sprite `diameterPx` texels wide. Returns
  /// the rows [first, last) that may differ from the last sum's (all of them after a change of
  /// size or kind, or reset()): the rows to upload.
  /// On an exception (memory) the next sum returns every row.
  std::pair<int, int> sum(const std::vector<float>& packed, std::size_t n, const float scale[2], const float offset[2],
                          float diameterPx, int w, int h, SplatSum kind);
  /// The texels of the last sum (w × h × channels floats).
  const float* texels() const { return texels_.data(); }
  /// Forgets what the texture holds: the next sum returns every row.
  void reset() { w_ = 0; }

  /// A sprite in the target's texels: its window position and the texels it can cover.
  struct Sprite {
    float xw, yw, weight;
    float k[4];  ///< the kernel weight's factor in each channel
    int x0, x1, y0, y1;
  };

 private:
  std::pair<int, int> sumAll(const std::vector<float>& packed, std::size_t n, const float scale[2],
                             const float offset[2], float diameterPx, int w, int h, SplatSum kind);
  std::vector<float> scratch_[2];  ///< a row of squared x distances per thread
  std::vector<float> texels_;
  int w_ = 0, h_ = 0, channels_ = 0;
  std::pair<int, int> rows_{0, 0};  ///< rows the last sum touched
  std::vector<Sprite> sprites_;
  std::vector<std::vector<std::uint32_t>> inBand_;
};

}  // namespace sph2d
