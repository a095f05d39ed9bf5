// app/loop/game_loop.hpp — the fixed-step game loop that `sph2d run` and `sph2d check` share.
//
//   boundary 0: apply events ─> observer.boundary ─> render if kept ─> observer.frame
//   then, while frames remain:  [paused? hold]  [real time: wait until a frame is due]
//     World::stepFrame  ‖  render the snapshot ─> observer.frame   (two threads, joined;
//                          in real time the render starts at once, the step when it is due)
//       ─> apply events due at the new boundary ─> observer.boundary
//       ─> snapshot if kept (unless the loop is behind the wall clock: dropped)
//   a snapshot still pending is rendered before a pause, at a stop and at the end.
//
// Headless with nothing live (no --realtime, no standard input: the run is a function of the
// scene and its events files alone), the stepping runs ahead instead: one thread steps,
// applies each boundary's events, tells the observer and snapshots every kept frame into a
// queue of up to kAheadFrames frames and kAheadBytes bytes, while this thread renders the
// queue in order. The first frame's shader compilation (about 0.3 s on llvmpipe) and the
// frames whose step costs more than their render then overlap the rest instead of adding
// up. The frames, the events and the hashes are the same either way; the observer's calls
// are serialized (boundary() of later frames may come before frame() of earlier ones).
//
// Rendering overlaps the next step: the renderer draws a copy of what it reads
// (positions, velocities, density, pressure, ids, ages, colliders) on the thread
// that owns its GL context, while a second thread steps the World. The frame is
// the same image as when drawn from the World itself, and it reaches the
// observer before the next boundary; the observer gets the boundary's time and
// state hash, never the World (which is stepping then).
//
// Design: a run is a function of the scene and the list (frame, event) alone. The
// loop applies every event at a frame boundary, before that frame is rendered and
// before the World steps past it, in the order the EventIntake gives them. Pacing
// (FrameClock) decides only when frames are stepped and which kept frames are
// rendered, never what a frame is, so a headless rerun (`sph2d check`, a replay)
// reproduces the states of a real-time run. The loop owns no output: what a
// command does with messages, applied events and rendered frames is its
// LoopObserver's business (run writes PNGs and a manifest, check compares hashes).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

#include "loop/event_intake.hpp"
#include "loop/frame_clock.hpp"
#include "loop/input_events.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/world.hpp"

namespace sph2d::cli {

/// How the loop runs.
struct LoopSettings {
  std::int64_t frames = 1;  ///< boundaries 0 .. frames − 1 (frames − 1 steps)
  double fps = 60;          ///< the scene's frame rate (one step = 1/fps)
  bool realtime = false;    ///< pace to the wall clock (else as fast as possible)
  int catchUp = 4;          ///< real time: at most this many steps per render
  const std::atomic<bool>* stop =
      nullptr;  ///< when set and true, the loop ends (SIGINT/SIGTERM; give the World the same flag)
  /// Live input's caps: at each boundary a live event (EventIntake::takeLive) that would take
  /// the fluid past `live.budget` is not applied (observer.notApplied); the per-event and
  /// per-second caps are the intake's (LiveGate). Budget 0: no cap.
  LiveLimits live;
};

/// Where the loop is, for progress lines and the summary.
struct LoopStatus {
  std::int64_t frames = 0;    ///< the frames the loop runs (LoopSettings::frames)
  std::int64_t frame = 0;     ///< the last frame boundary reached
  std::int64_t done = 0;      ///< boundaries complete (events applied, observer told)
  std::uint64_t dropped = 0;  ///< kept frames stepped but not rendered, to keep up
  std::uint64_t late = 0;     ///< frame periods forgotten: the simulation fell behind the wall clock
  double behindSeconds = 0;   ///< late × 1/fps
  double simSeconds = 0;      ///< wall seconds spent in World::stepFrame
  double renderSeconds = 0;   ///< wall seconds spent in Renderer::render (stepping ahead: once it ends)
  /// The most kept frames the stepping held ahead of the drawing (0: the loop interleaves them).
  std::uint64_t aheadMost = 0;
  int applied = 0;      ///< events applied
  bool paused = false;  ///< between a pause and a resume
};

/// A kept frame's boundary, as the loop captured it before stepping on.
struct FrameState {
  std::int64_t frame = 0;       ///< the boundary
  double time = 0;              ///< World::time() there [s]
  std::uint64_t stateHash = 0;  ///< World::stateHash() there
};

/// How the loop ended (exceptions from the World, the renderer or the observer propagate).
enum class LoopEnd {
  Finished,     ///< every frame was stepped
  Interrupted,  ///< LoopSettings::stop was set
  Ended,        ///< the observer's frame() returned false
};

/// What a command does with the loop's events, frames and messages.
class LoopObserver {
 public:
  virtual ~LoopObserver() = default;
  /// A warning for the user (a World warning, a skipped live line, a pause nothing can end).
  virtual void warn(const std::string& message) = 0;
  /// A note for the user (a pause starts or ends).
  virtual void note(const std::string& message) = 0;
  /// Event `e` was applied at boundary `frame`.
  virtual void applied(const TimedEvent& e, std::int64_t frame) = 0;
  /// Event `e` could not be applied at boundary `frame` (`why`); the World is unchanged.
  virtual void notApplied(const TimedEvent& e, std::int64_t frame, const std::string& why) = 0;
  /// Boundary `frame` is complete: stepped to and its events applied; not rendered yet.
  /// `rendered`: frame() will follow for it (a kept frame, not dropped).
  virtual void boundary(const World& world, std::int64_t frame, bool rendered) {}
  /// True when frame `frame` is to be rendered (a kept frame).
  virtual bool keeps(std::int64_t frame) = 0;
  /// The rendered kept frame (valid during the call) of boundary `state`. Called while the
  /// World steps on another thread: read what else it needs from the World in boundary()
  /// (keyed by frame: the World may have run ahead by several boundaries since).
  /// False ends the loop (after the step under way).
  virtual bool frame(const FrameState& state, const Frame& image) = 0;
  /// Called after each loop iteration and while paused; `force` at the last frame.
  virtual void progress(const World& world, const LoopStatus& status, bool force) {}
};

/// The simulation threads of a run without --threads: every core, but one fewer when the loop
/// steps ahead of its drawing (headless, drawing, nothing live; GameLoop's design above): the
/// renderer's thread then holds a core for the whole run, and a second step thread only
/// contends with it (the demo on 2 cores: 2.00–2.09 s of wall time with one step thread,
/// 2.22–2.29 s with two; docs/PERFORMANCE.md).
int defaultStepThreads(bool stepsAhead);

/// The fixed-step loop over one World: events at frame boundaries, optional real-time
/// pacing, rendering of the kept frames.
class GameLoop {
 public:
  /// `renderer` may be null (no images: nothing is rendered and nothing dropped).
  GameLoop(World& world, EventIntake& input, LoopObserver& observer, Renderer* renderer, LoopSettings settings);
  /// Runs boundary 0 and then steps until frames − 1, the stop flag or the observer ends it
  /// (nothing when frames < 1). When the World is built with the same flag as its stop flag
  /// (WorldOptions::stop), a stop also ends the step under way within milliseconds: the
  /// World's Interrupted becomes LoopEnd::Interrupted (that World is then abandoned,
  /// World::interrupted()).
  /// Exceptions (SimulationError from a step, a renderer error) propagate; status() then
  /// says how far the loop got.
  LoopEnd run();
  /// Where the loop is.
  const LoopStatus& status() const { return status_; }

