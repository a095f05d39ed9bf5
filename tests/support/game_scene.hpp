// tests/support/game_scene.hpp — the small game the renderer tests play in their own GL
// contexts (tests/app/test_render_context.cpp: OSMesa; tests/egl: EGL): one definition, so
// that both compare the same frames with the OSMesa path's.
#pragma once

#include <string>
#include <utility>

#include "sph2d/scene.hpp"

namespace sph2d::test {

/// A tank 1.2 m wide with 0.35 m of water, a crate of density 500 dropped in and a kinematic
/// paddle turning in the water, seen at w × h px in `mode` (liquid or particles).
inline SceneDef gameScene(const std::string& mode, int w, int h) {
  SceneDef s;
  s.name = "render_context";
  s.solver = solverDefaults("game");
  s.solver.spacing = 0.03;
  BodyDef tank;
  for (const auto& [c, half] :
       {std::pair{Vec2d(0.6, -0.05), Vec2d(0.75, 0.05)}, std::pair{Vec2d(-0.1, 0.4), Vec2d(0.05, 0.45)},
        std::pair{Vec2d(1.3, 0.4), Vec2d(0.05, 0.45)}}) {
    ShapeDef box;
    box.center = c;
    box.halfSize = half;
    tank.fixtures.push_back(box);
  }
  s.bodies.push_back(tank);
  BodyDef crate;
  crate.type = BodyDef::Type::Dynamic;
  crate.position = Vec2d(0.85, 0.45);
  ShapeDef crateBox;
  crateBox.halfSize = Vec2d(0.12, 0.05);
  crateBox.density = 500;
  crate.fixtures.push_back(crateBox);
  s.bodies.push_back(crate);
  BodyDef paddle;
  paddle.type = BodyDef::Type::Kinematic;
  paddle.position = Vec2d(0.3, 0.25);
  paddle.angularVelocity = 3.0;
  ShapeDef blade;
  blade.halfSize = Vec2d(0.14, 0.02);
  paddle.fixtures.push_back(blade);
  s.bodies.push_back(paddle);
  FluidBlockDef water;
  water.min = Vec2d(-0.05, 0);
  water.max = Vec2d(1.25, 0.35);
  s.blocks.push_back(water);
  s.render.mode = mode;
  s.render.width = w;
  s.render.height = h;
  s.render.camera.automatic = false;
  s.render.camera.min = Vec2d(-0.2, -0.15);
  s.render.camera.max = Vec2d(1.4, 1.05);
  return s;
}

}  // namespace sph2d::test
