// gl_state.cpp — the context probe, the passes' state and the state guard (see gl_state.hpp).
#include "gl_state.hpp"

#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace sph2d::gl {
namespace {

const GLenum kPixelStore[] = {
    GL_UNPACK_SWAP_BYTES, GL_UNPACK_LSB_FIRST,   GL_UNPACK_ROW_LENGTH,  GL_UNPACK_IMAGE_HEIGHT,
    GL_UNPACK_SKIP_ROWS,  GL_UNPACK_SKIP_PIXELS, GL_UNPACK_SKIP_IMAGES, GL_UNPACK_ALIGNMENT,
    GL_PACK_SWAP_BYTES,   GL_PACK_LSB_FIRST,     GL_PACK_ROW_LENGTH,    GL_PACK_IMAGE_HEIGHT,
    GL_PACK_SKIP_ROWS,    GL_PACK_SKIP_PIXELS,   GL_PACK_SKIP_IMAGES,   GL_PACK_ALIGNMENT};

/// The value setDrawState() gives a pixel-store parameter: GL's initial one.
GLint pixelStoreDefault(GLenum p) { return p == GL_UNPACK_ALIGNMENT || p == GL_PACK_ALIGNMENT ? 4 : 0; }

/// Capabilities the passes want off (glDisable), in both profiles.
const GLenum kOff[] = {GL_DEPTH_TEST,         GL_STENCIL_TEST,   GL_CULL_FACE,        GL_SCISSOR_TEST,
                       GL_RASTERIZER_DISCARD, GL_COLOR_LOGIC_OP, GL_FRAMEBUFFER_SRGB, GL_SAMPLE_ALPHA_TO_COVERAGE,
                       GL_SAMPLE_COVERAGE,    GL_SAMPLE_MASK,    GL_POLYGON_SMOOTH};
/// Capabilities the passes want on (glEnable): sprite sizes from the shader; dithering as in a
/// fresh context (llvmpipe does not dither; a driver that does dithers both paths alike).
const GLenum kOn[] = {GL_PROGRAM_POINT_SIZE, GL_DITHER};

/// Compatibility profile: the pixel-transfer stage scales, biases and maps every texture upload
/// and readback; the passes need it to pass values through (scale 1, bias 0, no maps).
const GLenum kTransferScale[] = {GL_RED_SCALE, GL_GREEN_SCALE, GL_BLUE_SCALE, GL_ALPHA_SCALE, GL_DEPTH_SCALE};
const GLenum kTransferBias[] = {GL_RED_BIAS, GL_GREEN_BIAS, GL_BLUE_BIAS, GL_ALPHA_BIAS, GL_DEPTH_BIAS};
const GLenum kTransferInt[] = {GL_MAP_COLOR, GL_MAP_STENCIL, GL_INDEX_SHIFT, GL_INDEX_OFFSET};

}  // namespace

ContextInfo currentContext() {
  const char* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  if (!version)  // the Renderer checks first, with a message for its path; this is the backstop
    throw std::runtime_error(std::string("no OpenGL context is current on this thread (glGetString(GL_VERSION) "
                                         "through the renderer's ") +
                             api().source + " OpenGL functions gives nothing)");
  ContextInfo c;
  c.version = version;
  const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  c.renderer = renderer ? renderer : "?";
  if (std::strncmp(version, "OpenGL ES", 9) == 0)
    throw std::runtime_error("the current context is " + c.version + " (" + c.renderer +
                             "); sph2d's renderer needs desktop OpenGL 3.3 or later");
  if (std::sscanf(version, "%d.%d", &c.major, &c.minor) != 2)
    throw std::runtime_error("the current context's GL_VERSION '" + c.version +
                             "' does not start with a version number");
  if (c.major < 3 || (c.major == 3 && c.minor < 3))
    throw std::runtime_error("sph2d's renderer needs OpenGL 3.3 or later; the current context is OpenGL " + c.version +
                             " (" + c.renderer + ")");
  GLint mask = 0;
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &mask);
  c.compatibility = (mask & GL_CONTEXT_COMPATIBILITY_PROFILE_BIT) != 0;
  c.perBufferBlend = c.major >= 4;
  c.copyImage = c.major > 4 || (c.major == 4 && c.minor >= 3);
  GLint n = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &n);
  for (GLint i = 0; i < n && !c.copyImage; ++i) {
    const char* e = reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, GLuint(i)));
    c.copyImage = e && std::strcmp(e, "GL_ARB_copy_image") == 0;
  }
  glGetIntegerv(GL_MAX_CLIP_DISTANCES, &c.clipDistances);
  glGetIntegerv(GL_MAX_DRAW_BUFFERS, &c.drawBuffers);
  throwOnError("while probing the OpenGL context");
  return c;
}