  /// Headless runs step at most this many kept frames ahead of the one being drawn, and queue
  /// at most kAheadBytes of their copies (at least one frame whatever its size); two spent
  /// copies are kept for reuse, the others freed. 64 frames of 10k particles take about 40 MB.
  static constexpr std::size_t kAheadFrames = 64;
  static constexpr std::size_t kAheadBytes = std::size_t(64) << 20;

 private:
  /// The command's observer with every call serialized: in a headless run the stepping
  /// thread calls boundary(), applied(), progress() … while this one calls frame().
  class SerialObserver final : public LoopObserver {
   public:
    explicit SerialObserver(LoopObserver& o) : o_(o) {}
    void warn(const std::string& m) override;
    void note(const std::string& m) override;
    void applied(const TimedEvent& e, std::int64_t frame) override;
    void notApplied(const TimedEvent& e, std::int64_t frame, const std::string& why) override;
    void boundary(const World& world, std::int64_t frame, bool rendered) override;
    bool keeps(std::int64_t frame) override;
    bool frame(const FrameState& state, const Frame& image) override;
    void progress(const World& world, const LoopStatus& status, bool force) override;

   private:
    LoopObserver& o_;
    std::mutex m_;
  };

  double wallNow() const;
  bool stopRequested() const;
  /// run()'s body (run() turns the World's Interrupted into LoopEnd::Interrupted).
  LoopEnd runFrames();
  void applyOne(const TimedEvent& t, std::int64_t frame);
  void applyDue(std::int64_t frame);
  /// Completes boundary status_.frame; renders it unless `drop`. False: the observer ended the loop.
  bool finishBoundary(bool drop);
  /// Holds a pause at the current boundary until it ends (or the stop flag is set).
  void holdPause();
  /// Copies what the renderer reads of the World at boundary `f` (the pending frame).
  void capture(std::int64_t f);
  /// Renders the pending frame and hands it to the observer. False: the observer ended the loop.
  bool renderPending();
  struct Pending;
  /// Copies what the renderer reads of the World at boundary `f` into `q`.
  void captureInto(Pending& q, std::int64_t f);
  /// Renders `q` (adding the wall seconds it took to `seconds`) and hands it to the observer.
  /// False: the observer ended the loop.
  bool renderSnapshot(Pending& q, double& seconds);
  /// Whether this run steps ahead of its rendering (headless, rendering, nothing live).
  bool runsAhead() const;
  /// The headless loop: steps and boundaries on a second thread, rendering of the queue here.
  LoopEnd runAhead();
  /// What stepAndRender did.
  enum class StepOutcome {
    Stepped,  ///< the World stepped one frame (and the pending frame, if any, was drawn)
    Ended,    ///< the observer ended the loop
    Stopped,  ///< the stop flag was set while the step waited for its time: not taken
  };
  /// One World::stepFrame, started at wall time `startAt` (wallNow()'s seconds; at once when it
  /// has passed), with the pending frame rendered on this thread meanwhile.
  StepOutcome stepAndRender(double startAt);

  World& world_;
  EventIntake& input_;
  SerialObserver observer_;
  Renderer* renderer_;
  LoopSettings settings_;
  FrameClock clock_;
  EventApplier applier_;
  LoopStatus status_;
  std::chrono::steady_clock::time_point start_;
  /// A kept frame captured at its boundary and not rendered yet.
  struct Pending {
    bool active = false;
    FrameState state;
    ParticleBuffer particles;  ///< copies of the fields the renderer reads
    DiffuseBuffer diffuse;     ///< and of the foam, spray and bubbles
    std::vector<Collider> colliders;
    RenderInput input;
    /// About the bytes the copies hold, their capacity (what kAheadBytes counts).
    std::size_t bytes() const;
  } pending_;
};

}  // namespace sph2d::cli
