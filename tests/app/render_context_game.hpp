// The game of tests/app/test_render_context*.cpp: its own OSMesa context, framebuffer, program,
// vertex array, textures and samplers, its GL state far from the defaults, snapshots of that
// state, readbacks and the OSMesa path's frames to compare with.
#pragma once

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/osmesa.h>
#include <doctest/doctest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "app_runner.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"
#include "support/game_scene.hpp"

namespace rctest {

using namespace sph2d;

constexpr int W = 160, H = 120;  // the frame; the tests' viewports are this size unless said

/// The game's scene (tests/support/game_scene.hpp) at W × H px unless said; in the particles
/// mode each particle's colour comes from the game (World::setParticleColor), so the frame has no
/// colour bar.
inline SceneDef gameScene(const std::string& mode, int w = W, int h = H) { return test::gameScene(mode, w, h); }

/// Options for `mode`: the particles mode colours by the game's own particle colours.
inline RenderOptions optionsFor(const std::string& mode) {
  RenderOptions o;
  if (mode == "particles") o.colorBy = ColorField::Color;
  return o;
}

/// Dyes the water: red on the left, green in the middle, the rest left uncoloured.
inline void dye(World& world) {
  for (std::size_t i = 0; i < world.particleCount(); ++i) {
    const double x = world.worldPosition(i).x();
    if (x < 0.4)
      world.setParticleColor(world.particles().id[i], 0xE03020u);
    else if (x < 0.8)
      world.setParticleColor(world.particles().id[i], 0x30C040u);
  }
}

/// The OSMesa path's frame of `world` (its own context, made and destroyed here).
inline std::vector<unsigned char> osmesaFrame(const World& world, const SceneDef& s, const RenderOptions& o) {
  Renderer own(s.render, o);
  return own.render(world).rgba;
}

/// The game's context: an OSMesa context it makes itself, with a window (OSMesa's buffer) of
/// ww × wh px.
struct GameContext {
  OSMesaContext ctx = nullptr;
  int ww = 16, wh = 16;
  std::vector<unsigned char> window;
  explicit GameContext(bool compatibility = false, int windowWidth = 16, int windowHeight = 16)
      : ww(windowWidth), wh(windowHeight), window(std::size_t(ww) * std::size_t(wh) * 4, 0) {
    pinRenderEnvironment();  // the Mesa settings of the OSMesa path, so both draw alike
    if (compatibility) {
      ctx = OSMesaCreateContextExt(OSMESA_RGBA, 0, 0, 0, nullptr);
    } else {
      const int attribs[] = {OSMESA_FORMAT,
                             OSMESA_RGBA,
                             OSMESA_DEPTH_BITS,
                             0,
                             OSMESA_STENCIL_BITS,
                             0,
                             OSMESA_ACCUM_BITS,
                             0,
                             OSMESA_PROFILE,
                             OSMESA_CORE_PROFILE,
                             OSMESA_CONTEXT_MAJOR_VERSION,
                             3,
                             OSMESA_CONTEXT_MINOR_VERSION,
                             3,
                             0};
      ctx = OSMesaCreateContextAttribs(attribs, nullptr);
    }
    REQUIRE(ctx);
    makeCurrent();
  }
  ~GameContext() { OSMesaDestroyContext(ctx); }
  GameContext(const GameContext&) = delete;
  GameContext& operator=(const GameContext&) = delete;
  void makeCurrent() { REQUIRE(OSMesaMakeCurrent(ctx, window.data(), GL_UNSIGNED_BYTE, ww, wh)); }
};

inline GLuint compile(GLenum type, const char* src) {
  const GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &src, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  REQUIRE(ok);
  return s;
}

/// The game's own GL objects: a framebuffer (RGBA8 + depth) of fw × fh px filled with its own
/// drawing, a second one bound for reading, a program, a vertex array and buffers, textures and a
/// sampler that filters with mipmaps (a texture without them sampled through it reads black).
/// RGBA8 pixels of framebuffer `fbo` (0: the window) over x, y, w, h, rows bottom-up as GL
/// gives them, read with the pack state made plain first.
inline std::vector<unsigned char> readRgba(GLuint fbo, int x, int y, int w, int h) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  glPixelStorei(GL_PACK_SKIP_ROWS, 0);
  glPixelStorei(GL_PACK_SKIP_PIXELS, 0);
  std::vector<unsigned char> p(std::size_t(w) * std::size_t(h) * 4);
  glReadPixels(x, y, w, h, GL_RGBA, GL_UNSIGNED_BYTE, p.data());
  REQUIRE(glGetError() == GL_NO_ERROR);
  return p;
}

