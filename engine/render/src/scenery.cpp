// scenery.cpp — the background texture and the solid triangles (see scenery.hpp).
#include "scenery.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace sph2d {

void Scenery::init() {
  solidProg_ = gl::program("solid.vert", "solid.frag");
  bgProg_ = gl::program("fullscreen.vert", "background.frag");
  glGenVertexArrays(1, &solidVao_);
  glGenBuffers(1, &solidVbo_);
  glGenVertexArrays(1, &emptyVao_);
  glGenVertexArrays(1, &movingVao_);
  glGenBuffers(1, &movingVbo_);
}

void Scenery::release() {
  for (GLuint p : {bgProg_, solidProg_})
    if (p) glDeleteProgram(p);
  const GLuint arrays[3] = {emptyVao_, solidVao_, movingVao_}, buffers[2] = {solidVbo_, movingVbo_};
  glDeleteVertexArrays(3, arrays);
  glDeleteBuffers(2, buffers);
  glDeleteTextures(1, &bgTex_);
  glDeleteFramebuffers(1, &bgFbo_);
  const GLuint textures[2] = {sceneTex_, backdropTex_}, fbos[2] = {sceneFbo_, backdropFbo_};
  glDeleteTextures(2, textures);
  glDeleteFramebuffers(2, fbos);
  bgProg_ = solidProg_ = emptyVao_ = solidVao_ = movingVao_ = solidVbo_ = movingVbo_ = bgTex_ = bgFbo_ = 0;
  sceneTex_ = sceneFbo_ = backdropTex_ = backdropFbo_ = 0;
  solidCount_ = 0;
}

void Scenery::build(const RenderDef& def, const FrameGeometry& geo, const RenderInput& in) {
  buildBackground(def, geo);
  buildSolids(geo, in);
  // The background with the static solids: what a frame starts from and the water is seen
  // against (the liquid composite samples it between texels where the water shifts it).
  if (sceneFbo_) glDeleteFramebuffers(1, &sceneFbo_);
  sceneFbo_ = gl::target(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, geo.EW, geo.EH, sceneTex_);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, bgFbo_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, sceneFbo_);
  glBlitFramebuffer(0, 0, geo.EW, geo.EH, 0, 0, geo.EW, geo.EH, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, sceneFbo_);
  glViewport(0, 0, geo.EW, geo.EH);
  drawSolids(def, 0, geo.EH);
  if (backdropFbo_) {  // a new size or new solids: the backdrop starts again from the background
    glDeleteTextures(1, &backdropTex_);
    glDeleteFramebuffers(1, &backdropFbo_);
    backdropTex_ = backdropFbo_ = 0;
  }
}

