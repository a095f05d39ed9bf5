// `sph2d run`: the game loop. Simulate a scene in fixed frames (as fast as possible,
// or paced to the wall clock with --realtime), apply input events at frame
// boundaries (the scene's timeline, events files, live standard input), render the
// kept frames, write PNGs (and exports, a video) in the background, a manifest.json
// of per-frame hashes and applied events, and optionally a record of the events.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <thread>

#include "cli.hpp"
#include "commands.hpp"
#include "events.hpp"
#include "frame_clock.hpp"
#include "manifest.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/render/frame_writer.hpp"
#include "sph2d/render/particle_export.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/render/video.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

namespace sph2d::cli {

namespace {

const char* kRunHelp =
    "Usage: sph2d run SCENE.json [options]\n"
    "\n"
    "Simulates SCENE and writes frame_00000.png, frame_00001.png, ... (frame k shows\n"
    "the state after k frames of 1/fps seconds) and manifest.json (per-frame hashes of\n"
    "the pixels and of the state, and the events applied, for `sph2d check`).\n"
    "The loop has a fixed time step: the simulation always advances whole frames of\n"
    "1/fps (the scene's rate). By default it runs as fast as it can and renders every\n"
    "kept frame; with --realtime it keeps pace with the wall clock and, when it cannot,\n"
    "renders fewer frames (dropped) or, beyond --catch-up frames per render, lets the\n"
    "simulation fall behind (late); the summary reports both.\n"
    "\n"
    "Options:\n"
    "  --out DIR       output directory (default: out/<scene name>)\n"
    "  --frames N      number of frames (default: the scene's duration × fps)\n"
    "  --every K       keep every K-th frame (0, K, 2K, ...; default 1)\n"
    "  --threads T     simulation threads (default: all cores)\n"
    "  --realtime      pace the loop to the wall clock (one simulated second per second)\n"
    "  --catch-up N    with --realtime: at most N frames stepped per render (default 4)\n"
    "  --input FILE    apply the events of FILE: one JSON object per line, each with\n"
    "                  \"frame\" or \"t\" (docs/SCENES.md); may be repeated\n"
    "  --input -       apply events read from standard input, one JSON object per line,\n"
    "                  at the next frame; a bad line is reported and skipped\n"
    "  --record FILE   write every applied event with its frame (replay it with --input)\n"
    "  --png-level N   PNG compression 0..9 (default 1: fast)\n"
    "  --export FMT    also write each kept frame's particles: csv, vtk (binary) or vtk-ascii\n"
    "  --video FILE    also encode the kept frames into FILE with ffmpeg (must be installed)\n"
    "%s"
    "  --no-images     simulate only; write no PNG and no manifest\n"
    "  --state-hash    print 'state-hash: <16 hex digits>' (XXH64 of ids, positions,\n"
    "                  velocities) as the last line\n"
    "  --profile       print each stage's time and call count\n"
    "  --quiet         no progress and no event lines\n"
    "  --help          this text\n"
    "\n"
    "Exit codes: 0 ok; 1 runtime failure; 2 bad input (command line, scene, an unreadable\n"
    "--input file, an unwritable --record file); 3 the simulation guard stopped the run;\n"
    "130 interrupted (SIGINT/SIGTERM: the frames written stay whole). A malformed event\n"
    "line is a warning, not an error.\n";

struct RunArgs {
  std::string scene, out, video;
  int frames = -1, threads = 0, every = 1, pngLevel = 1;
  std::optional<ExportFormat> exportFormat;
  RenderOptions render;
  bool images = true, stateHash = false, profile = false, quiet = false, realtime = false;
  int catchUp = 4;
  std::vector<std::string> inputs;  ///< events files, "-" for standard input
  std::string record;
};

RunArgs parseRun(const std::vector<std::string>& a) {
  RunArgs r;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string& s = a[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= a.size()) throw UsageError(s + " needs a value");
      return a[++i];
    };
    if (parseRenderFlag(a, i, r.render)) continue;
    if (s == "--out") r.out = value();
    else if (s == "--frames") r.frames = parseInt(s, value(), 1, 10000000);
    else if (s == "--every") r.every = parseInt(s, value(), 1, 10000000);
    else if (s == "--threads") r.threads = parseInt(s, value(), 1, 256);
    else if (s == "--png-level") r.pngLevel = parseInt(s, value(), 0, 9);
    else if (s == "--video") r.video = value();
    else if (s == "--export") {
      ExportFormat f;
      const std::string v = value();
      if (!parseExportFormat(v, f)) throw UsageError("--export expects csv, vtk or vtk-ascii, got '" + v + "'");
      r.exportFormat = f;
    } else if (s == "--realtime") r.realtime = true;
    else if (s == "--catch-up") r.catchUp = parseInt(s, value(), 1, 1000);
    else if (s == "--input") {
      r.inputs.push_back(value());
      if (r.inputs.back() == "-" && std::count(r.inputs.begin(), r.inputs.end(), "-") > 1)
        throw UsageError("--input - may be given once (there is one standard input)");
    } else if (s == "--record") r.record = value();
    else if (s == "--no-images") r.images = false;
    else if (s == "--state-hash") r.stateHash = true;
    else if (s == "--profile") r.profile = true;
    else if (s == "--quiet") r.quiet = true;
    else if (!s.empty() && s[0] == '-') throw UsageError("unknown option '" + s + "' (see sph2d run --help)");
    else if (r.scene.empty()) r.scene = s;
    else throw UsageError("unexpected argument '" + s + "' (one scene per run)");
  }
  if (r.scene.empty()) throw UsageError("missing the scene file (see sph2d run --help)");
  if (!r.images && (r.exportFormat || !r.video.empty()))
    throw UsageError("--no-images cannot be combined with --export or --video");
  return r;
}

