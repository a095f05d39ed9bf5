// The renderer in a game's EGL context (Renderer(currentGlContext, ...), draw()).
//
// A game does not make OSMesa contexts: it gets its context from EGL, GLX or WGL and calls
// OpenGL through libglvnd. This program plays such a game with the context a headless machine
// has: EGL's surfaceless platform on Mesa (llvmpipe), OpenGL 3.3 core, its own framebuffer.
// It asserts, with the game's own readback:
//  - the frame drawn into the game's framebuffer is the very frame the OSMesa path renders for
//    the same World (equal bytes), frame after frame with a floating crate and a turning paddle;
//  - the game's bindings, viewport and enables are given back.
// It is built twice (tests/CMakeLists.txt): with OSMesa's gl* functions first in the link and
// with libglvnd's libOpenGL first, the two orders a game's link can put them in; either must
// reach whichever context is current. The OSMesa reference frames are rendered in the same
// process, switching contexts between them, as a game that also writes PNGs would.
#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <ios>
#include <memory>
#include <string>
#include <vector>

#include "sph2d/hash.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"
#include "support/game_scene.hpp"

using namespace sph2d;

namespace {

constexpr int W = 160, H = 120;

/// The game's scene of tests/app/test_render_context.cpp, liquid, at W × H px.
SceneDef gameScene() {
  SceneDef s = test::gameScene("liquid", W, H);
  s.name = "render_egl";
  return s;
}

/// The game's context: EGL's surfaceless platform (no window system, no device needed),
/// OpenGL 3.3 core, made current without a surface. Every failure names the EGL call and error.
struct EglContext {
  EGLDisplay dpy = EGL_NO_DISPLAY;
  EGLContext ctx = EGL_NO_CONTEXT;

  EglContext() {
    pinRenderEnvironment();  // the Mesa settings of the OSMesa path, so both draw alike
    const char* clientExts = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    REQUIRE_MESSAGE(clientExts != nullptr, "eglQueryString(EGL_NO_DISPLAY): no client extensions");
    REQUIRE_MESSAGE(std::string(clientExts).find("EGL_MESA_platform_surfaceless") != std::string::npos,
                    "EGL has no surfaceless platform (client extensions: " << clientExts << ")");
    auto getPlatformDisplay =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    REQUIRE(reinterpret_cast<void*>(getPlatformDisplay) != nullptr);
    dpy = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    REQUIRE_MESSAGE(dpy != EGL_NO_DISPLAY, "eglGetPlatformDisplayEXT: error 0x" << std::hex << eglGetError());
    EGLint major = 0, minor = 0;
    REQUIRE_MESSAGE(eglInitialize(dpy, &major, &minor), "eglInitialize: error 0x" << std::hex << eglGetError());
    REQUIRE(eglBindAPI(EGL_OPENGL_API));
    const EGLint configAttribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint count = 0;
    REQUIRE(eglChooseConfig(dpy, configAttribs, &config, 1, &count));
    REQUIRE_MESSAGE(count > 0, "no EGL config renders OpenGL");
    const EGLint contextAttribs[] = {
        EGL_CONTEXT_MAJOR_VERSION,           3,       EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
        EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    ctx = eglCreateContext(dpy, config, EGL_NO_CONTEXT, contextAttribs);
    REQUIRE_MESSAGE(ctx != EGL_NO_CONTEXT, "eglCreateContext (3.3 core): error 0x" << std::hex << eglGetError());
    makeCurrentOnly();
  }
  ~EglContext() {
    eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (ctx != EGL_NO_CONTEXT) eglDestroyContext(dpy, ctx);
    if (dpy != EGL_NO_DISPLAY) eglTerminate(dpy);
  }
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;
  /// Makes the context current again after an OSMesa Renderer's render() made its own current:
  /// released first, because Mesa's EGL skips making current the context it believes is current
  /// already (docs/EMBEDDING.md).
  void makeCurrent() {
    REQUIRE(eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT));
    makeCurrentOnly();
  }
  /// eglMakeCurrent of the context alone (what a game that does not know the above would do).
  void makeCurrentOnly() {
    REQUIRE_MESSAGE(eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx),
                    "eglMakeCurrent: error 0x" << std::hex << eglGetError());
  }
};

/// The game's framebuffer: an RGBA8 texture of W × H px cleared to magenta.
struct GameFramebuffer {
  GLuint fbo = 0, tex = 0;
  GameFramebuffer() {
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, W, H, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
    REQUIRE(glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE);
    glClearColor(0.8f, 0.1f, 0.6f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    REQUIRE(glGetError() == GL_NO_ERROR);
  }
  /// The pixels, rows top-down (the Frame's order), read with plain pack settings.
  std::vector<unsigned char> pixels() const {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    std::vector<unsigned char> p(std::size_t(W) * H * 4), out(p.size());
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, p.data());
    REQUIRE(glGetError() == GL_NO_ERROR);
    const std::size_t row = std::size_t(W) * 4;
    for (int y = 0; y < H; ++y)
      std::copy_n(p.begin() + std::ptrdiff_t(row * std::size_t(y)), row,
                  out.begin() + std::ptrdiff_t(row * std::size_t(H - 1 - y)));
    return out;
  }
};

