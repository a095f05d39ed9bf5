// The renderer in a program that links libglvnd's libOpenGL (a GL game usually does).
//
// With libOpenGL in the link every gl* symbol binds to glvnd's dispatch, which reaches only
// contexts made current through EGL or GLX, not an OSMesa context. This program makes no EGL or
// GLX context at all: it plays a game that renders frames off-screen with the Renderer's own
// OSMesa context. It is built twice (tests/CMakeLists.txt): with libOpenGL first in the link
// (glvnd_first) and with only libOSMesa's gl* functions (osmesa_only, the plain link of the
// `sph2d` app). Both render the scene of tests/golden/liquid_dam_break and must give the very
// frames of its manifest: the hashes `sph2d run` (the plain link) wrote, which `sph2d check`
// checks in CTest (golden/liquid_dam_break). A first test asserts that the link is the one the
// build says, so that glvnd_first cannot pass by binding to libOSMesa.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/osmesa.h>
#include <dlfcn.h>
#include <doctest/doctest.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "sph2d/hash.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

using namespace sph2d;

namespace {

const std::string kGolden = std::string(SPH2D_SOURCE_DIR) + "/tests/golden/liquid_dam_break";

nlohmann::json manifest() {
  std::ifstream in(kGolden + "/manifest.json");
  REQUIRE_MESSAGE(in, "cannot read " << kGolden << "/manifest.json");
  return nlohmann::json::parse(in);
}

/// The Mesa settings the golden run recorded, before any context (as `sph2d check --adopt-env`).
void adoptGoldenEnvironment() {
  const nlohmann::json m = manifest();
  for (const auto& e : m["environment"]) {
    const std::string name = e["name"], value = e["value"];
    if (!value.empty() && !std::getenv(name.c_str())) setenv(name.c_str(), value.c_str(), 0);
  }
}

/// The library the process's glGetString symbol (the one sph2d::render's objects would bind
/// to as well) comes from.
std::string glGetStringLibrary() {
  Dl_info info{};
  REQUIRE(dladdr(reinterpret_cast<void*>(&glGetString), &info) != 0);
  return info.dli_fname ? info.dli_fname : "?";
}

/// Share of water pixels: blue clearly above red (the liquid mode's colours).
double waterShare(const std::vector<unsigned char>& p) {
  std::size_t n = 0;
  for (std::size_t k = 0; k < p.size(); k += 4) n += p[k + 2] > p[k] + 60;
  return double(n) / double(p.size() / 4);
}

}  // namespace

TEST_CASE("the link is the one this build is named for") {
  const std::string lib = glGetStringLibrary();
  MESSAGE("glGetString binds to " << lib);
  if (std::string(SPH2D_GL_LINK) == "glvnd_first")
    CHECK(lib.find("libOpenGL") != std::string::npos);
  else
    CHECK(lib.find("libOSMesa") != std::string::npos);
}

TEST_CASE("Renderer(def).render() in its own OSMesa context: the golden frames of the plain link, hash for hash") {
  adoptGoldenEnvironment();
  const nlohmann::json m = manifest();
  const SceneDef scene = loadScene(kGolden + "/scene.json");
  World world(scene, WorldOptions{m["run"]["threads"].get<int>()});
  Renderer renderer(scene.render);
  MESSAGE("renderer: " << renderer.rendererString());
  int checked = 0;
  for (const auto& f : m["frames"]) {
    const std::uint64_t frame = f["frame"];
    while (world.frame() < frame) world.stepFrame();
    REQUIRE(hex64(world.stateHash()) == f["state_hash"].get<std::string>());
    const Frame& image = renderer.render(world);
    REQUIRE(image.rgba.size() == std::size_t(scene.render.width) * scene.render.height * 4);
    // Not empty: the dam's water fills a good part of the frame, and not every pixel is alike.
    CHECK(waterShare(image.rgba) > 0.1);
    bool varied = false;
    for (std::size_t k = 4; k < image.rgba.size() && !varied; ++k) varied = image.rgba[k] != image.rgba[k % 4];
    CHECK(varied);
    CHECK_MESSAGE(hex64(xxh64(image.rgba.data(), image.rgba.size())) == f["rgba_xxh64"].get<std::string>(),
                  "frame " << frame << " differs from the golden frame of the plain link");
    ++checked;
  }
  CHECK(checked == 3);
}

TEST_CASE("Renderer(currentGlContext) in a game's own OSMesa context: the frame of the OSMesa path") {
  adoptGoldenEnvironment();
  const SceneDef scene = loadScene(kGolden + "/scene.json");
  World world(scene, WorldOptions{1});
  for (int f = 0; f < 4; ++f) world.stepFrame();
  Renderer own(scene.render);
  const std::vector<unsigned char> reference = own.render(world).rgba;
  // The game's context: OSMesa, 3.3 core, with a buffer of its own, made current (the game's
  // own gl* calls would need OSMesaGetProcAddress too in the glvnd_first link; it makes none).
  const int attribs[] = {OSMESA_FORMAT,
                         OSMESA_RGBA,
                         OSMESA_PROFILE,
                         OSMESA_CORE_PROFILE,
                         OSMESA_CONTEXT_MAJOR_VERSION,
                         3,
                         OSMESA_CONTEXT_MINOR_VERSION,
                         3,
                         0};
  OSMesaContext game = OSMesaCreateContextAttribs(attribs, nullptr);
  REQUIRE(game != nullptr);
  std::vector<unsigned char> buffer(std::size_t(scene.render.width) * scene.render.height * 4);
  REQUIRE(OSMesaMakeCurrent(game, buffer.data(), GL_UNSIGNED_BYTE, scene.render.width, scene.render.height));
  {
    Renderer inGame(currentGlContext, scene.render);
    CHECK(inGame.usesCurrentContext());
    CHECK(inGame.render(world).rgba == reference);  // the screenshot of the game's context
  }
  OSMesaMakeCurrent(nullptr, nullptr, GL_UNSIGNED_BYTE, 0, 0);
  OSMesaDestroyContext(game);
}

TEST_CASE("Renderer(currentGlContext) with no context current: the message names that path and what to do") {
  OSMesaMakeCurrent(nullptr, nullptr, GL_UNSIGNED_BYTE, 0, 0);
  const SceneDef scene = loadScene(kGolden + "/scene.json");
  std::string error;
  try {
    Renderer r(currentGlContext, scene.render);
  } catch (const std::runtime_error& e) {
    error = e.what();
  }
  MESSAGE(error);
  CHECK(error.find("no OpenGL context is current") != std::string::npos);
  CHECK(error.find("currentGlContext") != std::string::npos);           // the path in use
  CHECK(error.find("make the game's") != std::string::npos);            // what to do
  CHECK(error.find("OSMesa context of its own") != std::string::npos);  // and the other path needs none
}
