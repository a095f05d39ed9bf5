// sph2d/events.hpp — input events (docs/SCENES.md, "events"): what a player, a
// script or a scene's timeline does to a World between frames, and how one is
// read from JSON and written back. scene.hpp includes this header (a SceneDef
// holds its timeline); parseEvent needs a SceneDef and throws SceneError, both
// from sph2d/scene.hpp.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "sph2d/fluid_block.hpp"
#include "sph2d/math.hpp"

namespace sph2d {

struct SceneDef;

/// One input event (docs/SCENES.md, "events"): what a player, a script or the
/// scene's timeline does to a World between frames. The same validation reads
/// the scene's `events` key and every line of an events file or of live input
/// (parseEvent), so a mistake gets the same message wherever it is written.
struct EventDef {
  /// What the event does.
  enum class Type {
    Force,    ///< push/pull at `point` (World::setUserForces): slot `id`, `radius`, `strength`
    Release,  ///< removes user force `id` (all forces when id < 0)
    Block,    ///< adds a block of fluid `block` (World::addBlock)
    Drop,     ///< adds a disc of fluid at `point` of `radius` with `velocity` (World::addDrop)
    Emitter,  ///< emitter `index`: `enabled`, and/or moves it to `point` / `direction`
    Gravity,  ///< sets gravity to `gravity` (given as [x, y] or as a tilt of the scene's gravity)
    Effect,   ///< switches effect `effect` on or off (`enabled`)
    Pause,    ///< stops stepping until a resume event (or `seconds` of wall time when > 0)
    Resume,   ///< ends a pause
  };
  Type type = Type::Pause;
  double t = -1;              ///< stamp: simulated time [s] (-1: none)
  std::int64_t frame = -1;    ///< stamp: frame number (-1: none); a frame stamp wins over t
  std::string source;         ///< where a recorded event came from: "scene", "file", "live" ("" when not recorded)
  int id = 0;                 ///< Force/Release: user force slot (Release: -1 = every slot)
  Vec2d point{0, 0};          ///< Force: centre; Drop: centre; Emitter: new position [m]
  double radius = 0.5;        ///< Force: reach; Drop: disc radius [m]
  double strength = 0;        ///< Force: acceleration at the centre [m/s²] (> 0 pulls, < 0 pushes)
  Vec2d velocity{0, 0};       ///< Drop: initial velocity [m/s]
  std::string material;       ///< Block, Drop: the material's name ("": the first)
  FluidBlockDef block;        ///< Block: the rectangle
  std::size_t index = 0;      ///< Emitter: scene order
  bool hasEnabled = false;    ///< Emitter: whether `enabled` was given
  bool enabled = true;        ///< Emitter, Effect: on or off
  bool hasPoint = false;      ///< Emitter: whether a new position was given
  bool hasDirection = false;  ///< Emitter: whether a new direction was given
  Vec2d direction{0, -1};     ///< Emitter: new direction (as written; World::moveEmitter normalises it)
  Vec2d gravity{0, -9.81};    ///< Gravity: the new gravity [m/s²] (a tilt is resolved when read)
  std::string effect;         ///< Effect: its name
  double seconds = 0;         ///< Pause: wall seconds it lasts (0: until a resume event)
};

/// How parseEvent treats an event's stamp ("t" or "frame").
enum class EventStamp {
  Required,  ///< the scene's timeline and events files: one of "t" or "frame" must be given
  Optional,  ///< live input: without a stamp the event applies at the next frame
};

/// Parses and validates one event object (one line of an events file or of live
/// input; the scene's `events` entries go through the same checks). `file` and
/// `line` name it in errors (columns count within `text`). `scene` provides the
/// frame rate, the emitters, the effects and the gravity a tilt rotates. A
/// "source" key is accepted (records write it). Throws SceneError.
EventDef parseEvent(const std::string& text, const std::string& file, int line, const SceneDef& scene,
                    EventStamp stamp = EventStamp::Required);

/// The frame at whose boundary an event applies: its `frame` stamp, else the
/// first frame at or after its time, ceil(t·fps − 1e-9); -1 when unstamped.
std::int64_t eventFrame(const EventDef& event, double fps);

/// The most particles event `e` can add to a World of lattice spacing `spacing` (before any is
/// allocated, in O(1)): a block's lattice points (exact for its rectangle, before solids and the
/// budget skip some), a drop's points within its radius (exact up to 4096 rows, beyond them
/// π(r/dx + 1)², an upper bound); 0 for the events that add no particles (an emitter event
/// switches or moves an emitter of the scene, whose rate and budget are the scene's). As a
/// double: a hostile event's count does not overflow.
double eventParticles(const EventDef& e, double spacing);

/// The event's name in files: "force", "release", "block", "drop", "emitter",
/// "gravity", "effect", "pause" or "resume".
const char* eventTypeName(EventDef::Type type);

/// One line of JSON (no newline) that parseEvent reads back into the same event,
/// bit for bit: the type, the stamp (frame when set, else t), the source when
/// set, and every field of the type (a tilt is written as the gravity it gave).
std::string eventToJson(const EventDef& event);

/// Names of the effects a World of `scene` can switch (World::effects() plus
/// "user_force", which exists once a force is set): what an `effect` event may name.
std::vector<std::string> switchableEffects(const SceneDef& scene);

}  // namespace sph2d
