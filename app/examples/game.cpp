// app/examples/game.cpp — a tiny game on sph2d, as a tutorial (docs/EMBEDDING.md).
//
// The game owns a Box2D world whose static platforms it builds in code; the fluid
// lives in that world (sph2d::World(scene, b2World&)). A bucket holds a pool where two
// dynamic crates float and a kinematic paddle of the game's stirs the water. The player
// holds a hose, an emitter that a scripted input sweeps along the top and switches on
// and off; its water pours down the platforms to a drain on the floor (a sink), and the
// game counts what is in the bucket and what touches the bumper (World::forEachContact).
// Toys beside the water: a heap of sand on the top platform (a granular material), a jelly
// block on the middle one (an elastic group) and a wooden ball of particles floating in the
// bucket (a rigid group) that the player throws into the air every 2 s.
// Frames are drawn with sph2d::render and written as PNG files.
//
// Usage: sph2d_example_game [OUT_DIR] [FRAMES]   (default out/example_game, 150)
#include <box2d/box2d.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "sph2d/render/frame_writer.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/world.hpp"

namespace {

// The level: one static body with a tank, three tilted platforms and a bumper.
void buildLevel(b2World& level) {
  b2BodyDef def;  // a static body at the origin
  b2Body* body = level.CreateBody(&def);
  b2PolygonShape box;
  auto add = [&](float hx, float hy, float x, float y, float angle) {
    box.SetAsBox(hx, hy, b2Vec2(x, y), angle);
    body->CreateFixture(&box, 0.0f);
  };
  add(2.2f, 0.1f, 2.0f, -0.1f, 0.0f);    // floor
  add(0.1f, 1.7f, -0.1f, 1.5f, 0.0f);    // left wall
  add(0.1f, 1.7f, 4.1f, 1.5f, 0.0f);     // right wall
  add(0.05f, 0.45f, 3.0f, 0.45f, 0.0f);  // the bucket's left side (the bucket: x 3..4, floor)
  add(1.0f, 0.04f, 1.1f, 2.2f, -0.25f);  // platforms, tilted so water runs from one to the next
  add(1.0f, 0.04f, 2.8f, 1.5f, 0.25f);
  add(0.9f, 0.04f, 1.3f, 0.8f, -0.2f);
  b2CircleShape bumper;
  bumper.m_p.Set(2.2f, 0.35f);
  bumper.m_radius = 0.15f;
  body->CreateFixture(&bumper, 0.0f);
}

// A kinematic paddle in the bucket: the game moves it, the water is pushed by it.
b2Body* buildPaddle(b2World& level) {
  b2BodyDef def;
  def.type = b2_kinematicBody;
  def.position.Set(3.5f, 0.09f);  // under the pool's surface: it stirs the water, the water the crates
  b2Body* paddle = level.CreateBody(&def);
  b2PolygonShape blade;
  blade.SetAsBox(0.04f, 0.07f);
  paddle->CreateFixture(&blade, 0.0f);
  return paddle;
}

// Two crates dropped into the bucket's pool: a light one (pine, density 400 kg/m²) and a
// heavier one (oak, 700 kg/m²): the water holds both up, the oak one deeper.
b2Body* buildCrate(b2World& level, float x, float density) {
  b2BodyDef def;
  def.type = b2_dynamicBody;
  def.position.Set(x, 0.45f);
  b2Body* crate = level.CreateBody(&def);
  b2PolygonShape box;
  box.SetAsBox(0.1f, 0.08f);
  crate->CreateFixture(&box, density);
  return crate;
}

// The player, scripted: where the hose is at time t, and whether it sprays.
struct PlayerInput {
  double x;
  bool spraying;
};
PlayerInput script(double t) { return {0.5 + 0.35 * std::sin(1.5 * t), std::fmod(t, 2.0) < 1.6}; }

}  // namespace

