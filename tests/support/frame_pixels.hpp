// tests/support/frame_pixels.hpp — pixel probes of a rendered Frame, shared by the renderer
// tests (tests/app/test_renderer.cpp, tests/app/test_renderer_layout.cpp): one definition, so
// that "a solid there" means the same box of pixels in both.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "sph2d/render/image.hpp"
#include "sph2d/scene.hpp"

namespace sph2d::test {

/// Pixels of `def`'s solid colour in the 5 × 7 box around world point (wx, wy) of frame f,
/// seen through camera rectangle `cam` (Renderer::cameraRect: aspect-fitted).
inline int solidAround(const Frame& f, const RenderDef& def, const std::vector<double>& cam, double wx, double wy) {
  const std::array<std::uint8_t, 3> solid{std::uint8_t(std::lround(def.solid[0] * 255)),
                                          std::uint8_t(std::lround(def.solid[1] * 255)),
                                          std::uint8_t(std::lround(def.solid[2] * 255))};
  const int cx = int((wx - cam[0]) / (cam[2] - cam[0]) * f.width),
            cy = int((cam[3] - wy) / (cam[3] - cam[1]) * f.height);
  int n = 0;
  for (int y = cy - 3; y <= cy + 3; ++y)
    for (int x = cx - 2; x <= cx + 2; ++x) {
      const std::uint8_t* p = &f.rgba[(std::size_t(y) * std::size_t(f.width) + std::size_t(x)) * 4];
      n += p[0] == solid[0] && p[1] == solid[1] && p[2] == solid[2];
    }
  return n;
}

}  // namespace sph2d::test
