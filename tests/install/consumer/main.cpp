// A game outside the sph2d tree, built against the installed package as docs/EMBEDDING.md says:
// a level made in code (a tank of water, a crate of density 500 that floats, a kinematic paddle
// that pushes the water), particles coloured from the game's own data (a team per particle),
// a save and a reload of the World half way, and the frames drawn into the game's OWN OpenGL
// context: an OSMesa 3.3 core context the game makes itself (a window library's context in a
// real game), its own framebuffer, split screen: the liquid view on the left, the team colours
// on the right (sph2d::Renderer(sph2d::currentGlContext, ...).draw()).
// Prints what it measured; exits 0 only when the crate floats, the paddle stirs the water, the reload steps on to the
// uninterrupted World's state hash, both views show what they should and the game's GL state
// is as it left it. Writes the game's framebuffer to OUT.png.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/osmesa.h>
#include <box2d/box2d.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <vector>

#include "sph2d/hash.hpp"
#include "sph2d/render/png_io.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/world.hpp"

namespace {

constexpr int kViewW = 200, kViewH = 120;  // each half of the split screen
constexpr int kFrames = 60, kSaveAt = 30;  // 1 s at 60 fps; saved and reloaded after 0.5 s

sph2d::ShapeDef box(sph2d::Vec2d center, sph2d::Vec2d half, double density = 1000) {
  sph2d::ShapeDef s;
  s.center = center;
  s.halfSize = half;
  s.density = density;
  return s;
}

/// The level: a tank 2 m wide with 0.5 m of water, a crate dropped onto it, a paddle in it.
sph2d::SceneDef level() {
  sph2d::SceneDef scene;
  scene.name = "consumer";
  scene.solver = sph2d::solverDefaults("game");
  scene.solver.spacing = 0.04;
  sph2d::BodyDef tank;
  tank.fixtures = {box({1.0, -0.1}, {1.2, 0.1}), box({-0.1, 0.6}, {0.1, 0.7}), box({2.1, 0.6}, {0.1, 0.7})};
  scene.bodies.push_back(tank);
  sph2d::BodyDef crate;  // 0.4 m x 0.16 m of density 500: floats half under (draught 0.08 m)
  crate.type = sph2d::BodyDef::Type::Dynamic;
  crate.position = sph2d::Vec2d(1.4, 0.62);
  crate.fixtures = {box({0, 0}, {0.2, 0.08}, 500)};
  scene.bodies.push_back(crate);
  sph2d::BodyDef paddle;  // a blade turning about its middle, in the water on the left
  paddle.type = sph2d::BodyDef::Type::Kinematic;
  paddle.position = sph2d::Vec2d(0.45, 0.25);
  paddle.angularVelocity = 2.5;
  paddle.fixtures = {box({0, 0}, {0.18, 0.03})};
  scene.bodies.push_back(paddle);
  scene.blocks.push_back({sph2d::Vec2d(0, 0), sph2d::Vec2d(2.0, 0.5), sph2d::Vec2d(0, 0)});
  scene.render.width = kViewW;
  scene.render.height = kViewH;
  scene.render.camera.automatic = false;
  scene.render.camera.min = sph2d::Vec2d(-0.25, -0.25);
  scene.render.camera.max = sph2d::Vec2d(2.25, 1.25);
  return scene;
}

const b2Body* crateOf(const sph2d::World& world) {
  for (const b2Body* b = world.box2d().GetBodyList(); b; b = b->GetNext())
    if (b->GetType() == b2_dynamicBody) return b;
  return nullptr;
}

/// The game's own data: a team per particle id, and the team's colour.
struct Teams {
  std::map<std::uint32_t, int> teamOf;
  static constexpr std::uint32_t kColor[2] = {0xE02020u, 0xF0C020u};  // red, yellow
  void assign(sph2d::World& world) {
    for (std::size_t i = 0; i < world.particleCount(); ++i) {
      const std::uint32_t id = world.particles().id[i];
      teamOf[id] = world.worldPosition(i).x() < 1.0 ? 0 : 1;
      world.setParticleUserData(id, std::uint32_t(teamOf[id]));
      world.setParticleColor(id, kColor[teamOf[id]]);
    }
  }
};

/// Pixels of `rgba` (w x h) within 40 levels of colour `rgb`.
std::size_t near(const std::vector<unsigned char>& rgba, std::uint32_t rgb) {
  const int r = int(rgb >> 16), g = int((rgb >> 8) & 255u), b = int(rgb & 255u);
  std::size_t n = 0;
  for (std::size_t p = 0; p < rgba.size(); p += 4)
    n += std::abs(rgba[p] - r) < 40 && std::abs(rgba[p + 1] - g) < 40 && std::abs(rgba[p + 2] - b) < 40;
  return n;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer OUT.png\n");
    return 2;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const sph2d::SceneDef scene = level();

  // Simulate: one World straight through, one saved half way and reloaded into a fresh World.
  sph2d::World straight(scene, sph2d::WorldOptions{1});
  Teams teams;
  teams.assign(straight);
  for (int f = 0; f < kSaveAt; ++f) straight.stepFrame();
  std::ostringstream saved;
  straight.save(saved);
  sph2d::World reloaded(scene, sph2d::WorldOptions{1});
  std::istringstream in(saved.str());
  reloaded.load(in);
  for (int f = kSaveAt; f < kFrames; ++f) {
    straight.stepFrame();
    reloaded.stepFrame();
  }
  const bool sameState = reloaded.stateHash() == straight.stateHash();
  const b2Body* crate = crateOf(reloaded);
  const double crateY = crate ? double(crate->GetPosition().y) : -1;
  const bool afloat = crateY > 0.3;  // resting on the floor it would be at 0.08 m
  // The paddle (turning about (0.45, 0.25) m, its tips at 0.45 m/s) stirs the water around it:
  // 0.21 m/s on average within 0.2 m of its axis after 1 s, where the crate's waves alone (the
  // paddle held still) leave 0.09 m/s.
  double stirred = 0;
  const std::vector<std::size_t> around = reloaded.slotsInRadius(b2Vec2(0.45f, 0.25f), 0.2);
  for (const std::size_t i : around) stirred += double(reloaded.particles().v[i].norm());
  stirred = around.empty() ? 0 : stirred / double(around.size());
  const bool pushed = around.size() > 50 && stirred > 0.15;
  std::size_t dyed = 0;  // the colours came back with the save
  for (std::size_t i = 0; i < reloaded.particleCount(); ++i) {
    const std::uint32_t id = reloaded.particles().id[i];
    dyed += reloaded.particleColor(id) == Teams::kColor[reloaded.particleUserData(id)] &&
            int(reloaded.particleUserData(id)) == teams.teamOf[id];
  }

  // The game's own OpenGL context, framebuffer and state.
  std::vector<unsigned char> window(64 * 64 * 4);
  const int attribs[] = {OSMESA_FORMAT,
                         OSMESA_RGBA,
                         OSMESA_PROFILE,
                         OSMESA_CORE_PROFILE,
                         OSMESA_CONTEXT_MAJOR_VERSION,
                         3,
                         OSMESA_CONTEXT_MINOR_VERSION,
                         3,
                         0};
  OSMesaContext ctx = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!ctx || !OSMesaMakeCurrent(ctx, window.data(), GL_UNSIGNED_BYTE, 64, 64)) {
    std::fprintf(stderr, "consumer: no OpenGL 3.3 core context\n");
    return 1;
  }
  const int FW = 2 * kViewW, FH = kViewH;
  GLuint tex = 0, fbo = 0;
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, FW, FH, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
  glClearColor(0.05f, 0.05f, 0.05f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);  // the game's own frame, before the water goes in
  glEnable(GL_BLEND);            // the game's state, left as the game draws its sprites
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glViewport(0, 0, FW, FH);