void Scenery::buildBackground(const RenderDef& def, const FrameGeometry& geo) {
  if (bgFbo_) glDeleteFramebuffers(1, &bgFbo_);
  bgFbo_ = gl::target(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, geo.EW, geo.EH, bgTex_);
  glViewport(0, 0, geo.EW, geo.EH);
  glUseProgram(bgProg_);
  glUniform3f(gl::uniform(bgProg_, "uBackground"), float(def.background[0]), float(def.background[1]),
              float(def.background[2]));
  glUniform1f(gl::uniform(bgProg_, "uGuard"), float(geo.guard));
  glUniform1f(gl::uniform(bgProg_, "uHeight"), float(def.height));
  const std::vector<double>& ext = geo.ext;
  glUniform4f(gl::uniform(bgProg_, "uTiles"), float(ext[0]), float(ext[3]), float((ext[2] - ext[0]) / geo.EW),
              float(def.tiles));
  glBindVertexArray(emptyVao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

namespace {

/// Appends the two triangles of segment a → b (NDC) drawn 2·halfPx pixels wide (pixels of
/// pxX × pxY in NDC) to `tri`.
void segmentQuad(const std::array<float, 2>& a, const std::array<float, 2>& b, double halfPx, double pxX, double pxY,
                 std::vector<float>& tri) {
  const double dxp = (b[0] - a[0]) / pxX, dyp = (b[1] - a[1]) / pxY;
  const double len = std::sqrt(dxp * dxp + dyp * dyp);
  if (len <= 0) return;
  const float ox = float(-dyp / len * halfPx * pxX), oy = float(dxp / len * halfPx * pxY);
  const float q[6][2] = {{a[0] + ox, a[1] + oy}, {a[0] - ox, a[1] - oy}, {b[0] + ox, b[1] + oy},
                         {b[0] + ox, b[1] + oy}, {a[0] - ox, a[1] - oy}, {b[0] - ox, b[1] - oy}};
  for (const auto& p : q) tri.insert(tri.end(), {p[0], p[1]});
}

}  // namespace

std::vector<float> solidTriangles(const FrameGeometry& geo, const Vec2d& o, const std::vector<Collider>& colliders) {
  // Triangles in NDC.
  const std::vector<double>& ext = geo.ext;
  const double sx = 2.0 / (ext[2] - ext[0]), sy = 2.0 / (ext[3] - ext[1]);
  auto ndc = [&](const Vec2& p) {
    return std::array<float, 2>{float((p.x() + o.x() - ext[0]) * sx - 1.0), float(1.0 - (p.y() + o.y() - ext[1]) * sy)};
  };
  std::vector<float> tri;
  auto put = [&](const std::array<float, 2>& a) {
    tri.push_back(a[0]);
    tri.push_back(a[1]);
  };
  const double pxX = 2.0 / geo.EW, pxY = 2.0 / geo.EH;
  for (const Collider& c : colliders) {
    if (c.kind == Collider::Kind::Polygon) {
      for (std::size_t k = 1; k + 1 < c.vertices.size(); ++k) {
        put(ndc(c.vertices[0]));
        put(ndc(c.vertices[k]));
        put(ndc(c.vertices[k + 1]));
      }
    } else if (c.kind == Collider::Kind::Circle) {
      const int n = 64;
      for (int k = 0; k < n; ++k) {
        const Real a0 = 2 * kPi<Real> * Real(k) / n, a1 = 2 * kPi<Real> * Real(k + 1) / n;
        put(ndc(c.center));
        put(ndc(c.center + c.radius * Vec2(std::cos(a0), std::sin(a0))));
        put(ndc(c.center + c.radius * Vec2(std::cos(a1), std::sin(a1))));
      }
    } else {  // a zero-thickness segment drawn 3 px wide
      segmentQuad(ndc(c.vertices[0]), ndc(c.vertices[1]), 1.5, pxX, pxY, tri);
    }
  }
  return tri;
}

void Scenery::buildSolids(const FrameGeometry& geo, const RenderInput& in) {
  // The camera is fixed for a run: built once per target, and again when the solids change.
  const std::vector<float> tri = in.colliders ? solidTriangles(geo, in.origin, *in.colliders) : std::vector<float>();
  solidCount_ = GLsizei(tri.size() / 2);
  glBindVertexArray(solidVao_);
  glBindBuffer(GL_ARRAY_BUFFER, solidVbo_);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(tri.size() * sizeof(float)), tri.empty() ? nullptr : tri.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
}

void Scenery::drawSolids(const RenderDef& def, int rowFirst, int rowLast) const {
  if (!solidCount_ || rowLast <= rowFirst) return;
  glUseProgram(solidProg_);
  glUniform3f(gl::uniform(solidProg_, "uColor"), float(def.solid[0]), float(def.solid[1]), float(def.solid[2]));
  glBindVertexArray(solidVao_);
  GLint vp[4] = {0, 0, 0, 0};
  glGetIntegerv(GL_VIEWPORT, vp);
  glEnable(GL_SCISSOR_TEST);
  glScissor(0, rowFirst, vp[2], std::min(rowLast, vp[3]) - rowFirst);
  glDrawArrays(GL_TRIANGLES, 0, solidCount_);
  glDisable(GL_SCISSOR_TEST);
}

std::pair<int, int> Scenery::drawMoving(const RenderDef& def, const FrameGeometry& geo, const RenderInput& in) {
  if (in.moving.empty()) return {0, 0};
  return drawMovingTriangles(def, geo, solidTriangles(geo, in.origin, in.moving));
}

std::pair<GLuint, GLuint> Scenery::backdrop(const RenderDef& def, const FrameGeometry& geo, const RenderInput& in,
                                            std::pair<int, int> restore, std::pair<int, int>& rows) {
  rows = {0, 0};
  const std::vector<float> tri = in.moving.empty() ? std::vector<float>() : solidTriangles(geo, in.origin, in.moving);
  if (tri.empty() && !backdropFbo_) return {sceneTex_, sceneFbo_};
  if (!backdropFbo_) {  // the first moving body: the backdrop starts as the whole background
    backdropFbo_ = gl::target(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, geo.EW, geo.EH, backdropTex_);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    restore = {0, geo.EH};
  }
  restore.second = std::min(restore.second, geo.EH);
  if (restore.first < restore.second) {  // a 1:1 blit of the same texels (gl_state.hpp: no scissor)
    glBindFramebuffer(GL_READ_FRAMEBUFFER, sceneFbo_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, backdropFbo_);
    glBlitFramebuffer(0, restore.first, geo.EW, restore.second, 0, restore.first, geo.EW, restore.second,
                      GL_COLOR_BUFFER_BIT, GL_NEAREST);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, backdropFbo_);
  glViewport(0, 0, geo.EW, geo.EH);
  if (!tri.empty()) rows = drawMovingTriangles(def, geo, tri);
  return {backdropTex_, backdropFbo_};
}

std::pair<int, int> Scenery::drawMovingTriangles(const RenderDef& def, const FrameGeometry& geo,
                                                 const std::vector<float>& tri) {
  if (tri.empty()) return {0, 0};
  float lo = tri[1], hi = tri[1];
  for (std::size_t k = 1; k < tri.size(); k += 2) {
    lo = std::min(lo, tri[k]);
    hi = std::max(hi, tri[k]);
  }
  glUseProgram(solidProg_);
  glUniform3f(gl::uniform(solidProg_, "uColor"), float(def.solid[0]), float(def.solid[1]), float(def.solid[2]));
  glBindVertexArray(movingVao_);
  glBindBuffer(GL_ARRAY_BUFFER, movingVbo_);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(tri.size() * sizeof(float)), tri.data(), GL_STREAM_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
  glDrawArrays(GL_TRIANGLES, 0, GLsizei(tri.size() / 2));
  // NDC y to target rows, a row of margin each side (anti-aliasing, rounding).
  const int first = std::max(0, int(std::floor((double(lo) + 1) * 0.5 * geo.EH)) - 1);
  const int last = std::min(geo.EH, int(std::ceil((double(hi) + 1) * 0.5 * geo.EH)) + 1);
  return {first, last};
}

void Scenery::drawOutline(const FrameGeometry& geo, const std::vector<SurfaceCurve>& curves, const float color[3],
                          double widthPx, int rowFirst, int rowLast) {
  if (curves.empty() || rowLast <= rowFirst) return;
  const std::vector<double>& ext = geo.ext;
  const double sx = 2.0 / (ext[2] - ext[0]), sy = 2.0 / (ext[3] - ext[1]), pxX = 2.0 / geo.EW, pxY = 2.0 / geo.EH;
  auto ndc = [&](const Vec2d& p) {
    return std::array<float, 2>{float((p.x() - ext[0]) * sx - 1.0), float(1.0 - (p.y() - ext[1]) * sy)};
  };
  std::vector<float> tri;
  for (const SurfaceCurve& c : curves)
    for (std::size_t k = 0; k < c.points.size(); ++k)
      segmentQuad(ndc(c.points[k]), ndc(c.points[(k + 1) % c.points.size()]), widthPx / 2, pxX, pxY, tri);
  if (tri.empty()) return;
  glUseProgram(solidProg_);
  glUniform3f(gl::uniform(solidProg_, "uColor"), color[0], color[1], color[2]);
  glBindVertexArray(movingVao_);
  glBindBuffer(GL_ARRAY_BUFFER, movingVbo_);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(tri.size() * sizeof(float)), tri.data(), GL_STREAM_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
  GLint vp[4] = {0, 0, 0, 0};
  glGetIntegerv(GL_VIEWPORT, vp);
  glEnable(GL_SCISSOR_TEST);
  glScissor(0, rowFirst, vp[2], std::min(rowLast, vp[3]) - rowFirst);
  glDrawArrays(GL_TRIANGLES, 0, GLsizei(tri.size() / 2));
  glDisable(GL_SCISSOR_TEST);
}

}  // namespace sph2d
