// `sph2d run`: the game loop of a scene with its outputs. Reads the options
// (run_args), collects the events (event_intake: the scene's timeline, --input
// files, live standard input, --record), runs the fixed-step GameLoop (game_loop:
// events at frame boundaries, --realtime pacing, rendering of kept frames) and
// hands each rendered frame to the background FrameWriter (PNGs, exports, a video)
// and to the manifest (manifest: per-frame hashes, applied events). What it prints
// is run_console's. A failure keeps the frames already written whole and the
// manifest says how the run ended.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>

#include "cli.hpp"
#include "commands.hpp"
#include "loop/event_intake.hpp"
#include "loop/game_loop.hpp"
#include "output/manifest.hpp"
#include "output/output_dir.hpp"
#include "run/run_args.hpp"
#include "run/run_console.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/render/frame_writer.hpp"
#include "sph2d/render/particle_export.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/render/video.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace fs = std::filesystem;

namespace sph2d::cli {
namespace {

/// What `sph2d run` does with the loop: prints events and warnings, records applied
/// events, measures each boundary, and hands rendered kept frames to the writer and
/// the manifest.
class RunOutputs : public LoopObserver {
 public:
  RunOutputs(const RunArgs& a, RunConsole& console, EventRecord& record, FrameWriter* writer, RunManifest* manifest)
      : a_(a), console_(console), record_(record), writer_(writer), manifest_(manifest) {}

  void warn(const std::string& m) override { console_.warn(m); }
  void note(const std::string& m) override { console_.say(m); }
  void applied(const TimedEvent& t, std::int64_t frame) override {
    const std::string line = recordLine(t.event, frame);
    record_.write(line);
    if (manifest_) manifest_->addEvent(line);
    console_.say("event at frame " + std::to_string(frame) + ": " + describeEvent(t.event) + " (" + t.where + ")");
  }
  void notApplied(const TimedEvent& t, std::int64_t frame, const std::string& why) override {
    console_.warn(t.where + ": " + describeEvent(t.event) + " at frame " + std::to_string(frame) +
                  " not applied: " + why);
  }
  void boundary(const World& world, std::int64_t frame, bool rendered) override {
    density.measure(world, frame);
    // The export reads the World here (frame() runs while the World steps on, perhaps some
    // boundaries ahead), and only for a frame that will be rendered: a dropped frame is
    // neither drawn nor exported.
    if (a_.exportFormat && rendered) {
      const auto s0 = std::chrono::steady_clock::now();
      auto snap = std::make_shared<ParticleSnapshot>(snapshotOf(world));
      if (*a_.exportFormat == ExportFormat::Surface) snap->surface = world.surfaceCurves();
      snaps_[frame] = std::move(snap);
      exportSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
    }
  }
  bool keeps(std::int64_t frame) override { return frame % a_.every == 0; }
  bool frame(const FrameState& state, const Frame& image) override {
    std::shared_ptr<const ParticleSnapshot> snap;
    if (const auto it = snaps_.find(state.frame); it != snaps_.end()) {
      snap = std::move(it->second);
      snaps_.erase(it);
    }
    writer_->push(int(state.frame), image.width, image.height, image.rgba, std::move(snap));
    manifest_->addFrame(state.frame, state.time, xxh64(image.rgba.data(), image.rgba.size()), state.stateHash);
    return true;
  }
  void progress(const World& world, const LoopStatus& s, bool force) override { console_.progress(world, s, force); }

  WorstDensity density;      ///< the worst compression over the boundaries
  double exportSeconds = 0;  ///< wall seconds taking particle snapshots

