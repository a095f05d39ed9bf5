// The renderer in a game's own OpenGL context (Renderer(currentGlContext, ...), draw()).
//
// Each test plays the game: it makes its own OSMesa context (3.3 core, as the Renderer's own;
// one test a compatibility-profile one), its own framebuffer with a depth buffer, program,
// vertex array, textures and samplers, sets state far from GL's defaults, and draws a World
// through the renderer. The tests assert, with the game's own queries and readbacks:
//  - every state item the game set (and a few the renderer never touches) is exactly as before;
//  - the game's framebuffer holds the very pixels the OSMesa path reads back for the same World
//    (equal bytes: the frame is drawn at its own size, where the presentation copies texels;
//    the liquid and particles modes, solids, a floating crate and a turning paddle);
//  - pixels outside the viewport keep what the game drew; a scaled viewport still shows water;
//  - bad use is refused with a message that says what is wrong, and the state is still restored.
// Where the game's state would change the frame (a sampler that filters with mipmaps on the
// units the composite reads, scissor, blending, culling, line polygons, colour masks, logic op,
// rasterizer discard, a bound pixel-unpack buffer, odd unpack parameters, a depth buffer cleared
// to 0 with the depth test on), an item the renderer forgot to set fails the pixel check, and one
// it forgot to restore fails the state check.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>
#include <doctest/doctest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "app_runner.hpp"
#include "support/game_scene.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

using namespace sph2d;

