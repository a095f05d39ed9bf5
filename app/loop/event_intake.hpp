// app/loop/event_intake.hpp — where a run's events come from and where they are recorded.
//
//   scene timeline ─┐
//   --input FILE ───┴─> EventSchedule (by frame) ─> takeScheduled(f) ─┐
//   --input - ─────────> LiveInput ─> parsed here ─> takeLive(f) ─────┤
//   sph2d serve ───────> EventQueue (parsed by the network threads) ───┴─> GameLoop
//   applied events ────> EventRecord (--record FILE), recordLine() also for the manifest
//
// Design: the intake only collects and orders events; the game loop applies them
// at frame boundaries. Live lines are parsed on the loop's thread when the loop
// asks for them, so a bad line is reported (and skipped) between frames; a live
// event stamped for a later frame joins the schedule. Events from the network
// (sph2d serve) are parsed on the network threads, so that a bad one is answered to
// its client; they reach the loop through an EventQueue and are live events like
// standard input's lines from then on (while the loop is paused only pause and resume
// leave the queue, so it stays bounded). Live input is input from elsewhere: the particles
// its blocks and drops may add are capped (LiveGate, LiveLimits) before any is allocated.
// Events of one frame come in
// the order: the timeline's, the events files' (command-line and line order), live.
#pragma once

#include <cstdint>
#include <deque>
#include <fstream>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "loop/input_events.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/scene.hpp"

namespace sph2d::cli {

/// Caps on the particles live input (`sph2d run --input -`, `sph2d serve`'s network) may add,
/// so that no line or request takes the loop out of real time: per event, per second of wall
/// time, and the count the fluid may reach through live input. Only block and drop events add
/// particles (an emitter event switches or moves one of the scene's emitters, at the scene's
/// rate and under its budget). 0: no cap.
struct LiveLimits {
  std::size_t perEvent = 0;    ///< --max-event-particles: the most one event may add
  std::size_t perSecond = 0;   ///< --max-particles-per-second: the most added in any second
  std::size_t budget = 0;      ///< --max-particles: no live event takes the fluid past it
  std::size_t sceneCount = 0;  ///< S, the scene's own count the defaults are shares of
  /// The defaults for `scene`: with S = max(1024, peakParticles(scene)) (its blocks, emitters
  /// and timeline), S/4 an event, S/2 a second and 4·S in all, the last never above the
  /// scene's own budget (effects.budget or max_particles).
  static LiveLimits forScene(const SceneDef& scene);
};

/// Why a live event was refused: the HTTP status that says so (422: over the per-event cap,
/// 429: over the per-second cap, 409: over the budget) and a message naming the cap and the
/// option that raises it; status 0 when it is admitted.
struct LiveRefusal {
  int status = 0;
  std::string message;
  double retryAfter = 0;  ///< 429: seconds until the event would fit in the last second's window
  explicit operator bool() const { return status != 0; }
};

/// The particles live event `e` can add at the scene's spacing (sph2d::eventParticles).
double liveEventParticles(const EventDef& e, const SceneDef& scene);

/// The budget check of LiveLimits: refuses `e` when the fluid, holding `particles` (with the
/// events admitted and not applied yet), would pass `limits.budget` with it.
LiveRefusal checkLiveBudget(const EventDef& e, const SceneDef& scene, const LiveLimits& limits, double particles);

/// Admits live events under the per-event and per-second caps of LiveLimits, counting what it
/// admitted in a sliding one-second window of wall time. Thread-safe.
class LiveGate {
 public:
  LiveGate(const SceneDef& scene, LiveLimits limits) : scene_(scene), limits_(limits) {}
  /// Checks `e`, arriving at wall time `now` [s, any steady origin], against the per-event and
  /// per-second caps and, when `particles` >= 0 (the fluid's count with the events admitted
  /// and not applied yet), the budget; when admitted, counts it in the window.
  LiveRefusal admit(const EventDef& e, double now, double particles = -1);
  /// Takes back the last event admitted, `e`, when it could not be queued after all.
  void forget(const EventDef& e);
  /// The caps.
  const LiveLimits& limits() const { return limits_; }

 private:
  const SceneDef& scene_;
  LiveLimits limits_;
  std::mutex mutex_;
  std::deque<std::pair<double, double>> window_;  ///< (time, particles) admitted in the last second
  double inWindow_ = 0;                           ///< the sum of window_'s particles
};

/// Live events parsed on other threads (sph2d serve's network threads), waiting for the
/// loop's next boundary. Bounded: a client that floods it is refused, not queued.
class EventQueue {
 public:
  /// A queue that holds at most `capacity` events not taken yet, and besides them at most
  /// `capacity` pause and resume events (so that a resume gets in while others fill it).
  explicit EventQueue(std::size_t capacity = 256) : capacity_(capacity) {}
  /// Adds `e`, which may add `particles` to the fluid; false (nothing added) when `capacity`
  /// events of its kind (pause and resume, or the others) wait already.
  bool push(TimedEvent e, double particles = 0);
  /// The particles the waiting events may add (pushed and not taken).
  double particles() const;
  /// Removes and returns every event waiting, in the order pushed.
  std::vector<TimedEvent> take();
  /// Removes and returns the pause and resume events waiting (in order); the others stay,
  /// still counting against `capacity` (the loop takes only these while paused).
  std::vector<TimedEvent> takePauses();
  /// Events waiting.
  std::size_t size() const;

