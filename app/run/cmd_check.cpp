// `sph2d check`: rerun a scene and compare every frame's pixel hash with a manifest
// written by `sph2d run`; on the first difference, count the differing pixels
// against the reference PNG beside the manifest and write a diff image. The rerun
// is run's own GameLoop (headless), fed the events the manifest lists at their
// frames, so a run driven by input checks like any other.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <regex>
#include <string>
#include <utility>

#include "cli.hpp"
#include "commands.hpp"
#include "loop/event_intake.hpp"
#include "loop/game_loop.hpp"
#include "output/manifest.hpp"
#include "output/output_dir.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/render/particle_export.hpp"
#include "sph2d/render/png_io.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

namespace sph2d::cli {
namespace {

const char* kCheckHelp =
    "Usage: sph2d check SCENE.json --against MANIFEST [--out DIR] [--threads T] [--adopt-env] [--files]\n"
    "                   [--quiet]\n"
    "\n"
    "Reruns SCENE with the frame count, frame step and render options recorded in\n"
    "MANIFEST (a manifest.json written by `sph2d run`) and compares each frame's\n"
    "RGBA hash and state hash, after checking that the manifest's frame list is the\n"
    "run's (a malformed manifest exits 2). Exit 0 when every frame matches. Otherwise names the first differing\n"
    "frame, counts its differing pixels and the largest channel difference against the\n"
    "reference PNG beside MANIFEST, writes DIR/frame_NNNNN.png (this run) and\n"
    "DIR/diff_NNNNN.png (differences in red over a dimmed reference), and exits 1.\n"
    "Those replace only the images an earlier check wrote in DIR (DIR/.sph2d.journal lists\n"
    "them with their hashes): a frame_NNNNN.png or diff_NNNNN.png there that sph2d cannot\n"
    "prove it wrote is never touched, and the check exits 2 naming it before it reruns.\n"
    "The events the manifest lists (the run's timeline, --input files and live input)\n"
    "are applied at their frames, so runs driven by input check like any other.\n"
    "The manifest's environment is compared with this one, never trusted: only the\n"
    "Mesa settings sph2d itself records (GALLIUM_OVERRIDE_CPU_CAPS, LP_NUM_THREADS, ...)\n"
    "are read, each difference is named, and --adopt-env uses the manifest's values of\n"
    "those (where this environment does not set them); any other entry is ignored and\n"
    "named. A different renderer or CPU is named plainly.\n"
    "\n"
    "Options:\n"
    "  --against FILE  the manifest (required)\n"
    "  --adopt-env     render with the Mesa settings the manifest recorded (see above)\n"
    "  --files         also check the PNG files beside the manifest: each listed frame's\n"
    "                  file decodes to its recorded hash, and no other frame_*.png is there\n"
    "  --out DIR       where the diff image goes (default: out/check-<scene name>)\n"
    "  --threads T     simulation threads (default: all cores but one, which draws; frames do\n"
    "                  not depend on it)\n"
    "  --quiet         print only the verdict\n";

/// What `sph2d check` writes into its --out folder: this run's frame_NNNNN.png and diff_NNNNN.png.
FolderSpec checkFolderSpec() {
  FolderSpec spec;
  spec.command = "check";
  spec.writes = [](const std::string& name) {
    static const std::regex mine(R"((frame|diff)_\d{5,}\.png)");
    return std::regex_match(name, mine);
  };
  return spec;
}

struct PixelDiff {
  std::size_t differing = 0;
  int maxDiff = 0;
  int firstX = -1, firstY = -1;
};

PixelDiff diffImages(const Frame& got, const std::vector<std::uint8_t>& ref, Frame& diffImage) {
  PixelDiff d;
  diffImage = got;
  for (std::size_t p = 0; p < got.rgba.size(); p += 4) {
    int m = 0;
    for (int c = 0; c < 4; ++c) m = std::max(m, std::abs(int(got.rgba[p + c]) - int(ref[p + c])));
    const int luma = (int(ref[p]) * 3 + int(ref[p + 1]) * 6 + int(ref[p + 2])) / 10;
    std::uint8_t* q = &diffImage.rgba[p];
    if (m) {
      if (!d.differing) {
        d.firstX = int((p / 4) % std::size_t(got.width));
        d.firstY = int((p / 4) / std::size_t(got.width));
      }
      ++d.differing;
      d.maxDiff = std::max(d.maxDiff, m);
      q[0] = std::uint8_t(std::min(255, 160 + 24 * m));
      q[1] = 0;
      q[2] = 0;
    } else {
      q[0] = q[1] = q[2] = std::uint8_t(luma / 3);
    }
    q[3] = 255;
  }
  return d;
}

/// Compares each kept frame of the rerun with the manifest; stops at the first difference
/// after writing this run's frame and a diff image.
class FrameCheck : public LoopObserver {
 public:
  FrameCheck(const ManifestView& m, const std::string& out, const fs::path& refDir)
      : m_(m), out_(out), refDir_(refDir) {}

