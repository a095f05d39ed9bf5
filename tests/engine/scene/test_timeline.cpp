// The library's timeline player (engine/src/scene/timeline.cpp, sph2d/timeline.hpp): a scene's
// events applied at their frames, the same states as the same calls made by hand,
// failures reported without stopping, and the pause state.
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "sph2d/timeline.hpp"
#include "sph2d/world.hpp"
#include "support/fixture.hpp"

using namespace sph2d;

namespace {

/// A tank with a block of water and a timeline: a drop at frame 5, zero gravity at frame 10
/// (stamped by time: 10/60 s), switching user_force off at frame 12 (fails: no force yet).
SceneDef timelineScene() {
  SceneDef s = test::tank("game", 1.0, 1.0, 0.025);
  s.blocks.push_back(test::block({0, 0}, {1, 0.3}));
  EventDef drop;
  drop.type = EventDef::Type::Drop;
  drop.frame = 5;
  drop.point = Vec2d(0.5, 0.7);
  drop.radius = 0.08;
  drop.velocity = Vec2d(0, -1);
  EventDef g;
  g.type = EventDef::Type::Gravity;
  g.t = 10.0 / 60.0;
  g.gravity = Vec2d(0, 0);
  EventDef off;
  off.type = EventDef::Type::Effect;
  off.frame = 12;
  off.effect = "user_force";
  off.enabled = false;
  s.events = {drop, g, off};
  return s;
}

}  // namespace

TEST_CASE("timeline player: the scene's events apply at their frames, the same bits as the calls made by hand") {
  const SceneDef s = timelineScene();
  World played(s, WorldOptions{2});
  TimelinePlayer player(s);
  CHECK(player.pending() == 3);
  std::vector<std::string> failed;
  std::size_t before = 0, after = 0;
  for (int f = 0; f < 15; ++f) {
    if (f == 5) before = played.particleCount();
    for (const std::string& m : player.stepFrame(played)) failed.push_back(m);
    if (f == 5) after = played.particleCount();
  }
  CHECK(played.frame() == 15);
  CHECK(after > before);  // the drop arrived at frame 5
  CHECK(player.pending() == 0);
  REQUIRE(failed.size() == 1);  // switching user_force before any force exists
  MESSAGE(failed[0]);
  CHECK(failed[0].find("user_force") != std::string::npos);

  SceneDef plain = s;
  plain.events.clear();
  World byHand(plain, WorldOptions{1});
  for (int f = 0; f < 15; ++f) {
    if (f == 5) byHand.addDrop(Vec2d(0.5, 0.7), 0.08, Vec2d(0, -1));
    if (f == 10) byHand.setGravity(Vec2d(0, 0));
    byHand.stepFrame();
  }
  CHECK(played.stateHash() == byHand.stateHash());
}

TEST_CASE("timeline player: a pause event holds the frame until a resume, and a game adds its own events") {
  SceneDef s = test::tank("game", 1.0, 1.0, 0.025);
  s.blocks.push_back(test::block({0, 0}, {1, 0.3}));
  World w(s, WorldOptions{2});
  TimelinePlayer player(s);
  EventDef pause;
  pause.type = EventDef::Type::Pause;
  player.add(3, pause);
  EventDef g;
  g.type = EventDef::Type::Gravity;
  g.gravity = Vec2d(1, -9.81);
  player.add(4, g);
  for (int f = 0; f < 6; ++f) player.stepFrame(w);
  CHECK(player.paused());
  CHECK(w.frame() == 3);  // held at frame 3
  const std::uint64_t held = w.stateHash();
  player.stepFrame(w);
  CHECK(w.stateHash() == held);
  player.resume();
  for (int f = 0; f < 3; ++f) player.stepFrame(w);
  CHECK(w.frame() == 6);
  CHECK(player.pending() == 0);  // the gravity event applied after the pause
  // A pause with its resume at the same frame holds nothing; a pause's seconds are reported.
  pause.seconds = 2.5;
  player.add(7, pause);
  EventDef resume;
  resume.type = EventDef::Type::Resume;
  player.add(7, resume);
  player.add(8, pause);
  for (int f = 0; f < 3; ++f) player.stepFrame(w);
  CHECK(w.frame() == 8);  // frame 7 passed; held at 8
  CHECK(player.paused());
  CHECK(player.pauseSeconds() == 2.5);
}
