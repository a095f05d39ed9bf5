// `sph2d bench effects`: what each effect costs per substep (issue 7, "effects
// on demand"). Runs the dam break resampled to N particles once per
// configuration — gravity and pressure only ("none"), then each effect alone,
// then all of them — and times K substeps per configuration in interleaved
// rounds (the order rotates each round), so that a shared machine's load
// falls on every configuration alike. Prints, per configuration, the median
// over rounds of the milliseconds per substep, of the ratio to "none" in the
// same round, and of the effect's own stages (--clock cpu: process CPU time
// instead of the wall clock). A benchmark, not a test: compare the figures as
// ratios within one run. The cost of the effect machinery
// itself (a scene without effects against a build without effect modules) is
// measured by benchmarks/effects_overhead.sh.
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli.hpp"
#include "commands.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace sph2d::cli {
namespace {

const char* kHelp =
    "Usage: sph2d bench effects [--scene S] [--particles N] [--threads T] [--steps K] [--warmup W]\n"
    "                           [--rounds R] [--effects A,B,...] [--solver NAME] [--clock wall|cpu]\n"
    "                           [--csv FILE]\n"
    "\n"
    "Runs scene S (default assets/scenes/dam_break_muller2003.json) resampled to about N particles\n"
    "(default 20000) once per configuration: none (gravity and pressure only: viscosity 0,\n"
    "no effects), none_again (a second, identical World: the A/A control, whose ratio to none\n"
    "shows what the machine's noise and memory placement alone do), viscosity (the scene's nu, or 0.01), xsph (c = 0.05), force_field (one\n"
    "field everywhere), csf (sigma = 0.0728), akinci (gamma = 0.1), lifetime (max_age 1e6 s:\n"
    "ages kept, nothing removed), sink (a region above the fluid, never reached), user_force\n"
    "(one push/pull at the fluid's centre) and all (every one of them but akinci). After W\n"
    "warm-up substeps (default 50) each configuration runs K timed substeps (default 50) per\n"
    "round, R rounds (default 5), the configurations interleaved in an order that rotates\n"
    "each round. Prints the medians over rounds of ms per substep, of the ratio to none in\n"
    "the same round and of the effect's own stages (ms per substep and share of the step),\n"
    "the best round, and the substep length the configuration allows at the end. --effects\n"
    "runs only the listed configurations (none is always run); --solver replaces the scene's\n"
    "solver type; --threads T (default 1). --clock cpu times substeps with the process's CPU\n"
    "time instead of the wall clock (default wall): on a shared machine it leaves out the\n"
    "time other processes hold the core (with more than one thread it includes the workers'\n"
    "brief spinning). --csv FILE also writes the table as CSV.\n";

struct Config {
  std::string name;
  std::vector<std::string> stages;      ///< the effect's own stages (for its share)
  std::function<void(SceneDef&)> edit;  ///< applied to the "none" scene
  bool userForce = false;               ///< set one user force after construction
};

struct Row {
  Config cfg;
  std::unique_ptr<World> world;
  std::vector<double> ms, ratio, effectMs, share;
  std::map<std::string, double> stageSec;  ///< this round's seconds per stage
  double wallSec = 0;                      ///< this round's wall time
  std::string foldedInto;                  ///< the solver stage an effect of the configuration runs inside ("": none)
};

/// The seconds of configuration r's own effect stages in one round. An effect folded into a
/// solver's stage ("X+E", e.g. muller2003's pressure_force+viscosity) has no timer of its own:
/// its time is that stage's minus the stage X of `none` in the same round.
double effectSeconds(Row& r, const Row& none) {
  double sec = 0;
  for (const auto& [name, t] : r.stageSec) {
    if (std::find(r.cfg.stages.begin(), r.cfg.stages.end(), name) != r.cfg.stages.end()) {
      sec += t;
      continue;
    }
    const auto plus = name.find('+');
    if (plus == std::string::npos) continue;
    const std::string base = name.substr(0, plus), effect = name.substr(plus + 1);
    if (std::find(r.cfg.stages.begin(), r.cfg.stages.end(), effect) == r.cfg.stages.end()) continue;
    const auto it = none.stageSec.find(base);
    if (it == none.stageSec.end()) continue;
    sec += t - it->second;
    r.foldedInto = name;
  }
  return sec;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// Seconds of the process's CPU time (all threads).
double cpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

/// Seconds of the steady wall clock.
double wallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

int cmdBenchEffects(const std::vector<std::string>& args) {
  std::string scenePath = "assets/scenes/dam_break_muller2003.json", csvPath, solver, clock = "wall";
  int particles = 20000, threads = 1, steps = 50, warmup = 50, rounds = 5;
  std::vector<std::string> only;
  for (ArgReader opt(args, "bench effects"); opt.next();) {
    if (opt.help()) {
      std::fputs(kHelp, stdout);
      return 0;
    } else if (opt.is("--scene"))
      scenePath = opt.value();
    else if (opt.is("--particles"))
      particles = opt.intValue(1, 50000000);
    else if (opt.is("--threads"))
      threads = opt.intValue(1, 256);
    else if (opt.is("--steps"))
      steps = opt.intValue(1, 100000000);
    else if (opt.is("--warmup"))
      warmup = opt.intValue(0, 100000000);
    else if (opt.is("--rounds"))
      rounds = opt.intValue(1, 100000);
    else if (opt.is("--effects"))
      only = opt.listValue();
    else if (opt.is("--solver"))
      solver = opt.value();
    else if (opt.is("--csv"))
      csvPath = opt.value();
    else if (opt.is("--clock")) {
      clock = opt.value();
      if (clock != "wall" && clock != "cpu") throw UsageError("--clock expects wall or cpu, got '" + clock + "'");
    } else
      opt.unknown();
  }

  const std::vector<std::string> known = {"none",   "none_again", "viscosity", "xsph",       "force_field", "csf",
                                          "akinci", "lifetime",   "sink",      "user_force", "all"};
  for (const std::string& name : only)
    if (std::find(known.begin(), known.end(), name) == known.end())
      throw UsageError(
          "--effects: unknown configuration '" + name +
          "'; configurations: none, none_again, viscosity, xsph, force_field, csf, akinci, lifetime, sink, "
          "user_force, all");

  SceneDef base = loadScene(scenePath);
  const std::size_t n0 = countBlockParticles(base);
  if (n0 == 0) throw UsageError("scene " + scenePath + " has no fluid to resample");
  base.solver.spacing *= std::sqrt(double(n0) / double(particles));
  base.maxParticles = std::size_t(particles) * 4 + 1000;
  if (!solver.empty() && solver != base.solver.type) {
    base.solver.type = solver;
    base.solver.params.clear();  // the scene's solver's parameters are not another's: each at its default
  }
  const double nu = base.solver.viscosity > 0 ? base.solver.viscosity : 0.01;
  // "none": gravity and pressure only.
  SceneDef none = base;
  none.solver.viscosity = 0;
  none.effects = EffectsDef{};
  none.events.clear();
  // The fluid's bounding box places the user force (its centre) and the sink (above it).
  Vec2d lo = base.blocks.front().min, hi = base.blocks.front().max;
  for (const FluidBlockDef& b : base.blocks) {
    lo = lo.cwiseMin(b.min);
    hi = hi.cwiseMax(b.max);
  }
  UserForce push;
  push.point = 0.5 * (lo + hi);
  push.radius = 0.25 * (hi - lo).minCoeff();
  push.strength = -5;
  RegionDef sink;
  sink.min = Vec2d(lo.x(), hi.y() + 0.5);
  sink.max = Vec2d(hi.x(), hi.y() + 0.7);

  const auto viscosity = [nu](SceneDef& s) { s.solver.viscosity = nu; };
  const auto xsph = [](SceneDef& s) {
    s.effects.xsph = true;
    s.effects.xsphC = 0.05;
  };
  const auto field = [](SceneDef& s) {
    s.effects.forceFields.push_back(ForceFieldDef{Vec2d(0.1, 0.0), true, RegionDef{}});
  };
  const auto csf = [](SceneDef& s) {
    s.effects.surfaceTension = true;
    s.effects.tension.model = "csf";
    s.effects.tension.sigma = 0.0728;
  };
  const auto akinci = [](SceneDef& s) {
    s.effects.surfaceTension = true;
    s.effects.tension.model = "akinci";
    s.effects.tension.gamma = 0.1;
  };
  const auto lifetime = [](SceneDef& s) {
    s.effects.lifetime = true;
    s.effects.maxAge = 1e6;
  };
  const auto sinkEdit = [sink](SceneDef& s) { s.effects.sinks.push_back(sink); };
  const std::vector<std::string> allStages = {"viscosity",  "xsph",      "force_fields", "surface_tension",
                                              "user_force", "lifetimes", "sinks"};
  const std::vector<Config> configs = {
      {"none", {}, [](SceneDef&) {}, false},
      {"none_again", {}, [](SceneDef&) {}, false},
      {"viscosity", {"viscosity"}, viscosity, false},
      {"xsph", {"xsph"}, xsph, false},
      {"force_field", {"force_fields"}, field, false},
      {"csf", {"surface_tension"}, csf, false},
      {"akinci", {"surface_tension"}, akinci, false},
      {"lifetime", {"lifetimes"}, lifetime, false},
      {"sink", {"sinks"}, sinkEdit, false},
      {"user_force", {"user_force"}, [](SceneDef&) {}, true},
      {"all", allStages,
       [&](SceneDef& s) {
         viscosity(s);
         xsph(s);
         field(s);
         csf(s);
         lifetime(s);
         sinkEdit(s);
       },
       true},
  };

  std::vector<Row> rows;
  for (const Config& cfg : configs) {
    if (cfg.name != "none" && !only.empty() && std::find(only.begin(), only.end(), cfg.name) == only.end()) continue;
    SceneDef s = none;
    cfg.edit(s);
    Row r;
    r.cfg = cfg;
    try {
      r.world = std::make_unique<World>(s, WorldOptions{threads});
      if (cfg.userForce) r.world->setUserForces({push});
    } catch (const std::invalid_argument& e) {  // a build without effect modules refuses the scene
      std::fprintf(stderr, "sph2d: bench effects: %s skipped: %s\n", cfg.name.c_str(), e.what());
      continue;
    }
    r.world->takeWarnings();
    rows.push_back(std::move(r));
  }
  const std::size_t np = rows.front().world->particleCount();
  std::printf(
      "bench effects: %s resampled to %zu particles (spacing %.5g m), %s, %d thread%s; %d rounds of %d substeps after %d warm-up; %s clock\n",
      scenePath.c_str(), np, base.solver.spacing, rows.front().world->scene().solver.type.c_str(), threads,
      threads == 1 ? "" : "s", rounds, steps, warmup, clock == "cpu" ? "CPU-time" : "wall");
  double (*const now)() = clock == "cpu" ? &cpuSeconds : &wallSeconds;
  std::fflush(stdout);
  for (Row& r : rows)
    for (int i = 0; i < warmup; ++i) sph2d::bench::stepSubstep(*r.world);
  for (int round = 0; round < rounds; ++round) {
    std::vector<double> msThisRound(rows.size());
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const std::size_t idx = (k + std::size_t(round)) % rows.size();
      Row& r = rows[idx];
      r.world->resetProfile();
      const double t0 = now(), w0 = wallSeconds();
      for (int i = 0; i < steps; ++i) sph2d::bench::stepSubstep(*r.world);
      const double sec = now() - t0, wallSec = wallSeconds() - w0;
      msThisRound[idx] = 1e3 * sec / steps;
      r.stageSec.clear();
      for (const StageTiming& t : r.world->profile().stages) r.stageSec[t.name] += t.seconds;
      r.wallSec = wallSec;
    }
    for (std::size_t k = 0; k < rows.size(); ++k) {
      Row& r = rows[k];
      const double effectSec = effectSeconds(r, rows[0]);
      r.effectMs.push_back(1e3 * effectSec / steps);
      r.share.push_back(effectSec / r.wallSec);  // both wall: the stage timers use the wall clock
    }
    for (std::size_t k = 0; k < rows.size(); ++k) {
      rows[k].ms.push_back(msThisRound[k]);
      rows[k].ratio.push_back(msThisRound[k] / msThisRound[0]);
    }
  }

  std::printf("%-12s %10s %9s %9s %12s %7s %11s\n", "effect", "ms/substep", "best", "vs none", "effect ms", "share",
              "substep ms");
  std::ostringstream csv;
  csv << "effect,particles,threads,rounds,steps_per_round,clock,ms_per_step,ms_per_step_best,ratio_to_none,"
         "effect_ms_per_step,effect_share,substep_s\n";
  for (const Row& r : rows) {
    const double ms = median(r.ms), best = *std::min_element(r.ms.begin(), r.ms.end());
    const double ratio = median(r.ratio), eff = median(r.effectMs), share = median(r.share);
    const double dt = r.world->stableTimeStep();
    std::printf("%-12s %10.3f %9.3f %9.3f %12.3f %6.1f%% %11.3f\n", r.cfg.name.c_str(), ms, best, ratio, eff,
                100 * share, 1e3 * dt);
    csv << r.cfg.name << ',' << np << ',' << threads << ',' << rounds << ',' << steps << ',' << clock << ',' << ms
        << ',' << best << ',' << ratio << ',' << eff << ',' << share << ',' << dt << '\n';
  }
  std::printf(
      "(ms/substep and 'vs none' are medians over rounds, 'vs none' taken within each round; 'best' is the\n"
      " fastest round; 'effect ms' is the wall time of the effect's own stages per substep, 'share' its part of\n"
      " the round's wall time; 'substep ms' is the longest stable substep at the end: viscosity limits it)\n");
  for (const Row& r : rows)
    if (!r.foldedInto.empty())
      std::printf(
          "(%s: an effect runs inside the solver stage %s; its 'effect ms' is that stage's time minus the\n"
          " same stage's time in none, round by round)\n",
          r.cfg.name.c_str(), r.foldedInto.c_str());
  if (!csvPath.empty()) {
    const std::filesystem::path out(csvPath);
    if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());
    const std::string tmp = csvPath + ".tmp";
    {
      std::ofstream f(tmp);
      f << csv.str();
      if (!f) throw std::runtime_error("cannot write " + tmp);
    }
    std::filesystem::rename(tmp, csvPath);
    std::printf("wrote %s\n", csvPath.c_str());
  }
  return 0;
}

}  // namespace sph2d::cli