struct GameObjects {
  int fw = W, fh = H;
  GLuint fbo = 0, colorTex = 0, depthRb = 0, readFbo = 0, readTex = 0;
  GLuint prog = 0, vao = 0, vbo = 0, ebo = 0, unpackPbo = 0, packPbo = 0, sampler = 0;
  GLuint tex[7] = {0, 0, 0, 0, 0, 0, 0};

  explicit GameObjects(int w = W, int h = H) : fw(w), fh(h) {
    glGenTextures(1, &colorTex);
    glBindTexture(GL_TEXTURE_2D, colorTex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, fw, fh, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    glGenRenderbuffers(1, &depthRb);
    glBindRenderbuffer(GL_RENDERBUFFER, depthRb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, fw, fh);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, colorTex, 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depthRb);
    REQUIRE(glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE);
    // The game's drawing: magenta, a green band over the left third, depth 0 everywhere (so
    // anything drawn with the game's depth test, GL_LESS, would be rejected).
    glClearColor(0.8f, 0.1f, 0.6f, 1.0f);
    glClearDepth(0.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_SCISSOR_TEST);
    glScissor(0, 0, fw / 3, fh);
    glClearColor(0.1f, 0.7f, 0.2f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    glDisable(GL_SCISSOR_TEST);
    glGenTextures(1, &readTex);
    glBindTexture(GL_TEXTURE_2D, readTex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 8, 8, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    glGenFramebuffers(1, &readFbo);
    glBindFramebuffer(GL_FRAMEBUFFER, readFbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, readTex, 0);
    glGenTextures(7, tex);
    for (GLuint t : tex) {
      glBindTexture(GL_TEXTURE_2D, t);
      glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 4, 4, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    }
    glGenSamplers(1, &sampler);
    glSamplerParameteri(sampler, GL_TEXTURE_MIN_FILTER,
                        GL_LINEAR_MIPMAP_LINEAR);  // textures without mipmaps: incomplete
    glSamplerParameteri(sampler, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glSamplerParameteri(sampler, GL_TEXTURE_WRAP_S, GL_REPEAT);
    const GLuint vs = compile(GL_VERTEX_SHADER,
                              "#version 330 core\nlayout(location = 0) in vec2 p;\n"
                              "void main() { gl_Position = vec4(p, 0.0, 1.0); }\n");
    const GLuint fs = compile(GL_FRAGMENT_SHADER, "#version 330 core\nout vec4 c;\nvoid main() { c = vec4(1.0); }\n");
    prog = glCreateProgram();
    glAttachShader(prog, vs);
    glAttachShader(prog, fs);
    glLinkProgram(prog);
    GLint ok = 0;
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    REQUIRE(ok);
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glGenBuffers(1, &vbo);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    const float tri[6] = {0, 0, 1, 0, 0, 1};
    glBufferData(GL_ARRAY_BUFFER, sizeof tri, tri, GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
    glGenBuffers(1, &ebo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo);
    glGenBuffers(1, &unpackPbo);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, unpackPbo);
    glBufferData(GL_PIXEL_UNPACK_BUFFER, 64, nullptr, GL_STREAM_DRAW);
    glGenBuffers(1, &packPbo);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, packPbo);
    glBufferData(GL_PIXEL_PACK_BUFFER, 64, nullptr, GL_STREAM_READ);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glBindVertexArray(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    REQUIRE(glGetError() == GL_NO_ERROR);
  }

  /// The game's colour pixels over x, y, w, h (rows bottom-up, as GL gives them), read with
  /// the game's own pack settings made plain first.
  std::vector<unsigned char> pixels(int x, int y, int w, int h) const { return readRgba(fbo, x, y, w, h); }
  std::vector<unsigned char> pixels() const { return pixels(0, 0, fw, fh); }

  /// The game's depth buffer, every pixel.
  std::vector<float> depth() const {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    std::vector<float> d(std::size_t(fw) * std::size_t(fh));
    glReadPixels(0, 0, fw, fh, GL_DEPTH_COMPONENT, GL_FLOAT, d.data());
    REQUIRE(glGetError() == GL_NO_ERROR);
    return d;
  }
};

/// Sets state far from GL's defaults, everything a game might have left set when it calls
/// draw(): framebuffers, program, vertex array, buffers, textures on units 0 to 6 with a mipmap
/// sampler on each, the active unit 3, viewport, scissor, blending, depth and stencil tests,
/// culling, clear colour, colour mask, polygon mode, sprite origin, point size, pixel store,
/// sRGB, dithering, alpha to coverage, a clip distance, logic op, polygon smoothing, rasterizer
/// discard, provoking vertex (the last two the renderer never needs to touch).
inline void setGameState(const GameObjects& g, bool compatibility = false) {
  if (compatibility) {  // the stipple pattern first: it is read with the unpack state set below
    GLubyte stipple[128];
    for (int k = 0; k < 128; ++k) stipple[k] = GLubyte(k % 8 < 4 ? 0xF0 : 0x0F);  // a checkerboard
    glPolygonStipple(stipple);
  }
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, g.fbo);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, g.readFbo);
  glUseProgram(g.prog);
  glBindVertexArray(g.vao);
  glBindBuffer(GL_ARRAY_BUFFER, g.vbo);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, g.unpackPbo);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, g.packPbo);
  for (int u = 0; u < 7; ++u) {
    glActiveTexture(GLenum(GL_TEXTURE0 + u));
    glBindTexture(GL_TEXTURE_2D, g.tex[u]);
    glBindSampler(GLuint(u), g.sampler);  // the renderer's units 0 to 5 and one beyond them
  }
  glActiveTexture(GL_TEXTURE3);
  glViewport(5, 7, 33, 21);
  glEnable(GL_SCISSOR_TEST);
  glScissor(1, 2, 3, 4);
  glEnable(GL_BLEND);
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ZERO);
  glBlendEquationSeparate(GL_FUNC_REVERSE_SUBTRACT, GL_MAX);
  glBlendColor(0.1f, 0.2f, 0.3f, 0.4f);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glEnable(GL_STENCIL_TEST);
  glStencilFunc(GL_NEVER, 1, 0xff);
  glEnable(GL_CULL_FACE);
  glCullFace(GL_FRONT_AND_BACK);
  glClearColor(0.25f, 0.5f, 0.75f, 1.0f);
  glColorMask(GL_TRUE, GL_FALSE, GL_TRUE, GL_FALSE);
  glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
  glPointParameteri(GL_POINT_SPRITE_COORD_ORIGIN, GL_LOWER_LEFT);
  glDisable(GL_PROGRAM_POINT_SIZE);
  glPointSize(3.0f);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glPixelStorei(GL_PACK_ROW_LENGTH, 3);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 2);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 7);
  glPixelStorei(GL_UNPACK_SKIP_ROWS, 1);
  glEnable(GL_FRAMEBUFFER_SRGB);
  glDisable(GL_DITHER);
  glEnable(GL_SAMPLE_ALPHA_TO_COVERAGE);
  glEnable(GL_CLIP_DISTANCE0);
  glEnable(GL_COLOR_LOGIC_OP);
  glLogicOp(GL_COPY_INVERTED);
  glEnable(GL_POLYGON_SMOOTH);
  glProvokingVertex(GL_FIRST_VERTEX_CONVENTION);
  if (compatibility) {
    glEnable(GL_ALPHA_TEST);
    glAlphaFunc(GL_GREATER, 0.99f);                  // would drop the discs' soft edges
    glDisable(GL_POINT_SPRITE);                      // gl_PointCoord would be undefined
    glClampColor(GL_CLAMP_FRAGMENT_COLOR, GL_TRUE);  // the float splat would stop at 1
    glEnable(GL_POLYGON_STIPPLE);                    // would punch holes in every triangle
    glPixelTransferf(GL_RED_SCALE, 0.5f);            // would halve the red of every upload
    glPixelTransferf(GL_GREEN_BIAS, 0.25f);
    glPixelTransferf(GL_DEPTH_SCALE, 2.0f);
    glPixelTransferi(GL_INDEX_SHIFT, 1);
  }
  glEnable(GL_RASTERIZER_DISCARD);  // last: nothing at all would be drawn
  REQUIRE(glGetError() == GL_NO_ERROR);
}

