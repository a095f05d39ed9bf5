// gl_util.hpp — the OpenGL plumbing every pass needs: shaders from shaders/ (embedded at build
// time, or read from $SPH2D_SHADER_DIR for shader work), programs, textures and framebuffers.
//
// Design: thin free functions over the GL 3.3 core API of the current context (the Renderer's
// own OSMesa context, or a game's: gl_state.hpp); they throw std::runtime_error with the
// shader's log or the object that failed, and hold no state. Their gl* calls, like every one of
// the renderer's, go through the calling thread's function table (gl_api.hpp).
#pragma once

#include "gl_api.hpp"

#include <string>

namespace sph2d::gl {

/// Shader text: $SPH2D_SHADER_DIR/name when that is set (for shader work), else the embedded copy.
std::string shaderSource(const std::string& name);
/// Compiles and links shaders/`vs` + shaders/`fs` into a program, `fsDefines` ("#define X\n"
/// lines) inserted after the fragment shader's #version line. Throws with the compiler's log.
GLuint program(const std::string& vs, const std::string& fs, const std::string& fsDefines = "");
/// (Re)allocates `tex` (created when 0) as a w × h 2D texture, clamped at the edges, with `filter`.
void makeTexture(GLuint& tex, GLenum internal, GLenum format, GLenum type, int w, int h, GLint filter);
/// A framebuffer rendering into `tex` (made as by makeTexture, nearest filtering). Throws when incomplete.
GLuint target(GLenum internal, GLenum format, GLenum type, int w, int h, GLuint& tex);
/// The location of uniform `name` of `prog` (-1 when the program has none).
inline GLint uniform(GLuint prog, const char* name) { return glGetUniformLocation(prog, name); }
/// Throws std::runtime_error naming `what` and the GL error code when an error is pending.
void throwOnError(const char* what);

}  // namespace sph2d::gl
