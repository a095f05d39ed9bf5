// sprites.cpp — id order and the particle vertex buffer (see sprites.hpp for the design).
#include "sprites.hpp"

#include <algorithm>
#include <numeric>

namespace sph2d {

void idOrder(const Particles& P, std::vector<std::uint32_t>& order, std::vector<std::uint32_t>& slotOfId) {
  const std::size_t n = P.size();
  order.resize(n);
  std::uint32_t maxId = 0;
  for (std::size_t i = 0; i < n; ++i) maxId = std::max(maxId, P.id[i]);
  if (n && std::size_t(maxId) < 4 * n + 64) {
    const std::uint32_t none = 0xffffffffu;
    slotOfId.assign(std::size_t(maxId) + 1, none);
    bool unique = true;
    for (std::size_t i = 0; i < n; ++i) {
      std::uint32_t& s = slotOfId[P.id[i]];
      if (s != none) unique = false;
      s = std::uint32_t(i);
    }
    if (unique) {
      std::size_t k = 0;
      for (std::uint32_t s : slotOfId)
        if (s != none) order[k++] = s;
      return;
    }
  }
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return P.id[a] < P.id[b]; });
}

void SpriteBatch::init() {
  GLfloat range[2] = {1, 255};
  glGetFloatv(GL_POINT_SIZE_RANGE, range);
  maxPoint_ = std::max(1.0f, range[1]);
  minPoint_ = std::clamp(range[0], 0.0f, maxPoint_);
  glGenBuffers(1, &particleVbo_);
  glGenBuffers(1, &cornerVbo_);
  const float corners[8] = {-1, -1, 1, -1, -1, 1, 1, 1};
  glBindBuffer(GL_ARRAY_BUFFER, cornerVbo_);
  glBufferData(GL_ARRAY_BUFFER, sizeof corners, corners, GL_STATIC_DRAW);
  // Points: one vertex per particle. Quads: four corners per instance, the particle per instance.
  for (int q = 0; q < 2; ++q) {
    GLuint& vao = q ? quadVao_ : pointVao_;
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, particleVbo_);
    const GLsizei stride = 4 * sizeof(float);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, stride, nullptr);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 1, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<const void*>(2 * sizeof(float)));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<const void*>(3 * sizeof(float)));
    if (q) {
      for (GLuint a = 0; a < 3; ++a) glVertexAttribDivisor(a, 1);
      glBindBuffer(GL_ARRAY_BUFFER, cornerVbo_);
      glEnableVertexAttribArray(3);
      glVertexAttribPointer(3, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
    }
  }
  // GL_PROGRAM_POINT_SIZE: set with the rest of the passes' state each frame (gl_state.hpp).
}

void SpriteBatch::release() {
  const GLuint buffers[2] = {particleVbo_, cornerVbo_}, arrays[2] = {pointVao_, quadVao_};
  glDeleteBuffers(2, buffers);
  glDeleteVertexArrays(2, arrays);
  particleVbo_ = cornerVbo_ = pointVao_ = quadVao_ = 0;
}

void SpriteBatch::upload(const std::vector<float>& packed) {
  glBindBuffer(GL_ARRAY_BUFFER, particleVbo_);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(packed.size() * sizeof(float)), packed.empty() ? nullptr : packed.data(),
               GL_STREAM_DRAW);
}

void SpriteBatch::setUniforms(GLuint prog, const float scale[2], const float offset[2], float diameterPx, int vw,
                              int vh, bool quads) const {
  glUseProgram(prog);
  glUniform2fv(gl::uniform(prog, "uScale"), 1, scale);
  glUniform2fv(gl::uniform(prog, "uOffset"), 1, offset);
  glUniform1f(gl::uniform(prog, "uPointSize"), std::min(diameterPx, maxPoint_));
  glUniform1i(gl::uniform(prog, "uQuads"), quads ? 1 : 0);
  glUniform2f(gl::uniform(prog, "uHalfNdc"), diameterPx / float(vw), diameterPx / float(vh));
  glUniform1f(gl::uniform(prog, "uRadiusPx"), 0.5f * diameterPx);
}

void SpriteBatch::draw(GLsizei n, bool quads) const {
  if (!n) return;
  if (quads) {
    glBindVertexArray(quadVao_);
    glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, n);
  } else {
    glBindVertexArray(pointVao_);
    glDrawArrays(GL_POINTS, 0, n);
  }
}

}  // namespace sph2d