void setDrawState(const ContextInfo& ctx) {
  for (GLenum cap : kOff) glDisable(cap);
  for (int i = 0; i < ctx.clipDistances; ++i) glDisable(GLenum(GL_CLIP_DISTANCE0 + i));
  glDisable(GL_BLEND);  // every draw buffer; a pass enables it around its own draws
  for (GLenum cap : kOn) glEnable(cap);
  if (ctx.compatibility) {
    glDisable(GL_ALPHA_TEST);                              // would drop the discs' soft edges
    glEnable(GL_POINT_SPRITE);                             // gl_PointCoord is undefined without it
    glClampColor(GL_CLAMP_FRAGMENT_COLOR, GL_FIXED_ONLY);  // the float splat target must not clamp at 1
    glDisable(GL_POLYGON_STIPPLE);                         // would punch holes in every triangle
    for (GLenum p : kTransferScale) glPixelTransferf(p, 1.0f);
    for (GLenum p : kTransferBias) glPixelTransferf(p, 0.0f);
    for (GLenum p : kTransferInt) glPixelTransferi(p, 0);
  }
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glBlendEquation(GL_FUNC_ADD);
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  glPointParameteri(GL_POINT_SPRITE_COORD_ORIGIN, GL_UPPER_LEFT);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  for (GLenum p : kPixelStore) glPixelStorei(p, pixelStoreDefault(p));
  for (int u = 0; u < kTextureUnits; ++u) glBindSampler(GLuint(u), 0);
  glActiveTexture(GL_TEXTURE0);
}

GlStateGuard::GlStateGuard(const ContextInfo& ctx) : ctx_(ctx) {
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &drawFbo_);
  glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &readFbo_);
  glGetIntegerv(GL_CURRENT_PROGRAM, &program_);
  glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &vao_);
  glGetIntegerv(GL_ARRAY_BUFFER_BINDING, &arrayBuffer_);
  glGetIntegerv(GL_PIXEL_UNPACK_BUFFER_BINDING, &unpackBuffer_);
  glGetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &packBuffer_);
  glGetIntegerv(GL_ACTIVE_TEXTURE, &activeTexture_);
  for (int u = 0; u < kTextureUnits; ++u) {
    glActiveTexture(GLenum(GL_TEXTURE0 + u));
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &textures_[u]);
    glGetIntegerv(GL_SAMPLER_BINDING, &samplers_[u]);
  }
  glActiveTexture(GLenum(activeTexture_));
  glGetIntegerv(GL_VIEWPORT, viewport_);
  glGetIntegerv(GL_SCISSOR_BOX, scissorBox_);
  glGetFloatv(GL_COLOR_CLEAR_VALUE, clearColor_);
  glGetIntegerv(GL_POLYGON_MODE, polygonMode_);
  glGetIntegerv(GL_POINT_SPRITE_COORD_ORIGIN, &spriteOrigin_);

  for (GLenum cap : kOff) caps_.push_back({cap, glIsEnabled(cap)});
  for (GLenum cap : kOn) caps_.push_back({cap, glIsEnabled(cap)});
  for (int i = 0; i < ctx.clipDistances; ++i)
    caps_.push_back({GLenum(GL_CLIP_DISTANCE0 + i), glIsEnabled(GLenum(GL_CLIP_DISTANCE0 + i))});
  if (ctx.compatibility) {
    caps_.push_back({GL_ALPHA_TEST, glIsEnabled(GL_ALPHA_TEST)});
    caps_.push_back({GL_POINT_SPRITE, glIsEnabled(GL_POINT_SPRITE)});
    caps_.push_back({GL_POLYGON_STIPPLE, glIsEnabled(GL_POLYGON_STIPPLE)});
    glGetIntegerv(GL_CLAMP_FRAGMENT_COLOR, &clampFragment_);
    for (const GLenum* list : {kTransferScale, kTransferBias})
      for (int k = 0; k < 5; ++k) {
        GLfloat v = 0;
        glGetFloatv(list[k], &v);
        transfer_.emplace_back(list[k], v);
      }
    for (GLenum p : kTransferInt) {
      GLint v = 0;
      glGetIntegerv(p, &v);
      transferI_.emplace_back(p, v);
    }
  }
  const int buffers = ctx.drawBuffers;
  blendOn_.resize(std::size_t(buffers));
  colorMask_.resize(4 * std::size_t(buffers));
  for (int b = 0; b < buffers; ++b) {
    blendOn_[std::size_t(b)] = glIsEnabledi(GL_BLEND, GLuint(b));
    glGetBooleani_v(GL_COLOR_WRITEMASK, GLuint(b), &colorMask_[4 * std::size_t(b)]);
  }
  blend_.resize(ctx.perBufferBlend ? std::size_t(buffers) : 1);
  for (std::size_t b = 0; b < blend_.size(); ++b) {
    BlendFunc& f = blend_[b];
    if (ctx.perBufferBlend) {
      const GLuint i = GLuint(b);
      glGetIntegeri_v(GL_BLEND_SRC_RGB, i, &f.srcRgb);
      glGetIntegeri_v(GL_BLEND_DST_RGB, i, &f.dstRgb);
      glGetIntegeri_v(GL_BLEND_SRC_ALPHA, i, &f.srcAlpha);
      glGetIntegeri_v(GL_BLEND_DST_ALPHA, i, &f.dstAlpha);
      glGetIntegeri_v(GL_BLEND_EQUATION_RGB, i, &f.eqRgb);
      glGetIntegeri_v(GL_BLEND_EQUATION_ALPHA, i, &f.eqAlpha);
    } else {
      glGetIntegerv(GL_BLEND_SRC_RGB, &f.srcRgb);
      glGetIntegerv(GL_BLEND_DST_RGB, &f.dstRgb);
      glGetIntegerv(GL_BLEND_SRC_ALPHA, &f.srcAlpha);
      glGetIntegerv(GL_BLEND_DST_ALPHA, &f.dstAlpha);
      glGetIntegerv(GL_BLEND_EQUATION_RGB, &f.eqRgb);
      glGetIntegerv(GL_BLEND_EQUATION_ALPHA, &f.eqAlpha);
    }
  }
  for (GLenum p : kPixelStore) {
    GLint v = 0;
    glGetIntegerv(p, &v);
    pixelStore_.emplace_back(p, v);
  }
}

