// `sph2d run`: simulate a scene, render each frame, write PNGs in the background.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "cli.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/render/frame_writer.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace fs = std::filesystem;

namespace sph2d::cli {
namespace {

const char* kRunHelp =
    "Usage: sph2d run SCENE.json [options]\n"
    "\n"
    "Simulates SCENE and writes frame_00000.png, frame_00001.png, ... (frame k shows\n"
    "the state after k frames of 1/fps seconds).\n"
    "\n"
    "Options:\n"
    "  --out DIR       output directory (default: out/<scene name>)\n"
    "  --frames N      number of frames (default: the scene's duration × fps)\n"
    "  --threads T     simulation threads (default: all cores)\n"
    "  --no-images     simulate only; write no PNG\n"
    "  --state-hash    print 'state-hash: <16 hex digits>' (XXH64 of ids, positions,\n"
    "                  velocities) as the last line\n"
    "  --profile       print each stage's time and call count\n"
    "  --quiet         no progress lines\n"
    "  --help          this text\n";

struct RunArgs {
  std::string scene, out;
  int frames = -1, threads = 0;
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
    if (s == "--out") r.out = value();
    else if (s == "--frames") r.frames = parseInt(s, value(), 1, 10000000);
    else if (s == "--threads") r.threads = parseInt(s, value(), 1, 256);
    else if (s == "--no-images") r.images = false;
    else if (s == "--state-hash") r.stateHash = true;
    else if (s == "--profile") r.profile = true;
    else if (s == "--quiet") r.quiet = true;
    else if (!s.empty() && s[0] == '-') throw UsageError("unknown option '" + s + "' (see sph2d run --help)");
    else if (r.scene.empty()) r.scene = s;
    else throw UsageError("unexpected argument '" + s + "' (one scene per run)");
  }
  if (r.scene.empty()) throw UsageError("missing the scene file (see sph2d run --help)");
  return r;
}

}  // namespace

int cmdRun(const std::vector<std::string>& args) {
  for (const auto& s : args)
    if (s == "--help" || s == "-h") {
      std::fputs(kRunHelp, stdout);
      return 0;
    }
  const RunArgs a = parseRun(args);
  const SceneDef scene = loadScene(a.scene);
  const int frames = a.frames > 0 ? a.frames : std::max(1, int(std::lround(scene.duration * scene.fps)));
  const std::string out = a.out.empty() ? "out/" + scene.name : a.out;
  if (a.images) {
    std::error_code ec;
    fs::create_directories(out, ec);
    if (ec || !fs::is_directory(out)) throw UsageError("cannot create the output directory '" + out + "': " + ec.message());
    if (::access(out.c_str(), W_OK) != 0) throw UsageError("the output directory '" + out + "' is not writable");
  }

  installStopHandler();
  const auto t0 = std::chrono::steady_clock::now();
  World world(scene, WorldOptions{a.threads});
  for (const auto& w : world.takeWarnings()) std::fprintf(stderr, "warning: %s\n", w.c_str());
  std::unique_ptr<Renderer> renderer;
  std::unique_ptr<FrameWriter> writer;
  if (a.images) {
    renderer = std::make_unique<Renderer>(scene.render);
    writer = std::make_unique<FrameWriter>(out);
  }
  const bool tty = ::isatty(STDOUT_FILENO);
  double simSeconds = 0, renderSeconds = 0;
  auto lastReport = std::chrono::steady_clock::now();
  int done = 0;
  int status = 0;
  std::string failure;
  try {
    for (int f = 0; f < frames; ++f) {
      if (stopRequested.load()) {
        status = 130;
        break;
      }
      if (f > 0) {
        const auto s0 = std::chrono::steady_clock::now();
        world.stepFrame();
        simSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
        for (const auto& w : world.takeWarnings()) std::fprintf(stderr, "warning: %s\n", w.c_str());
      }
      if (renderer) {
        const auto r0 = std::chrono::steady_clock::now();
        const Frame& fr = renderer->render(world);
        renderSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
        writer->push(f, fr.width, fr.height, fr.rgba);
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
    status = 3;
  }
  if (tty && !a.quiet) std::printf("\n");
  int written = 0;
  if (writer) {
    try {
      written = writer->finish();
    } catch (const std::exception& e) {
      written = writer->written();
      std::fprintf(stderr, "error: %s\n", e.what());
      if (status == 0) status = 1;
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (status == 3) std::fprintf(stderr, "error: %s\n", failure.c_str());
  if (status == 130) std::fprintf(stderr, "interrupted: ");
  const DensityStats ds = world.densityStats();
  std::printf("sph2d: %d frames, %zu particles, %.3f simulated s, %.2f wall s (simulation %.2f s, rendering %.2f s), "
              "mean density error %.2f%%, %d PNG files in %s\n",
              done, world.particleCount(), world.time(), wall, simSeconds, renderSeconds, 100 * ds.meanError, written,
              a.images ? out.c_str() : "(none)");
  if (a.profile) printProfile(world);
  if (a.stateHash) std::printf("state-hash: %s\n", hex64(world.stateHash()).c_str());
  return status;
}

}  // namespace sph2d::cli