  void warn(const std::string&) override {}
  void note(const std::string&) override {}
  void applied(const TimedEvent&, std::int64_t) override {}
  void notApplied(const TimedEvent& t, std::int64_t frame, const std::string& why) override {
    std::printf("note: frame %d: %s not applied: %s\n", int(frame), describeEvent(t.event).c_str(), why.c_str());
  }
  bool keeps(std::int64_t frame) override { return frame % m_.every == 0 && m_.expected.count(int(frame)); }
  bool frame(const FrameState& state, const Frame& fr) override {
    const int f = int(state.frame);
    const json& e = m_.expected.at(f);
    const std::string got = hex64(xxh64(fr.rgba.data(), fr.rgba.size()));
    const std::string want = e.value("rgba_xxh64", "");
    const std::string stateHash = hex64(state.stateHash), wantState = e.value("state_hash", "");
    ++compared;
    if (got == want && stateHash == wantState) return true;
    failed = true;
    if (got == want) {  // the pixels agree, the simulation does not: both hashes must match
      std::printf(
          "check: frame %d: the pixels match but the state hash differs (%s here, %s in the manifest): the "
          "simulation changed\n",
          f, stateHash.c_str(), wantState.c_str());
      std::printf("check: FAILED at frame %d (%d frames matched before it)\n", f, compared - 1);
      return false;
    }
    std::printf("check: frame %d differs: RGBA XXH64 %s here, %s in the manifest\n", f, got.c_str(), want.c_str());
    std::printf("check: state hash %s\n",
                stateHash == wantState
                    ? "matches: the simulation agrees, the rendering differs"
                    : ("differs too (" + stateHash + " vs " + wantState + "): the simulation changed").c_str());
    // The folder: this check's files replace an earlier check's (proven by its journal); a
    // file there that sph2d cannot prove it wrote stops the check (exit 2), untouched.
    makeOutputDir(out_);
    OutputLock lock(out_);
    const FolderSpec spec = checkFolderSpec();
    const FolderScan scan = scanOutputFolder(out_, spec);
    refuseForeignFiles(out_, scan, spec);
    const std::vector<std::string> removed = removeOwnFiles(out_, scan, [](const std::string&) { return true; });
    if (!removed.empty())
      std::printf("check: removed %s that an earlier sph2d check wrote in %s\n", describeFiles(removed).c_str(),
                  out_.c_str());
    OutputJournal journal(out_, spec.command, {});
    auto write = [&](const std::string& path, const Frame& image) {
      std::vector<std::uint8_t> bytes;
      encodePng(image.width, image.height, image.rgba.data(), pngSettings(1), bytes);
      journal.note(fs::path(path).filename().string(), fs::path(tempPathFor(path)).filename().string(),
                   xxh64(bytes.data(), bytes.size()));
      writeEncodedPngAtomic(path, bytes);
    };
    const std::string name = frameFileName(f);
    const std::string mine = out_ + "/" + name;
    write(mine, fr);
    const std::string refPath = (refDir_ / e.value("file", name)).string();
    int rw = 0, rh = 0;
    std::vector<std::uint8_t> ref;
    try {
      readPng(refPath, rw, rh, ref);
    } catch (const std::exception& ex) {
      std::printf("check: no readable reference image (%s); cannot count pixels. This run's frame: %s\n", ex.what(),
                  mine.c_str());
      return false;
    }
    if (rw != fr.width || rh != fr.height) {
      std::printf("check: the reference %s is %dx%d, this run renders %dx%d. This run's frame: %s\n", refPath.c_str(),
                  rw, rh, fr.width, fr.height, mine.c_str());
      return false;
    }
    if (hex64(xxh64(ref.data(), ref.size())) != want)
      std::printf("note: the reference %s does not match its own manifest hash either\n", refPath.c_str());
    Frame diff;
    const PixelDiff d = diffImages(fr, ref, diff);
    char diffName[64];
    std::snprintf(diffName, sizeof diffName, "diff_%05d.png", f);
    const std::string diffPath = out_ + "/" + diffName;
    write(diffPath, diff);
    std::printf("check: frame %d: %zu of %d pixels differ (%.4f %%), max channel difference %d (first at x %d, y %d)\n",
                f, d.differing, fr.width * fr.height, 100.0 * double(d.differing) / double(fr.width * fr.height),
                d.maxDiff, d.firstX, d.firstY);
    std::printf("check: wrote %s (this run) and %s (differing pixels in red)\n", mine.c_str(), diffPath.c_str());
    std::printf("check: FAILED at frame %d (%d frames matched before it)\n", f, compared - 1);
    return false;
  }

