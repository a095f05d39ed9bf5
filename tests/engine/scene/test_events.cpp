// Input events: the scene's timeline and one-line events share one validation
// (parseEvent), write back bit for bit (eventToJson), map to frames, and the
// World calls they need (addDrop, moveEmitter) do what they say.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "sph2d/events.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"
#include "test_util.hpp"

using namespace sph2d;

namespace {

const char* kTank = R"({
  "name": "tank", "fps": 60,
  "solver": { "type": "muller2003", "spacing": 0.05 },
  "boundaries": [ { "fixtures": [ { "shape": "box", "center": [1, -0.1], "half_size": [1.2, 0.1] } ] } ],
  "fluid": [ { "min": [0, 0], "max": [0.5, 0.5] } ],
  "effects": { "xsph": { "c": 0.1 },
               "emitters": [ { "position": [1, 1], "direction": [0, -1], "rate": 90, "speed": 4.5 } ] })";

SceneDef tank(const std::string& events = "") {
  return parseScene(std::string(kTank) + (events.empty() ? "" : ",\n  \"events\": " + events) + "\n}\n", "tank.json");
}

SceneError eventError(const std::string& line, int lineNo = 7, EventStamp stamp = EventStamp::Required) {
  try {
    parseEvent(line, "events.jsonl", lineNo, tank(), stamp);
  } catch (const SceneError& e) {
    return e;
  }
  FAIL("no SceneError for: " << line);
  return SceneError("", 0, 0, "", "");
}

SceneError sceneError(const std::string& events) {
  try {
    tank(events);
  } catch (const SceneError& e) {
    return e;
  }
  FAIL("no SceneError for: " << events);
  return SceneError("", 0, 0, "", "");
}

}  // namespace

TEST_CASE("the scene's events key reads every event type with its fields") {
  const SceneDef s = tank(R"([
    { "t": 0.5, "type": "force", "point": [1, 0.2], "radius": 0.3, "strength": -40, "id": 2 },
    { "t": 0.75, "type": "release" },
    { "frame": 3, "type": "block", "min": [1, 1], "max": [1.2, 1.3], "velocity": [0, -1] },
    { "t": 1, "type": "drop", "center": [1.5, 1], "radius": 0.1 },
    { "t": 1, "type": "emitter", "index": 0, "enabled": false },
    { "t": 1.5, "type": "gravity", "tilt": 0.5235987755982988 },
    { "t": 2, "type": "effect", "name": "xsph", "enabled": false },
    { "t": 2, "type": "pause", "seconds": 0.5 },
    { "t": 2, "type": "resume" } ])");
  REQUIRE(s.events.size() == 9);
  using T = EventDef::Type;
  CHECK(s.events[0].type == T::Force);
  CHECK(s.events[0].t == 0.5);
  CHECK(s.events[0].id == 2);
  CHECK(s.events[0].strength == -40);
  CHECK(s.events[0].radius == 0.3);
  CHECK(s.events[1].type == T::Release);
  CHECK(s.events[1].id == -1);  // every force
  CHECK(s.events[2].frame == 3);
  CHECK(s.events[2].block.max.y() == 1.3);
  CHECK(s.events[2].block.velocity.y() == -1);
  CHECK(s.events[3].type == T::Drop);
  CHECK(s.events[3].radius == 0.1);
  CHECK(s.events[4].hasEnabled);
  CHECK_FALSE(s.events[4].enabled);
  CHECK_FALSE(s.events[4].hasPoint);
  // A tilt of 30° rotates the scene's gravity (0, -9.81) counter-clockwise: (9.81 sin 30°, -9.81 cos 30°).
  CHECK(s.events[5].gravity.x() == doctest::Approx(4.905).epsilon(1e-12));
  CHECK(s.events[5].gravity.y() == doctest::Approx(-8.4957).epsilon(1e-4));
  CHECK(s.events[6].effect == "xsph");
  CHECK(s.events[7].seconds == 0.5);
  CHECK(s.events[8].type == T::Resume);
}