/// Pixels that differ between two RGBA8 images of the same size.
std::size_t differing(const std::vector<unsigned char>& a, const std::vector<unsigned char>& b) {
  REQUIRE(a.size() == b.size());
  std::size_t n = 0;
  for (std::size_t p = 0; p < a.size(); p += 4) n += !std::equal(&a[p], &a[p] + 4, &b[p]);
  return n;
}

/// Share of water pixels: blue clearly above red (the liquid mode's colours).
double waterShare(const std::vector<unsigned char>& p) {
  std::size_t n = 0;
  for (std::size_t k = 0; k < p.size(); k += 4) n += p[k + 2] > p[k] + 60;
  return double(n) / double(p.size() / 4);
}

}  // namespace

TEST_CASE(
    "draw() into a framebuffer of the game's EGL context (surfaceless, 3.3 core), frame after frame: the OSMesa path's pixels, and the game's state given back") {
  const SceneDef s = gameScene();
  World world(s, WorldOptions{1});
  for (int f = 0; f < 2; ++f) world.stepFrame();
  EglContext game;
  const std::string version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  MESSAGE("the game's context: OpenGL " << version << " on "
                                        << std::string(reinterpret_cast<const char*>(glGetString(GL_RENDERER))));
  GameFramebuffer target;
  Renderer renderer(currentGlContext, s.render);
  CHECK(renderer.usesCurrentContext());
  Renderer own(s.render);  // the OSMesa path beside it (makes its own context current to render)
  std::vector<std::uint64_t> hashes;
  for (int k = 0; k < 4; ++k) {
    for (int f = 0; f < 4; ++f) world.stepFrame();
    const std::vector<unsigned char> reference = own.render(world).rgba;
    game.makeCurrent();
    // Some of the game's state, to be given back.
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(3, 4, 50, 60);
    glEnable(GL_BLEND);
    glEnable(GL_SCISSOR_TEST);
    glScissor(1, 1, 2, 2);
    renderer.draw(world, GlTarget{target.fbo, std::array<int, 4>{0, 0, W, H}});
    CHECK(glGetError() == GL_NO_ERROR);
    GLint fb = -1, vp[4] = {};
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &fb);
    glGetIntegerv(GL_VIEWPORT, vp);
    CHECK(fb == 0);
    CHECK((vp[0] == 3 && vp[1] == 4 && vp[2] == 50 && vp[3] == 60));
    CHECK(glIsEnabled(GL_BLEND) == GL_TRUE);
    CHECK(glIsEnabled(GL_SCISSOR_TEST) == GL_TRUE);
    glDisable(GL_BLEND);
    glDisable(GL_SCISSOR_TEST);

    const std::vector<unsigned char> drawn = target.pixels();
    const std::size_t diff = differing(drawn, reference);
    CHECK_MESSAGE(diff == 0, "frame " << world.frame() << ": " << diff << " of " << W * H
                                      << " pixels differ from the OSMesa path's frame");
    CHECK(waterShare(drawn) > 0.15);
    hashes.push_back(xxh64(drawn.data(), drawn.size()));
  }
  std::sort(hashes.begin(), hashes.end());
  CHECK(std::unique(hashes.begin(), hashes.end()) == hashes.end());  // the paddle turns: every frame differs
}

TEST_CASE(
    "after an OSMesa Renderer's render(), an eglMakeCurrent that Mesa skips leaves the OSMesa context current: draw() refuses and says what to do, and the released-then-made context draws") {
  const SceneDef s = gameScene();
  World world(s, WorldOptions{1});
  for (int f = 0; f < 3; ++f) world.stepFrame();
  EglContext game;
  GameFramebuffer target;
  Renderer renderer(currentGlContext, s.render);
  Renderer own(s.render);
  const std::vector<unsigned char> reference = own.render(world).rgba;  // its own context is current now
  game.makeCurrentOnly();  // Mesa's EGL believes the game's context is still current: nothing happens
  std::string error;
  try {
    renderer.draw(world, GlTarget{target.fbo, std::array<int, 4>{0, 0, W, H}});
  } catch (const std::runtime_error& e) {
    error = e.what();
  }
  CHECK(error.find("another OpenGL context is current") != std::string::npos);
  CHECK(error.find("EGL_NO_CONTEXT") != std::string::npos);  // names the fix
  game.makeCurrent();                                        // released, then made current: now it is
  renderer.draw(world, GlTarget{target.fbo, std::array<int, 4>{0, 0, W, H}});
  CHECK(glGetError() == GL_NO_ERROR);
  CHECK(differing(target.pixels(), reference) == 0);
}
