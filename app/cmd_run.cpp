// `sph2d run`: simulate a scene, render the kept frames, write PNGs (and exports,
// a video) in the background, and a manifest.json of per-frame hashes.
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "cli.hpp"
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

const char* kRenderFlagsHelp =
    "  --mode M        liquid (default: the scene's) or particles\n"
    "  --color-by F    particles mode: speed (default), pressure, density or age\n"
    "  --range LO,HI   particles mode: fixed colour range (default: each frame's min..max)\n"
    "  --overlay       draw frame number, simulated time and particle count\n"
    "  --foam-speed V  liquid: foam starts at V m/s, full at 2V (default 0.35·sqrt(g·view height))\n"
    "  --depth-scale D liquid: D metres of water above darken the colour by 1/e (default 1)\n";

namespace {

const char* kRunHelp =
    "Usage: sph2d run SCENE.json [options]\n"
    "\n"
    "Simulates SCENE and writes frame_00000.png, frame_00001.png, ... (frame k shows\n"
    "the state after k frames of 1/fps seconds) and manifest.json (per-frame hashes of\n"
    "the pixels and of the state, for `sph2d check`).\n"
    "\n"
    "Options:\n"
    "  --out DIR       output directory (default: out/<scene name>)\n"
    "  --frames N      number of frames (default: the scene's duration × fps)\n"
    "  --every K       keep every K-th frame (0, K, 2K, ...; default 1)\n"
    "  --threads T     simulation threads (default: all cores)\n"
    "  --png-level N   PNG compression 0..9 (default 1: fast)\n"
    "  --export FMT    also write each kept frame's particles: csv, vtk (binary) or vtk-ascii\n"
    "  --video FILE    also encode the kept frames into FILE with ffmpeg (must be installed)\n"
    "%s"
    "  --no-images     simulate only; write no PNG and no manifest\n"
    "  --state-hash    print 'state-hash: <16 hex digits>' (XXH64 of ids, positions,\n"
    "                  velocities) as the last line\n"
    "  --profile       print each stage's time and call count\n"
    "  --quiet         no progress lines\n"
    "  --help          this text\n";

struct RunArgs {
  std::string scene, out, video;
  int frames = -1, threads = 0, every = 1, pngLevel = 1;
  std::optional<ExportFormat> exportFormat;
  RenderOptions render;
  bool images = true, stateHash = false, profile = false, quiet = false;
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
    } else if (s == "--no-images") r.images = false;
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

double parseNumber(const std::string& flag, const std::string& v) {
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  if (v.empty() || *end || !std::isfinite(x)) throw UsageError(flag + " expects a number, got '" + v + "'");
  return x;
}

std::string frameName(int f) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.png", f);
  return name;
}

}  // namespace

bool parseRenderFlag(const std::vector<std::string>& a, std::size_t& i, RenderOptions& o) {
  const std::string& s = a[i];
  auto value = [&]() -> std::string {
    if (i + 1 >= a.size()) throw UsageError(s + " needs a value");
    return a[++i];
  };
  if (s == "--mode") {
    o.mode = value();
    if (o.mode != "liquid" && o.mode != "particles")
      throw UsageError("--mode expects liquid or particles, got '" + o.mode + "'");
  } else if (s == "--color-by") {
    const std::string v = value();
    if (!parseColorField(v, o.colorBy))
      throw UsageError("--color-by expects speed, pressure, density or age, got '" + v + "'");
  } else if (s == "--range") {
    const std::string v = value();
    const auto c = v.find(',');
    if (c == std::string::npos) throw UsageError("--range expects LO,HI, got '" + v + "'");
    const double lo = parseNumber(s, v.substr(0, c)), hi = parseNumber(s, v.substr(c + 1));
    if (!(hi > lo)) throw UsageError("--range needs HI > LO, got '" + v + "'");
    o.range = std::array<double, 2>{lo, hi};
  } else if (s == "--overlay") {
    o.overlay = true;
  } else if (s == "--foam-speed") {
    o.foamSpeed = parseNumber(s, value());
    if (!(o.foamSpeed > 0)) throw UsageError("--foam-speed must be > 0");
  } else if (s == "--depth-scale") {
    o.depthScale = parseNumber(s, value());
    if (!(o.depthScale > 0)) throw UsageError("--depth-scale must be > 0");
  } else {
    return false;
  }
  return true;
}

json renderOptionsJson(const RenderOptions& o) {
  json j;
  j["mode"] = o.mode;
  j["color_by"] = colorFieldName(o.colorBy);
  j["range"] = o.range ? json::array({(*o.range)[0], (*o.range)[1]}) : json(nullptr);
  j["overlay"] = o.overlay;
  j["foam_speed"] = o.foamSpeed;
  j["depth_scale"] = o.depthScale;
  return j;
}

