// `sph2d bench accuracy`: what accuracy costs in time (issue 6). Runs every
// solver over the validation cases at several resolutions and CFL numbers,
// measures each run's error against experiment or theory and its cost, and
// writes accuracy.csv, accuracy.md and one chart per case (error against wall
// seconds per simulated second, log-log, one series per solver, the Pareto
// front drawn, by gnuplot: app/bench/accuracy_charts.hpp). A benchmark, not a
// test: timings depend on the machine and its load; compare them as ratios
// within one run.
//
// Cases (scenes in assets/scenes/validation/):
//   hydrostatic  2 m × 1 m tank at rest: worst error of the time-averaged
//                pressure profile against ρ0 g (H − y), as a share of ρ0 g H.
//   dam_break    1 m × 2 m column, 4 m × 3 m tank: RMS of the surge front Z = x/a
//                against Martin & Moyce 1952 (Table 2) at the table's T = t·sqrt(2g/a).
//   taylor_green periodic unit box, Re = 100: RMS of |u|max/U against exp(−8π²t/Re)
//                (assets/reference/taylor_green_decay.csv) over 1 s (app/bench/validation.hpp).
//   poiseuille   start-up flow between plates, periodic in x: RMS of u/u_c against
//                Morris, Fox & Zhu's series (channel_flow_transient.csv), τ ≤ 0.5.
//   surge_long   the same column in a 16 m tank for 2 s (T ≈ 8.9): RMS of Z against
//                Martin & Moyce's long record (Figure 3) over every point and over the
//                points to T = 3.35, per floor: free-slip, Coulomb friction μ 0.2 / 0.5 / 1
//                at contact, no-slip (solver.no_slip). Only when named (--cases).
// The CFL number varied is each solver's own: solver.cfl (muller2003, wcsph),
// solver.velocity_cfl (dfsph), solver.max_move (pbf, game).
//
// Every run has an id (case-solver-particles-cflK[-floor]); --list prints each run as
// a command of its own (--only ID --out DIR/ID) for a scheduler, and --merge DIR gathers
// their CSV files into one report (app/bench/sweep.hpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "bench/accuracy_charts.hpp"
#include "bench/accuracy_report.hpp"
#include "bench/sweep.hpp"
#include "bench/validation.hpp"
#include "cli.hpp"
#include "commands.hpp"
#include "output/output_dir.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace fs = std::filesystem;

