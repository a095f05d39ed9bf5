// present.hpp — the last step of a frame drawn into a caller's context: the Renderer's colour
// target into the caller's framebuffer, over the caller's viewport.
//
// Design: a full-viewport triangle (shaders/fullscreen.vert) whose fragment shader
// (shaders/present.frag) fetches the colour target, flipping its top-down rows into GL's
// bottom-up ones. A draw rather than glBlitFramebuffer: it works into any framebuffer a game
// has (multisampled, sRGB, several colour attachments: it writes colour output 0 to the first
// draw buffer, the others masked so they keep what the game drew), and it scales bilinearly when the viewport is not
// the image's size. At the image's size it copies texels, so the caller gets the very pixels the OSMesa path reads
// back. It runs with setDrawState()'s state (no blending, depth, stencil, scissor, sRGB conversion), which the
// GlStateGuard around it gives back afterwards.
#pragma once

#include "gl_util.hpp"

namespace sph2d {

/// Draws a finished frame into a framebuffer of the caller's context.
class Presenter {
 public:
  /// Compiles the program and makes its vertex array in the current context.
  void init();
  /// Deletes the program and vertex array (the context that made them must be current).
  void release();
  /// Throws std::invalid_argument when `viewport` (x, y, width, height) is empty or `fbo` is not
  /// a framebuffer of the current context (0, the default framebuffer, always is).
  static void check(GLuint fbo, const GLint viewport[4]);
  /// Draws the image of `frameTex` (`guard` px of band around a `width` × `height` image) into
  /// framebuffer `fbo` over `viewport` (checked first). Throws std::runtime_error when the
  /// framebuffer is incomplete.
  void draw(GLuint frameTex, int guard, int width, int height, GLuint fbo, const GLint viewport[4]) const;

 private:
  GLuint prog_ = 0, vao_ = 0;
};

}  // namespace sph2d
