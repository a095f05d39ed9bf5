// `sph2d info`: what a scene will simulate, without running it.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "cli.hpp"
#include "commands.hpp"
#include "loop/input_events.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace sph2d::cli {
namespace {

const char* kInfoHelp =
    "Usage: sph2d info SCENE.json [--threads T] [--max-memory S]\n"
    "\n"
    "Prints what SCENE will simulate, without running it: particles, solver, effects\n"
    "and stages, emitters, boundaries, frames and the substeps per frame the initial\n"
    "state needs, the timeline's events, memory and the image.\n"
    "\n"
    "Options:\n"
    "  --threads T     job-system threads (default: all cores)\n"
    "  --max-memory S  the limit the memory estimate is held to (default: the memory\n"
    "                  available); above it info prints the estimate and exits 2\n"
    "  --help          this text\n";

}  // namespace

int cmdInfo(const std::vector<std::string>& args) {
  std::string path;
  int threads = 0;
  double maxMemory = 0;
  for (ArgReader opt(args, "info"); opt.next();) {
    if (opt.help()) {
      std::fputs(kInfoHelp, stdout);
      return 0;
    }
    if (opt.is("--threads"))
      threads = opt.intValue(1, 256);
    else if (opt.is("--max-memory"))
      maxMemory = opt.bytesValue();
    else if (opt.option())
      opt.unknown();
    else if (path.empty())
      path = opt.arg();
    else
      opt.unexpected();
  }
  if (path.empty()) throw UsageError("missing the scene file (see sph2d info --help)");
  const SceneDef s = loadScene(path);
  // The estimate comes first: info builds the World (its boundary samples, its particles),
  // and a scene too large for the machine is refused before that.
  const double estimate = estimateRunBytes(s, true);
  std::printf(
      "memory       about %.1f MB at the peak, estimated before allocating (%zu particles at most, "
      "about %.0f boundary samples, the renderer at %dx%d)\n",
      estimate / 1e6, peakParticles(s), estimateBoundarySamples(s), s.render.width, s.render.height);
  checkMemory(s, true, maxMemory);
  World w(s, WorldOptions{threads});
  for (const auto& m : w.takeWarnings()) std::printf("warning: %s\n", m.c_str());
  std::size_t fixtures = 0;
  for (const auto& b : s.bodies)
    if (b.type == BodyDef::Type::Static) fixtures += b.fixtures.size();
  auto list = [](const std::vector<std::string>& v) {
    std::string out;
    for (const auto& x : v) out += (out.empty() ? "" : ", ") + x;
    return out.empty() ? std::string("none") : out;
  };
  std::printf("scene        %s (%s)\n", s.name.c_str(), path.c_str());
  std::printf("particles    %zu (spacing %.4g m, support %.4g m, mass %.4g kg)\n", w.particleCount(), w.spacing(),
              w.support(), w.particleMass());
  std::printf("solver       %s, c = %.4g m/s, viscosity %.4g m^2/s, cfl %.3g, max %d substeps/frame\n",
              s.solver.type.c_str(), s.solver.soundSpeed, s.solver.viscosity, s.solver.cfl, s.solver.maxSubsteps);
  if (!s.solver.params.empty()) {
    std::string params;
    for (const auto& p : s.solver.params) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "%s%s %.4g", params.empty() ? "" : ", ", p.first.c_str(), p.second);
      params += buf;
    }
    std::printf("             %s parameters: %s\n", s.solver.type.c_str(), params.c_str());
  }
  std::printf("effects      %s\n", list(w.effects()).c_str());
  {
    std::string st;
    for (const std::string& n : w.stages()) st += (st.empty() ? "" : " > ") + n;
    std::printf("stages       %s\n", st.c_str());  // one substep, in order (World::stages())
  }
  if (w.emitterCount()) {
    double rate = 0;
    for (const auto& e : s.effects.emitters) rate += e.rate;
    std::printf("emitters     %zu, %.4g particles/s in all; budget %zu (%s)\n", w.emitterCount(), rate,
                s.effects.budget ? s.effects.budget : s.maxParticles,
                s.effects.budgetPolicy == BudgetPolicy::RecycleOldest ? "recycle_oldest" : "stop_emitting");
  }
  std::size_t kinematic = 0, dynamic = 0;
  for (const BodyDef& b : s.bodies) {
    kinematic += b.type == BodyDef::Type::Kinematic;
    dynamic += b.type == BodyDef::Type::Dynamic;
  }
  std::printf("boundaries   %zu static bodies, %zu fixtures, %zu colliders, %zu boundary samples\n",
              s.bodies.size() - kinematic - dynamic, fixtures, w.colliders().size(), w.boundarySamples().size());
  if (kinematic || dynamic)
    std::printf(
        "moving       %zu kinematic and %zu dynamic bodies (%zu shapes; they push the fluid, stage 'bodies'%s)\n",
        kinematic, dynamic, w.movingColliders().size(), dynamic ? ", and the fluid pushes the dynamic ones" : "");
  const double dt = w.stableTimeStep();
  const int substeps = std::min(s.solver.maxSubsteps, int(std::ceil(1.0 / s.fps / dt - 1e-9)));
  std::printf(
      "frames       %d at %.4g fps (%.4g s); %d substeps per frame in the initial state (substep %.3g ms, "
      "at most %d; more once the fluid moves: the CFL limit shrinks with speed)\n",
      int(std::lround(s.duration * s.fps)), s.fps, s.duration, substeps, 1e3 * dt, s.solver.maxSubsteps);
  std::printf("events       %zu in the timeline\n", s.events.size());
  for (const EventDef& e : s.events)
    std::printf("             frame %lld: %s\n", (long long)eventFrame(e, s.fps), describeEvent(e).c_str());
  std::printf(
      "engine       %.1f MB held by the World now (particle arrays %.1f MB; grid, neighbour lists, "
      "boundary samples)\n",
      double(w.counters().memoryBytes) / 1e6, double(w.counters().particleBytes) / 1e6);
  std::printf("image        %dx%d, %s mode\n", s.render.width, s.render.height, s.render.mode.c_str());
  return 0;
}

}  // namespace sph2d::cli
