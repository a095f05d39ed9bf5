// sprites.hpp — particles on their way to the GPU: in id order, one vertex (x, y, value, weight)
// each, drawn as point sprites or, when wider than the driver's point-size limit, as instanced
// quads (splat.vert serves both the liquid's splat and the particles mode's discs).
//
// Design: additive float blending depends on the order of the additions, so particles are
// always submitted in id order, not in the engine's storage order (which the neighbour grid
// reorders): a frame is a function of the particles' values alone. Ids are usually dense, so
// the order comes from a table slot-of-id in O(n); sparse or repeated ids fall back to a
// stable sort. GL culls a point whose centre leaves the viewport; the guard band of the
// targets (camera.hpp) keeps particles just outside the image drawing their part of it.
#pragma once

#include <cstdint>
#include <vector>

#include "gl_util.hpp"
#include "sph2d/particles.hpp"

namespace sph2d {

/// The slots of `P` in id order (into `order`); `scratch` is reused between calls.
void idOrder(const Particles& P, std::vector<std::uint32_t>& order, std::vector<std::uint32_t>& scratch);

/// The particle vertex buffer and the two ways of drawing it (points, instanced quads).
class SpriteBatch {
 public:
  /// Creates the buffers and vertex arrays in the current context; reads the point-size limit.
  void init();
  /// Deletes them (the context that made them must be current).
  void release();
  /// The driver's largest point sprite [px] (255 on llvmpipe).
  float maxPoint() const { return maxPoint_; }
  /// The driver's smallest point sprite [px] (1 on llvmpipe): smaller sizes are drawn this wide.
  float minPoint() const { return minPoint_; }
  /// Uploads `packed` (4 floats per particle: x, y, value, weight in the engine's local frame).
  void upload(const std::vector<float>& packed);
  /// Uses `prog` (splat.vert + a fragment shader) and sets its sprite uniforms: the local →
  /// NDC transform, the diameter [px] in a target of vw × vh px, points or quads.
  void setUniforms(GLuint prog, const float scale[2], const float offset[2], float diameterPx, int vw, int vh,
                   bool quads) const;
  /// Draws the first `n` particles uploaded, as quads or points.
  void draw(GLsizei n, bool quads) const;

 private:
  GLuint particleVbo_ = 0, cornerVbo_ = 0, pointVao_ = 0, quadVao_ = 0;
  float maxPoint_ = 255.0f, minPoint_ = 1.0f;
};

}  // namespace sph2d