 private:
  mutable std::mutex mutex_;
  std::size_t capacity_;
  std::size_t pauses_ = 0;  ///< pause and resume events in events_
  double particles_ = 0;    ///< what the waiting non-pause events may add
  std::vector<TimedEvent> events_;
};

/// The events of a run: the schedule known in advance and live input (standard input
/// or an EventQueue).
class EventIntake {
 public:
  /// Events for `scene` (which must outlive the intake); `warn` reports skipped lines.
  EventIntake(const SceneDef& scene, WarnFn warn);
  /// Adds the scene's timeline (source "scene").
  void addScene();
  /// Adds the events of an events file (see addEventsFile) and returns how many.
  /// Throws UsageError when the file cannot be read.
  std::size_t addFile(const std::string& path);
  /// Adds one event at its frame (e.g. an event a manifest lists).
  void add(TimedEvent e);
  /// Starts reading live events from `fd` (`--input -`); with `gate`, each line's event must
  /// pass its per-event and per-second caps (else it is skipped with a warning naming the cap).
  void openLive(int fd, std::shared_ptr<LiveGate> gate = nullptr);
  /// Stops reading live events (joins the reader thread).
  void closeLive();
  /// Takes live events from `queue` too (sph2d serve); live input is open while it is set.
  void openQueue(std::shared_ptr<EventQueue> queue) { queue_ = std::move(queue); }
  /// True while live input is open or has lines not taken yet.
  bool liveOpen() const;
  /// Removes and returns the scheduled events due at or before `frame`, in order.
  std::vector<TimedEvent> takeScheduled(std::int64_t frame);
  /// Reads the live lines that arrived, and removes and returns the live events due at
  /// `frame` (unstamped, or stamped for it or before); later ones join the schedule.
  std::vector<TimedEvent> takeLive(std::int64_t frame);
  /// While paused at `frame`: reads the live lines that arrived, and removes and returns
  /// the live pause and resume events due at `frame`; other live events wait.
  std::vector<TimedEvent> takeLivePauses(std::int64_t frame);
  /// Scheduled events not taken yet.
  std::size_t pending() const { return schedule_.pending(); }
  /// Events files' lines skipped because a record took them from the scene's timeline.
  std::size_t skippedSceneEvents() const { return skippedScene_; }

 private:
  void pollLive(bool pausesOnly);
  const SceneDef& scene_;
  WarnFn warn_;
  EventSchedule schedule_;
  std::size_t skippedScene_ = 0;  ///< events files' lines a record took from the timeline
  std::unique_ptr<LiveInput> live_;
  std::shared_ptr<LiveGate> gate_;
  std::shared_ptr<EventQueue> queue_;
  std::vector<TimedEvent> liveQueue_;  ///< parsed live events not taken yet
};

/// One live event (a line of `--input -`, a message from the network): parsed and checked
/// by parseEvent with the stamp optional, as coming from `name` (its `number`th line or
/// message), source "live", the frame it is due at, and `where` = "name:number". Throws
/// SceneError naming the key and what is allowed.
TimedEvent parseLiveEvent(const std::string& text, const std::string& name, int number, const SceneDef& scene);

/// The line --record writes and the manifest lists for event `e` applied at `frame`:
/// the event stamped with that frame (eventToJson, read back bit for bit).
std::string recordLine(const EventDef& e, std::int64_t frame);

/// The --record file: every applied event, one line each, flushed as it is applied.
class EventRecord {
 public:
  /// Opens (truncates) `path`; an empty path records nothing. Throws UsageError when
  /// the file cannot be written.
  explicit EventRecord(const std::string& path);
  /// True when recording.
  bool open() const { return out_.is_open(); }
  /// The file's path ("" when not recording).
  const std::string& path() const { return path_; }
  /// Appends one line (recordLine) and flushes it; nothing when not recording.
  /// Throws std::runtime_error naming the file when the line could not be written.
  void write(const std::string& line);
  /// True once a write failed (the file is not a whole record of the run).
  bool failed() const { return failed_; }
  /// XXH64 of the bytes written so far.
  std::uint64_t hash() const { return hash_.digest(); }
  /// Calls `f` before each line is written, with the XXH64 the file will have after it (the
  /// run notes it in its folder's journal).
  void beforeWrite(std::function<void(std::uint64_t)> f) { beforeWrite_ = std::move(f); }

 private:
  std::string path_;
  std::ofstream out_;
  bool failed_ = false;
  Xxh64 hash_;
  std::function<void(std::uint64_t)> beforeWrite_;
};

}  // namespace sph2d::cli
