// `sph2d check`: rerun a scene and compare every frame's pixel hash with a manifest
// written by `sph2d run`; on the first difference, count the differing pixels
// against the reference PNG beside the manifest and write a diff image.
#include <algorithm>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "cli.hpp"
#include "commands.hpp"
#include "events.hpp"
#include "manifest.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/render/png_io.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

namespace sph2d::cli {
namespace {

const char* kCheckHelp =
    "Usage: sph2d check SCENE.json --against MANIFEST [--out DIR] [--threads T] [--quiet]\n"
    "\n"
    "Reruns SCENE with the frame count, frame step and render options recorded in\n"
    "MANIFEST (a manifest.json written by `sph2d run`) and compares each frame's\n"
    "RGBA hash. Exit 0 when every frame matches. Otherwise names the first differing\n"
    "frame, counts its differing pixels and the largest channel difference against the\n"
    "reference PNG beside MANIFEST, writes DIR/frame_NNNNN.png (this run) and\n"
    "DIR/diff_NNNNN.png (differences in red over a dimmed reference), and exits 1.\n"
    "The events the manifest lists (the run's timeline, --input files and live input)\n"
    "are applied at their frames, so runs driven by input check like any other.\n"
    "Mesa settings the manifest recorded (GALLIUM_OVERRIDE_CPU_CAPS, ...) are used\n"
    "unless set in this environment; a different renderer or CPU is named plainly.\n"
    "\n"
    "Options:\n"
    "  --against FILE  the manifest (required)\n"
    "  --out DIR       where the diff image goes (default: out/check-<scene name>)\n"
    "  --threads T     simulation threads (default: all cores; frames do not depend on it)\n"
    "  --quiet         print only the verdict\n";

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

}  // namespace

int cmdCheck(const std::vector<std::string>& args) {
  std::string scenePath, manifestPath, out;
  int threads = 0;
  bool quiet = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& s = args[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= args.size()) throw UsageError(s + " needs a value");
      return args[++i];
    };
    if (s == "--help" || s == "-h") {
      std::fputs(kCheckHelp, stdout);
      return 0;
    }
    if (s == "--against") manifestPath = value();
    else if (s == "--out") out = value();
    else if (s == "--threads") threads = parseInt(s, value(), 1, 256);
    else if (s == "--quiet") quiet = true;
    else if (!s.empty() && s[0] == '-') throw UsageError("unknown option '" + s + "' (see sph2d check --help)");
    else if (scenePath.empty()) scenePath = s;
    else throw UsageError("unexpected argument '" + s + "'");
  }
  if (scenePath.empty()) throw UsageError("missing the scene file (see sph2d check --help)");
  if (manifestPath.empty()) throw UsageError("missing --against MANIFEST (see sph2d check --help)");

  json m;
  {
    std::ifstream in(manifestPath);
    if (!in) throw UsageError("cannot read the manifest " + manifestPath);
    try {
      in >> m;
    } catch (const json::exception& e) {
      throw UsageError(manifestPath + " is not valid JSON: " + e.what());
    }
  }
  int frames = 0, every = 1;
  std::map<int, json> expected;
  std::string expRenderer, expCpu, expSceneHash;
  RenderOptions opt;
  try {
    if (m.at("format").get<std::string>() != "sph2d-frames") throw UsageError(manifestPath + " is not an sph2d frames manifest");
    frames = m.at("run").at("frames").get<int>();
    every = std::max(1, m.at("run").at("every").get<int>());
    expRenderer = m.at("renderer").get<std::string>();
    expCpu = m.value("cpu", "");
    expSceneHash = m.at("scene").at("xxh64").get<std::string>();
    opt = renderOptionsFromJson(m.at("render"));
    for (const json& f : m.at("frames")) expected[f.at("frame").get<int>()] = f;
  } catch (const json::exception& e) {
    throw UsageError(manifestPath + " lacks a field `sph2d check` needs: " + e.what());
  }
  if (expected.empty()) {
    std::printf("check: %s lists no frames; nothing to compare\n", manifestPath.c_str());
    return 1;
  }
  const SceneDef scene = loadScene(scenePath);
  if (out.empty()) out = "out/check-" + scene.name;
  const fs::path refDir = fs::path(manifestPath).parent_path();

  const std::string sceneHash = fileHash(scenePath);
  if (sceneHash != expSceneHash)
    std::printf("note: %s has XXH64 %s but the manifest was made from a file with %s: the scene changed, "
                "frames will likely differ\n",
                scenePath.c_str(), sceneHash.c_str(), expSceneHash.c_str());
  if (m.value("complete", true) == false && m.contains("stop") && m["stop"].is_object())
    std::printf("note: the manifest's run stopped early (%s: %s); checking the %zu frames it lists\n",
                m["stop"].value("reason", "?").c_str(), m["stop"].value("message", "").c_str(), expected.size());

  // Rerun as the manifest's run rendered: adopt the Mesa settings it recorded (e.g. a pinned
  // GALLIUM_OVERRIDE_CPU_CAPS) unless this environment sets them itself.
  if (m.contains("environment") && m["environment"].is_array())
    for (const json& e : m["environment"]) {
      const std::string name = e.value("name", ""), value = e.value("value", "");
      if (name.empty() || value.empty() || std::getenv(name.c_str())) continue;
      setenv(name.c_str(), value.c_str(), 0);
      if (!quiet && e.value("source", "") == "user")
        std::printf("note: using %s=%s as the manifest's run did\n", name.c_str(), value.c_str());
    }
  // The events the manifest's run applied, at their frames (a manifest without an event list:
  // the scene's own timeline).
  std::map<std::int64_t, std::vector<EventDef>> events;
  if (m.contains("events") && m["events"].is_array()) {
    for (std::size_t k = 0; k < m["events"].size(); ++k) {
      try {
        const EventDef e = parseEvent(m["events"][k].dump(), manifestPath + " events[" + std::to_string(k) + "]", 1, scene);
        events[eventFrame(e, scene.fps)].push_back(e);
      } catch (const SceneError& e) {
        throw UsageError(std::string("the manifest's event is malformed: ") + e.what());
      }
    }
  } else {
    for (const EventDef& e : scene.events) events[eventFrame(e, scene.fps)].push_back(e);
  }
  EventApplier applier;
  World world(scene, WorldOptions{threads});
  world.takeWarnings();
  Renderer renderer(scene.render, opt);
  const std::string here = renderer.rendererString();
  if (here != expRenderer)
    std::printf("note: this machine's renderer is \"%s\" but the manifest was made with \"%s\"; "
                "pixels may differ for that reason alone\n",
                here.c_str(), expRenderer.c_str());
  const std::string cpu = cpuSummary();
  if (!expCpu.empty() && cpu != expCpu)
    std::printf("note: this CPU is \"%s\"; the manifest's was \"%s\"\n", cpu.c_str(), expCpu.c_str());
  if (m.contains("environment") && m["environment"].is_array()) {
    std::map<std::string, std::string> now;
    for (const EnvSetting& e : pinRenderEnvironment()) now[e.name] = e.value;
    for (const json& e : m["environment"]) {
      const std::string name = e.value("name", ""), value = e.value("value", "");
      if (now.count(name) && now[name] != value)
        std::printf("note: %s is \"%s\" here but was \"%s\" for the manifest\n", name.c_str(), now[name].c_str(),
                    value.c_str());
    }
  }
  if (!quiet) std::printf("check: rerunning %s, %d frames, comparing %zu\n", scenePath.c_str(), frames, expected.size());

  const int last = expected.rbegin()->first;
  int compared = 0;
  try {
    for (int f = 0; f <= last && f < frames; ++f) {
      if (f > 0) world.stepFrame();
      if (events.count(f))
        for (const EventDef& e : events[f]) {
          const std::string err = applier.apply(world, e);
          if (!err.empty()) std::printf("note: frame %d: %s not applied: %s\n", f, describeEvent(e).c_str(), err.c_str());
        }
      world.takeWarnings();
      if (f % every != 0 || !expected.count(f)) continue;
      const json& e = expected[f];
      const Frame& fr = renderer.render(world);
      const std::string got = hex64(xxh64(fr.rgba.data(), fr.rgba.size()));
      const std::string state = hex64(world.stateHash());
      const std::string want = e.value("rgba_xxh64", ""), wantState = e.value("state_hash", "");
      ++compared;
      if (got == want) continue;

      std::printf("check: frame %d differs: RGBA XXH64 %s here, %s in the manifest\n", f, got.c_str(), want.c_str());
      std::printf("check: state hash %s\n", state == wantState
                                               ? "matches: the simulation agrees, the rendering differs"
                                               : ("differs too (" + state + " vs " + wantState + "): the simulation changed").c_str());
      std::error_code ec;
      fs::create_directories(out, ec);
      char name[64];
      std::snprintf(name, sizeof name, "frame_%05d.png", f);
      const std::string mine = out + "/" + name;
      writePngAtomic(mine, fr.width, fr.height, fr.rgba.data(), 1);
      const std::string refPath = (refDir / e.value("file", std::string(name))).string();
      int rw = 0, rh = 0;
      std::vector<std::uint8_t> ref;
      try {
        readPng(refPath, rw, rh, ref);
      } catch (const std::exception& ex) {
        std::printf("check: no readable reference image (%s); cannot count pixels. This run's frame: %s\n", ex.what(),
                    mine.c_str());
        return 1;
      }
      if (rw != fr.width || rh != fr.height) {
        std::printf("check: the reference %s is %dx%d, this run renders %dx%d. This run's frame: %s\n", refPath.c_str(),
                    rw, rh, fr.width, fr.height, mine.c_str());
        return 1;
      }
      if (hex64(xxh64(ref.data(), ref.size())) != want)
        std::printf("note: the reference %s does not match its own manifest hash either\n", refPath.c_str());
      Frame diff;
      const PixelDiff d = diffImages(fr, ref, diff);
      std::snprintf(name, sizeof name, "diff_%05d.png", f);
      const std::string diffPath = out + "/" + name;
      writePngAtomic(diffPath, diff.width, diff.height, diff.rgba.data(), 1);
      std::printf("check: frame %d: %zu of %d pixels differ (%.4f %%), max channel difference %d (first at x %d, y %d)\n",
                  f, d.differing, fr.width * fr.height, 100.0 * double(d.differing) / double(fr.width * fr.height),
                  d.maxDiff, d.firstX, d.firstY);
      std::printf("check: wrote %s (this run) and %s (differing pixels in red)\n", mine.c_str(), diffPath.c_str());
      std::printf("check: FAILED at frame %d (%d frames matched before it)\n", f, compared - 1);
      return 1;
    }
  } catch (const SimulationError& e) {
    std::printf("check: the simulation stopped: %s\n", e.what());
    const bool expectedStop = m.contains("stop") && m["stop"].is_object() && m["stop"].value("reason", "") == "guard";
    std::printf("check: %s after %d matching frames\n", expectedStop ? "as in the manifest's run" : "FAILED", compared);
    return expectedStop && compared == int(expected.size()) ? 0 : 1;
  }
  if (compared != int(expected.size())) {
    std::printf("check: FAILED: compared %d frames, the manifest lists %zu\n", compared, expected.size());
    return 1;
  }
  std::printf("check: OK, %d frames match (%dx%d, %s mode, renderer %s)\n", compared, scene.render.width,
              scene.render.height, renderer.mode().c_str(), here.c_str());
  return 0;
}

}  // namespace sph2d::cli
