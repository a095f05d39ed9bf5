// `sph2d bench step`: the step-throughput benchmark (issue 4). Runs a scene
// resampled to N particles for K substeps after a warm-up, at each thread
// count, and prints a table or CSV. A benchmark, not a test: rerun it, and
// compare figures as ratios within one run (the machines are shared).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "cli.hpp"
#include "commands.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace sph2d::cli {
namespace {

const char* kHelp =
    "Usage: sph2d bench step [--scene S] [--particles N[,N...]] [--threads T[,T...]] [--steps K] [--warmup W] [--csv]\n"
    "\n"
    "Runs scene S (default assets/scenes/dam_break_muller2003.json, Müller et al. 2003's step) with its spacing scaled so the fluid\n"
    "blocks hold about N particles, for W warm-up substeps (default 20) and K timed substeps\n"
    "(default: enough for about 2e7 particle-steps, at least 10), at each thread count\n"
    "(default: 1 and all cores). Default sweep: 5000,20000,100000,500000,1000000 particles.\n"
    "Columns: particles, threads, steps, ms_per_step, particle_steps_per_s, pairs_per_s,\n"
    "bytes_per_particle (engine-held), rss_bytes_per_particle (peak resident set / N), then one\n"
    "share per stage.\n";

long peakRssBytes() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stol(line.substr(6)) * 1024;
  return 0;
}

}  // namespace

int cmdBenchStep(const std::vector<std::string>& args) {
  std::string scenePath = "assets/scenes/dam_break_muller2003.json";
  std::vector<int> counts = {5000, 20000, 100000, 500000, 1000000};
  std::vector<int> threads = {1, 0};
  int steps = 0, warmup = 20;
  bool csv = false;
  for (ArgReader opt(args, "bench step"); opt.next();) {
    if (opt.help()) {
      std::fputs(kHelp, stdout);
      return 0;
    } else if (opt.is("--scene"))
      scenePath = opt.value();
    else if (opt.is("--particles"))
      counts = opt.intListValue(1, 50000000);
    else if (opt.is("--threads"))
      threads = opt.intListValue(1, 256);
    else if (opt.is("--steps"))
      steps = opt.intValue(1, 100000000);
    else if (opt.is("--warmup"))
      warmup = opt.intValue(0, 100000000);
    else if (opt.is("--csv"))
      csv = true;
    else
      opt.unknown();
  }
  const SceneDef base = loadScene(scenePath);
  const std::size_t n0 = countBlockParticles(base);
  if (n0 == 0) throw UsageError("scene " + scenePath + " has no fluid to resample");

  bool header = false;
  for (int n : counts) {
    SceneDef s = base;
    s.solver.spacing = base.solver.spacing * std::sqrt(double(n0) / double(n));
    s.maxParticles = std::size_t(n) * 4 + 1000;
    for (int t : threads) {
      World w(s, WorldOptions{t});
      w.takeWarnings();
      const std::size_t np = w.particleCount();
      const int k = steps > 0 ? steps : std::max(10, int(2e7 / double(np)));
      for (int i = 0; i < warmup; ++i) sph2d::bench::stepSubstep(w);
      w.resetProfile();
      std::size_t pairs = 0;
      const auto t0 = std::chrono::steady_clock::now();
      for (int i = 0; i < k; ++i) {
        sph2d::bench::stepSubstep(w);
        pairs += w.counters().neighbourPairs;
      }
      const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const auto timings = w.profile().stages;
      double stageTotal = 0;
      for (const auto& st : timings) stageTotal += st.seconds;
      if (!header) {
        if (csv) {
          std::printf(
              "particles,threads,steps,ms_per_step,particle_steps_per_s,pairs_per_s,bytes_per_particle,rss_bytes_per_particle");
          for (const auto& st : timings) std::printf(",share_%s", st.name.c_str());
          std::printf("\n");
        } else {
          std::printf("%9s %7s %6s %11s %14s %12s %9s %9s  stage shares\n", "particles", "threads", "steps", "ms/step",
                      "particle-st/s", "pairs/s", "B/part", "RSS B/p");
        }
        header = true;
      }
      const double ms = 1e3 * sec / k;
      const double ps = double(np) * k / sec;
      const double pairsPerS = double(pairs) / sec;
      const double bpp = double(w.counters().memoryBytes) / double(np);
      const double rss = double(peakRssBytes()) / double(np);
      if (csv) {
        std::printf("%zu,%d,%d,%.4f,%.0f,%.0f,%.1f,%.1f", np, w.threads(), k, ms, ps, pairsPerS, bpp, rss);
        for (const auto& st : timings) std::printf(",%.4f", stageTotal > 0 ? st.seconds / stageTotal : 0.0);
        std::printf("\n");
      } else {
        std::printf("%9zu %7d %6d %11.3f %14.3e %12.3e %9.1f %9.1f ", np, w.threads(), k, ms, ps, pairsPerS, bpp, rss);
        for (const auto& st : timings)
          std::printf(" %s %.0f%%", st.name.c_str(), stageTotal > 0 ? 100 * st.seconds / stageTotal : 0.0);
        std::printf("\n");
      }
      std::fflush(stdout);
    }
  }
  return 0;
}

}  // namespace sph2d::cli