/// One state item: its name and values, as the game queries it.
struct Item {
  std::string name;
  std::vector<double> v;
};

/// Everything setGameState() sets and more, queried by the game (not by the renderer's guard).
inline std::vector<Item> snapshot(bool compatibility = false) {
  std::vector<Item> s;
  auto ints = [&](const char* name, GLenum e, int n = 1) {
    GLint v[16] = {};
    glGetIntegerv(e, v);
    s.push_back({name, std::vector<double>(v, v + n)});
  };
  auto floats = [&](const char* name, GLenum e, int n = 1) {
    GLfloat v[16] = {};
    glGetFloatv(e, v);
    s.push_back({name, std::vector<double>(v, v + n)});
  };
  auto on = [&](const char* name, GLenum e) { s.push_back({name, {double(glIsEnabled(e))}}); };
  ints("draw framebuffer", GL_DRAW_FRAMEBUFFER_BINDING);
  ints("read framebuffer", GL_READ_FRAMEBUFFER_BINDING);
  ints("renderbuffer", GL_RENDERBUFFER_BINDING);
  ints("program", GL_CURRENT_PROGRAM);
  ints("vertex array", GL_VERTEX_ARRAY_BINDING);
  ints("array buffer", GL_ARRAY_BUFFER_BINDING);
  ints("element array buffer", GL_ELEMENT_ARRAY_BUFFER_BINDING);
  ints("pixel unpack buffer", GL_PIXEL_UNPACK_BUFFER_BINDING);
  ints("pixel pack buffer", GL_PIXEL_PACK_BUFFER_BINDING);
  ints("active texture", GL_ACTIVE_TEXTURE);
  GLint active = 0;
  glGetIntegerv(GL_ACTIVE_TEXTURE, &active);
  for (int u = 0; u < 7; ++u) {
    glActiveTexture(GLenum(GL_TEXTURE0 + u));
    const std::string unit = "unit " + std::to_string(u);
    ints((unit + " texture 2D").c_str(), GL_TEXTURE_BINDING_2D);
    ints((unit + " sampler").c_str(), GL_SAMPLER_BINDING);
  }
  glActiveTexture(GLenum(active));
  ints("viewport", GL_VIEWPORT, 4);
  on("scissor test", GL_SCISSOR_TEST);
  ints("scissor box", GL_SCISSOR_BOX, 4);
  on("blend", GL_BLEND);
  ints("blend src rgb", GL_BLEND_SRC_RGB);
  ints("blend dst rgb", GL_BLEND_DST_RGB);
  ints("blend src alpha", GL_BLEND_SRC_ALPHA);
  ints("blend dst alpha", GL_BLEND_DST_ALPHA);
  ints("blend equation rgb", GL_BLEND_EQUATION_RGB);
  ints("blend equation alpha", GL_BLEND_EQUATION_ALPHA);
  floats("blend colour", GL_BLEND_COLOR, 4);
  on("depth test", GL_DEPTH_TEST);
  ints("depth func", GL_DEPTH_FUNC);
  ints("depth mask", GL_DEPTH_WRITEMASK);
  floats("clear depth", GL_DEPTH_CLEAR_VALUE);
  on("stencil test", GL_STENCIL_TEST);
  ints("stencil func", GL_STENCIL_FUNC);
  on("cull face", GL_CULL_FACE);
  ints("cull face mode", GL_CULL_FACE_MODE);
  ints("front face", GL_FRONT_FACE);
  floats("clear colour", GL_COLOR_CLEAR_VALUE, 4);
  ints("colour mask", GL_COLOR_WRITEMASK, 4);
  ints("polygon mode", GL_POLYGON_MODE, 2);
  ints("point sprite coord origin", GL_POINT_SPRITE_COORD_ORIGIN);
  on("program point size", GL_PROGRAM_POINT_SIZE);
  floats("point size", GL_POINT_SIZE);
  for (const auto& [name, e] : {std::pair{"pack alignment", GL_PACK_ALIGNMENT},
                                {"pack row length", GL_PACK_ROW_LENGTH},
                                {"pack skip rows", GL_PACK_SKIP_ROWS},
                                {"pack skip pixels", GL_PACK_SKIP_PIXELS},
                                {"unpack alignment", GL_UNPACK_ALIGNMENT},
                                {"unpack row length", GL_UNPACK_ROW_LENGTH},
                                {"unpack skip rows", GL_UNPACK_SKIP_ROWS},
                                {"unpack skip pixels", GL_UNPACK_SKIP_PIXELS},
                                {"unpack image height", GL_UNPACK_IMAGE_HEIGHT},
                                {"unpack swap bytes", GL_UNPACK_SWAP_BYTES}})
    ints(name, e);
  on("framebuffer sRGB", GL_FRAMEBUFFER_SRGB);
  on("dither", GL_DITHER);
  on("sample alpha to coverage", GL_SAMPLE_ALPHA_TO_COVERAGE);
  on("sample coverage", GL_SAMPLE_COVERAGE);
  on("sample mask", GL_SAMPLE_MASK);
  on("multisample", GL_MULTISAMPLE);
  for (int i = 0; i < 8; ++i) on(("clip distance " + std::to_string(i)).c_str(), GLenum(GL_CLIP_DISTANCE0 + i));
  on("colour logic op", GL_COLOR_LOGIC_OP);
  ints("logic op mode", GL_LOGIC_OP_MODE);
  on("polygon smooth", GL_POLYGON_SMOOTH);
  on("polygon offset fill", GL_POLYGON_OFFSET_FILL);
  on("depth clamp", GL_DEPTH_CLAMP);
  on("rasterizer discard", GL_RASTERIZER_DISCARD);
  ints("provoking vertex", GL_PROVOKING_VERTEX);
  if (compatibility) {
    on("alpha test", GL_ALPHA_TEST);
    ints("alpha test func", GL_ALPHA_TEST_FUNC);
    floats("alpha test ref", GL_ALPHA_TEST_REF);
    on("point sprite", GL_POINT_SPRITE);
    ints("clamp fragment colour", GL_CLAMP_FRAGMENT_COLOR);
    on("polygon stipple", GL_POLYGON_STIPPLE);
    floats("red scale", GL_RED_SCALE);
    floats("green bias", GL_GREEN_BIAS);
    floats("depth scale", GL_DEPTH_SCALE);
    ints("index shift", GL_INDEX_SHIFT);
  }
  REQUIRE(glGetError() == GL_NO_ERROR);
  return s;
}

