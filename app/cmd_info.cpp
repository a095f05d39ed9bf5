// `sph2d info`: what a scene will simulate, without running it.
#include <cmath>
#include <cstdio>

#include "cli.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace sph2d::cli {
namespace {

const char* kInfoHelp =
    "Usage: sph2d info SCENE.json [--threads T]\n"
    "\n"
    "Prints the scene's particles, solver, boundaries, frames and memory without running it.\n";

}  // namespace

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

}  // namespace sph2d::cli