GlStateGuard::~GlStateGuard() {
  for (const Cap& c : caps_) (c.on ? glEnable : glDisable)(c.cap);
  if (ctx_.compatibility) glClampColor(GL_CLAMP_FRAGMENT_COLOR, GLenum(clampFragment_));
  for (const auto& t : transfer_) glPixelTransferf(t.first, t.second);
  for (const auto& t : transferI_) glPixelTransferi(t.first, t.second);
  for (std::size_t b = 0; b < blendOn_.size(); ++b) {
    (blendOn_[b] ? glEnablei : glDisablei)(GL_BLEND, GLuint(b));
    const GLboolean* m = &colorMask_[4 * b];
    glColorMaski(GLuint(b), m[0], m[1], m[2], m[3]);
  }
  if (ctx_.perBufferBlend) {
    for (std::size_t b = 0; b < blend_.size(); ++b) {
      const BlendFunc& f = blend_[b];
      glBlendFuncSeparatei(GLuint(b), GLenum(f.srcRgb), GLenum(f.dstRgb), GLenum(f.srcAlpha), GLenum(f.dstAlpha));
      glBlendEquationSeparatei(GLuint(b), GLenum(f.eqRgb), GLenum(f.eqAlpha));
    }
  } else {
    const BlendFunc& f = blend_[0];
    glBlendFuncSeparate(GLenum(f.srcRgb), GLenum(f.dstRgb), GLenum(f.srcAlpha), GLenum(f.dstAlpha));
    glBlendEquationSeparate(GLenum(f.eqRgb), GLenum(f.eqAlpha));
  }
  if (ctx_.compatibility) {  // front and back may differ there
    glPolygonMode(GL_FRONT, GLenum(polygonMode_[0]));
    glPolygonMode(GL_BACK, GLenum(polygonMode_[1]));
  } else {
    glPolygonMode(GL_FRONT_AND_BACK, GLenum(polygonMode_[0]));
  }
  glPointParameteri(GL_POINT_SPRITE_COORD_ORIGIN, spriteOrigin_);
  for (const auto& [p, v] : pixelStore_) glPixelStorei(p, v);
  glClearColor(clearColor_[0], clearColor_[1], clearColor_[2], clearColor_[3]);
  glViewport(viewport_[0], viewport_[1], viewport_[2], viewport_[3]);
  glScissor(scissorBox_[0], scissorBox_[1], scissorBox_[2], scissorBox_[3]);
  for (int u = 0; u < kTextureUnits; ++u) {
    glActiveTexture(GLenum(GL_TEXTURE0 + u));
    glBindTexture(GL_TEXTURE_2D, GLuint(textures_[u]));
    glBindSampler(GLuint(u), GLuint(samplers_[u]));
  }
  glActiveTexture(GLenum(activeTexture_));
  glUseProgram(GLuint(program_));
  glBindVertexArray(GLuint(vao_));
  glBindBuffer(GL_ARRAY_BUFFER, GLuint(arrayBuffer_));
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, GLuint(unpackBuffer_));
  glBindBuffer(GL_PIXEL_PACK_BUFFER, GLuint(packBuffer_));
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, GLuint(drawFbo_));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, GLuint(readFbo_));
}

}  // namespace sph2d::gl