TEST_CASE("a bad timeline event names the file, line, column and key") {
  SceneError e = sceneError("[\n  { \"t\": 1, \"type\": \"jump\" } ]");
  CHECK(e.key == "events[0].type");
  CHECK(e.line == 9);  // the line of the event in tank.json
  CHECK(e.message ==
        "'jump' is not allowed; allowed values: force, release, block, drop, emitter, gravity, effect, pause, resume");

  e = sceneError("[ { \"type\": \"resume\" } ]");
  CHECK(e.key == "events[0].t");
  CHECK(e.message.find("every event needs \"t\" (seconds) or \"frame\"") != std::string::npos);

  e = sceneError("[ { \"t\": 1, \"type\": \"force\", \"point\": [0, 0], \"strenght\": 3 } ]");
  CHECK(e.key == "events[0].strenght");
  CHECK(e.message ==
        "unknown key 'strenght' (did you mean 'strength'?); allowed keys: type, t, frame, id, point, radius, strength");

  // "source" belongs to recorded lines, not to a scene's timeline.
  e = sceneError("[ { \"t\": 1, \"type\": \"resume\", \"source\": \"live\" } ]");
  CHECK(e.key == "events[0].source");
}

TEST_CASE("one event line is checked exactly like a timeline entry, with the file's line number") {
  SceneError e = eventError(R"({"t": 1, "type": "effect", "name": "surface_tension", "enabled": true})", 7);
  CHECK(e.file == "events.jsonl");
  CHECK(e.line == 7);
  CHECK(e.column == 28);  // the key "name"
  CHECK(e.key == "name");
  CHECK(e.message == "'surface_tension' is not allowed; allowed values: viscosity, xsph, user_force");
  CHECK(std::string(e.what()) ==
        "events.jsonl:7:28: key 'name': 'surface_tension' is not allowed; allowed values: viscosity, xsph, user_force");

  e = eventError(R"({"frame": 2, "type": "emitter", "index": 1, "enabled": true})", 3);
  CHECK(e.line == 3);
  CHECK(e.key == "index");
  CHECK(e.message == "emitter 1 does not exist; the scene has 1 (0 to 0)");

  e = eventError(R"({"frame": 2, "type": "drop", "center": [1, 1]})", 4);
  CHECK(e.key == "radius");
  CHECK(e.message == "missing; expected a number > 0 (metres)");

  e = eventError(R"({"t": 1, "frame": 60, "type": "resume"})");
  CHECK(e.message == "give either \"t\" or \"frame\", not both");

  e = eventError(R"({"t": 1, "type": "gravity", "gravity": [0, -1], "tilt": 0.1})");
  CHECK(e.key == "gravity");

  e = eventError("{\"t\": 1, \"type\": ", 12);
  CHECK(e.line == 12);
  CHECK(e.message.rfind("invalid JSON", 0) == 0);

  // Live input may leave the stamp out; files may not.
  CHECK(parseEvent(R"({"type": "pause"})", "-", 1, tank(), EventStamp::Optional).frame == -1);
  e = eventError(R"({"type": "pause"})", 5, EventStamp::Required);
  CHECK(e.key == "t");
}

TEST_CASE("eventToJson writes what parseEvent reads back bit for bit") {
  const SceneDef s = tank(R"([
    { "t": 0.1, "type": "force", "point": [0.1, 0.7], "radius": 0.3, "strength": 12.345678901234567 },
    { "t": 0.3, "type": "gravity", "tilt": 0.1 },
    { "t": 0.3, "type": "emitter", "index": 0, "position": [0.3, 0.9], "direction": [1, -3] },
    { "t": 0.4, "type": "drop", "center": [1.25, 0.333333333333333], "radius": 0.07, "velocity": [0.1, -2] },
    { "t": 0.4, "type": "block", "min": [1, 1], "max": [1.2, 1.3] },
    { "t": 0.5, "type": "release", "id": 0 } ])");
  for (const EventDef& e : s.events) {
    EventDef stamped = e;
    stamped.frame = eventFrame(e, s.fps);
    stamped.source = "scene";
    const std::string line = eventToJson(stamped);
    const EventDef back = parseEvent(line, "record.jsonl", 1, s);
    CHECK(eventToJson(back) == line);
    CHECK(back.frame == stamped.frame);
    CHECK(back.source == "scene");
    CHECK(back.gravity == e.gravity);
    CHECK(back.point == e.point);
    CHECK(back.direction == e.direction);
    CHECK(back.strength == e.strength);
    CHECK(back.velocity == e.velocity);
    CHECK(back.block.min == e.block.min);
  }
  CHECK(eventToJson(s.events[0]) ==
        R"({"t":0.1,"type":"force","id":0,"point":[0.1,0.7],"radius":0.3,"strength":12.345678901234567})");
}

