// sph2d/timeline.hpp — a scene's timeline of input events, played onto a World.
//
//   scene events ─┐
//   game's events ┴─> EventSchedule (by frame, stable) ─> EventApplier ─> World
//
// Every event takes effect at a frame boundary, before the World steps past it, so a
// run is a function of the scene and the list (frame, event) alone: the same list gives
// the same states bit for bit (what `sph2d run --record` / `--input` rely on). A game
// that wants a scene's timeline played calls TimelinePlayer::stepFrame instead of
// World::stepFrame; the app's loop uses the schedule and the applier directly, adding
// events files and live input (app/loop/input_events.hpp).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace sph2d {

/// An event with the frame it applies at and where it came from.
struct TimedEvent {
  std::int64_t frame = 0;  ///< the frame boundary it applies at
  EventDef event;          ///< its fields (event.source says "scene", "file" or "live")
  std::string where;       ///< "FILE:LINE" or "scene events[k]", for messages
};

/// Events known in advance (the scene's timeline, a game's, events files), in frame
/// order; events of one frame keep the order they were added in.
class EventSchedule {
 public:
  /// Adds the scene's `events` (source "scene").
  void addScene(const SceneDef& scene);
  /// Adds one event (e.g. a live event stamped for a later frame).
  void add(TimedEvent e) { insert(std::move(e)); }
  /// Removes and returns the events due at or before `frame`, in order.
  std::vector<TimedEvent> take(std::int64_t frame);
  /// Events not applied yet.
  std::size_t pending() const { return events_.size(); }

 private:
  void insert(TimedEvent e);
  std::vector<TimedEvent> events_;  ///< sorted by frame (stable)
};

/// Applies events to a World: keeps the user forces by slot and the pause state.
class EventApplier {
 public:
  /// Applies `e` now. Returns "" on success, else why it could not be applied
  /// (e.g. switching user_force before any force exists); the World is then unchanged.
  /// sph2d::Interrupted (the World's stop flag) propagates: nothing was added.
  std::string apply(World& world, const EventDef& e);
  /// True between a pause and a resume.
  bool paused() const { return paused_; }
  /// Wall seconds the current pause lasts (0: until a resume event).
  double pauseSeconds() const { return pauseSeconds_; }
  /// Ends a pause without an event (its time ran out, or nothing can resume it).
  void endPause() { paused_ = false; }

 private:
  std::map<int, UserForce> forces_;
  bool paused_ = false;
  double pauseSeconds_ = 0;
};

/// A short human description of an event, e.g. "gravity (4.905, -8.496) m/s²".
std::string describeEvent(const EventDef& e);

/// A scene's timeline played onto a World by a game: the scene's events (and any the game
/// adds) applied at their frames, then the frame stepped.
class TimelinePlayer {
 public:
  /// The timeline of `scene` (its `events`, in frame order).
  explicit TimelinePlayer(const SceneDef& scene);
  /// Adds an event at `frame` (after the events already at that frame).
  void add(std::int64_t frame, const EventDef& e, const std::string& where = "game");
  /// Applies the events due at `world`'s next frame boundary (world.frame()), then steps
  /// the frame unless a pause event holds it. A pause holds the frame, so events of later
  /// frames wait too: it ends with a resume event at the same frame, or when the game calls
  /// resume() (a pause's `seconds` are wall time, pauseSeconds(): the game's clock to keep).
  /// Returns one message per event that could not be applied ("WHERE: EVENT not applied:
  /// WHY"); the others apply.
  std::vector<std::string> stepFrame(World& world);
  /// True between a pause and a resume event.
  bool paused() const { return applier_.paused(); }
  /// Wall seconds the current pause asked for (0: until a resume).
  double pauseSeconds() const { return applier_.pauseSeconds(); }
  /// Ends a pause (the game's own resume).
  void resume() { applier_.endPause(); }
  /// Events not applied yet.
  std::size_t pending() const { return schedule_.pending(); }

 private:
  EventSchedule schedule_;
  EventApplier applier_;
};

}  // namespace sph2d
