// sph2d — the command line: run a scene headless and write PNG frames.
//
// Exit codes: 0 success; 1 a runtime failure (output, OpenGL); 2 bad input
// (command line or scene file); 3 the simulation guard stopped the run;
// 130 interrupted (SIGINT/SIGTERM) — frames already written stay whole.
// Each command lives in its own cmd_*.cpp; commands.hpp lists them.
#include <cstdio>
#include <string>
#include <vector>

#include "cli.hpp"
#include "commands.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

using namespace sph2d;
using namespace sph2d::cli;

namespace {

const char* kMainHelp =
    "sph2d — real-time 2D SPH fluids against Box2D static boundaries, rendered off-screen.\n"
    "\n"
    "Usage:\n"
    "  sph2d run SCENE.json [options]   simulate a scene and write PNG frames (a fixed-step game\n"
    "                                   loop: --realtime, --input events, --record)\n"
    "  sph2d info SCENE.json            print what a scene will simulate\n"
    "  sph2d serve SCENE.json [options] play a scene in a browser: live frames over a WebSocket,\n"
    "                                   input from the page (http://127.0.0.1:8080/)\n"
    "  sph2d check SCENE.json --against MANIFEST   rerun and compare frame hashes\n"
    "  sph2d render SCENE.json --particles FRAME.csv --out IMAGE.png   re-render exported particles\n"
    "  sph2d bench step [options]       step throughput (particle-steps per second)\n"
    "  sph2d bench render [options]     per-stage render and PNG timings\n"
    "  sph2d bench accuracy [options]   every solver against experiment and theory: error vs cost\n"
    "  sph2d bench effects [options]    milliseconds per substep with and without each effect\n"
    "  sph2d bench game [options]       the real-time end: the dam break per quality preset, beside LiquidFun\n"
    "  sph2d bench serve --port P       frames/s and input-to-frame latency a running serve delivers\n"
    "  sph2d --help | COMMAND --help\n"
    "\n"
    "Exit codes: 0 ok, 1 runtime failure (check: frames differ), 2 bad input, 3 simulation stopped by the guard, 130 interrupted.\n";

/// A command this build left out (./demo.sh builds the run commands alone): exit 2, saying how
/// to build it.
[[noreturn]] [[maybe_unused]] void leftOut(const char* command, const char* option) {
  throw UsageError(std::string("this sph2d was built without `") + command + "` (./demo.sh builds `run`, `info`, " +
                   "`check` and `render` only): ./test.sh builds it, or configure build/ with -D" + option + "=ON");
}

}  // namespace

int main(int argc, char** argv) {
  installExitHandler();  // until a command's loop says otherwise, a signal ends the process now
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
    if (cmd == "check") return cmdCheck(args);
#ifdef SPH2D_HAVE_SERVE
    if (cmd == "serve") return cmdServe(args);
#else
    if (cmd == "serve") leftOut("serve", "SPH2D_APP_SERVE");
#endif
    if (cmd == "render") return cmdRender(args);
    if (cmd == "bench") {
#ifdef SPH2D_HAVE_BENCH
      if (!args.empty() && args[0] == "step")
        return cmdBenchStep(std::vector<std::string>(args.begin() + 1, args.end()));
#ifdef SPH2D_HAVE_SERVE
      if (!args.empty() && args[0] == "serve")
        return cmdBenchServe(std::vector<std::string>(args.begin() + 1, args.end()));
#else
      if (!args.empty() && args[0] == "serve") leftOut("bench serve", "SPH2D_APP_SERVE");
#endif
      if (!args.empty() && args[0] == "game")
        return cmdBenchGame(std::vector<std::string>(args.begin() + 1, args.end()));
      if (!args.empty() && args[0] == "effects")
        return cmdBenchEffects(std::vector<std::string>(args.begin() + 1, args.end()));
      if (!args.empty() && args[0] == "accuracy")
        return cmdBenchAccuracy(std::vector<std::string>(args.begin() + 1, args.end()));
      return cmdBench(args);
#else
      leftOut("bench", "SPH2D_APP_BENCH");
#endif
    }
    throw UsageError("unknown command '" + cmd +
                     "'; commands: run, info, check, render, bench, serve (see sph2d --help)");
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