TEST_CASE("an event applies at the first frame boundary at or after its time") {
  EventDef e;
  e.t = 0.5;
  CHECK(eventFrame(e, 60) == 30);
  e.t = 0.501;
  CHECK(eventFrame(e, 60) == 31);
  e.t = 0;
  CHECK(eventFrame(e, 60) == 0);
  e.t = 1.0 / 3.0;
  CHECK(eventFrame(e, 30) == 10);
  e.frame = 7;  // a frame stamp wins
  CHECK(eventFrame(e, 60) == 7);
  CHECK(eventFrame(EventDef{}, 60) == -1);
}

TEST_CASE("addDrop fills a disc on the lattice and skips points inside solids") {
  SceneDef s = tank();
  s.effects.emitters.clear();
  World w(s, WorldOptions{1});
  const std::size_t before = w.particleCount();
  // Radius 0.2 at spacing 0.05: the lattice points of [0.8, 1.2]² within 0.2 of (1, 1).
  const std::size_t added = w.addDrop(Vec2d(1, 1), 0.2, Vec2d(0.5, -1)).count;
  CHECK(added == 52);  // 8 × 8 lattice points, the 12 corner ones outside the disc
  CHECK(std::fabs(double(added) - M_PI * 0.04 / 0.0025) < 3);  // π r² / dx² = 50.3
  CHECK(w.particleCount() == before + added);
  for (std::size_t i = before; i < w.particleCount(); ++i) {
    CHECK((w.worldPosition(i) - Vec2d(1, 1)).norm() <= 0.2 + 1e-6);
    CHECK(w.particles().v[i].x() == 0.5f);
  }
  // Half of this drop lies inside the floor (y < 0): those points are skipped, with a warning.
  w.takeWarnings();
  const std::size_t half = w.addDrop(Vec2d(1.5, 0.0), 0.1).count;
  CHECK(half == 6);  // the 6 lattice points of the upper half of a 4 × 4 patch within the disc
  const auto warnings = w.takeWarnings();
  REQUIRE(warnings.size() == 1);
  CHECK(warnings[0].find("dropped 6 particles") == 0);
}

TEST_CASE("moveEmitter moves the nozzle from the next substep on") {
  SceneDef s = tank();
  s.blocks.clear();
  World w(s, WorldOptions{1});
  w.stepFrame();
  const std::size_t first = w.particleCount();
  CHECK(first == 2);  // 90 per second: emissions at 0 and 1/90 s within the first 1/60 s
  w.moveEmitter(0, Vec2d(0.2, 0.6), Vec2d(3, 0));
  CHECK(w.emitter(0).direction == Vec2d(1, 0));
  for (int f = 0; f < 4; ++f) w.stepFrame();
  CHECK(w.particleCount() == 8);  // ceil(90 · 5/60) = ceil(7.5)
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    if (w.particles().id[i] < first) continue;
    CHECK((w.worldPosition(i) - Vec2d(0.2, 0.6)).norm() < 0.35);  // 4.5 m/s for at most 4/60 s
    CHECK(w.particles().v[i].x() > 4.0f);
  }
  CHECK_THROWS_AS(w.moveEmitter(1, Vec2d(0, 0), Vec2d(1, 0)), std::out_of_range);
  CHECK_THROWS_AS(w.moveEmitter(0, Vec2d(0, 0), Vec2d(0, 0)), std::invalid_argument);
}
