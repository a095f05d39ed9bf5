// A program outside the sph2d tree, built against the installed package: a scene
// made in code, a World stepped a few frames, a frame rendered and saved.
// Prints the particle count, the state hash and the share of water pixels.
#include <cstdio>

#include "sph2d/hash.hpp"
#include "sph2d/render/png_io.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/world.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer OUT.png\n");
    return 2;
  }
  sph2d::SceneDef scene;
  scene.solver.spacing = 0.05;
  sph2d::BodyDef tank;
  for (const auto& box : {sph2d::Vec2d(1, -0.1), sph2d::Vec2d(-0.1, 0.6), sph2d::Vec2d(2.1, 0.6)}) {
    sph2d::ShapeDef s;
    s.center = box;
    s.halfSize = box.y() < 0 ? sph2d::Vec2d(1.2, 0.1) : sph2d::Vec2d(0.1, 0.8);
    tank.fixtures.push_back(s);
  }
  scene.bodies.push_back(tank);
  scene.blocks.push_back({sph2d::Vec2d(0, 0), sph2d::Vec2d(0.6, 0.8), sph2d::Vec2d(0, 0)});
  scene.render.width = 128;
  scene.render.height = 96;

  sph2d::World world(scene, sph2d::WorldOptions{1});
  for (int f = 0; f < 5; ++f) world.stepFrame();
  sph2d::Renderer renderer(scene.render);
  const sph2d::Frame& frame = renderer.render(world);
  std::size_t water = 0;
  for (std::size_t p = 0; p < frame.rgba.size(); p += 4)
    if (frame.rgba[p + 2] > frame.rgba[p] + 60) ++water;
  sph2d::writePngAtomic(argv[1], frame.width, frame.height, frame.rgba.data(), 1);
  std::printf("consumer: %zu particles, state %s, water %.1f %% of %dx%d pixels\n", world.particleCount(),
              sph2d::hex64(world.stateHash()).c_str(), 100.0 * double(water) / double(frame.width * frame.height),
              frame.width, frame.height);
  return water > 0 ? 0 : 1;
}
