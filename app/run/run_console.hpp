// app/run/run_console.hpp — what `sph2d run` prints: warnings, event and pause lines,
// the progress bar (a terminal) or progress lines (a pipe, a log), the summary at
// the end and the stage profile table.
//
// Design: on a terminal the progress bar owns the current line, so every other
// message clears it first; warnings go to standard error and are counted for the
// summary; --quiet silences progress and event lines, never warnings, notices (files
// removed from the output folder) or the summary.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include "loop/game_loop.hpp"
#include "sph2d/world.hpp"

namespace sph2d::cli {

/// The density figures of the summary: the worst per-frame mean and single-particle compression.
struct WorstDensity {
  double mean = 0, max = 0;                  ///< fractions of ρ0
  std::int64_t meanFrame = 0, maxFrame = 0;  ///< where they were measured
  /// Measures the state of boundary `frame`.
  void measure(const World& world, std::int64_t frame);
};

/// Everything the end-of-run summary reports.
struct RunReport {
  int status = 0;               ///< the exit code
  int frames = 0;               ///< frames asked for
  std::string out;              ///< the output directory
  bool images = true;           ///< false with --no-images
  int written = 0;              ///< PNG files written
  int exports = 0;              ///< particle files written
  std::string exportExtension;  ///< their extension
  int videoFrames = 0;          ///< frames piped to ffmpeg
  std::string video;            ///< the video file
  std::string record;           ///< the --record file ("" when not recording)
  std::size_t pending = 0;      ///< events stamped after the last frame
  bool realtime = false;        ///< --realtime
  double fps = 60;              ///< the scene's frame rate
  double wall = 0;              ///< wall seconds of the run
  double exportSeconds = 0;     ///< wall seconds taking particle snapshots for exports
  bool profile = false;         ///< --profile: the stage table
  bool stateHash = false;       ///< --state-hash: the last line
  WorstDensity density;         ///< the worst compression measured
  LoopStatus loop;              ///< where the loop got
};

/// The console of one run.
class RunConsole {
 public:
  /// `quiet`: no progress and no event lines; `realtime` adds dropped/late to progress lines.
  RunConsole(bool quiet, bool realtime);
  /// Starts the wall clock the progress lines and the summary measure from.
  void start() { t0_ = std::chrono::steady_clock::now(); }
  /// Wall seconds since start().
  double wall() const;
  /// Prints "warning: MESSAGE" to standard error and counts it.
  void warn(const std::string& message);
  /// Prints a line unless quiet.
  void say(const std::string& message);
  /// Prints a line even when quiet (what the run did to files already in its folder).
  void notice(const std::string& message);
  /// Redraws the progress bar (terminal, at most every 0.1 s) or prints a progress line
  /// (otherwise, every 5 s); `force` prints now.
  void progress(const World& world, const LoopStatus& status, bool force);
  /// Clears the progress bar if it is shown.
  void clearBar();
  /// Warnings printed so far.
  int warnings() const { return warnings_; }
  /// The lines at the end of a run: an interruption note (standard error), the summary,
  /// then the profile table and the state hash when asked for.
  void summary(const World& world, const RunReport& r) const;

 private:
  bool quiet_, realtime_, tty_;
  bool barShown_ = false;
  int warnings_ = 0;
  double lastReport_ = -1e9;
  std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};

/// Prints each stage's calls, seconds, ms per call and share.
void printProfile(const World& w);

}  // namespace sph2d::cli