/// CHECKs every item of `after` against `before`, by name.
inline void checkSame(const std::vector<Item>& before, const std::vector<Item>& after) {
  REQUIRE(before.size() == after.size());
  for (std::size_t k = 0; k < before.size(); ++k) {
    std::ostringstream was, is;
    for (double x : before[k].v) was << x << " ";
    for (double x : after[k].v) is << x << " ";
    CHECK_MESSAGE(before[k].v == after[k].v, before[k].name << ": was " << was.str() << "now " << is.str());
  }
}

/// Rows bottom-up (GL) ↔ top-down (the Frame's).
inline std::vector<unsigned char> flipRows(const std::vector<unsigned char>& p, int w, int h) {
  std::vector<unsigned char> out(p.size());
  const std::size_t row = std::size_t(w) * 4;
  for (int y = 0; y < h; ++y)
    std::copy_n(p.begin() + std::ptrdiff_t(row * std::size_t(y)), row,
                out.begin() + std::ptrdiff_t(row * std::size_t(h - 1 - y)));
  return out;
}

/// Pixels that differ between two RGBA8 images of the same size.
inline std::size_t differing(const std::vector<unsigned char>& a, const std::vector<unsigned char>& b) {
  REQUIRE(a.size() == b.size());
  std::size_t n = 0;
  for (std::size_t p = 0; p < a.size(); p += 4)
    n += !(a[p] == b[p] && a[p + 1] == b[p + 1] && a[p + 2] == b[p + 2] && a[p + 3] == b[p + 3]);
  return n;
}

/// Share of water pixels: blue clearly above red (the liquid mode's colours).
inline double waterShare(const std::vector<unsigned char>& p) {
  std::size_t n = 0;
  for (std::size_t k = 0; k < p.size(); k += 4) n += p[k + 2] > p[k] + 60;
  return double(n) / double(p.size() / 4);
}

/// A World of gameScene(mode) stepped `frames` frames (dyed in the particles mode).
inline std::unique_ptr<World> steppedWorld(const SceneDef& s, int frames) {
  auto w = std::make_unique<World>(s, WorldOptions{1});
  if (s.render.mode == "particles") dye(*w);
  for (int f = 0; f < frames; ++f) w->stepFrame();
  return w;
}

/// Runs this test binary's test case `name` in a child process with `env` (assignments) added;
/// the child knows it is one by SPH2D_RENDER_CONTEXT_CHILD.
inline apptest::Result runChild(const std::string& name, const std::string& env) {
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  return apptest::runShell("env SPH2D_RENDER_CONTEXT_CHILD=1 " + env + " \"" + self + "\" \"--test-case=" + name +
                           "\" --no-version");
}

inline bool isChild() { return std::getenv("SPH2D_RENDER_CONTEXT_CHILD") != nullptr; }

}  // namespace rctest
