// present.cpp — the frame into the caller's framebuffer (see present.hpp).
#include "present.hpp"

#include <cstdio>
#include <stdexcept>
#include <string>

namespace sph2d {

void Presenter::init() {
  prog_ = gl::program("fullscreen.vert", "present.frag");
  glGenVertexArrays(1, &vao_);
}

void Presenter::release() {
  if (prog_) glDeleteProgram(prog_);
  if (vao_) glDeleteVertexArrays(1, &vao_);
  prog_ = vao_ = 0;
}

void Presenter::check(GLuint fbo, const GLint viewport[4]) {
  if (viewport[2] <= 0 || viewport[3] <= 0)
    throw std::invalid_argument("Renderer::draw: the viewport is empty (" + std::to_string(viewport[2]) + " x " +
                                std::to_string(viewport[3]) + " px)");
  if (fbo != 0 && !glIsFramebuffer(fbo))
    throw std::invalid_argument("Renderer::draw: " + std::to_string(fbo) +
                                " is not a framebuffer object of the current context");
  // Complete? (Binds it for drawing: the caller's state guard puts the binding back.)
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo);
  const GLenum status = glCheckFramebufferStatus(GL_DRAW_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    char code[16];
    std::snprintf(code, sizeof code, "0x%x", status);
    throw std::runtime_error("Renderer::draw: framebuffer " + std::to_string(fbo) + " is not complete (status " + code +
                             ")");
  }
}

void Presenter::draw(GLuint frameTex, int guard, int width, int height, GLuint fbo, const GLint viewport[4]) const {
  check(fbo, viewport);
  // present.frag writes colour output 0 only: the framebuffer's other draw buffers keep what the
  // game drew there (their colour masks are the guard's to restore).
  GLint drawBuffers = 1;
  glGetIntegerv(GL_MAX_DRAW_BUFFERS, &drawBuffers);
  glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  for (GLint b = 1; b < drawBuffers; ++b) glColorMaski(GLuint(b), GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
  glUseProgram(prog_);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, frameTex);
  glUniform1i(gl::uniform(prog_, "uFrame"), 0);
  glUniform4i(gl::uniform(prog_, "uViewport"), viewport[0], viewport[1], viewport[2], viewport[3]);
  glUniform3i(gl::uniform(prog_, "uImage"), guard, width, height);
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

}  // namespace sph2d
