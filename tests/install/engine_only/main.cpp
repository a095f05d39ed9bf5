// A program outside the sph2d tree that links the engine alone: a column of water made
// in code falls for a third of a second. Exits 0 when no particle was lost and the
// column's centre of mass fell (as it must under gravity), and prints what it saw.
#include <cstdio>

// Every installed header of the engine, so each is compiled here without Eigen on the path.
#include "sph2d/boundary.hpp"
#include "sph2d/events.hpp"
#include "sph2d/fluid_block.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/math.hpp"
#include "sph2d/particles.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/timeline.hpp"
#include "sph2d/world.hpp"

namespace {
double meanHeight(const sph2d::World& world) {
  double sum = 0;
  for (const auto& x : world.particles().x) sum += double(x.y());
  return sum / double(world.particleCount());
}
}  // namespace

int main() {
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

  sph2d::World world(scene, sph2d::WorldOptions{1});
  const std::size_t n0 = world.particleCount();
  const double h0 = meanHeight(world);
  for (int f = 0; f < 20; ++f) world.stepFrame();
  const double h1 = meanHeight(world);
  std::printf("engine_only: %zu particles, centre of mass %.3f m -> %.3f m, state %s\n", world.particleCount(), h0, h1,
              sph2d::hex64(world.stateHash()).c_str());
  return world.particleCount() == n0 && n0 > 0 && h1 < h0 - 0.01 ? 0 : 1;
}
