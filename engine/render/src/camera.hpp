// camera.hpp — where the image lies in the world and how large the render targets are.
//
// Design: the camera rectangle (the scene's, or the solids and fluid with a margin, widened to
// the image's aspect ratio: resolveCamera() in renderer.hpp) is fixed by a renderer's first
// frame. Every target is the image plus a guard band on each side, because GL culls a point
// sprite whose centre leaves the viewport: a particle just outside the image must still land
// inside the targets to draw its part of the image. The band is half a sprite plus 2 px, or
// 2 px when sprites are drawn as instanced quads (quads are clipped, not culled).
#pragma once

#include <array>
#include <vector>

#include "sph2d/math.hpp"

namespace sph2d {

/// The image's world rectangle and the extended targets around it.
struct FrameGeometry {
  std::vector<double> cam;  ///< the world rectangle of the image: min x, min y, max x, max y
  std::vector<double> ext;  ///< the world rectangle of the extended targets
  int guard = -1;           ///< guard band [px] on each side
  int EW = 0, EH = 0;       ///< target size [px]: the image plus two guard bands

  /// Image pixels per metre for an image `width` pixels wide.
  double pxPerM(int width) const { return width / (cam[2] - cam[0]); }
  /// Sets the guard band to `g` pixels for an image of width × height (ext, EW, EH follow).
  void setGuard(int g, int width, int height);
  /// The local-frame → NDC transform of the extended targets for a local frame at `origin`
  /// (y flipped: rows of every target run top-down in the world).
  void ndcTransform(const Vec2d& origin, float scale[2], float offset[2]) const;
};

/// The guard band [px] for sprites `diameterPx` wide at full resolution, drawn into a target
/// `shrink` times smaller, when the driver's largest point is `maxPoint` px.
int guardBand(float diameterPx, int shrink, float maxPoint);

}  // namespace sph2d
