// app/loop/frame_clock.hpp — the fixed-timestep clock of the game loop.
//
// The simulation always advances in whole frames of dt = 1/fps (the scene's
// rate), whatever the render rate. In real time the clock accumulates wall time
// and the loop steps while a whole frame is due (Fiedler, "Fix your timestep!",
// 2004): on a fast machine it waits for the wall clock; on a slow one it steps
// several frames per render and renders only the last (the others are
// *dropped*), and at most `maxStepsPerRender` per render, beyond which the
// backlog is forgotten (those frames are *late*: the simulation then runs
// behind the wall clock instead of spiralling). Headless (not real time), every
// loop iteration is exactly one frame, as fast as the machine goes.
#pragma once

#include <algorithm>
#include <cstdint>

namespace sph2d::cli {

/// Accumulator of wall time in whole frames.
class FrameClock {
 public:
  /// `dt` = 1/fps [s]; `realtime` paces to the wall clock; `maxStepsPerRender` ≥ 1.
  FrameClock(double dt, bool realtime, int maxStepsPerRender)
      : dt_(dt), realtime_(realtime), maxSteps_(std::max(1, maxStepsPerRender)) {}

  /// Starts (or restarts after a pause) at wall time `now` [s] with nothing due.
  void resync(double now) {
    last_ = now;
    acc_ = 0;
  }
  /// Adds the wall time since the last call (real time) or exactly one frame (headless).
  void tick(double now) {
    if (!realtime_) {
      acc_ = dt_;
      return;
    }
    acc_ += std::max(0.0, now - last_);
    last_ = std::max(last_, now);  // the loop may tick ahead (a step scheduled for its due time)
  }
  /// True while a whole frame is due.
  bool due() const { return acc_ >= dt_ * (1 - 1e-9); }
  /// One frame was stepped.
  void consume() { acc_ = std::max(0.0, acc_ - dt_); }
  /// Seconds until the next frame is due (0 when one is due, or headless).
  double untilDue() const { return realtime_ ? std::max(0.0, dt_ - acc_) : 0.0; }
  /// The most frames stepped between two renders.
  int maxStepsPerRender() const { return maxSteps_; }
  /// After a render iteration stepped its maximum: forgets the frames still due
  /// (the simulation falls behind the wall clock) and returns how many.
  std::uint64_t dropBacklog() {
    if (!due()) return 0;
    const auto n = std::uint64_t(acc_ / dt_ + 1e-9);
    acc_ -= double(n) * dt_;
    late_ += n;
    return n;
  }
  /// Frames forgotten so far by dropBacklog().
  std::uint64_t late() const { return late_; }
  /// Seconds the simulation has fallen behind the wall clock.
  double behindSeconds() const { return double(late_) * dt_; }
  /// True in real time.
  bool realtime() const { return realtime_; }

 private:
  double dt_;
  bool realtime_;
  int maxSteps_;
  double last_ = 0, acc_ = 0;
  std::uint64_t late_ = 0;
};

}  // namespace sph2d::cli