RenderOptions renderOptionsFromJson(const json& j) {
  RenderOptions o;
  try {
    o.mode = j.at("mode").get<std::string>();
    if (!parseColorField(j.at("color_by").get<std::string>(), o.colorBy)) throw UsageError("bad color_by");
    if (!j.at("range").is_null()) o.range = std::array<double, 2>{j.at("range").at(0).get<double>(), j.at("range").at(1).get<double>()};
    o.overlay = j.at("overlay").get<bool>();
    o.foamSpeed = j.at("foam_speed").get<double>();
    o.depthScale = j.at("depth_scale").get<double>();
  } catch (const json::exception& e) {
    throw UsageError(std::string("the manifest's render options are malformed: ") + e.what());
  }
  return o;
}

std::string fileHash(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UsageError("cannot read " + path);
  std::ostringstream ss;
  ss << in.rdbuf();
  const std::string bytes = ss.str();
  return hex64(xxh64(bytes.data(), bytes.size()));
}

json environmentJson() {
  json env = json::array();
  for (const EnvSetting& e : pinRenderEnvironment())
    env.push_back({{"name", e.name}, {"value", e.value}, {"source", e.source}});
  return env;
}

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

  installStopHandler();
  std::signal(SIGPIPE, SIG_IGN);  // a dead ffmpeg shows up as EPIPE, not as a kill
  const auto t0 = std::chrono::steady_clock::now();
  World world(scene, WorldOptions{a.threads});
  for (const auto& w : world.takeWarnings()) std::fprintf(stderr, "warning: %s\n", w.c_str());
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
                       {"video", a.video}};
    manifest["frames"] = json::array();
  }
  const bool tty = ::isatty(STDOUT_FILENO);
  double simSeconds = 0, renderSeconds = 0;
  auto lastReport = std::chrono::steady_clock::now();
  int done = 0;
  int status = 0;
  std::string failure, stopReason;
  try {
    for (int f = 0; f < frames; ++f) {
      if (stopRequested.load()) {
        status = 130;
        stopReason = "interrupted";
        failure = "SIGINT or SIGTERM before frame " + std::to_string(f);
        break;
      }
      if (f > 0) {
        const auto s0 = std::chrono::steady_clock::now();
        world.stepFrame();
        simSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
        for (const auto& w : world.takeWarnings()) std::fprintf(stderr, "warning: %s\n", w.c_str());
      }
      if (renderer && f % a.every == 0) {
        const auto r0 = std::chrono::steady_clock::now();
        const Frame& fr = renderer->render(world);
        const std::uint64_t pixels = xxh64(fr.rgba.data(), fr.rgba.size());
        std::shared_ptr<const ParticleSnapshot> snap;
        if (a.exportFormat) snap = std::make_shared<ParticleSnapshot>(snapshotOf(world));
        renderSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
        writer->push(f, fr.width, fr.height, fr.rgba, snap);
        manifest["frames"].push_back({{"frame", f},
                                      {"time", world.time()},
                                      {"file", frameName(f)},
                                      {"rgba_xxh64", hex64(pixels)},
                                      {"state_hash", hex64(world.stateHash())}});
      }
      done = f + 1;
      const auto now = std::chrono::steady_clock::now();
      if (!a.quiet && (now - lastReport > std::chrono::seconds(tty ? 0 : 5) || done == frames)) {
        lastReport = now;
        const double wall = std::chrono::duration<double>(now - t0).count();
        const double fps = done / std::max(wall, 1e-9);
        if (tty)
          std::printf("\rframe %d/%d  t = %.3f s  %.1f frames/s  ETA %.0f s   ", done, frames, world.time(), fps,
                      (frames - done) / std::max(fps, 1e-9));
        else
          std::printf("frame %d/%d  t = %.3f s  %.1f frames/s\n", done, frames, world.time(), fps);
        std::fflush(stdout);
      }
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
  if (tty && !a.quiet) std::printf("\n");
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
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
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
  const DensityStats ds = world.densityStats();
  std::printf("sph2d: %d frames, %zu particles, %.3f simulated s, %.2f wall s (simulation %.2f s, rendering %.2f s), "
              "mean density error %.2f%%, %d PNG files in %s\n",
              done, world.particleCount(), world.time(), wall, simSeconds, renderSeconds, 100 * ds.meanError, written,
              a.images ? out.c_str() : "(none)");
  if (counts.exports) std::printf("sph2d: %d particle files (%s) in %s\n", counts.exports,
                                  exportExtension(*a.exportFormat).c_str(), out.c_str());
  if (counts.videoFrames) std::printf("sph2d: %d frames encoded into %s\n", counts.videoFrames, a.video.c_str());
  if (a.profile) printProfile(world);
  if (a.stateHash) std::printf("state-hash: %s\n", hex64(world.stateHash()).c_str());
  return status;
}

}  // namespace sph2d::cli
