// app/events.hpp — the input side of the game loop.
//
//   scene timeline ─┐
//   --input FILE ───┼─> EventSchedule (by frame, stable) ─┐
//   --input - ──────┴─> LiveInput (reader thread) ────────┴─> EventApplier ─> World
//                                                                  └──> --record, manifest
//
// Design: every event takes effect at a frame boundary, before that frame is
// rendered and before the World steps past it, so a run is a function of the
// scene and the list (frame, event) alone: the record of a run, replayed,
// gives the same states bit for bit. Live lines are read on their own thread
// (poll + read on the file descriptor, so the loop never blocks and the thread
// stops cleanly) and are parsed on the loop's thread at the next boundary. One
// malformed line is reported with its line number and skipped; it never stops
// the run. Field validation is the engine's parseEvent, shared with the scene.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace sph2d::cli {

/// An event with the frame it applies at and where it came from.
struct TimedEvent {
  std::int64_t frame = 0;  ///< the frame boundary it applies at
  EventDef event;          ///< its fields (event.source says "scene", "file" or "live")
  std::string where;       ///< "FILE:LINE" or "scene events[k]", for messages
};

/// Reports a message the user should see (a skipped line, a failed event).
using WarnFn = std::function<void(const std::string&)>;

/// Events known in advance (the scene's timeline, events files), in frame order;
/// events of one frame keep the order they were added in.
class EventSchedule {
 public:
  /// Adds the scene's `events` (source "scene").
  void addScene(const SceneDef& scene);
  /// Reads an events file: one JSON object per line, each with "frame" or "t".
  /// Blank lines are skipped; a malformed line is reported through `warn` with
  /// its line number and skipped; lines a record took from a scene's timeline
  /// (source "scene") are skipped, since the scene applies them itself. Returns
  /// the number of events read. Throws std::runtime_error when the file cannot be read.
  std::size_t addFile(const std::string& path, const SceneDef& scene, const WarnFn& warn);
  /// Adds one event (e.g. a live event stamped for a later frame).
  void add(TimedEvent e) { insert(std::move(e)); }
  /// Removes and returns the events due at or before `frame`, in order.
  std::vector<TimedEvent> take(std::int64_t frame);
  /// Events not applied yet.
  std::size_t pending() const { return events_.size(); }
  /// Events skipped by addFile because a record took them from the scene.
  std::size_t skippedSceneEvents() const { return skippedScene_; }

 private:
  void insert(TimedEvent e);
  std::vector<TimedEvent> events_;  ///< sorted by frame (stable)
  std::size_t skippedScene_ = 0;
};

/// Lines of live input read on a separate thread; the loop takes them without waiting.
/// The longest live input line kept (1 MiB): an event is a few hundred bytes; a longer
/// line is skipped as it arrives, so a runaway writer costs neither memory nor time.
constexpr std::size_t kMaxLiveLine = std::size_t(1) << 20;

class LiveInput {
 public:
  /// Starts reading `fd` (standard input by default).
  explicit LiveInput(int fd = 0);
  /// Stops the reader thread and joins it.
  ~LiveInput();
  LiveInput(const LiveInput&) = delete;
  LiveInput& operator=(const LiveInput&) = delete;
  /// The complete lines read since the last call, with their 1-based line numbers.
  std::vector<std::pair<int, std::string>> take();
  /// Lines too long to be an event (over kMaxLiveLine bytes), skipped since the last call.
  std::vector<std::string> takeWarnings();
  /// False once the input reached its end (or failed) and every line was taken.
  bool open() const;

 private:
  void loop(int fd);
  mutable std::mutex mutex_;
  std::vector<std::pair<int, std::string>> lines_;
  std::vector<std::string> warnings_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> eof_{false};
  std::thread thread_;
};

/// Applies events to a World: keeps the user forces by slot and the pause state.
class EventApplier {
 public:
  /// Applies `e` now. Returns "" on success, else why it could not be applied
  /// (e.g. switching user_force before any force exists); the World is then unchanged.
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

}  // namespace sph2d::cli