namespace {

constexpr int W = 160, H = 120;  // the frame; the tests' viewports are this size unless said

/// The game's scene (tests/support/game_scene.hpp) at W × H px unless said; in the particles
/// mode each particle's colour comes from the game (World::setParticleColor), so the frame has no
/// colour bar.
SceneDef gameScene(const std::string& mode, int w = W, int h = H) { return test::gameScene(mode, w, h); }

/// Options for `mode`: the particles mode colours by the game's own particle colours.
RenderOptions optionsFor(const std::string& mode) {
  RenderOptions o;
  if (mode == "particles") o.colorBy = ColorField::Color;
  return o;
}

/// Dyes the water: red on the left, green in the middle, the rest left uncoloured.
void dye(World& world) {
  for (std::size_t i = 0; i < world.particleCount(); ++i) {
    const double x = world.worldPosition(i).x();
    if (x < 0.4) world.setParticleColor(world.particles().id[i], 0xE03020u);
    else if (x < 0.8) world.setParticleColor(world.particles().id[i], 0x30C040u);
  }
}

/// The OSMesa path's frame of `world` (its own context, made and destroyed here).
std::vector<unsigned char> osmesaFrame(const World& world, const SceneDef& s, const RenderOptions& o) {
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
      const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0, OSMESA_STENCIL_BITS, 0,
                             OSMESA_ACCUM_BITS, 0, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                             OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
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

GLuint compile(GLenum type, const char* src) {
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
std::vector<unsigned char> readRgba(GLuint fbo, int x, int y, int w, int h) {
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
  GLuint tex[4] = {0, 0, 0, 0};

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
    glGenTextures(4, tex);
    for (GLuint t : tex) {
      glBindTexture(GL_TEXTURE_2D, t);
      glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 4, 4, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    }
    glGenSamplers(1, &sampler);
    glSamplerParameteri(sampler, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);  // textures without mipmaps: incomplete
    glSamplerParameteri(sampler, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glSamplerParameteri(sampler, GL_TEXTURE_WRAP_S, GL_REPEAT);
    const GLuint vs = compile(GL_VERTEX_SHADER, "#version 330 core\nlayout(location = 0) in vec2 p;\n"
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
/// draw(): framebuffers, program, vertex array, buffers, textures on units 0 to 3 with a mipmap
/// sampler on 0 to 2, the active unit 3, viewport, scissor, blending, depth and stencil tests,
/// culling, clear colour, colour mask, polygon mode, sprite origin, point size, pixel store,
/// sRGB, dithering, alpha to coverage, a clip distance, logic op, polygon smoothing, rasterizer
/// discard, provoking vertex (the last two the renderer never needs to touch).
void setGameState(const GameObjects& g, bool compatibility = false) {
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
  for (int u = 0; u < 4; ++u) {
    glActiveTexture(GLenum(GL_TEXTURE0 + u));
    glBindTexture(GL_TEXTURE_2D, g.tex[u]);
    if (u < 3) glBindSampler(GLuint(u), g.sampler);
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
    glAlphaFunc(GL_GREATER, 0.99f);  // would drop the discs' soft edges
    glDisable(GL_POINT_SPRITE);      // gl_PointCoord would be undefined
    glClampColor(GL_CLAMP_FRAGMENT_COLOR, GL_TRUE);  // the float splat would stop at 1
    glEnable(GL_POLYGON_STIPPLE);                  // would punch holes in every triangle
    glPixelTransferf(GL_RED_SCALE, 0.5f);          // would halve the red of every upload
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
std::vector<Item> snapshot(bool compatibility = false) {
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
  for (int u = 0; u < 4; ++u) {
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
  for (const auto& [name, e] :
       {std::pair{"pack alignment", GL_PACK_ALIGNMENT}, {"pack row length", GL_PACK_ROW_LENGTH},
        {"pack skip rows", GL_PACK_SKIP_ROWS}, {"pack skip pixels", GL_PACK_SKIP_PIXELS},
        {"unpack alignment", GL_UNPACK_ALIGNMENT}, {"unpack row length", GL_UNPACK_ROW_LENGTH},
        {"unpack skip rows", GL_UNPACK_SKIP_ROWS}, {"unpack skip pixels", GL_UNPACK_SKIP_PIXELS},
        {"unpack image height", GL_UNPACK_IMAGE_HEIGHT}, {"unpack swap bytes", GL_UNPACK_SWAP_BYTES}})
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
void checkSame(const std::vector<Item>& before, const std::vector<Item>& after) {
  REQUIRE(before.size() == after.size());
  for (std::size_t k = 0; k < before.size(); ++k) {
    std::ostringstream was, is;
    for (double x : before[k].v) was << x << " ";
    for (double x : after[k].v) is << x << " ";
    CHECK_MESSAGE(before[k].v == after[k].v, before[k].name << ": was " << was.str() << "now " << is.str());
  }
}

/// Rows bottom-up (GL) ↔ top-down (the Frame's).
std::vector<unsigned char> flipRows(const std::vector<unsigned char>& p, int w, int h) {
  std::vector<unsigned char> out(p.size());
  const std::size_t row = std::size_t(w) * 4;
  for (int y = 0; y < h; ++y) std::copy_n(p.begin() + std::ptrdiff_t(row * std::size_t(y)), row,
                                          out.begin() + std::ptrdiff_t(row * std::size_t(h - 1 - y)));
  return out;
}

/// Pixels that differ between two RGBA8 images of the same size.
std::size_t differing(const std::vector<unsigned char>& a, const std::vector<unsigned char>& b) {
  REQUIRE(a.size() == b.size());
  std::size_t n = 0;
  for (std::size_t p = 0; p < a.size(); p += 4)
    n += !(a[p] == b[p] && a[p + 1] == b[p + 1] && a[p + 2] == b[p + 2] && a[p + 3] == b[p + 3]);
  return n;
}

/// Share of water pixels: blue clearly above red (the liquid mode's colours).
double waterShare(const std::vector<unsigned char>& p) {
  std::size_t n = 0;
  for (std::size_t k = 0; k < p.size(); k += 4) n += p[k + 2] > p[k] + 60;
  return double(n) / double(p.size() / 4);
}

/// A World of gameScene(mode) stepped `frames` frames (dyed in the particles mode).
std::unique_ptr<World> steppedWorld(const SceneDef& s, int frames) {
  auto w = std::make_unique<World>(s, WorldOptions{1});
  if (s.render.mode == "particles") dye(*w);
  for (int f = 0; f < frames; ++f) w->stepFrame();
  return w;
}

/// Runs this test binary's test case `name` in a child process with `env` (assignments) added;
/// the child knows it is one by SPH2D_RENDER_CONTEXT_CHILD.
apptest::Result runChild(const std::string& name, const std::string& env) {
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  return apptest::runShell("env SPH2D_RENDER_CONTEXT_CHILD=1 " + env + " \"" + self + "\" \"--test-case=" + name +
                           "\" --no-version");
}

bool isChild() { return std::getenv("SPH2D_RENDER_CONTEXT_CHILD") != nullptr; }

}  // namespace

TEST_CASE("draw() into the game's framebuffer: every piece of GL state the game set is given back and the pixels are the OSMesa path's") {
  for (const std::string mode : {"liquid", "particles"}) {
    CAPTURE(mode);
    const SceneDef s = gameScene(mode);
    const RenderOptions o = optionsFor(mode);
    const auto world = steppedWorld(s, 12);
    REQUIRE(world->movingColliders().size() == 2);  // the crate and the paddle are drawn too
    const std::vector<unsigned char> reference = osmesaFrame(*world, s, o);

    GameContext game;
    GameObjects g;
    Renderer renderer(currentGlContext, s.render, o);
    CHECK(renderer.usesCurrentContext());
    setGameState(g);
    const std::vector<Item> before = snapshot();
    renderer.draw(*world, GlTarget{g.fbo, std::array<int, 4>{0, 0, W, H}});
    CHECK(glGetError() == GL_NO_ERROR);  // nothing left pending
    checkSame(before, snapshot());

    // The frame, exactly: the game reads its framebuffer back (rows bottom-up) and flips it.
    const std::vector<unsigned char> drawn = flipRows(g.pixels(), W, H);
    const std::size_t diff = differing(drawn, reference);
    MESSAGE(mode << ": " << diff << " of " << W * H << " pixels differ from the OSMesa path's frame");
    CHECK(diff == 0);
    CHECK(xxh64(drawn.data(), drawn.size()) == xxh64(reference.data(), reference.size()));
    if (mode == "liquid") CHECK(waterShare(drawn) > 0.15);
    // Drawn with the depth test off: the game's depth buffer (cleared to 0) is untouched.
    const std::vector<float> depth = g.depth();
    CHECK(std::count(depth.begin(), depth.end(), 0.0f) == std::ptrdiff_t(depth.size()));
    CHECK(renderer.lastTimings().present > 0);
    CHECK(renderer.lastTimings().readback == 0);  // no readback
  }
}

TEST_CASE("draw() over a sub-viewport leaves every pixel outside it as the game drew it") {
  const SceneDef s = gameScene("liquid");
  const auto world = steppedWorld(s, 12);
  const std::vector<unsigned char> reference = osmesaFrame(*world, s, {});
  GameContext game;
  const int FW = W + 50, FH = H + 40;
  GameObjects g(FW, FH);
  const std::vector<unsigned char> gameDrawing = g.pixels();
  Renderer renderer(currentGlContext, s.render);

  SUBCASE("at the frame's size, through the bound framebuffer and the current viewport (the default target)") {
    const int X = 21, Y = 13;
    setGameState(g);
    glViewport(X, Y, W, H);
    const std::vector<Item> before = snapshot();
    renderer.draw(*world);
    checkSame(before, snapshot());
    const std::vector<unsigned char> after = g.pixels();
    std::size_t outsideChanged = 0, insideDiffer = 0;
    for (int y = 0; y < FH; ++y)
      for (int x = 0; x < FW; ++x) {
        const std::size_t p = (std::size_t(y) * FW + std::size_t(x)) * 4;
        const bool inside = x >= X && x < X + W && y >= Y && y < Y + H;
        // inside: the reference's pixel at (x − X, row from the top)
        const std::size_t r = (std::size_t(H - 1 - (y - Y)) * W + std::size_t(x - X)) * 4;
        const bool same = inside ? std::equal(after.begin() + std::ptrdiff_t(p), after.begin() + std::ptrdiff_t(p + 4),
                                              reference.begin() + std::ptrdiff_t(r))
                                 : std::equal(after.begin() + std::ptrdiff_t(p), after.begin() + std::ptrdiff_t(p + 4),
                                              gameDrawing.begin() + std::ptrdiff_t(p));
        (inside ? insideDiffer : outsideChanged) += !same;
      }
    CHECK(outsideChanged == 0);
    CHECK(insideDiffer == 0);
  }
  SUBCASE("scaled to half the frame's size: outside untouched, water inside") {
    const int X = 30, Y = 25, VW = W / 2, VH = H / 2;
    setGameState(g);
    const std::vector<Item> before = snapshot();
    renderer.draw(*world, GlTarget{std::nullopt, std::array<int, 4>{X, Y, VW, VH}});
    checkSame(before, snapshot());
    const std::vector<unsigned char> after = g.pixels();
    std::size_t outsideChanged = 0;
    std::vector<unsigned char> inside;
    for (int y = 0; y < FH; ++y)
      for (int x = 0; x < FW; ++x) {
        const std::size_t p = (std::size_t(y) * FW + std::size_t(x)) * 4;
        if (x >= X && x < X + VW && y >= Y && y < Y + VH) inside.insert(inside.end(), after.begin() + std::ptrdiff_t(p), after.begin() + std::ptrdiff_t(p + 4));
        else outsideChanged += !std::equal(after.begin() + std::ptrdiff_t(p), after.begin() + std::ptrdiff_t(p + 4), gameDrawing.begin() + std::ptrdiff_t(p));
      }
    CHECK(outsideChanged == 0);
    const double full = waterShare(reference), half = waterShare(inside);
    MESSAGE("water: " << full << " of the frame, " << half << " of the half-size viewport");
    CHECK(half == doctest::Approx(full).epsilon(0.1));
    // The water is at the bottom of the viewport (GL rows: the world's bottom is row 0); a
    // quarter up is 0.15 m above the floor, the top row 1.05 m.
    const std::vector<unsigned char> lowRow(inside.begin() + std::ptrdiff_t(VW * 4 * (VH / 4)),
                                            inside.begin() + std::ptrdiff_t(VW * 4 * (VH / 4 + 1)));
    const std::vector<unsigned char> highRow(inside.begin() + std::ptrdiff_t(VW * 4 * (VH - 2)),
                                             inside.begin() + std::ptrdiff_t(VW * 4 * (VH - 1)));
    CHECK(waterShare(lowRow) > 0.5);
    CHECK(waterShare(highRow) == 0);
  }
}

TEST_CASE("draw() into the default framebuffer (the game's window) at a viewport: the OSMesa path's pixels there and the window's own elsewhere") {
  const SceneDef s = gameScene("particles", W, H);
  const RenderOptions o = optionsFor("particles");
  const auto world = steppedWorld(s, 12);
  const std::vector<unsigned char> reference = osmesaFrame(*world, s, o);
  const int WW = W + 30, WH = H + 20, X = 12, Y = 9;
  GameContext game(false, WW, WH);
  glClearColor(0.3f, 0.3f, 0.1f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);  // the game's drawing in its window
  auto readWindow = [&](int x, int y, int w, int h) { return readRgba(0, x, y, w, h); };
  const std::vector<unsigned char> gameDrawing = readWindow(0, 0, WW, WH);
  GameObjects g;
  Renderer renderer(currentGlContext, s.render, o);
  setGameState(g);
  const std::vector<Item> before = snapshot();
  renderer.draw(*world, GlTarget{0u, std::array<int, 4>{X, Y, W, H}});
  checkSame(before, snapshot());
  CHECK(differing(flipRows(readWindow(X, Y, W, H), W, H), reference) == 0);
  const std::vector<unsigned char> win = readWindow(0, 0, WW, WH);
  std::size_t outsideChanged = 0;
  for (int y = 0; y < WH; ++y)
    for (int x = 0; x < WW; ++x) {
      if (x >= X && x < X + W && y >= Y && y < Y + H) continue;
      const std::size_t p = (std::size_t(y) * WW + std::size_t(x)) * 4;
      outsideChanged += !std::equal(&win[p], &win[p] + 4, &gameDrawing[p]);
    }
  CHECK(outsideChanged == 0);
  CHECK(std::count(gameDrawing.begin(), gameDrawing.end(), 0) == 0);  // the clear colour, not OSMesa's zeros
}

TEST_CASE("draw() frame after frame with a floating crate and a turning paddle, interleaved with the OSMesa path: the same pixels every frame") {
  const SceneDef s = gameScene("liquid");
  auto world = steppedWorld(s, 2);
  Renderer own(s.render);  // the OSMesa path, alive beside the game's context
  GameContext game;
  GameObjects g;
  Renderer renderer(currentGlContext, s.render);
  std::vector<std::uint64_t> hashes;
  for (int k = 0; k < 5; ++k) {
    for (int f = 0; f < 4; ++f) world->stepFrame();
    const std::vector<unsigned char> reference = own.render(*world).rgba;  // makes its own context current
    game.makeCurrent();
    setGameState(g);
    const std::vector<Item> before = snapshot();
    renderer.draw(*world, GlTarget{g.fbo, std::array<int, 4>{0, 0, W, H}});
    checkSame(before, snapshot());
    const std::vector<unsigned char> drawn = flipRows(g.pixels(), W, H);
    CHECK_MESSAGE(differing(drawn, reference) == 0, "frame " << world->frame());
    hashes.push_back(xxh64(drawn.data(), drawn.size()));
  }
  std::sort(hashes.begin(), hashes.end());
  CHECK(std::unique(hashes.begin(), hashes.end()) == hashes.end());  // the paddle turns: every frame differs
}

TEST_CASE("render() in the game's context reads back the OSMesa path's frame (overlay and colour bar included) and gives the state back") {
  SceneDef s = gameScene("particles");
  RenderOptions o;  // colour by speed: a colour bar
  o.overlay = true;
  const auto world = steppedWorld(s, 12);
  const std::vector<unsigned char> reference = osmesaFrame(*world, s, o);
  GameContext game;
  GameObjects g;
  const std::vector<unsigned char> gameDrawing = g.pixels();
  Renderer renderer(currentGlContext, s.render, o);
  setGameState(g);
  const std::vector<Item> before = snapshot();
  const Frame& frame = renderer.render(*world);
  checkSame(before, snapshot());
  CHECK(differing(frame.rgba, reference) == 0);
  CHECK(differing(g.pixels(), gameDrawing) == 0);  // render() leaves the game's framebuffer alone
  CHECK(renderer.lastTimings().readback > 0);
}

TEST_CASE("draw() in a compatibility-profile context: the game's alpha test, point sprites off, colour clamping, polygon stipple and pixel transfer change nothing and are given back") {
  for (const std::string mode : {"liquid", "particles"}) {
    CAPTURE(mode);
    const SceneDef s = gameScene(mode);
    const RenderOptions o = optionsFor(mode);
    const auto world = steppedWorld(s, 12);
    const std::vector<unsigned char> reference = osmesaFrame(*world, s, o);
    GameContext game(true);
    GLint mask = 0;
    glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &mask);
    REQUIRE((mask & GL_CONTEXT_COMPATIBILITY_PROFILE_BIT) != 0);
    GameObjects g;
    Renderer renderer(currentGlContext, s.render, o);
    setGameState(g, true);
    const std::vector<Item> before = snapshot(true);
    renderer.draw(*world, GlTarget{g.fbo, std::array<int, 4>{0, 0, W, H}});
    CHECK(glGetError() == GL_NO_ERROR);
    checkSame(before, snapshot(true));
    // The game's pixel transfer would change the game's own readback too: plain for reading.
    glPixelTransferf(GL_RED_SCALE, 1.0f);
    glPixelTransferf(GL_GREEN_BIAS, 0.0f);
    CHECK(differing(flipRows(g.pixels(), W, H), reference) == 0);
  }
}

TEST_CASE("the renderer on the game's context refuses bad use with a clear error and gives the state back") {
  const SceneDef s = gameScene("liquid");
  const auto world = steppedWorld(s, 2);
  {
    Renderer own(s.render);
    CHECK_FALSE(own.usesCurrentContext());
    CHECK_THROWS_WITH_AS(own.draw(*world), doctest::Contains("OSMesa context of its own"), std::logic_error);
  }
  GameContext game;
  GameObjects g;
  Renderer renderer(currentGlContext, s.render);
  setGameState(g);
  const std::vector<Item> before = snapshot();

  // Not a framebuffer, an empty viewport, an incomplete framebuffer.
  CHECK_THROWS_WITH_AS(renderer.draw(*world, GlTarget{4242u, std::nullopt}),
                       doctest::Contains("4242 is not a framebuffer object"), std::invalid_argument);
  CHECK_THROWS_WITH_AS(renderer.draw(*world, GlTarget{g.fbo, std::array<int, 4>{0, 0, 0, 10}}),
                       doctest::Contains("viewport is empty"), std::invalid_argument);
  GLuint empty = 0;
  glGenFramebuffers(1, &empty);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, empty);  // made a framebuffer, without attachments
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, g.fbo);
  CHECK_THROWS_WITH_AS(renderer.draw(*world, GlTarget{empty, std::nullopt}), doctest::Contains("is not complete"),
                       std::runtime_error);
  CHECK(glGetError() == GL_NO_ERROR);
  checkSame(before, snapshot());  // also after a throw from the middle of a frame

  // An error of the game's, pending: reported (glGetError has taken it), nothing drawn.
  const std::vector<unsigned char> pixelsBefore = g.pixels();
  setGameState(g);
  glEnable(GLenum(0x1234));  // GL_INVALID_ENUM
  CHECK_THROWS_WITH_AS(renderer.draw(*world), doctest::Contains("an OpenGL error (0x500) was pending"),
                       std::runtime_error);
  CHECK(glGetError() == GL_NO_ERROR);
  checkSame(before, snapshot());
  CHECK(differing(g.pixels(), pixelsBefore) == 0);

  // No context current: construction and drawing say so.
  REQUIRE(OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0));
  CHECK_THROWS_WITH_AS(Renderer(currentGlContext, s.render), doctest::Contains("no OpenGL context is current"),
                       std::runtime_error);
  CHECK_THROWS_WITH_AS(renderer.draw(*world), doctest::Contains("no OpenGL context is current"), std::runtime_error);
  game.makeCurrent();
  glDeleteFramebuffers(1, &empty);
}

TEST_CASE("draw() into a framebuffer with two colour attachments writes the first and leaves the second as the game drew it") {
  const SceneDef s = gameScene("liquid");
  const RenderOptions o = optionsFor("liquid");
  const auto world = steppedWorld(s, 12);
  const std::vector<unsigned char> reference = osmesaFrame(*world, s, o);
  GameContext game;
  GameObjects g;
  // A second colour attachment (the game's G-buffer, say), cleared to one colour, both drawn to.
  GLuint second = 0;
  glGenTextures(1, &second);
  glBindTexture(GL_TEXTURE_2D, second);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, W, H, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
  glBindFramebuffer(GL_FRAMEBUFFER, g.fbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, second, 0);
  const GLenum both[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glDrawBuffers(2, both);
  const GLfloat teal[4] = {0.0f, 0.5f, 0.5f, 1.0f};
  glClearBufferfv(GL_COLOR, 1, teal);
  REQUIRE(glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE);
  auto readSecond = [&] {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, g.fbo);
    glReadBuffer(GL_COLOR_ATTACHMENT1);
    std::vector<unsigned char> p = readRgba(g.fbo, 0, 0, W, H);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    return p;
  };
  const std::vector<unsigned char> secondBefore = readSecond();
  REQUIRE(secondBefore[1] == 128);  // teal
  Renderer renderer(currentGlContext, s.render, o);
  glBindFramebuffer(GL_FRAMEBUFFER, g.fbo);
  renderer.draw(*world, GlTarget{g.fbo, std::array<int, 4>{0, 0, W, H}});
  CHECK(glGetError() == GL_NO_ERROR);
  CHECK(differing(readSecond(), secondBefore) == 0);
  CHECK(differing(flipRows(g.pixels(), W, H), reference) == 0);
  glDeleteTextures(1, &second);
}

TEST_CASE("another context current (an OSMesa renderer's) is refused by draw(), and destroying the game's renderer there leaves that context's objects alone") {
  const SceneDef s = gameScene("liquid");
  const auto world = steppedWorld(s, 6);
  GameContext game;
  auto mine = std::make_unique<Renderer>(currentGlContext, s.render);
  Renderer screenshots(s.render);  // an OSMesa renderer: render() leaves its own context current
  const std::uint64_t first = xxh64(screenshots.render(*world).rgba.data(), screenshots.render(*world).rgba.size());
  CHECK_THROWS_WITH_AS(mine->draw(*world), doctest::Contains("another OpenGL context is current"), std::runtime_error);
  mine.reset();  // in the OSMesa renderer's context: must not delete objects by our names there
  const Frame& again = screenshots.render(*world);
  CHECK(xxh64(again.rgba.data(), again.rgba.size()) == first);
  game.makeCurrent();
  Renderer back(currentGlContext, s.render);
  GameObjects g;
  back.draw(*world, GlTarget{g.fbo, std::array<int, 4>{0, 0, W, H}});
  CHECK(glGetError() == GL_NO_ERROR);
}

TEST_CASE("a context below OpenGL 3.3 is refused naming the version found") {
  if (!isChild()) {
    const apptest::Result r =
        runChild("a context below OpenGL 3.3 is refused naming the version found", "MESA_GL_VERSION_OVERRIDE=2.1");
    INFO(r.out);
    CHECK(r.code == 0);
    CHECK(r.out.find("child: refused: ") != std::string::npos);
    return;
  }
  GameContext game(true);  // compatibility profile, reported as 2.1 by the override
  const std::string version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  REQUIRE(version.rfind("2.1", 0) == 0);
  try {
    Renderer renderer(currentGlContext, gameScene("liquid").render);
    FAIL("a 2.1 context was accepted");
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    CHECK(what.find("needs OpenGL 3.3 or later") != std::string::npos);
    CHECK(what.find("is OpenGL 2.1 Mesa") != std::string::npos);
    std::printf("child: refused: %s\n", e.what());
  }
  CHECK(glGetError() == GL_NO_ERROR);
}

TEST_CASE("an OpenGL 3.3 core context without GL_ARB_copy_image gets the same pixels (background rows blitted)") {
  const char* name = "an OpenGL 3.3 core context without GL_ARB_copy_image gets the same pixels (background rows blitted)";
  const SceneDef s = gameScene("liquid");
  const auto world = steppedWorld(s, 12);
  if (!isChild()) {
    const std::vector<unsigned char> reference = osmesaFrame(*world, s, {});  // glCopyImageSubData here
    const apptest::Result r = runChild(name, "MESA_GL_VERSION_OVERRIDE=3.3 MESA_EXTENSION_OVERRIDE=-GL_ARB_copy_image "
                                             "SPH2D_EXPECT_RGBA_XXH64=" + hex64(xxh64(reference.data(), reference.size())));
    INFO(r.out);
    CHECK(r.code == 0);
    CHECK(r.out.find("child: 3.3 without GL_ARB_copy_image: same pixels") != std::string::npos);
    return;
  }
  GameContext game;
  const std::string version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  REQUIRE(version.rfind("3.3", 0) == 0);
  GLint n = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &n);
  for (GLint i = 0; i < n; ++i)
    REQUIRE(std::string(reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, GLuint(i)))) != "GL_ARB_copy_image");
  GameObjects g;
  Renderer renderer(currentGlContext, s.render);
  const char* expected = std::getenv("SPH2D_EXPECT_RGBA_XXH64");
  REQUIRE(expected);
  for (int k = 0; k < 2; ++k) {  // the second frame restores only the rows the first one changed
    setGameState(g);
    const std::vector<Item> before = snapshot();
    renderer.draw(*world, GlTarget{g.fbo, std::array<int, 4>{0, 0, W, H}});
    CHECK(glGetError() == GL_NO_ERROR);
    checkSame(before, snapshot());
    const std::vector<unsigned char> drawn = flipRows(g.pixels(), W, H);
    CHECK(hex64(xxh64(drawn.data(), drawn.size())) == expected);
  }
  std::printf("child: 3.3 without GL_ARB_copy_image: same pixels\n");
}