namespace sph2d::cli {
namespace {

using namespace accuracy;

const char* kHelp =
    "Usage: sph2d bench accuracy [--out DIR] [--quick] [--levels K] [--solvers A,B] [--cases A,B] [--threads T]\n"
    "                            [--assets DIR] [--list | --list-ids | --only ID[,ID...]]\n"
    "       sph2d bench accuracy --merge DIR | --from-csv A.csv[,B.csv...] [--allow-mixed] [--out DIR]\n"
    "       sph2d bench accuracy --charts-only A.csv[,B.csv...] [--allow-mixed] [--out DIR]\n"
    "\n"
    "Runs every solver over the validation cases (hydrostatic tank, dam break against\n"
    "Martin & Moyce 1952, Taylor-Green vortex, start-up Poiseuille flow) at three\n"
    "resolutions (dam break about 5k, 20k and 80k particles)\n"
    "and two CFL numbers, and writes DIR/accuracy.csv, DIR/accuracy.md and per case a chart\n"
    "(default DIR: out/accuracy): DIR/<case>.gp, a gnuplot script, and DIR/<case>.dat, its data,\n"
    "always; DIR/<case>.svg and DIR/<case>.png drawn from them when gnuplot is on PATH (else\n"
    "`gnuplot DIR/<case>.gp` draws them later). Each chart: error against wall seconds per simulated\n"
    "second, log-log, one series per solver, each point labelled with its particle count, the\n"
    "Pareto front drawn. --quick runs one small resolution and one\n"
    "CFL number per solver (a smoke test of a minute or two). --assets: the assets folder\n"
    "(default: ./assets). --levels K runs only the K coarsest resolutions (1..3).\n"
    "--cases hydrostatic,dam_break,taylor_green,poiseuille,surge_long (or all) runs only those\n"
    "cases (default: the first four). surge_long: the column in a 16 m tank for 2 s against\n"
    "Martin & Moyce's long record, per floor (free, mu0.2, mu0.5, mu1, noslip), at the first\n"
    "CFL number and the two coarsest resolutions only.\n"
    "\n"
    "One run at a time, for a scheduler (GNU parallel, Slurm, a CI matrix; docs/ACCURACY.md):\n"
    "--list prints every run of the sweep the other options select as one command line,\n"
    "  `sph2d bench accuracy --only ID --out DIR/ID ...`, each writing its own accuracy.csv\n"
    "  (paths made absolute); --list-ids prints the ids alone. Neither runs anything.\n"
    "--only ID[,ID...] runs exactly those runs of the sweep that --quick and --levels define\n"
    "  (ids like dam_break-dfsph-20000-cfl1, surge_long-game-5000-cfl1-mu0.5) and writes\n"
    "  DIR/accuracy.csv and DIR/accuracy.md; not with --solvers or --cases.\n"
    "--merge DIR gathers every DIR/*/accuracy.csv (the runs of --list's --out DIR) and\n"
    "--from-csv A.csv[,B.csv...] the files named; either runs nothing and writes the report\n"
    "  and charts into --out from them, rows in the sweep's order. Every row records the\n"
    "  build's commit and the settings (quick, levels, threads, the assets' hash): rows of\n"
    "  different builds or settings are refused (exit 2, naming two files) unless\n"
    "  --allow-mixed, and a run id twice is refused.\n"
    "--charts-only A.csv[,B.csv...] reads those files as --from-csv does and writes the charts\n"
    "  alone into --out (default: the first file's folder), its accuracy.csv left as it is\n"
    "  (benchmarks/plot_accuracy.sh runs it).\n"
    "\n"
    "Those files replace only the ones an earlier bench accuracy wrote in DIR (its\n"
    "DIR/.sph2d.journal lists them with their hashes): a file of those names that sph2d\n"
    "cannot prove it wrote is never touched, and the bench exits 2 naming it before it runs.\n";

/// surge_long's floors, in the order they run.
const char* const kSurgeFloors[] = {"free", "mu0.2", "mu0.5", "mu1", "noslip"};
/// surge_long: Martin & Moyce's points up to this T make the second error (the span of Table 2).
constexpr double kSurgeEarlyT = 3.35;
/// surge_long's tank (assets/scenes/validation/surge_long.json): the far wall's inner face [m].
constexpr double kSurgeLongTank = 16.0;

std::string caseList() {
  std::string s;
  for (const char* c : kCases) s += std::string(s.empty() ? "" : ", ") + c;
  return s;
}

/// The surge front of a column of width a = 1 m against `table`'s (T, Z) rows, T = t·sqrt(2g/a):
/// `error` over every row within the run (and short of the far wall at `tankLength`),
/// `error2` over those with T ≤ `earlyT` (when earlyT > 0). x_front: the largest x of any particle.
Run runSurge(SceneDef s, const std::vector<std::vector<double>>& table, double tankLength, double earlyT, int threads) {
  Run r;
  World w(s, WorldOptions{threads});
  w.takeWarnings();
  const double a = 1.0, g = 9.81;
  std::vector<double> times = {0}, fronts;
  auto front = [&] {
    double m = 0;
    for (std::size_t i = 0; i < w.particleCount(); ++i) m = std::max(m, w.worldPosition(i).x());
    return m;
  };
  fronts.push_back(front());
  const int frames = int(std::lround(s.duration * s.fps));
  double densSum = 0, densMax = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int f = 0; f < frames; ++f) {
    w.stepFrame();
    times.push_back(w.time());
    fronts.push_back(front());
    const DensityStats d = w.densityStats();
    densSum += d.meanError;
    densMax = std::max(densMax, d.meanError);
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  double se = 0, se2 = 0;
  int n = 0, n2 = 0;
  for (const auto& row : table) {
    const double t = row[0] / std::sqrt(2 * g / a);
    if (t > times.back() || row[1] * a >= tankLength) continue;
    std::size_t k = 1;
    while (k + 1 < times.size() && times[k] < t) ++k;
    const double u = (t - times[k - 1]) / (times[k] - times[k - 1]);
    const double x = fronts[k - 1] + u * (fronts[k] - fronts[k - 1]);
    const double e2 = (x / a - row[1]) * (x / a - row[1]);
    se += e2;
    ++n;
    if (row[0] <= earlyT) {
      se2 += e2;
      ++n2;
    }
  }
  r.error = n ? std::sqrt(se / n) : 0;
  if (earlyT > 0) r.error2 = n2 ? std::sqrt(se2 / n2) : NAN;
  r.particles = w.particleCount();
  r.meanDensityError = densSum / frames;
  r.maxDensityError = densMax;
  r.wallPerSim = wall / w.time();
  r.msPerStep = 1e3 * wall / double(std::max<std::uint64_t>(1, w.counters().substeps));
  return r;
}

Run runHydrostatic(SceneDef s, int threads) {
  Run r;
  World w(s, WorldOptions{threads});
  w.takeWarnings();
  const double rho0 = s.solver.restDensity, g = 9.81, dx = s.solver.spacing;
  validation::PressureProfile profile;
  const int frames = int(std::lround(s.duration * s.fps)), avgFrom = frames * 2 / 3;
  double densSum = 0, densMax = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int f = 0; f < frames; ++f) {
    w.stepFrame();
    if (f < avgFrom) continue;
    const DensityStats d = w.densityStats();
    densSum += d.meanError;
    densMax = std::max(densMax, d.maxError);
    profile.add(w);
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double H = validation::PressureProfile::surface(w, 1.0, dx);
  // muller2003's symmetric force recovers ∇p/2: its pressure at rest is 2ρg(H − y) by design;
  // compare its profile against that, so the error measures the scheme, not the convention.
  const double expectScale = s.solver.type == "muller2003" ? 2.0 : 1.0;
  int measured = 0, empty = 0;
  const double worst = profile.worstError(H, rho0, g, dx, expectScale, measured, empty);
  r.error = measured ? worst : NAN;  // nothing measured: no figure, not a perfect one
  r.particles = w.particleCount();
  r.meanDensityError = densSum / std::max(1, frames - avgFrom);
  r.maxDensityError = densMax;
  r.wallPerSim = wall / w.time();
  r.msPerStep = 1e3 * wall / double(std::max<std::uint64_t>(1, w.counters().substeps));
  return r;
}

/// The scenes and reference tables of the cases.
struct Inputs {
  SceneDef dam, hydro, tg, channel, surgeLong;
  std::vector<std::vector<double>> damTable, surgeLongTable, tgTable, channelTable;
  std::vector<std::string> files;  ///< every file read, for the assets' hash
};

Inputs loadInputs(const std::string& assets) {
  Inputs in;
  const std::string v = assets + "/scenes/validation/", ref = assets + "/reference/";
  in.files = {v + "dam_break.json",
              v + "hydrostatic_tank.json",
              v + "taylor_green.json",
              v + "poiseuille.json",
              v + "surge_long.json",
              ref + "martin_moyce_1952_surge_front.csv",
              ref + "martin_moyce_1952_surge_front_long.csv",
              ref + "taylor_green_decay.csv",
              ref + "channel_flow_transient.csv"};
  in.dam = loadScene(in.files[0]);
  in.hydro = loadScene(in.files[1]);
  in.tg = loadScene(in.files[2]);
  in.channel = loadScene(in.files[3]);
  in.surgeLong = loadScene(in.files[4]);
  in.damTable = validation::readReferenceCsv(in.files[5]);
  in.surgeLongTable = validation::readReferenceCsv(in.files[6]);
  in.tgTable = validation::readReferenceCsv(in.files[7]);
  in.channelTable = validation::readReferenceCsv(in.files[8]);
  return in;
}

/// One run of the sweep before it runs: what it is, its scene and its id.
struct Spec {
  std::string id, caseName, solver, floor;
  int cflIndex = 1;  ///< 1: each solver's CFL-type number at its default, 2: twice it
  double cfl = 0;
  SceneDef scene;
};

/// The scene of a run: the case's scene with the solver, its CFL-type number, the spacing and the floor.
Spec makeSpec(const Inputs& in, const std::string& caseName, const std::string& solver, int cflIndex, double dx,
              const std::string& floor) {
  Spec p;
  p.caseName = caseName;
  p.solver = solver;
  p.floor = floor;
  p.cflIndex = cflIndex;
  SceneDef& s = p.scene;
  s = caseName == "hydrostatic"    ? in.hydro
      : caseName == "dam_break"    ? in.dam
      : caseName == "taylor_green" ? in.tg
      : caseName == "poiseuille"   ? in.channel
                                   : in.surgeLong;
  p.cfl = setSolver(s, solver, double(cflIndex));
  s.solver.spacing = dx;
  s.solver.maxSubsteps = 100000;
  if (caseName == "dam_break" || caseName == "surge_long") s.maxParticles = 1000000;
  if (solver == "muller2003" && (caseName == "hydrostatic" || caseName == "dam_break" || caseName == "surge_long"))
    s.solver.viscosity = 0.01;
  if (caseName == "poiseuille") {
    // The period must hold 3 support radii: 8 spacings at the coarse level (the plates reach 1 m beyond).
    const double period = std::max(s.periodic.max.x() - s.periodic.min.x(), 8 * dx);
    s.periodic.max.x() = s.periodic.min.x() + period;
    s.blocks[0].max.x() = s.blocks[0].min.x() + period;
  }
  if (!floor.empty()) applyFloorVariant(s, parseFloorVariant("floor", floor));
  p.id = caseName + "-" + solver + "-" + std::to_string(countBlockParticles(s)) + "-cfl" + std::to_string(cflIndex) +
         (floor.empty() ? "" : "-" + floor);
  return p;
}

/// The runs of the sweep, in the order they run (and the CSV's).
std::vector<Spec> sweep(const Inputs& in, const std::vector<std::string>& solvers,
                        const std::vector<std::string>& cases, bool quick, int levels) {
  auto spacings = [&](std::vector<double> full, double q, std::size_t cap) {
    if (quick) return std::vector<double>{q};
    full.resize(std::min<std::size_t>(std::size_t(levels), cap));
    return full;
  };
  const std::map<std::string, std::vector<double>> dx = {{"hydrostatic", spacings({0.05, 0.025, 0.0125}, 0.05, 3)},
                                                         {"dam_break", spacings({0.02, 0.01, 0.005}, 0.04, 3)},
                                                         {"taylor_green", spacings({0.04, 0.02, 0.01}, 0.04, 3)},
                                                         {"poiseuille", spacings({0.1, 0.05, 0.025}, 0.1, 3)},
                                                         {"surge_long", spacings({0.02, 0.01}, 0.04, 2)}};
  std::vector<Spec> out;
  for (const std::string& solver : solvers)
    for (int k = 1; k <= (quick ? 1 : 2); ++k)
      for (const char* c : kCases) {
        if (std::find(cases.begin(), cases.end(), c) == cases.end()) continue;
        if (std::string(c) == "surge_long" && k > 1) continue;  // the floor is its variable, not the CFL number
        for (double h : dx.at(c)) {
          if (std::string(c) == "surge_long")
            for (const char* f : kSurgeFloors) out.push_back(makeSpec(in, c, solver, k, h, f));
          else
            out.push_back(makeSpec(in, c, solver, k, h, ""));
        }
      }
  return out;
}

/// Runs one run; an unstable run (the guard stopped it) gives a row with status "unstable".
Run execute(const Spec& p, const Inputs& in, int threads) {
  Run r;
  const SceneDef& s = p.scene;
  try {
    if (p.caseName == "hydrostatic") {
      r = runHydrostatic(s, threads);
      r.errorName = "pressure_profile_max_rel";
    } else if (p.caseName == "dam_break") {
      r = runSurge(s, in.damTable, 1e9, 0, threads);
      r.errorName = "surge_front_rms_Z";
    } else if (p.caseName == "surge_long") {
      r = runSurge(s, in.surgeLongTable, kSurgeLongTank, kSurgeEarlyT, threads);
      r.errorName = "surge_front_rms_Z";
      r.error2Name = "surge_front_rms_Z_to_T3.35";
    } else {
      // The analytic cases: error, mean and max density error, simulated s, substeps.
      struct Measured {
        double error, meanDensityError, maxDensityError, simSeconds;
        std::uint64_t substeps;
      };
      const auto t0 = std::chrono::steady_clock::now();
      Measured v{};
      if (p.caseName == "taylor_green") {
        const auto m = validation::runTaylorGreen(s, s.duration, in.tgTable, threads);
        v = Measured{m.umaxRms, m.meanDensityError, m.maxDensityError, m.simSeconds, m.substeps};
        r.errorName = "umax_ratio_rms";
      } else {
        const auto m = validation::runPoiseuille(s, 0.0, 1.0, in.channelTable, threads);
        v = Measured{m.rmsError, m.meanDensityError, m.maxDensityError, m.simSeconds, m.substeps};
        r.errorName = "u_rms_vs_series";
      }
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      r.error = v.error;
      r.particles = countBlockParticles(s);
      r.meanDensityError = v.meanDensityError;
      r.maxDensityError = v.maxDensityError;
      r.wallPerSim = wall / v.simSeconds;
      r.msPerStep = 1e3 * wall / double(std::max<std::uint64_t>(1, v.substeps));
    }
  } catch (const SimulationError& e) {
    std::printf("%-12s %-11s dx %.4f cfl %.3f%s: unstable (%s)\n", p.caseName.c_str(), p.solver.c_str(),
                s.solver.spacing, p.cfl, p.floor.empty() ? "" : (" floor " + p.floor).c_str(), e.what());
    r = Run{};
    r.status = "unstable";
    r.particles = countBlockParticles(s);
    r.errorName = p.caseName == "hydrostatic"    ? "pressure_profile_max_rel"
                  : p.caseName == "taylor_green" ? "umax_ratio_rms"
                  : p.caseName == "poiseuille"   ? "u_rms_vs_series"
                                                 : "surge_front_rms_Z";
    if (p.caseName == "surge_long") r.error2Name = "surge_front_rms_Z_to_T3.35";
  }
  r.id = p.id;
  r.caseName = p.caseName;
  r.solver = p.solver;
  r.floor = p.floor;
  r.cfl = p.cfl;
  r.params = solverParamsText(s.solver);
  return r;
}

/// --charts-only writes the charts alone: the report's names in its folder are not in its way.
void dropReport(FolderScan& scan) {
  auto& f = scan.foreign;
  f.erase(std::remove_if(f.begin(), f.end(),
                         [](const ForeignFile& x) { return x.name == "accuracy.csv" || x.name == "accuracy.md"; }),
          f.end());
}

}  // namespace

int cmdBenchAccuracy(const std::vector<std::string>& args) {
  std::string out = "out/accuracy", assets = "assets";
  bool quick = false, list = false, listIds = false, allowMixed = false, filtered = false, chartsOnly = false,
       outGiven = false;
  int threads = 0, levels = 3;
  std::vector<std::string> solvers, fromCsv, only, mergeDirs,
      cases(std::begin(kCases), std::begin(kCases) + kDefaultCases);
  for (ArgReader opt(args, "bench accuracy"); opt.next();) {
    if (opt.help()) {
      std::fputs(kHelp, stdout);
      return 0;
    } else if (opt.is("--out")) {
      out = opt.value();
      outGiven = true;
    } else if (opt.is("--assets"))
      assets = opt.value();
    else if (opt.is("--quick"))
      quick = true;
    else if (opt.is("--threads"))
      threads = opt.intValue(1, 256);
    else if (opt.is("--levels"))
      levels = opt.intValue(1, 3);
    else if (opt.is("--from-csv")) {
      for (const std::string& f : opt.listValue()) fromCsv.push_back(f);
    } else if (opt.is("--charts-only")) {
      for (const std::string& f : opt.listValue()) fromCsv.push_back(f);
      chartsOnly = true;
    } else if (opt.is("--merge"))
      mergeDirs.push_back(opt.value());
    else if (opt.is("--allow-mixed"))
      allowMixed = true;
    else if (opt.is("--list"))
      list = true;
    else if (opt.is("--list-ids"))
      listIds = true;
    else if (opt.is("--only")) {
      only = opt.listValue();
      if (only.empty()) throw UsageError("--only needs a run id (sph2d bench accuracy --list-ids lists them)");
    } else if (opt.is("--solvers")) {
      solvers = opt.listValue();
      filtered = true;
    } else if (opt.is("--cases")) {
      cases = opt.listValue();
      filtered = true;
      if (cases.size() == 1 && cases[0] == "all") cases.assign(std::begin(kCases), std::end(kCases));
      if (cases.empty()) throw UsageError("--cases needs at least one case (" + caseList() + ", or all)");
      for (const std::string& k : cases)
        if (indexOf(kCases, k) < 0)
          throw UsageError("--cases: unknown case '" + k + "' (allowed: " + caseList() + ", or all)");
    } else
      opt.unknown();
  }
  const bool merging = !fromCsv.empty() || !mergeDirs.empty();
  if (int(list) + int(listIds) + int(!only.empty()) + int(merging) > 1)
    throw UsageError("--list, --list-ids, --only and --merge/--from-csv/--charts-only are one each: give one of them");
  if (!only.empty() && filtered)
    throw UsageError("--only names its runs: not with --solvers or --cases (they select what --list prints)");
  if (allowMixed && !merging) throw UsageError("--allow-mixed is for --merge, --from-csv and --charts-only");
  if (chartsOnly && fromCsv.empty()) throw UsageError("--charts-only needs an accuracy.csv");
  if (chartsOnly && !outGiven) out = fs::path(fromCsv.front()).parent_path().string();
  if (out.empty()) out = ".";

  // The folder, before any run: held by this bench alone, and refused when it holds a file of
  // the names it writes that an earlier bench accuracy did not write (its journal lists those).
  const FolderSpec spec = accuracyFolderSpec();
  auto holdFolder = [&](std::optional<OutputLock>& lock) {
    if (holdsLockFile(out)) lock.emplace(out);
    FolderScan scan = scanOutputFolder(out, spec);
    if (chartsOnly) dropReport(scan);
    refuseForeignFiles(out, scan, spec);
    makeOutputDir(out);
    if (!lock) lock.emplace(out);
  };
  std::optional<OutputLock> lock;
  std::vector<Run> runs;
  std::string header;

  if (merging) {
    for (const std::string& d : mergeDirs)
      for (const std::string& f : mergeParts("--merge", d, "accuracy.csv")) fromCsv.push_back(f);
    std::map<std::string, std::string> seen;  // run id → file
    std::vector<RowOrigin> origins;
    for (const std::string& path : fromCsv)
      for (Run& r : readRuns(path)) {
        const auto [it, fresh] = seen.emplace(r.id, path);
        if (!fresh)
          throw UsageError("bench accuracy: run " + r.id + " is in " + it->second +
                           (it->second == path ? " twice" : " and in " + path) + ": merge each run once");
        origins.push_back(RowOrigin{path, r.build, r.settings});
        runs.push_back(std::move(r));
      }
    const std::vector<RowOrigin> kinds = checkOrigins("bench accuracy", origins, allowMixed);
    for (const RowOrigin& k : kinds)
      header +=
          "build " + k.build + ", settings " + k.settings + (kinds.size() > 1 ? " (mixed: --allow-mixed)" : "") + "\n";
    std::printf("bench accuracy: %zu rows from %zu files; %s", runs.size(), fromCsv.size(), header.c_str());
    holdFolder(lock);
  } else {
    const Inputs in = loadInputs(assets);
    if (solvers.empty()) solvers.assign(std::begin(kSolvers), std::end(kSolvers));
    std::vector<std::string> known;
    // Keep the solvers this build has (a scene with an unknown type fails to load).
    for (const auto& s : solvers) {
      try {
        parseScene("{\"solver\": {\"type\": \"" + s + "\"}}", "solver check");
        known.push_back(s);
      } catch (const SceneError&) {
        std::fprintf(stderr, "bench accuracy: solver '%s' is not in this build, skipped\n", s.c_str());
      }
    }
    std::vector<Spec> specs =
        sweep(in, known, only.empty() ? cases : std::vector<std::string>(std::begin(kCases), std::end(kCases)), quick,
              levels);
    const std::string settings = "quick=" + std::string(quick ? "1" : "0") + ";levels=" + std::to_string(levels) +
                                 ";threads=" + (threads ? std::to_string(threads) : std::string("auto")) +
                                 ";assets=" + filesHash(in.files);
    if (list || listIds) {
      // One line per run: a command that runs it alone into its own folder.
      const std::string exe = shellQuote(selfExe()), root = absolutePath(out),
                        assetsAbs = shellQuote(absolutePath(assets));
      for (const Spec& p : specs) {
        if (listIds) {
          std::printf("%s\n", p.id.c_str());
          continue;
        }
        std::string cmd = exe + " bench accuracy --only " + p.id + " --out " + shellQuote(root + "/" + p.id) +
                          " --assets " + assetsAbs;
        if (quick) cmd += " --quick";
        if (levels != 3) cmd += " --levels " + std::to_string(levels);
        if (threads) cmd += " --threads " + std::to_string(threads);
        std::printf("%s\n", cmd.c_str());
      }
      return specs.empty() ? 1 : 0;
    }
    if (!only.empty()) {
      std::vector<Spec> chosen;
      for (const std::string& id : only) {
        const auto it = std::find_if(specs.begin(), specs.end(), [&](const Spec& p) { return p.id == id; });
        if (it == specs.end()) {
          const std::string flags =
              std::string(quick ? " --quick" : "") + (levels != 3 ? " --levels " + std::to_string(levels) : "");
          throw UsageError("--only: no run '" + id + "' in this sweep (" + std::to_string(specs.size()) + " runs" +
                           (quick ? ", --quick" : "") + "); ids are case-solver-particles-cflK[-floor], e.g. " +
                           (specs.empty() ? std::string("dam_break-dfsph-20000-cfl1") : specs.front().id) +
                           "; `sph2d bench accuracy --list-ids" + flags + "` lists them all");
        }
        chosen.push_back(*it);
      }
      specs = chosen;
    }
    holdFolder(lock);
    std::printf("%-12s %-11s %9s %6s %-8s %-26s %10s %10s %10s %12s %10s\n", "case", "solver", "particles", "cfl",
                "floor", "error_name", "error", "mean_rho", "max_rho", "wall/sim_s", "ms/step");
    std::fflush(stdout);
    for (const Spec& p : specs) {
      Run r = execute(p, in, threads);
      r.build = buildCommit();
      r.settings = settings;
      if (r.status == "ok") {
        std::printf("%-12s %-11s %9zu %6.3f %-8s %-26s %10.4f %9.3f%% %9.3f%% %12.3f %10.3f", r.caseName.c_str(),
                    r.solver.c_str(), r.particles, r.cfl, r.floor.empty() ? "-" : r.floor.c_str(), r.errorName.c_str(),
                    r.error, 100 * r.meanDensityError, 100 * r.maxDensityError, r.wallPerSim, r.msPerStep);
        if (!r.error2Name.empty()) std::printf("  %s %.4f", r.error2Name.c_str(), r.error2);
        std::printf("\n");
      }
      std::fflush(stdout);
      runs.push_back(std::move(r));
    }
    header = "build " + std::string(buildCommit()) + ", settings " + settings + "\n";
  }
  sortRuns(runs);

  // The files replace only an earlier bench accuracy's (scanned again: proven now), each whole.
  // An earlier run's charts go first: this run draws its own, or none (no stale chart stays).
  FolderScan scan = scanOutputFolder(out, spec);
  if (chartsOnly) dropReport(scan);
  refuseForeignFiles(out, scan, spec);
  removeOwnFiles(out, scan, isChartFile);
  std::vector<OwnedFile> kept;
  for (const OwnedFile& f : scan.own)
    if (!isChartFile(f.name)) kept.push_back(f);
  OutputJournal journal(out, spec.command, kept);
  std::string wrote;
  if (!chartsOnly) {
    std::string csv = std::string(kCsvHeader) + "\n";
    for (const Run& r : runs) csv += csvLine(r);
    writeNoted(journal, out, "accuracy.csv", csv);
    writeNoted(journal, out, "accuracy.md", reportMarkdown(runs, header));
    wrote = "accuracy.csv, accuracy.md";
  }
  // The charts: for the sweep and for merges, not for single runs.
  const ChartsDone charts = only.empty() ? writeCharts(runs, journal, out) : ChartsDone{};
  for (const std::string& f : charts.written) wrote += (wrote.empty() ? "" : ", ") + f;
  std::printf("bench accuracy: %zu runs; wrote %s into %s\n", runs.size(), wrote.empty() ? "nothing" : wrote.c_str(),
              out.c_str());
  if (!charts.problem.empty()) {
    // One line: why, and how to draw them (the scripts and their data are written either way).
    const std::string script = "`gnuplot " + out + "/" + charts.scripts.front() + "`";
    if (charts.problem == kNoGnuplot)
      std::printf(
          "bench accuracy: charts not drawn (gnuplot is not on PATH); once it is installed (Debian: apt-get "
          "install gnuplot-nox) draw them with `benchmarks/plot_accuracy.sh %s` or, one script per case, %s\n",
          out.c_str(), script.c_str());
    else {
      std::printf("bench accuracy: charts not drawn (%s; gnuplot's message above)\n", charts.problem.c_str());
      return 1;
    }
  }
  return runs.empty() ? 1 : 0;
}

}  // namespace sph2d::cli
