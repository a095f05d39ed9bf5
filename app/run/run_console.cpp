// app/run/run_console.cpp — the messages, progress and summary of `sph2d run`; see run_console.hpp.
#include "run/run_console.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "sph2d/hash.hpp"

namespace sph2d::cli {

void WorstDensity::measure(const World& world, std::int64_t frame) {
  const DensityStats ds = world.densityStats();
  if (ds.meanError > mean) mean = ds.meanError, meanFrame = frame;
  if (ds.maxError > max) max = ds.maxError, maxFrame = frame;
}

RunConsole::RunConsole(bool quiet, bool realtime) : quiet_(quiet), realtime_(realtime), tty_(::isatty(STDOUT_FILENO)) {}

double RunConsole::wall() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
}

void RunConsole::clearBar() {
  if (barShown_) std::printf("\r\033[K");
  barShown_ = false;
}

void RunConsole::warn(const std::string& message) {
  ++warnings_;
  clearBar();
  std::fflush(stdout);
  std::fprintf(stderr, "warning: %s\n", message.c_str());
}

void RunConsole::say(const std::string& message) {
  if (quiet_) return;
  clearBar();
  std::printf("%s\n", message.c_str());
}

void RunConsole::notice(const std::string& message) {
  clearBar();
  std::printf("%s\n", message.c_str());
}

void RunConsole::progress(const World& world, const LoopStatus& s, bool force) {
  if (quiet_) return;
  const double now = wall();
  if (!force && now - lastReport_ < (tty_ ? 0.1 : 5.0)) return;
  lastReport_ = now;
  const int frames = int(s.frames), done = int(s.done);
  const double fps = double(s.frame) / std::max(now, 1e-9);
  const double eta = fps > 0 ? double(frames - done) / fps : 0.0;
  char extra[96] = "";
  if (realtime_)
    std::snprintf(extra, sizeof extra, "  dropped %llu late %llu", (unsigned long long)s.dropped,
                  (unsigned long long)s.late);
  if (s.paused) std::snprintf(extra + std::strlen(extra), sizeof extra - std::strlen(extra), "  PAUSED");
  if (tty_) {
    const int width = 24, fill = int(std::lround(double(width) * done / frames));
    std::printf("\r\033[K[%s%s] frame %d/%d  t = %.3f s  %.1f frames/s  ETA %.0f s%s",
                std::string(std::size_t(fill), '#').c_str(), std::string(std::size_t(width - fill), '-').c_str(), done,
                frames, world.time(), fps, eta, extra);
    barShown_ = true;
  } else {
    std::printf("frame %d/%d  t = %.3f s  %.1f frames/s  ETA %.0f s%s\n", done, frames, world.time(), fps, eta, extra);
  }
  std::fflush(stdout);
}

void RunConsole::summary(const World& world, const RunReport& r) const {
  const int done = int(r.loop.done), applied = r.loop.applied;
  if (r.status == 130)
    std::fprintf(stderr,
                 "sph2d: interrupted after %d of %d frames; %d whole PNG files kept in %s (manifest.json says so)\n",
                 done, r.frames, r.written, r.out.c_str());
  std::printf(
      "sph2d: %d frames, %zu particles, %.3f simulated s, %.2f wall s (simulation %.2f s, rendering %.2f s), "
      "%d PNG files in %s\n",
      done, world.particleCount(), world.time(), r.wall, r.loop.simSeconds, r.loop.renderSeconds + r.exportSeconds,
      r.written, r.images ? r.out.c_str() : "(none)");
  std::printf(
      "sph2d: worst density error %.3f %% (the largest per-frame mean compression, at frame %lld); "
      "largest single-particle compression %.3f %% (frame %lld)\n",
      100 * r.density.mean, (long long)r.density.meanFrame, 100 * r.density.max, (long long)r.density.maxFrame);
  std::printf("sph2d: %d event%s applied, %d warning%s%s%s\n", applied, applied == 1 ? "" : "s", warnings_,
              warnings_ == 1 ? "" : "s", r.record.empty() ? "" : "; events recorded in ", r.record.c_str());
  if (r.pending && r.status == 0)
    std::printf("sph2d: %zu event%s never applied: stamped after the last frame (%d)\n", r.pending,
                r.pending == 1 ? " was" : "s were", r.frames - 1);
  if (r.loop.aheadMost > 0)
    std::printf("sph2d: the simulation ran up to %llu kept frames ahead of the drawing\n",
                (unsigned long long)r.loop.aheadMost);
  if (r.realtime)
    std::printf(
        "sph2d: realtime at %.4g fps: %llu frames dropped (stepped but not rendered, to keep up), %llu frames late "
        "(the simulation fell %.3f s behind the wall clock)\n",
        r.fps, (unsigned long long)r.loop.dropped, (unsigned long long)r.loop.late, r.loop.behindSeconds);
  if (r.exports)
    std::printf("sph2d: %d %s (%s) in %s\n", r.exports,
                r.exportExtension == "json" ? "surface outlines" : "particle files",
                r.exportExtension == "json" ? "json and svg" : r.exportExtension.c_str(), r.out.c_str());
  if (r.videoFrames) std::printf("sph2d: %d frames encoded into %s\n", r.videoFrames, r.video.c_str());
  if (r.profile) printProfile(world);
  if (r.stateHash) {
    if (world.interrupted())  // stopped inside a step: no state the solver produced
      std::printf("state-hash: none (SIGINT/SIGTERM stopped the World inside a step)\n");
    else
      std::printf("state-hash: %s\n", hex64(world.stateHash()).c_str());
  }
}

void printProfile(const World& w) {
  double total = 0;
  for (const auto& t : w.profile().stages) total += t.seconds;
  std::printf("%-16s %10s %10s %8s %7s\n", "stage", "calls", "seconds", "ms/call", "share");
  for (const auto& t : w.profile().stages)
    std::printf("%-16s %10llu %10.3f %8.4f %6.1f%%\n", t.name.c_str(), (unsigned long long)t.calls, t.seconds,
                t.calls ? 1e3 * t.seconds / double(t.calls) : 0.0, total > 0 ? 100.0 * t.seconds / total : 0.0);
}

}  // namespace sph2d::cli