std::string frameName(int f) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.png", f);
  return name;
}

}  // namespace

int cmdRun(const std::vector<std::string>& args) {
  for (const auto& s : args)
    if (s == "--help" || s == "-h") {
      std::printf(kRunHelp, kRenderFlagsHelp);
      return 0;
    }
  const RunArgs a = parseRun(args);
  const SceneDef scene = loadScene(a.scene);
  const int frames = a.frames > 0 ? a.frames : std::max(1, int(std::lround(scene.duration * scene.fps)));
  const std::string out = a.out.empty() ? "out/" + scene.name : a.out;
  if (!a.video.empty() && findFfmpeg().empty()) {
    std::fprintf(stderr, "sph2d: --video needs ffmpeg, which is not installed here (not found on PATH); "
                         "install it (Debian: apt-get install ffmpeg) or leave out --video\n");
    return 2;
  }
  if (a.images && a.render.colorBy == ColorField::Age && (a.render.mode == "particles" || (a.render.mode.empty() && scene.render.mode == "particles")))
    if (!scene.effects.lifetime)
      throw UsageError("--color-by age needs particle ages: enable effects.lifetime in the scene");
  if (a.images) {
    std::error_code ec;
    fs::create_directories(out, ec);
    if (ec || !fs::is_directory(out)) throw UsageError("cannot create the output directory '" + out + "': " + ec.message());
    if (::access(out.c_str(), W_OK) != 0) throw UsageError("the output directory '" + out + "' is not writable");
  }

  // Messages: on a terminal the progress bar owns the current line, so clear it first.
  const bool tty = ::isatty(STDOUT_FILENO);
  bool barShown = false;
  auto clearBar = [&] {
    if (barShown) std::printf("\r\033[K");
    barShown = false;
  };
  int warningCount = 0;
  auto warn = [&](const std::string& m) {
    ++warningCount;
    clearBar();
    std::fflush(stdout);
    std::fprintf(stderr, "warning: %s\n", m.c_str());
  };
  auto say = [&](const std::string& m) {
    if (a.quiet) return;
    clearBar();
    std::printf("%s\n", m.c_str());
  };

  // The input: the scene's timeline, events files, live standard input; the record.
  EventSchedule schedule;
  schedule.addScene(scene);
  std::unique_ptr<LiveInput> live;
  for (const std::string& in : a.inputs) {
    if (in == "-") continue;
    std::size_t n = 0;
    try {
      n = schedule.addFile(in, scene, warn);
    } catch (const std::runtime_error& e) {
      throw UsageError(e.what());
    }
    say("sph2d: " + std::to_string(n) + " events from " + in);
  }
  if (schedule.skippedSceneEvents())
    say("sph2d: " + std::to_string(schedule.skippedSceneEvents()) +
        " recorded events of the scene's own timeline skipped (the scene applies them)");
  std::ofstream record;
  if (!a.record.empty()) {
    record.open(a.record, std::ios::trunc);
    if (!record) throw UsageError("cannot write the record file '" + a.record + "'");
  }

  installStopHandler();
  std::signal(SIGPIPE, SIG_IGN);  // a dead ffmpeg shows up as EPIPE, not as a kill
  const auto t0 = std::chrono::steady_clock::now();
  auto wallNow = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  World world(scene, WorldOptions{a.threads});
  for (const auto& w : world.takeWarnings()) warn(w);
  std::unique_ptr<Renderer> renderer;
  std::unique_ptr<FrameWriter> writer;
  json manifest;
  if (a.images) {
    renderer = std::make_unique<Renderer>(scene.render, a.render);
    FrameWriterOptions wo;
    wo.dir = out;
    wo.pngLevel = a.pngLevel;
    wo.exportFormat = a.exportFormat;
    wo.videoPath = a.video;
    wo.videoFps = scene.fps / a.every;
    writer = std::make_unique<FrameWriter>(wo);
    manifest["format"] = "sph2d-frames";
    manifest["format_version"] = 1;
    manifest["engine_version"] = SPH2D_VERSION;
    manifest["scene"] = {{"path", a.scene}, {"name", scene.name}, {"xxh64", fileHash(a.scene)}};
    manifest["renderer"] = renderer->rendererString();
    manifest["cpu"] = cpuSummary();
    manifest["environment"] = environmentJson();
    manifest["image"] = {{"width", scene.render.width}, {"height", scene.render.height}, {"format", "png"},
                         {"png_level", a.pngLevel}, {"mode", renderer->mode()}};
    manifest["render"] = renderOptionsJson(a.render);
    manifest["run"] = {{"frames", frames}, {"every", a.every}, {"threads", world.threads()}, {"fps", scene.fps},
                       {"export", a.exportFormat ? exportExtension(*a.exportFormat) + (*a.exportFormat == ExportFormat::VtkAscii ? "-ascii" : "") : "none"},
                       {"video", a.video}, {"realtime", a.realtime}, {"inputs", a.inputs}};
    manifest["frames"] = json::array();
    manifest["events"] = json::array();
  }
  if (std::count(a.inputs.begin(), a.inputs.end(), "-")) live = std::make_unique<LiveInput>(STDIN_FILENO);

  // ---- applying events at a frame boundary ----
  EventApplier applier;
  std::vector<TimedEvent> liveQueue;  ///< parsed live events not applied yet
  int applied = 0;
  auto pollLive = [&] {
    if (!live) return;
    for (auto& [lineNo, text] : live->take()) {
      if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
      try {
        TimedEvent t;
        t.event = parseEvent(text, "stdin", lineNo, scene, EventStamp::Optional);
        t.event.source = "live";
        t.frame = eventFrame(t.event, scene.fps);
        t.where = "stdin:" + std::to_string(lineNo);
        liveQueue.push_back(std::move(t));
      } catch (const SceneError& e) {
        warn(std::string(e.what()) + " (line skipped)");
      }
    }
  };
  auto applyOne = [&](const TimedEvent& t, std::int64_t frame) {
    const std::string err = applier.apply(world, t.event);
    if (!err.empty()) {
      warn(t.where + ": " + describeEvent(t.event) + " at frame " + std::to_string(frame) + " not applied: " + err);
      return;
    }
    ++applied;
    EventDef stamped = t.event;
    stamped.frame = frame;
    stamped.t = -1;
    const std::string line = eventToJson(stamped);
    if (record.is_open()) {
      record << line << '\n';
      record.flush();
    }
    if (a.images) manifest["events"].push_back(json::parse(line));
    say("event at frame " + std::to_string(frame) + ": " + describeEvent(t.event) + " (" + t.where + ")");
    for (const auto& w : world.takeWarnings()) warn(w);
  };
  // Everything due at boundary `frame`: the schedule first, then live events (unstamped or
  // stamped for now; a live event stamped for a later frame joins the schedule).
  auto applyAt = [&](std::int64_t frame) {
    for (const TimedEvent& t : schedule.take(frame)) applyOne(t, frame);
    pollLive();
    std::vector<TimedEvent> now;
    now.swap(liveQueue);
    for (TimedEvent& t : now) {
      if (t.frame > frame) schedule.add(std::move(t));
      else applyOne(t, frame);
    }
  };

  // ---- the loop ----
  FrameClock clock(1.0 / scene.fps, a.realtime, a.catchUp);
  double simSeconds = 0, renderSeconds = 0;
  double worstMean = 0, worstMax = 0;
  std::int64_t worstMeanFrame = 0, worstMaxFrame = 0;
  std::uint64_t dropped = 0;
  double lastReport = -1e9;
  std::int64_t f = 0;
  int done = 0;
  int status = 0;
  std::string failure, stopReason;
  auto stopped = [&] {
    if (!stopRequested.load()) return false;
    status = 130;
    stopReason = "interrupted";
    failure = "SIGINT or SIGTERM before frame " + std::to_string(f + 1);
    return true;
  };
  auto renderFrame = [&] {
    const auto r0 = std::chrono::steady_clock::now();
    const Frame& fr = renderer->render(world);
    const std::uint64_t pixels = xxh64(fr.rgba.data(), fr.rgba.size());
    std::shared_ptr<const ParticleSnapshot> snap;
    if (a.exportFormat) snap = std::make_shared<ParticleSnapshot>(snapshotOf(world));
    renderSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
    writer->push(int(f), fr.width, fr.height, fr.rgba, snap);
    manifest["frames"].push_back({{"frame", f},
                                  {"time", world.time()},
                                  {"file", frameName(int(f))},
                                  {"rgba_xxh64", hex64(pixels)},
                                  {"state_hash", hex64(world.stateHash())}});
  };
  // The state of boundary f is complete (events applied): measure it.
  auto measure = [&] {
    const DensityStats ds = world.densityStats();
    if (ds.meanError > worstMean) worstMean = ds.meanError, worstMeanFrame = f;
    if (ds.maxError > worstMax) worstMax = ds.maxError, worstMaxFrame = f;
    done = int(f) + 1;
  };
  auto progress = [&](bool force) {
    if (a.quiet) return;
    const double wall = wallNow();
    if (!force && wall - lastReport < (tty ? 0.1 : 5.0)) return;
    lastReport = wall;
    const double fps = double(f) / std::max(wall, 1e-9);
    const double eta = fps > 0 ? double(frames - done) / fps : 0.0;
    char extra[96] = "";
    if (a.realtime) std::snprintf(extra, sizeof extra, "  dropped %llu late %llu", (unsigned long long)dropped,
                                  (unsigned long long)clock.late());
    if (applier.paused()) std::snprintf(extra + std::strlen(extra), sizeof extra - std::strlen(extra), "  PAUSED");
    if (tty) {
      const int width = 24, fill = int(std::lround(double(width) * done / frames));
      std::printf("\r\033[K[%s%s] frame %d/%d  t = %.3f s  %.1f frames/s  ETA %.0f s%s", std::string(std::size_t(fill), '#').c_str(),
                  std::string(std::size_t(width - fill), '-').c_str(), done, frames, world.time(), fps, eta, extra);
      barShown = true;
    } else {
      std::printf("frame %d/%d  t = %.3f s  %.1f frames/s  ETA %.0f s%s\n", done, frames, world.time(), fps, eta, extra);
    }
    std::fflush(stdout);
  };
  // Paused at boundary f (already rendered): wait for a resume, or the pause's own seconds (real
  // time only). Live pause/resume take effect at once; other live events wait for the next frame.
  auto holdPause = [&] {
    const double start = wallNow();
    const double seconds = applier.pauseSeconds();
    if (seconds > 0 && !a.realtime) {  // headless: a timed pause takes no time
      applier.endPause();
      return;
    }
    if (seconds <= 0 && !(live && live->open())) {
      warn("pause at frame " + std::to_string(f) + ": no live input (--input -) can resume it; ignored");
      applier.endPause();
      return;
    }
    say("paused at frame " + std::to_string(f) + (seconds > 0 ? " for " + std::to_string(seconds) + " s" : ": waiting for {\"type\": \"resume\"}"));
    while (applier.paused() && !stopped()) {
      pollLive();
      std::vector<TimedEvent> keep;
      for (TimedEvent& t : liveQueue) {
        const auto type = t.event.type;
        if ((type == EventDef::Type::Resume || type == EventDef::Type::Pause) && t.frame <= f) applyOne(t, f);
        else keep.push_back(std::move(t));
      }
      liveQueue.swap(keep);
      if (!applier.paused()) break;
      if (seconds > 0 && wallNow() - start >= seconds) {
        applier.endPause();
        break;
      }
      if (seconds <= 0 && !live->open()) {
        warn("standard input closed while paused at frame " + std::to_string(f) + "; resuming");
        applier.endPause();
        break;
      }
      progress(false);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (!applier.paused()) say("resumed at frame " + std::to_string(f));
  };

  try {
    applyAt(0);
    measure();
    if (renderer) renderFrame();
    if (frames == 1) progress(true);
    clock.resync(wallNow());
    while (f + 1 < frames) {
      if (stopped()) break;
      if (applier.paused()) {
        holdPause();
        clock.resync(wallNow());
        continue;
      }
      clock.tick(wallNow());
      if (!clock.due()) {
        // Ahead of the wall clock: sleep (in short slices, so Ctrl-C stays prompt).
        std::this_thread::sleep_for(std::chrono::duration<double>(std::min(clock.untilDue(), 0.02)));
        continue;
      }
      int steps = 0;
      while (clock.due() && steps < clock.maxStepsPerRender() && f + 1 < frames && !applier.paused()) {
        const auto s0 = std::chrono::steady_clock::now();
        world.stepFrame();
        simSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
        ++f;
        ++steps;
        clock.consume();
        for (const auto& w : world.takeWarnings()) warn(w);
        applyAt(f);
        measure();
        // Render the last frame of this iteration; a kept frame that another step follows
        // at once (the loop is behind the wall clock) is dropped.
        const bool behind = clock.due() && steps < clock.maxStepsPerRender() && f + 1 < frames && !applier.paused();
        if (renderer && f % a.every == 0) {
          if (behind) ++dropped;
          else renderFrame();
        }
      }
      if (a.realtime && steps == clock.maxStepsPerRender()) clock.dropBacklog();
      progress(f + 1 == frames);
    }
  } catch (const SimulationError& e) {
    failure = e.what();
    stopReason = "guard";
    status = 3;
  } catch (const std::exception& e) {
    failure = e.what();
    stopReason = "error";
    status = 1;
  }
  live.reset();
  clearBar();
  int written = 0;
  FrameWriterCounts counts;
  if (writer) {
    try {
      written = writer->finish();
    } catch (const std::exception& e) {
      written = writer->written();
      if (status == 0 || status == 130) {
        failure = e.what();
        stopReason = "error";
        status = 1;
      }
    }
    counts = writer->counts();
  }
  const double wall = wallNow();
  if (status == 3 || status == 1) std::fprintf(stderr, "error: %s\n", failure.c_str());
  if (a.images) {
    // Only the frames whose PNG exists (the writer writes in order and stops at its first error).
    json& list = manifest["frames"];
    while (int(list.size()) > written) list.erase(list.size() - 1);
    manifest["complete"] = status == 0;
    manifest["stop"] = status == 0 ? json(nullptr)
                                   : json{{"reason", stopReason}, {"message", failure}, {"frames_simulated", done},
                                          {"frames_written", written}};
    try {
      writeFileAtomic(out + "/manifest.json", manifest.dump(1) + "\n");
    } catch (const std::exception& e) {
      std::fprintf(stderr, "error: %s\n", e.what());
      if (status == 0) status = 1;
    }
  }
  if (status == 130)
    std::fprintf(stderr, "sph2d: interrupted after %d of %d frames; %d whole PNG files kept in %s (manifest.json says so)\n",
                 done, frames, written, out.c_str());
  std::printf("sph2d: %d frames, %zu particles, %.3f simulated s, %.2f wall s (simulation %.2f s, rendering %.2f s), "
              "%d PNG files in %s\n",
              done, world.particleCount(), world.time(), wall, simSeconds, renderSeconds, written,
              a.images ? out.c_str() : "(none)");
  std::printf("sph2d: worst density error %.3f %% (the largest per-frame mean compression, at frame %lld); "
              "largest single-particle compression %.3f %% (frame %lld)\n",
              100 * worstMean, (long long)worstMeanFrame, 100 * worstMax, (long long)worstMaxFrame);
  std::printf("sph2d: %d event%s applied, %d warning%s%s%s\n", applied, applied == 1 ? "" : "s", warningCount,
              warningCount == 1 ? "" : "s",
              record.is_open() ? "; events recorded in " : "", record.is_open() ? a.record.c_str() : "");
  if (schedule.pending() && status == 0)
    std::printf("sph2d: %zu event%s never applied: stamped after the last frame (%d)\n", schedule.pending(),
                schedule.pending() == 1 ? " was" : "s were", frames - 1);
  if (a.realtime)
    std::printf("sph2d: realtime at %.4g fps: %llu frames dropped (stepped but not rendered, to keep up), %llu frames late "
                "(the simulation fell %.3f s behind the wall clock)\n",
                scene.fps, (unsigned long long)dropped, (unsigned long long)clock.late(), clock.behindSeconds());
  if (counts.exports) std::printf("sph2d: %d particle files (%s) in %s\n", counts.exports,
                                  exportExtension(*a.exportFormat).c_str(), out.c_str());
  if (counts.videoFrames) std::printf("sph2d: %d frames encoded into %s\n", counts.videoFrames, a.video.c_str());
  if (a.profile) printProfile(world);
  if (a.stateHash) std::printf("state-hash: %s\n", hex64(world.stateHash()).c_str());
  return status;
}

}  // namespace sph2d::cli