  // The renderers live in the game's context and go before it (their destructors delete their
  // GL objects there).
  std::string renderer;
  bool stateKept = false;
  std::vector<unsigned char> image(std::size_t(FW) * FH * 4), left, right;
  {
    sph2d::Renderer liquid(sph2d::currentGlContext, scene.render);
    sph2d::RenderOptions byTeam;
    byTeam.mode = "particles";
    byTeam.colorBy = sph2d::ColorField::Color;
    sph2d::Renderer particles(sph2d::currentGlContext, scene.render, byTeam);
    liquid.draw(reloaded, sph2d::GlTarget{fbo, std::array<int, 4>{0, 0, kViewW, kViewH}});
    particles.draw(reloaded, sph2d::GlTarget{fbo, std::array<int, 4>{kViewW, 0, kViewW, kViewH}});

    GLint boundFbo = 0, viewport[4] = {0, 0, 0, 0}, src = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &boundFbo);
    glGetIntegerv(GL_VIEWPORT, viewport);
    glGetIntegerv(GL_BLEND_SRC_RGB, &src);
    stateKept = GLuint(boundFbo) == fbo && viewport[2] == FW && viewport[3] == FH && glIsEnabled(GL_BLEND) &&
                src == GL_SRC_ALPHA && glGetError() == GL_NO_ERROR;