int main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : "out/example_game";
  const int frames = argc > 2 ? std::atoi(argv[2]) : 150;
  std::filesystem::create_directories(out);

  // 1. The game's physics world and its level.
  b2World level(b2Vec2(0.0f, -9.81f));
  buildLevel(level);
  b2Body* paddle = buildPaddle(level);
  const b2Body* pine = buildCrate(level, 3.25f, 400.0f);
  const b2Body* oak = buildCrate(level, 3.8f, 700.0f);

  // 2. The fluid's settings, in code: no boundaries (the level is the game's), a pool in
  // the bucket, one hose, and a drain on the floor left of the bucket.
  sph2d::SceneDef scene;
  scene.fps = 30;
  scene.solver.spacing = 0.03;
  // Materials: the water first (the solver's fluid), then the toys'.
  sph2d::MaterialDef water, sand, jelly, wood;
  water.name = "water";
  sand.name = "sand";
  sand.kind = sph2d::MaterialDef::Kind::granular;  // piles at its friction angle
  sand.density = 1600;
  sand.frictionAngle = 30;
  sand.color = {0.86, 0.72, 0.45};
  jelly.name = "jelly";
  jelly.density = 1050;
  jelly.color = {0.35, 0.8, 0.3};
  wood.name = "wood";
  wood.density = 600;  // floats
  wood.color = {0.6, 0.38, 0.2};
  scene.materials = {water, sand, jelly, wood};
  sph2d::FluidBlockDef heap;  // sand on the top platform, upstream of the hose's water
  heap.min = {0.2, 2.47};
  heap.max = {0.5, 2.6};
  heap.material = 1;
  scene.blocks.push_back(heap);
  sph2d::GroupDef block;  // a jelly block on the middle platform
  block.region.min = {3.0, 1.68};
  block.region.max = {3.2, 1.86};
  block.region.material = 2;
  block.stiffness = 0.4;
  scene.groups.push_back(block);
  sph2d::GroupDef ball;  // a wooden ball of particles in the bucket (a rigid group: stiffness 1)
  ball.region = sph2d::circleRegion({3.55, 0.36}, 0.08, 0.03);
  ball.region.material = 3;
  scene.groups.push_back(ball);
  sph2d::FluidBlockDef pool;
  pool.min = {3.05, 0.0};
  pool.max = {4.0, 0.25};
  scene.blocks.push_back(pool);
  scene.effects.sinks.push_back(sph2d::RegionDef{{0.0, 0.0}, {2.9, 0.06}});
  sph2d::EmitterDef hose;
  hose.position = {0.5, 2.9};
  hose.direction = {0.3, -1};
  hose.width = 0.12;
  hose.speed = 2;
  hose.rate = hose.speed * hose.width / (0.03 * 0.03);  // a stream at rest density
  scene.effects.emitters.push_back(hose);
  scene.effects.budget = 4000;  // the oldest water is recycled beyond 4000 particles
  scene.effects.budgetPolicy = sph2d::BudgetPolicy::RecycleOldest;
  scene.render.width = 320;
  scene.render.height = 240;
  scene.render.camera = {{-0.2, -0.2}, {4.2, 3.1}, false};

  try {
    // 3. The fluid in the game's world; a renderer and a background PNG writer.
    sph2d::World fluid(scene, level, sph2d::WorldOptions{2});
    sph2d::Renderer renderer(scene.render);
    sph2d::FrameWriter writer(out);
    const sph2d::Vec2d bucketLo(3.05, 0.0), bucketHi(4.0, 0.9);

    for (int f = 0; f < frames; ++f) {
      // 4. Input between frames: move the hose, switch it on or off.
      const PlayerInput in = script(fluid.time());
      fluid.moveEmitter(0, {in.x, 2.9}, {0.3, -1});
      fluid.setEmitterEnabled(0, in.spraying);
      // Every 2 s a gust pushes the water on the top platform for a moment.
      const bool gust = std::fmod(fluid.time(), 2.0) > 1.0 && std::fmod(fluid.time(), 2.0) < 1.2;
      fluid.setUserForces({sph2d::UserForce{{0.6, 2.4}, 0.5, gust ? -30.0 : 0.0}});
      // The paddle sweeps the bucket: 0.4 m/s, turning every second.
      paddle->SetLinearVelocity(b2Vec2(std::fmod(fluid.time(), 2.0) < 1.0 ? 0.4f : -0.4f, 0.0f));
      // Every 2 s the player throws the ball (group 1) up and to the left: an impulse of 3 m/s
      // times its mass, and a spin.
      sph2d::GroupState thrown;
      if (f % 60 == 45 && fluid.groupState(1, thrown))
        fluid.applyGroupImpulse(1, sph2d::Vec2d(-1.0, 3.0) * thrown.mass, 0.02 * thrown.mass);

      // 5. Step one frame: the fluid (it pushes out of the paddle where the paddle is
      // going), then the game's own b2World, which moves the paddle; draw it.
      if (f > 0) {
        fluid.stepFrame();
        level.Step(float(1.0 / scene.fps), 8, 3);
      }
      const sph2d::Frame& image = renderer.render(fluid);
      writer.push(f, image.width, image.height, image.rgba);
      for (const std::string& w : fluid.takeWarnings()) std::fprintf(stderr, "warning: %s\n", w.c_str());

      // 6. Game logic reads the fluid: water in the bucket, and a probe above it.
      if (f % 30 == 29 || f == frames - 1) {
        std::size_t inBucket = 0;  // the water in the bucket (material 0: not the ball's wood)
        for (const std::size_t slot : fluid.slotsInBox(bucketLo, bucketHi))
          inBucket += fluid.particles().material[slot] == 0;
        const sph2d::World::FieldSample probe = fluid.sampleAt({3.5, 0.05});
        std::size_t onBumper = 0;  // the bumper is the level's only circle: a "button" the water presses
        fluid.forEachContact([&](const b2Fixture& fx, const std::vector<std::uint32_t>& ids) {
          if (fx.GetShape()->GetType() == b2Shape::e_circle) onBumper = ids.size();
        });
        sph2d::GroupState jellyState, ballState;
        fluid.groupState(0, jellyState);
        fluid.groupState(1, ballState);
        std::printf(
            "t = %.1f s: %zu particles, %zu in the bucket, density at its bottom %.0f kg/m3, %zu on the bumper, "
            "crates at (%.2f, %.2f) m and (%.2f, %.2f) m, jelly at (%.2f, %.2f) m, ball at (%.2f, %.2f) m\n",
            fluid.time(), fluid.particleCount(), inBucket, probe.density, onBumper, pine->GetPosition().x,
            pine->GetPosition().y, oak->GetPosition().x, oak->GetPosition().y, jellyState.centre.x(),
            jellyState.centre.y(), ballState.centre.x(), ballState.centre.y());
      }
    }
    writer.finish();
    std::printf("%d frames in %s\n", frames, out.c_str());
  } catch (const sph2d::SimulationError& e) {  // the guard: a non-finite or runaway particle
    std::fprintf(stderr, "simulation stopped: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {  // OpenGL, output files
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