  int compared = 0;     ///< frames rendered and compared
  bool failed = false;  ///< a frame differed

 private:
  const ManifestView& m_;
  std::string out_;
  fs::path refDir_;
};

/// --files: every listed frame's PNG beside the manifest decodes to its recorded hash, and
/// no frame_*.png there is unlisted (a stale frame of another run). Prints each problem.
bool checkFiles(const ManifestView& mv, const fs::path& dir) {
  int bad = 0;
  for (const auto& [frame, e] : mv.expected) {
    const fs::path file = dir / frameFileName(frame);
    int w = 0, h = 0;
    std::vector<std::uint8_t> rgba;
    try {
      readPng(file.string(), w, h, rgba);
    } catch (const std::exception& ex) {
      std::printf("check: %s: %s\n", file.string().c_str(), ex.what());
      ++bad;
      continue;
    }
    const std::string got = hex64(xxh64(rgba.data(), rgba.size()));
    if (got != e.value("rgba_xxh64", "")) {
      std::printf("check: %s decodes to RGBA XXH64 %s, the manifest says %s\n", file.string().c_str(), got.c_str(),
                  e.value("rgba_xxh64", "").c_str());
      ++bad;
    }
  }
  std::error_code ec;
  std::vector<std::string> stale;
  for (const auto& entry : fs::directory_iterator(dir.empty() ? fs::path(".") : dir, ec)) {
    const std::string name = entry.path().filename().string();
    int frame = -1;
    char tail = 0;
    if (std::sscanf(name.c_str(), "frame_%d.pn%c", &frame, &tail) == 2 && tail == 'g' && name == frameFileName(frame) &&
        !mv.expected.count(frame))
      stale.push_back(name);
  }
  std::sort(stale.begin(), stale.end());
  if (!stale.empty()) {
    std::printf("check: %zu frame file%s beside the manifest %s not listed in it (another run's?): %s%s\n",
                stale.size(), stale.size() == 1 ? "" : "s", stale.size() == 1 ? "is" : "are", stale.front().c_str(),
                stale.size() > 1 ? " ..." : "");
    bad += int(stale.size());
  }
  if (bad) std::printf("check: FAILED: %d problem%s with the files beside the manifest\n", bad, bad == 1 ? "" : "s");
  return bad == 0;
}

/// The events the manifest's run applied, at their frames (a manifest without an event
/// list: the scene's own timeline).
void addManifestEvents(EventIntake& input, const json& m, const std::string& manifestPath, const SceneDef& scene) {
  if (!m.contains("events") || !m["events"].is_array()) {
    input.addScene();
    return;
  }
  for (std::size_t k = 0; k < m["events"].size(); ++k) {
    const std::string where = manifestPath + " events[" + std::to_string(k) + "]";
    try {
      TimedEvent t;
      t.event = parseEvent(m["events"][k].dump(), where, 1, scene);
      t.frame = eventFrame(t.event, scene.fps);
      t.where = where;
      input.add(std::move(t));
    } catch (const SceneError& e) {
      throw UsageError(std::string("the manifest's event is malformed: ") + e.what());
    }
  }
}

}  // namespace

int cmdCheck(const std::vector<std::string>& args) {
  std::string scenePath, manifestPath, out;
  int threads = 0;
  bool quiet = false, adoptEnv = false, files = false;
  for (ArgReader opt(args, "check"); opt.next();) {
    const std::string s = opt.arg();
    if (opt.help()) {
      std::fputs(kCheckHelp, stdout);
      return 0;
    }
    if (opt.is("--against"))
      manifestPath = opt.value();
    else if (opt.is("--out"))
      out = opt.value();
    else if (opt.is("--threads"))
      threads = opt.intValue(1, 256);
    else if (opt.is("--quiet"))
      quiet = true;
    else if (opt.is("--adopt-env"))
      adoptEnv = true;
    else if (opt.is("--files"))
      files = true;
    else if (opt.option())
      opt.unknown();
    else if (scenePath.empty())
      scenePath = s;
    else
      opt.unexpected();
  }
  if (scenePath.empty()) throw UsageError("missing the scene file (see sph2d check --help)");
  if (manifestPath.empty()) throw UsageError("missing --against MANIFEST (see sph2d check --help)");

  const ManifestView mv = readManifest(manifestPath);
  const json& m = mv.json;
  if (mv.expected.empty()) {
    std::printf("check: %s lists no frames; nothing to compare\n", manifestPath.c_str());
    return 1;
  }
  if (!mv.listProblems.empty()) {
    for (const std::string& p : mv.listProblems) std::printf("check: FAILED: %s\n", p.c_str());
    return 1;
  }
  const SceneDef scene = loadScene(scenePath);
  if (out.empty()) out = "out/check-" + scene.name;
  {
    // Before the rerun: a folder it could not write its images into is refused now, not after it.
    const FolderSpec spec = checkFolderSpec();
    refuseForeignFiles(out, scanOutputFolder(out, spec), spec);
  }
  const fs::path refDir = fs::path(manifestPath).parent_path();
  if (files && !checkFiles(mv, refDir)) return 1;

  const std::string sceneHash = fileHash(scenePath);
  if (sceneHash != mv.sceneHash)
    std::printf(
        "note: %s has XXH64 %s but the manifest was made from a file with %s: the scene changed, "
        "frames will likely differ\n",
        scenePath.c_str(), sceneHash.c_str(), mv.sceneHash.c_str());
  if (m.value("complete", true) == false && m.contains("stop") && m["stop"].is_object())
    std::printf("note: the manifest's run stopped early (%s: %s); checking the %zu frames it lists\n",
                m["stop"].value("reason", "?").c_str(), m["stop"].value("message", "").c_str(), mv.expected.size());

  // The manifest's environment is input from elsewhere: only the variables sph2d records for
  // the renderer's identity are looked at, with plain values; with --adopt-env those are
  // used where this environment does not set them. Nothing else is ever set.
  const std::vector<ManifestEnv> env = manifestEnvironment(m);
  for (const ManifestEnv& e : env) {
    if (!e.problem.empty()) {
      std::printf("note: the manifest's environment entry %s is ignored: %s\n", e.name.c_str(), e.problem.c_str());
      continue;
    }
    if (!adoptEnv || e.value.empty() || std::getenv(e.name.c_str())) continue;
    setenv(e.name.c_str(), e.value.c_str(), 0);
    if (!quiet)
      std::printf("note: using %s=%s as the manifest's run did (--adopt-env)\n", e.name.c_str(), e.value.c_str());
  }
  EventIntake input(scene, [](const std::string&) {});
  addManifestEvents(input, m, manifestPath, scene);
  checkMemory(scene, true, 0);                                                     // before anything is allocated
  World world(scene, WorldOptions{threads ? threads : defaultStepThreads(true)});  // check draws, headless
  world.takeWarnings();
  Renderer renderer(scene.render, mv.render);
  const std::string here = renderer.rendererString();
  if (here != mv.renderer)
    std::printf(
        "note: this machine's renderer is \"%s\" but the manifest was made with \"%s\"; "
        "pixels may differ for that reason alone\n",
        here.c_str(), mv.renderer.c_str());
  const std::string cpu = cpuSummary();
  if (!mv.cpu.empty() && cpu != mv.cpu)
    std::printf("note: this CPU is \"%s\"; the manifest's was \"%s\"\n", cpu.c_str(), mv.cpu.c_str());
  {
    std::map<std::string, std::string> now;
    for (const EnvSetting& e : pinRenderEnvironment()) now[e.name] = e.value;
    for (const ManifestEnv& e : env)
      if (e.problem.empty() && now.count(e.name) && now[e.name] != e.value)
        std::printf("note: %s is \"%s\" here but was \"%s\" for the manifest%s\n", e.name.c_str(), now[e.name].c_str(),
                    e.value.c_str(), adoptEnv ? "" : " (--adopt-env uses the manifest's value)");
  }
  if (!quiet)
    std::printf("check: rerunning %s, %d frames, comparing %zu\n", scenePath.c_str(), mv.frames, mv.expected.size());

  // The rerun: run's loop, headless, up to the last listed frame.
  FrameCheck check(mv, out, refDir);
  LoopSettings settings;
  settings.frames = std::min(mv.frames, mv.expected.rbegin()->first + 1);
  settings.fps = scene.fps;
  GameLoop loop(world, input, check, &renderer, settings);
  try {
    loop.run();
  } catch (const SimulationError& e) {
    std::printf("check: the simulation stopped: %s\n", e.what());
    const bool expectedStop = m.contains("stop") && m["stop"].is_object() && m["stop"].value("reason", "") == "guard";
    std::printf("check: %s after %d matching frames\n", expectedStop ? "as in the manifest's run" : "FAILED",
                check.compared);
    return expectedStop && check.compared == int(mv.expected.size()) ? 0 : 1;
  }
  if (check.failed) return 1;
  if (check.compared != int(mv.expected.size())) {
    std::printf("check: FAILED: compared %d frames, the manifest lists %zu\n", check.compared, mv.expected.size());
    return 1;
  }
  std::printf("check: OK, %d frames match (%dx%d, %s mode, renderer %s)\n", check.compared, scene.render.width,
              scene.render.height, renderer.mode().c_str(), here.c_str());
  return 0;
}

}  // namespace sph2d::cli