    // The game reads its own framebuffer back (rows bottom-up) to check and save it.
    std::vector<unsigned char> gl(image.size());
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, FW, FH, GL_RGBA, GL_UNSIGNED_BYTE, gl.data());
    for (int y = 0; y < FH; ++y)
      for (int x = 0; x < FW; ++x) {
        const unsigned char* p = &gl[(std::size_t(FH - 1 - y) * FW + std::size_t(x)) * 4];
        std::copy(p, p + 4, &image[(std::size_t(y) * FW + std::size_t(x)) * 4]);
        (x < kViewW ? left : right).insert((x < kViewW ? left : right).end(), p, p + 4);
      }
    renderer = liquid.rendererString();
  }
  OSMesaDestroyContext(ctx);
  std::size_t water = 0;
  for (std::size_t p = 0; p < left.size(); p += 4) water += left[p + 2] > left[p] + 60;
  const std::size_t red = near(right, Teams::kColor[0]), yellow = near(right, Teams::kColor[1]);
  sph2d::writePngAtomic(argv[1], FW, FH, image.data(), 1);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const double waterShare = double(water) / double(kViewW * kViewH);
  std::printf("consumer: %zu particles, state %s, water %.1f %% of the liquid view (%dx%d)\n", reloaded.particleCount(),
              sph2d::hex64(reloaded.stateHash()).c_str(), 100.0 * waterShare, kViewW, kViewH);
  std::printf("consumer: crate at y = %.3f m after %d frames: %s\n", crateY, kFrames, afloat ? "afloat" : "NOT afloat");
  std::printf("consumer: the paddle stirs the %zu particles within 0.2 m of its axis at a mean %.3f m/s: %s\n",
              around.size(), stirred, pushed ? "pushed" : "NOT pushed");
  std::printf(
      "consumer: saved at frame %d and reloaded: state %s the uninterrupted World's; %zu of %zu particles keep their team colour\n",
      kSaveAt, sameState ? "equal to" : "DIFFERENT from", dyed, reloaded.particleCount());
  std::printf("consumer: drawn into the game's own context (%s): team pixels red %zu, yellow %zu; game state %s\n",
              renderer.c_str(), red, yellow, stateKept ? "kept" : "CHANGED");
  std::printf("consumer: %.2f s\n", seconds);
  const bool ok = afloat && pushed && sameState && dyed == reloaded.particleCount() && waterShare > 0.1 && red > 100 &&
                  yellow > 100 && stateKept;
  return ok ? 0 : 1;
}
