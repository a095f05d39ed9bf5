// gl_state.hpp — the OpenGL context a Renderer draws in: what it offers, the state the passes
// rely on, and a guard that gives a caller's context back as it was.
//
// Design: the passes were written for a context of their own and assume a few settings (no
// depth, stencil or scissor test, no culling, blending off between passes, filled polygons,
// sprite coordinates from the upper left, program point size, tightly packed pixel transfers
// without a pixel buffer, no sampler objects on the units they use). setDrawState() sets exactly
// those at the start of every frame, in both paths: in the Renderer's own OSMesa context it
// only repeats what is already so (the same pixels), in a caller's context it makes the frame
// independent of what the game left set. GlStateGuard queries, before anything changes, every
// item that setDrawState(), the passes and the presentation into the caller's framebuffer
// change, and sets each back when it goes out of scope (also when a pass throws). It queries
// instead of shadowing: a game may change any of it between frames, and a query of a few dozen
// integers costs microseconds. Items are listed in docs/EMBEDDING.md; a new GL call in a pass
// that changes global state must be added to both lists.
#pragma once

#include <string>
#include <vector>

#include "gl_util.hpp"

namespace sph2d::gl {

/// What a Renderer needs to know of the context it draws in.
struct ContextInfo {
  std::string renderer;         ///< GL_RENDERER
  std::string version;          ///< GL_VERSION, e.g. "4.5 (Core Profile) Mesa 22.3.6"
  int major = 0, minor = 0;     ///< the version's numbers
  bool compatibility = false;   ///< a compatibility-profile context (alpha test, point sprites, colour clamping exist)
  bool copyImage = false;       ///< glCopyImageSubData (OpenGL 4.3 or GL_ARB_copy_image); else rows are blitted
  bool perBufferBlend = false;  ///< blend functions and equations per draw buffer (OpenGL 4.0)
  int clipDistances = 0;        ///< GL_MAX_CLIP_DISTANCES
  int drawBuffers = 1;          ///< GL_MAX_DRAW_BUFFERS
};

/// Probes the context current on the calling thread. Throws std::runtime_error when no context
/// is current, when it is OpenGL ES, or when its version is below 3.3 (naming the version).
ContextInfo currentContext();

/// The texture units the Renderer binds textures on (and unbinds sampler objects from):
/// 0 .. kTextureUnits - 1.
constexpr int kTextureUnits = 6;

/// Sets the state the passes rely on (see the design note); the active texture unit is 0.
void setDrawState(const ContextInfo& ctx);

/// Saves every piece of state the Renderer changes when constructed; restores it when destroyed.
class GlStateGuard {
 public:
  /// Queries the state of the current context (`ctx` says which items it has).
  explicit GlStateGuard(const ContextInfo& ctx);
  /// Sets every saved item back.
  ~GlStateGuard();
  GlStateGuard(const GlStateGuard&) = delete;
  GlStateGuard& operator=(const GlStateGuard&) = delete;
  /// The framebuffer bound to GL_DRAW_FRAMEBUFFER when the guard was made.
  GLuint drawFramebuffer() const { return GLuint(drawFbo_); }
  /// The viewport when the guard was made: x, y, width, height.
  const GLint* viewport() const { return viewport_; }

 private:
  struct Cap {
    GLenum cap;
    GLboolean on;
  };
  struct BlendFunc {
    GLint srcRgb, dstRgb, srcAlpha, dstAlpha, eqRgb, eqAlpha;
  };
  ContextInfo ctx_;
  GLint drawFbo_ = 0, readFbo_ = 0, program_ = 0, vao_ = 0, arrayBuffer_ = 0, activeTexture_ = 0;
  GLint unpackBuffer_ = 0, packBuffer_ = 0;
  GLint textures_[kTextureUnits] = {}, samplers_[kTextureUnits] = {};
  GLint viewport_[4] = {}, scissorBox_[4] = {};
  GLfloat clearColor_[4] = {};
  GLint polygonMode_[2] = {};
  GLint spriteOrigin_ = 0;
  GLint clampFragment_ = 0;                           // compatibility profile only
  std::vector<std::pair<GLenum, GLfloat>> transfer_;  // compatibility: pixel-transfer scales and biases
  std::vector<std::pair<GLenum, GLint>> transferI_;   // compatibility: colour/stencil maps, index shift and offset
  std::vector<Cap> caps_;                             // glIsEnabled items
  std::vector<GLboolean> blendOn_;                    // GL_BLEND per draw buffer
  std::vector<BlendFunc> blend_;                      // per draw buffer (OpenGL 4.0), else one
  std::vector<GLboolean> colorMask_;                  // 4 per draw buffer
  std::vector<std::pair<GLenum, GLint>> pixelStore_;
};

}  // namespace sph2d::gl
