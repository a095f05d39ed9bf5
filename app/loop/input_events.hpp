// app/loop/input_events.hpp — the input side of the game loop.
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
// the run. Field validation is the engine's parseEvent, shared with the scene;
// the schedule and the applier are the library's (sph2d/timeline.hpp): this file
// adds events files and live standard input.
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
#include "sph2d/timeline.hpp"
#include "sph2d/world.hpp"

namespace sph2d::cli {

// The schedule, the applier and TimedEvent are the library's (sph2d/timeline.hpp).
using sph2d::describeEvent;
using sph2d::EventApplier;
using sph2d::EventSchedule;
using sph2d::TimedEvent;

/// Reports a message the user should see (a skipped line, a failed event).
using WarnFn = std::function<void(const std::string&)>;

/// Reads an events file into `schedule`: one JSON object per line, each with "frame" or "t".
/// Blank lines are skipped; a malformed line is reported through `warn` with its line number
/// and skipped; lines a record took from a scene's timeline (source "scene") are skipped and
/// counted in `skippedScene`, since the scene applies them itself. Returns the number of events
/// read. Throws std::runtime_error when the file cannot be read.
std::size_t addEventsFile(EventSchedule& schedule, const std::string& path, const SceneDef& scene, const WarnFn& warn,
                          std::size_t& skippedScene);

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

}  // namespace sph2d::cli
