// sph2d/render/renderer.hpp — off-screen frames of a World through OSMesa.
//
// Passes per frame (GLSL in shaders/, embedded at build time):
//   splat      particles → soft kernel sums in an R32F target (additive)
//   composite  field → liquid colour with an anti-aliased edge
//   solid      Box2D fixtures drawn with their real shapes
// then glReadPixels into an RGBA8 buffer whose rows run top-down.
// The OSMesa context belongs to the thread that created the Renderer.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sph2d/scene.hpp"

namespace sph2d {

class World;

/// An RGBA8 image, rows top-down.
struct Frame {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;
};

/// Renders frames of a World.
class Renderer {
 public:
  /// Creates the OSMesa context and GL resources for `def`. Throws std::runtime_error.
  explicit Renderer(const RenderDef& def);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Renders the current state of `world`; the frame stays valid until the next call.
  const Frame& render(const World& world);
  /// GL_RENDERER and GL_VERSION of the context, e.g. "llvmpipe (LLVM 15.0.6, 256 bits) / 4.5 (Core Profile) Mesa 22.3.6".
  std::string rendererString() const;
  /// The world rectangle shown (after aspect correction), min x, min y, max x, max y.
  std::vector<double> cameraRect() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

/// The camera of `def` for `world`: its own rectangle, or the solids and fluid
/// with a margin; widened to the image's aspect ratio.
std::vector<double> resolveCamera(const RenderDef& def, const World& world);

}  // namespace sph2d
