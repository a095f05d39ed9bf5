// sph2d — the command line: run a scene headless and write PNG frames.
//
// Exit codes: 0 success; 1 a runtime failure (output, OpenGL); 2 bad input
// (command line or scene file); 3 the simulation guard stopped the run;
// 130 interrupted (SIGINT/SIGTERM) — frames already written stay whole.
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "sph2d/hash.hpp"
#include "sph2d/render/frame_writer.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace fs = std::filesystem;
using namespace sph2d;

namespace {

std::atomic<bool> g_stop{false};
extern "C" void onSignal(int) { g_stop.store(true); }

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

const char* kMainHelp =
    "sph2d — real-time 2D SPH fluids against Box2D static boundaries, rendered off-screen.\n"
    "\n"
    "Usage:\n"
    "  sph2d run SCENE.json [options]   simulate a scene and write PNG frames\n"
    "  sph2d info SCENE.json            print what a scene will simulate\n"
    "  sph2d --help | COMMAND --help\n"
    "\n"
    "Exit codes: 0 ok, 1 runtime failure, 2 bad input, 3 simulation stopped by the guard, 130 interrupted.\n";

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

const char* kInfoHelp =
    "Usage: sph2d info SCENE.json [--threads T]\n"
    "\n"
    "Prints the scene's particles, solver, boundaries, frames and memory without running it.\n";

int parseInt(const std::string& flag, const std::string& v, int lo, int hi) {
  char* end = nullptr;
  errno = 0;
  const long x = std::strtol(v.c_str(), &end, 10);
  if (v.empty() || *end || errno || x < lo || x > hi)
    throw UsageError(flag + " expects an integer from " + std::to_string(lo) + " to " + std::to_string(hi) + ", got '" + v + "'");
  return int(x);
}

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

void printProfile(const World& w) {
  double total = 0;
  for (const auto& t : w.timings()) total += t.seconds;
  std::printf("%-10s %10s %10s %8s %7s\n", "stage", "calls", "seconds", "ms/call", "share");
  for (const auto& t : w.timings())
    std::printf("%-10s %10llu %10.3f %8.4f %6.1f%%\n", t.name.c_str(), (unsigned long long)t.calls, t.seconds,
                t.calls ? 1e3 * t.seconds / double(t.calls) : 0.0, total > 0 ? 100.0 * t.seconds / total : 0.0);
}

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

  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
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
      if (g_stop.load()) {
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

int cmdInfo(const std::vector<std::string>& args) {
  std::string path;
  int threads = 0;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--help" || args[i] == "-h") {
      std::fputs(kInfoHelp, stdout);
      return 0;
    }
    if (args[i] == "--threads") {
      if (i + 1 >= args.size()) throw UsageError("--threads needs a value");
      threads = parseInt("--threads", args[++i], 1, 256);
    } else if (args[i][0] == '-') {
      throw UsageError("unknown option '" + args[i] + "' (see sph2d info --help)");
    } else if (path.empty()) {
      path = args[i];
    } else {
      throw UsageError("unexpected argument '" + args[i] + "'");
    }
  }
  if (path.empty()) throw UsageError("missing the scene file (see sph2d info --help)");
  const SceneDef s = loadScene(path);
  World w(s, WorldOptions{threads});
  for (const auto& m : w.takeWarnings()) std::printf("warning: %s\n", m.c_str());
  std::size_t fixtures = 0;
  for (const auto& b : s.bodies) fixtures += b.fixtures.size();
  std::printf("scene        %s (%s)\n", s.name.c_str(), path.c_str());
  std::printf("particles    %zu (spacing %.4g m, support %.4g m, mass %.4g kg)\n", w.particleCount(), w.spacing(),
              w.support(), w.particleMass());
  std::printf("solver       %s, c = %.4g m/s, viscosity %.4g m^2/s, cfl %.3g, max %d substeps/frame\n",
              s.solver.type.c_str(), s.solver.soundSpeed, s.solver.viscosity, s.solver.cfl, s.solver.maxSubsteps);
  std::printf("boundaries   %zu static bodies, %zu fixtures, %zu colliders, %zu boundary samples\n", s.bodies.size(),
              fixtures, w.colliders().size(), w.boundarySamples().size());
  const double dtRest = s.solver.cfl * w.support() / s.solver.soundSpeed;
  std::printf("frames       %d at %.4g fps (%.4g s); about %.0f substeps per frame at rest\n",
              int(std::lround(s.duration * s.fps)), s.fps, s.duration, std::ceil(1.0 / s.fps / dtRest));
  std::printf("memory       %.1f MB of particle arrays\n", double(w.particles().bytes()) / 1e6);
  std::printf("image        %dx%d, %s mode\n", s.render.width, s.render.height, s.render.mode.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  try {
    if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
      std::fputs(kMainHelp, args.empty() ? stderr : stdout);
      return args.empty() ? 2 : 0;
    }
    const std::string cmd = args[0];
    args.erase(args.begin());
    if (cmd == "run") return cmdRun(args);
    if (cmd == "info") return cmdInfo(args);
    throw UsageError("unknown command '" + cmd + "'; commands: run, info (see sph2d --help)");
  } catch (const UsageError& e) {
    std::fprintf(stderr, "sph2d: %s\n", e.what());
    return 2;
  } catch (const SceneError& e) {
    std::fprintf(stderr, "sph2d: bad scene: %s\n", e.what());
    return 2;
  } catch (const SimulationError& e) {
    std::fprintf(stderr, "sph2d: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sph2d: error: %s\n", e.what());
    return 1;
  }
}