 private:
  const RunArgs& a_;
  RunConsole& console_;
  EventRecord& record_;
  FrameWriter* writer_;
  RunManifest* manifest_;
  /// The exports of the kept frames captured and not yet rendered, by frame.
  std::map<std::int64_t, std::shared_ptr<const ParticleSnapshot>> snaps_;
};

/// What `sph2d run` writes into its folder: frames, exports, and the video and record files
/// when they are in it (`video`, `record`: their names there, "" when elsewhere).
FolderSpec runFolderSpec(const std::string& video, const std::string& record) {
  FolderSpec spec;
  spec.command = "run";
  spec.manifest = true;
  spec.writes = [video, record](const std::string& name) {
    return isRunFileName(name) || (!video.empty() && name == video) || (!record.empty() && name == record);
  };
  return spec;
}

/// The name of `path` in the output folder `out` when it is there ("" when elsewhere); a name
/// the run writes itself is refused.
std::string nameInFolder(const std::string& path, const std::string& out, const std::string& flag) {
  if (path.empty() || !isInFolder(path, out)) return "";
  const std::string name = fs::path(path).filename().string();
  if (isRunFileName(name) || name == "manifest.json" || name.rfind(".sph2d.", 0) == 0 || name.empty() || name == "." ||
      name == "..")
    throw UsageError(flag + " " + path + ": sph2d run writes a file of that name in " + out +
                     " itself; choose another name");
  return name;
}

}  // namespace

int cmdRun(const std::vector<std::string>& args) {
  if (wantsRunHelp(args)) {
    printRunHelp();
    return 0;
  }
  const RunArgs a = parseRunArgs(args);
  const SceneDef scene = loadScene(a.scene);
  const int frames = a.frames > 0 ? a.frames : std::max(1, int(std::lround(scene.duration * scene.fps)));
  const std::string out = a.out.empty() ? "out/" + scene.name : a.out;
  if (!a.video.empty() && findFfmpeg().empty()) {
    std::fprintf(stderr,
                 "sph2d: --video needs ffmpeg, which is not installed here (not found on PATH); "
                 "install it (Debian: apt-get install ffmpeg) or leave out --video\n");
    return 2;
  }
  if (a.images && a.render.colorBy == ColorField::Age &&
      (a.render.mode == "particles" || (a.render.mode.empty() && scene.render.mode == "particles")))
    if (!scene.effects.lifetime)
      throw UsageError("--color-by age needs particle ages: enable effects.lifetime in the scene");
  // Memory, before anything is allocated: a scene that cannot fit is refused now, not after
  // seconds of set-up with std::bad_alloc.
  checkMemory(scene, a.images, a.maxMemory);
  // The output directory: one run at a time holds it (a second one is refused, naming the
  // first), and a run writes there only where what is in the way is sph2d's own (output_dir.hpp):
  // a folder holding a frame, an export, the manifest or the video or record file that sph2d
  // cannot prove it wrote is refused now, before anything is read or written.
  std::optional<OutputLock> outLock;
  std::string videoName, recordName;  // their names in the folder ("" when elsewhere)
  FolderSpec spec;
  if (a.images) {
    videoName = nameInFolder(a.video, out, "--video");
    recordName = nameInFolder(a.record, out, "--record");
    spec = runFolderSpec(videoName, recordName);
    // A folder another run holds is named as such (its lock first); the scan reads only, so a
    // refused folder is left as it was (no lock file made in it).
    if (holdsLockFile(out)) outLock.emplace(out);
    refuseForeignFiles(out, scanOutputFolder(out, spec), spec);
    makeOutputDir(out);
    if (!outLock) outLock.emplace(out);
  }
  if (!a.video.empty() && videoName.empty()) refuseExistingFile(a.video, "--video");

  // The input: the scene's timeline, events files, the record (live input opens last).
  RunConsole console(a.quiet, a.realtime);
  EventIntake input(scene, [&](const std::string& m) { console.warn(m); });
  input.addScene();
  for (const std::string& in : a.inputs) {
    if (in == "-") continue;
    const std::size_t n = input.addFile(in);
    console.say("sph2d: " + std::to_string(n) + " events from " + in);
  }
  if (input.skippedSceneEvents())
    console.say("sph2d: " + std::to_string(input.skippedSceneEvents()) +
                " recorded events of the scene's own timeline skipped (the scene applies them)");
  // The record file must not be one of the inputs: opening it truncates the file.
  for (const std::string& in : a.inputs) {
    std::error_code ec;
    if (!a.record.empty() && in != "-" && fs::exists(a.record, ec) && fs::equivalent(in, a.record, ec))
      throw UsageError("--record " + a.record +
                       " is also an --input file: recording would overwrite it; record to another file");
  }
  // A record file in the output folder opens once the folder's journal has noted it (below).
  if (!a.record.empty() && recordName.empty()) refuseExistingFile(a.record, "--record");
  std::unique_ptr<EventRecord> record = std::make_unique<EventRecord>(recordName.empty() ? a.record : std::string());

  std::signal(SIGPIPE, SIG_IGN);  // a dead ffmpeg shows up as EPIPE, not as a kill
  console.start();
  // The World reads the stop flag (set by SIGINT/SIGTERM once the loop starts): a signal ends
  // the step under way within milliseconds. Until then a signal ends the process at once.
  const bool live = std::count(a.inputs.begin(), a.inputs.end(), "-") > 0;
  const int threads = a.threads ? a.threads : defaultStepThreads(a.images && !a.realtime && !live);
  World world(scene, WorldOptions{threads, &stopRequested});
  for (const auto& w : world.takeWarnings()) console.warn(w);
  std::unique_ptr<Renderer> renderer;
  std::unique_ptr<OutputJournal> journal;
  std::unique_ptr<FrameWriter> writer;
  std::unique_ptr<RunManifest> manifest;
  if (a.images) {
    renderer = std::make_unique<Renderer>(scene.render, a.render);
    FrameWriterOptions wo;
    wo.dir = out;
    wo.pngLevel = a.pngLevel;
    wo.exportFormat = a.exportFormat;
    wo.videoPath = a.video;
    wo.videoFps = scene.fps / a.every;
    // Each file is noted in the folder's journal (its name, the hash of its bytes, its
    // temporary name) before it is written, so that a later run knows a killed run's files.
    wo.beforeWrite = [&journal](const std::string& name, std::uint64_t h, const std::string& temp) {
      journal->note(name, temp, h);
    };
    writer = std::make_unique<FrameWriter>(wo);
    manifest = std::make_unique<RunManifest>(a, scene, *renderer, frames, world.threads());
    // Before the first frame: the frames, exports and manifest an earlier run wrote go (a
    // shorter rerun leaves none behind), once proven its own again (the folder is scanned
    // anew); and the manifest says "running" until the end, so a run killed midway never
    // leaves a complete manifest beside its frames.
    const FolderScan scan = scanOutputFolder(out, spec);
    refuseForeignFiles(out, scan, spec);
    auto stale = [](const std::string& name) { return isRunFileName(name) || name == "manifest.json"; };
    const std::vector<std::string> removed = removeOwnFiles(out, scan, stale);
    if (!removed.empty())
      console.notice("sph2d: removed " + describeFiles(removed) + " that an earlier sph2d run wrote in " + out);
    if (!scan.strayTemps.empty())
      console.notice("sph2d: left " + describeFiles(scan.strayTemps) + " in " + out +
                     ": named like the temporary files of an unfinished write, but no record of sph2d lists them");
    std::vector<OwnedFile> kept;  // an earlier run's video or record, replaced only by one of the same name
    for (const OwnedFile& f : scan.own)
      if (!stale(f.name)) kept.push_back(f);
    journal = std::make_unique<OutputJournal>(out, "run", kept);
    if (!recordName.empty()) {
      journal->note(recordName, "", xxh64("", 0));  // opened empty
      record = std::make_unique<EventRecord>(a.record);
      record->beforeWrite([&journal, &recordName](std::uint64_t h) { journal->note(recordName, "", h); });
    }
    if (!videoName.empty())
      journal->note(videoName, fs::path(videoTempPath(a.video)).filename().string(), std::nullopt);
    manifest->writeRunning(out);
  }
  // Standard input is input from elsewhere: its block and drop events are capped as the network's are.
  LiveLimits limits = LiveLimits::forScene(scene);
  if (a.maxEventParticles) limits.perEvent = a.maxEventParticles;
  if (a.maxParticlesPerSecond) limits.perSecond = a.maxParticlesPerSecond;
  if (a.maxParticles) limits.budget = a.maxParticles;
  if (live) input.openLive(STDIN_FILENO, std::make_shared<LiveGate>(scene, limits));

  // The loop. A failure stops it; what was written stays, and the manifest says why.
  RunOutputs outputs(a, console, *record, writer.get(), manifest.get());
  LoopSettings settings;
  settings.frames = frames;
  settings.fps = scene.fps;
  settings.realtime = a.realtime;
  settings.catchUp = a.catchUp;
  settings.stop = &stopRequested;
  if (live) settings.live = limits;
  GameLoop loop(world, input, outputs, renderer.get(), settings);
  // From here a signal stops the loop at the next frame and the files are finished. Until
  // now it ended the process at once: set-up wrote nothing that needs finishing (the
  // manifest, if any, already says "running", which is true of a process that ends there).
  installStopHandler();
  int status = 0;
  std::string failure, stopReason;
  try {
    if (loop.run() == LoopEnd::Interrupted) {
      status = 130;
      stopReason = "interrupted";
      failure = "SIGINT or SIGTERM before frame " + std::to_string(loop.status().frame + 1);
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
  input.closeLive();
  console.clearBar();

  // Finish the files: the PNGs (and exports, video) queued, then the manifest.
  RunReport report;
  if (writer) {
    try {
      report.written = writer->finish();
    } catch (const std::exception& e) {
      report.written = writer->written();
      if (status == 0 || status == 130) {
        failure = e.what();
        stopReason = "error";
        status = 1;
      }
    }
    const FrameWriterCounts counts = writer->counts();
    report.exports = counts.exports;
    report.videoFrames = counts.videoFrames;
    try {
      if (!videoName.empty() && counts.videoFrames > 0)
        if (const auto h = hashFile(a.video)) journal->note(videoName, "", *h);
    } catch (const std::exception& e) {
      if (status == 0 || status == 130) {
        failure = e.what();
        stopReason = "error";
        status = 1;
      }
    }
  }
  report.wall = console.wall();
  if (status == 3 || status == 1) std::fprintf(stderr, "error: %s\n", failure.c_str());
  if (manifest) {
    // Only the frames whose PNG exists (the writer writes in order and stops at its first error).
    // The files it wrote into the folder that are there whole (a failed write left none).
    std::vector<OwnedFile> files;
    for (const OwnedFile& f : journal->files()) {
      std::error_code ec;
      if (fs::is_regular_file(fs::symlink_status(fs::path(out) / f.name, ec))) files.push_back(f);
    }
    manifest->finish(report.written, files, status, stopReason, failure, loop.status().done);
    try {
      manifest->write(out);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "error: %s\n", e.what());
      if (status == 0) status = 1;
    }
  }
  report.status = status;
  report.frames = frames;
  report.out = out;
  report.images = a.images;
  if (a.exportFormat) report.exportExtension = exportExtension(*a.exportFormat);
  report.video = a.video;
  report.record = record->open() && !record->failed() ? record->path() : "";
  report.pending = input.pending();
  report.realtime = a.realtime;
  report.fps = scene.fps;
  report.exportSeconds = outputs.exportSeconds;
  report.profile = a.profile;
  report.stateHash = a.stateHash;
  report.density = outputs.density;
  report.loop = loop.status();
  console.summary(world, report);
  return status;
}

}  // namespace sph2d::cli
