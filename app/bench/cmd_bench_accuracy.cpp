// `sph2d bench accuracy`: what accuracy costs in time (issue 6). Runs every
// solver over the validation cases at several resolutions and CFL numbers,
// measures each run's error against experiment or theory and its cost, and
// writes accuracy.csv, accuracy.md and one chart per case (error against wall
// seconds per simulated second, log-log, one colour per solver, the Pareto
// front drawn). A benchmark, not a test: timings depend on the machine and its
// load; compare them as ratios within one run.
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
// The CFL number varied is each solver's own: solver.cfl (muller2003, wcsph),
// solver.velocity_cfl (dfsph), solver.max_move (pbf).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cli.hpp"
#include "commands.hpp"
#include "output/output_dir.hpp"
#include "bench/validation.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/render/image.hpp"
#include "sph2d/render/particle_export.hpp"
#include "sph2d/render/png_io.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace fs = std::filesystem;

namespace sph2d::cli {
namespace {

const char* kHelp =
    "Usage: sph2d bench accuracy [--out DIR] [--quick] [--solvers A,B] [--cases A,B] [--threads T] [--assets DIR]\n"
    "\n"
    "Runs every solver over the validation cases (hydrostatic tank, dam break against\n"
    "Martin & Moyce 1952, Taylor-Green vortex, start-up Poiseuille flow) at three\n"
    "resolutions (dam break about 5k, 20k and 80k particles)\n"
    "and two CFL numbers, and writes DIR/accuracy.csv, DIR/accuracy.md and\n"
    "DIR/<case>.png (default DIR: out/accuracy). --quick runs one small resolution and one\n"
    "CFL number per solver (a smoke test of a minute or two). --assets: the assets folder\n"
    "(default: ./assets). --levels K runs only the K coarsest resolutions (1..3).\n"
    "--from-csv A.csv[,B.csv...] runs nothing: it redraws accuracy.csv, accuracy.md and the\n"
    "charts in DIR from earlier runs' CSV files. --cases hydrostatic,dam_break,taylor_green,\n"
    "poiseuille runs only those cases (default: all four).\n"
    "Those files replace only the ones an earlier bench accuracy wrote in DIR (its\n"
    "DIR/.sph2d.journal lists them with their hashes): a file of those names that sph2d\n"
    "cannot prove it wrote is never touched, and the bench exits 2 naming it before it runs.\n";

/// The validation cases, in the order they run.
const char* const kCases[] = {"hydrostatic", "dam_break", "taylor_green", "poiseuille"};

struct Run {
  std::string caseName, solver;
  std::size_t particles = 0;
  double cfl = 0;
  std::string errorName;
  double error = 0, meanDensityError = 0, maxDensityError = 0, wallPerSim = 0, msPerStep = 0;
};

/// Sets `solver` and its own CFL-type number to `scale` × its default; returns the number.
double setSolver(SceneDef& s, const std::string& solver, double scale) {
  const SolverDef d = solverDefaults(solver);
  if (s.solver.type != solver) {
    s.solver.type = solver;
    s.solver.params = d.params;
    // The support a solver tunes (the game solver's 2 dx); the case keeps its own viscosity.
    s.solver.supportRatio = d.supportRatio;
  }
  if (solver == "dfsph") return s.solver.params["velocity_cfl"] = 0.4 * scale;
  if (solver == "pbf" || solver == "game") return s.solver.params["max_move"] = d.param("max_move") * scale;
  return s.solver.cfl = 0.25 * scale;
}

/// `table`: Martin & Moyce 1952's (T, Z) rows.
Run runDamBreak(SceneDef s, const std::vector<std::vector<double>>& table, int threads) {
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
  double se = 0;
  int n = 0;
  for (const auto& row : table) {
    const double t = row[0] / std::sqrt(2 * g / a);
    if (t > times.back()) continue;
    std::size_t k = 1;
    while (k + 1 < times.size() && times[k] < t) ++k;
    const double u = (t - times[k - 1]) / (times[k] - times[k - 1]);
    const double x = fronts[k - 1] + u * (fronts[k] - fronts[k - 1]);
    se += (x / a - row[1]) * (x / a - row[1]);
    ++n;
  }
  r.caseName = "dam_break";
  r.errorName = "surge_front_rms_Z";
  r.error = n ? std::sqrt(se / n) : 0;
  r.particles = w.particleCount();
  r.meanDensityError = densSum / frames;
  r.maxDensityError = densMax;
  r.wallPerSim = wall / w.time();
  r.msPerStep = 1e3 * wall / double(std::max<std::uint64_t>(1, w.substeps()));
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
  r.caseName = "hydrostatic";
  r.errorName = "pressure_profile_max_rel";
  r.error = measured ? worst : NAN;  // nothing measured: no figure, not a perfect one
  r.particles = w.particleCount();
  r.meanDensityError = densSum / std::max(1, frames - avgFrom);
  r.maxDensityError = densMax;
  r.wallPerSim = wall / w.time();
  r.msPerStep = 1e3 * wall / double(std::max<std::uint64_t>(1, w.substeps()));
  return r;
}

/// Log-log chart of error against wall seconds per simulated second, one colour per solver, Pareto front.
/// Writes `bytes` to `out`/`name` whole, noted in the folder's journal first.
void writeNoted(OutputJournal& journal, const std::string& out, const std::string& name, const std::string& bytes) {
  const std::string path = out + "/" + name;
  journal.note(name, fs::path(tempPathFor(path)).filename().string(), xxh64(bytes.data(), bytes.size()));
  writeFileAtomic(path, bytes);
}

/// The files `sph2d bench accuracy` writes into its --out folder.
const char* const kOutputs[] = {"accuracy.csv", "accuracy.md", "dam_break.png", "hydrostatic.png", "taylor_green.png",
                                "poiseuille.png"};

FolderSpec accuracyFolderSpec() {
  FolderSpec spec;
  spec.command = "bench accuracy";
  spec.writes = [](const std::string& name) { return std::find(std::begin(kOutputs), std::end(kOutputs), name) != std::end(kOutputs); };
  return spec;
}

void chart(const std::vector<Run>& runs, const std::string& caseName, OutputJournal& journal, const std::string& out) {
  const std::string path = out + "/" + caseName + ".png";
  Frame img;
  img.width = 720;
  img.height = 480;
  img.rgba.assign(std::size_t(img.width) * img.height * 4, 255);
  std::vector<const Run*> rs;
  for (const Run& r : runs)
    if (r.caseName == caseName && r.error > 0 && r.wallPerSim > 0) rs.push_back(&r);
  if (rs.empty()) return;
  double x0 = 1e30, x1 = -1e30, y0 = 1e30, y1 = -1e30;
  for (const Run* r : rs) {
    x0 = std::min(x0, std::log10(r->wallPerSim));
    x1 = std::max(x1, std::log10(r->wallPerSim));
    y0 = std::min(y0, std::log10(r->error));
    y1 = std::max(y1, std::log10(r->error));
  }
  x0 = std::floor(x0 - 0.1);
  x1 = std::ceil(x1 + 0.1);
  y0 = std::floor(y0 - 0.1);
  y1 = std::ceil(y1 + 0.1);
  const int L = 90, R = 700, T = 40, B = 420;
  auto px = [&](double lx) { return L + int((lx - x0) / (x1 - x0) * (R - L)); };
  auto py = [&](double ly) { return B - int((ly - y0) / (y1 - y0) * (B - T)); };
  const Rgba8 axis{40, 40, 40, 255}, grid{220, 220, 220, 255};
  for (double d = x0; d <= x1 + 1e-9; d += 1) {
    fillRect(img, px(d), T, px(d) + 1, B, grid);
    drawText(img, px(d) - 12, B + 8, formatLabel(std::pow(10.0, d)), 2, axis);
  }
  for (double d = y0; d <= y1 + 1e-9; d += 1) {
    fillRect(img, L, py(d), R, py(d) + 1, grid);
    drawText(img, 4, py(d) - 7, formatLabel(std::pow(10.0, d)), 2, axis);
  }
  fillRect(img, L, B, R, B + 2, axis);
  fillRect(img, L - 2, T, L, B, axis);
  drawText(img, L, 8, caseName + ": " + rs[0]->errorName + " vs wall s per sim s", 2, axis);
  std::map<std::string, Rgba8> colour;
  const Rgba8 palette[] = {{200, 40, 40, 255}, {40, 120, 200, 255}, {40, 160, 60, 255}, {200, 140, 0, 255}, {140, 60, 180, 255}};
  for (const Run* r : rs)
    if (!colour.count(r->solver)) colour[r->solver] = palette[colour.size() % 5];
  // Pareto front: runs no other run beats in both error and cost.
  std::vector<const Run*> front;
  for (const Run* a : rs) {
    bool dominated = false;
    for (const Run* b : rs)
      dominated = dominated || (b != a && b->error <= a->error && b->wallPerSim <= a->wallPerSim &&
                                (b->error < a->error || b->wallPerSim < a->wallPerSim));
    if (!dominated) front.push_back(a);
  }
  std::sort(front.begin(), front.end(), [](const Run* a, const Run* b) { return a->wallPerSim < b->wallPerSim; });
  for (std::size_t k = 1; k < front.size(); ++k) {
    const int ax = px(std::log10(front[k - 1]->wallPerSim)), ay = py(std::log10(front[k - 1]->error));
    const int bx = px(std::log10(front[k]->wallPerSim)), by = py(std::log10(front[k]->error));
    const int steps = std::max(std::abs(bx - ax), std::abs(by - ay)) + 1;
    for (int s = 0; s <= steps; ++s)
      fillRect(img, ax + (bx - ax) * s / steps, ay + (by - ay) * s / steps, ax + (bx - ax) * s / steps + 2,
               ay + (by - ay) * s / steps + 2, Rgba8{120, 120, 120, 255});
  }
  for (const Run* r : rs) {
    const int x = px(std::log10(r->wallPerSim)), y = py(std::log10(r->error));
    const int size = 3 + int(std::log10(double(std::max<std::size_t>(r->particles, 10))));
    fillRect(img, x - size, y - size, x + size + 1, y + size + 1, colour[r->solver]);
  }
  int ly = T + 10;
  for (const auto& c : colour) {
    fillRect(img, R - 150, ly, R - 138, ly + 12, c.second);
    drawText(img, R - 132, ly, c.first, 2, axis);
    ly += 20;
  }
  drawText(img, R - 150, ly, "LINE: PARETO FRONT", 1, axis);
  std::vector<std::uint8_t> bytes;
  encodePng(img.width, img.height, img.rgba.data(), pngSettings(6), bytes);
  journal.note(caseName + ".png", fs::path(tempPathFor(path)).filename().string(), xxh64(bytes.data(), bytes.size()));
  writeEncodedPngAtomic(path, bytes);
}

}  // namespace

int cmdBenchAccuracy(const std::vector<std::string>& args) {
  std::string out = "out/accuracy", assets = "assets";
  bool quick = false;
  int threads = 0, levels = 3;
  std::vector<std::string> solvers, fromCsv, cases(std::begin(kCases), std::end(kCases));
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= args.size()) throw UsageError(a + " needs a value");
      return args[++i];
    };
    if (a == "--help" || a == "-h") {
      std::fputs(kHelp, stdout);
      return 0;
    } else if (a == "--out") out = value();
    else if (a == "--assets") assets = value();
    else if (a == "--quick") quick = true;
    else if (a == "--threads") threads = parseInt(a, value(), 1, 256);
    else if (a == "--levels") levels = parseInt(a, value(), 1, 3);
    else if (a == "--from-csv") fromCsv = splitList(value());
    else if (a == "--solvers") solvers = splitList(value());
    else if (a == "--cases") {
      cases = splitList(value());
      if (cases.empty()) throw UsageError("--cases needs at least one case (hydrostatic, dam_break, taylor_green, poiseuille)");
      for (const std::string& k : cases)
        if (std::find(std::begin(kCases), std::end(kCases), k) == std::end(kCases))
          throw UsageError("--cases: unknown case '" + k + "' (allowed: hydrostatic, dam_break, taylor_green, poiseuille)");
    }
    else throw UsageError("unknown option '" + a + "' (see sph2d bench accuracy --help)");
  }
  std::vector<Run> runs;
  if (!fromCsv.empty()) {
    for (const std::string& path : fromCsv) {
      std::ifstream in(path);
      if (!in) throw UsageError("cannot open " + path);
      std::string line;
      std::getline(in, line);  // header
      while (std::getline(in, line)) {
        std::vector<std::string> f;
        std::stringstream ls(line);
        std::string cell;
        while (std::getline(ls, cell, ',')) f.push_back(cell);
        if (f.size() != 10) throw UsageError(path + ": expected 10 columns in '" + line + "'");
        Run r;
        r.caseName = f[0];
        r.solver = f[1];
        r.particles = std::size_t(std::stoull(f[2]));
        r.cfl = std::stod(f[3]);
        r.errorName = f[4];
        r.error = std::stod(f[5]);
        r.meanDensityError = std::stod(f[6]);
        r.maxDensityError = std::stod(f[7]);
        r.wallPerSim = std::stod(f[8]);
        r.msPerStep = std::stod(f[9]);
        runs.push_back(r);
      }
    }
  }
  SceneDef dam = loadScene(assets + "/scenes/validation/dam_break.json");
  SceneDef hydro = loadScene(assets + "/scenes/validation/hydrostatic_tank.json");
  SceneDef tg = loadScene(assets + "/scenes/validation/taylor_green.json");
  SceneDef channel = loadScene(assets + "/scenes/validation/poiseuille.json");
  const auto tgTable = validation::readReferenceCsv(assets + "/reference/taylor_green_decay.csv");
  const auto channelTable = validation::readReferenceCsv(assets + "/reference/channel_flow_transient.csv");
  const auto table = validation::readReferenceCsv(assets + "/reference/martin_moyce_1952_surge_front.csv");
  if (solvers.empty()) solvers = {"muller2003", "wcsph", "dfsph", "pbf", "game"};
  std::vector<std::string> known;
  {
    // Keep the solvers this build has (a scene with an unknown type fails to load).
    for (const auto& s : solvers) {
      try {
        parseScene("{\"solver\": {\"type\": \"" + s + "\"}}", "solver check");
        known.push_back(s);
      } catch (const SceneError&) {
        std::fprintf(stderr, "bench accuracy: solver '%s' is not in this build, skipped\n", s.c_str());
      }
    }
  }
  // The folder, before any run: held by this bench alone, and refused when it holds a file of
  // the names it writes that an earlier bench accuracy did not write (its journal lists those).
  const FolderSpec spec = accuracyFolderSpec();
  std::optional<OutputLock> lock;
  if (holdsLockFile(out)) lock.emplace(out);
  refuseForeignFiles(out, scanOutputFolder(out, spec), spec);
  makeOutputDir(out);
  if (!lock) lock.emplace(out);

  std::vector<double> damSpacings = quick ? std::vector<double>{0.04} : std::vector<double>{0.02, 0.01, 0.005};
  std::vector<double> hydroSpacings = quick ? std::vector<double>{0.05} : std::vector<double>{0.05, 0.025, 0.0125};
  std::vector<double> tgSpacings = quick ? std::vector<double>{0.04} : std::vector<double>{0.04, 0.02, 0.01};
  std::vector<double> channelSpacings = quick ? std::vector<double>{0.1} : std::vector<double>{0.1, 0.05, 0.025};
  if (!quick) {
    damSpacings.resize(std::size_t(levels));
    hydroSpacings.resize(std::size_t(levels));
    tgSpacings.resize(std::size_t(levels));
    channelSpacings.resize(std::size_t(levels));
  }
  auto want = [&](const char* k) { return std::find(cases.begin(), cases.end(), k) != cases.end(); };
  if (!want("hydrostatic")) hydroSpacings.clear();
  if (!want("dam_break")) damSpacings.clear();
  if (!want("taylor_green")) tgSpacings.clear();
  if (!want("poiseuille")) channelSpacings.clear();
  const std::vector<double> cflScales = quick ? std::vector<double>{1.0} : std::vector<double>{1.0, 2.0};
  if (!fromCsv.empty()) known.clear();  // redraw only
  std::printf("%-12s %-11s %9s %6s %-26s %10s %10s %10s %12s %10s\n", "case", "solver", "particles", "cfl", "error_name",
              "error", "mean_rho", "max_rho", "wall/sim_s", "ms/step");
  auto report = [&](const Run& r) {
    runs.push_back(r);
    std::printf("%-12s %-11s %9zu %6.3f %-26s %10.4f %9.3f%% %9.3f%% %12.3f %10.3f\n", r.caseName.c_str(), r.solver.c_str(),
                r.particles, r.cfl, r.errorName.c_str(), r.error, 100 * r.meanDensityError, 100 * r.maxDensityError,
                r.wallPerSim, r.msPerStep);
    std::fflush(stdout);
  };
  for (const std::string& solver : known)
    for (double cs : cflScales) {
      for (double dx : hydroSpacings) {
        SceneDef s = hydro;
        const double cfl = setSolver(s, solver, cs);
        s.solver.spacing = dx;
        s.solver.maxSubsteps = 100000;
        if (solver == "muller2003") s.solver.viscosity = 0.01;
        try {
          Run r = runHydrostatic(s, threads);
          r.solver = solver;
          r.cfl = cfl;
          report(r);
        } catch (const SimulationError& e) {
          std::printf("hydrostatic  %-11s dx %.4f cfl %.3f: unstable (%s)\n", solver.c_str(), dx, cfl, e.what());
        }
      }
      for (double dx : damSpacings) {
        SceneDef s = dam;
        const double cfl = setSolver(s, solver, cs);
        s.solver.spacing = dx;
        s.solver.maxSubsteps = 100000;
        s.maxParticles = 1000000;
        if (solver == "muller2003") s.solver.viscosity = 0.01;
        try {
          Run r = runDamBreak(s, table, threads);
          r.solver = solver;
          r.cfl = cfl;
          report(r);
        } catch (const SimulationError& e) {
          std::printf("dam_break    %-11s dx %.4f cfl %.3f: unstable (%s)\n", solver.c_str(), dx, cfl, e.what());
        }
      }
      // The analytic cases: `run` returns (error, mean and max density error, simulated s, substeps).
      auto analytic = [&](const char* caseName, const char* errorName, const SceneDef& s, double cfl, auto run) {
        try {
          const auto t0 = std::chrono::steady_clock::now();
          const auto v = run(s);
          const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          Run r;
          r.caseName = caseName;
          r.errorName = errorName;
          r.error = v.error;
          r.particles = countBlockParticles(s);
          r.meanDensityError = v.meanDensityError;
          r.maxDensityError = v.maxDensityError;
          r.wallPerSim = wall / v.simSeconds;
          r.msPerStep = 1e3 * wall / double(std::max<std::uint64_t>(1, v.substeps));
          r.solver = s.solver.type;
          r.cfl = cfl;
          report(r);
        } catch (const SimulationError& e) {
          std::printf("%-12s %-11s dx %.4f cfl %.3f: unstable (%s)\n", caseName, s.solver.type.c_str(), s.solver.spacing, cfl,
                      e.what());
        }
      };
      struct Measured {
        double error, meanDensityError, maxDensityError, simSeconds;
        std::uint64_t substeps;
      };
      for (double dx : tgSpacings) {
        SceneDef s = tg;
        const double cfl = setSolver(s, solver, cs);
        s.solver.spacing = dx;
        s.solver.maxSubsteps = 100000;
        analytic("taylor_green", "umax_ratio_rms", s, cfl, [&](const SceneDef& sc) {
          const auto v = validation::runTaylorGreen(sc, sc.duration, tgTable, threads);
          return Measured{v.umaxRms, v.meanDensityError, v.maxDensityError, v.simSeconds, v.substeps};
        });
      }
      for (double dx : channelSpacings) {
        SceneDef s = channel;
        const double cfl = setSolver(s, solver, cs);
        s.solver.spacing = dx;
        // The period must hold 3 support radii: 8 spacings at the coarse level (the plates reach 1 m beyond).
        const double period = std::max(s.periodic.max.x() - s.periodic.min.x(), 8 * dx);
        s.periodic.max.x() = s.periodic.min.x() + period;
        s.blocks[0].max.x() = s.blocks[0].min.x() + period;
        s.solver.maxSubsteps = 100000;
        analytic("poiseuille", "u_rms_vs_series", s, cfl, [&](const SceneDef& sc) {
          const auto v = validation::runPoiseuille(sc, 0.0, 1.0, channelTable, threads);
          return Measured{v.rmsError, v.meanDensityError, v.maxDensityError, v.simSeconds, v.substeps};
        });
      }
    }

  // The files replace only an earlier bench accuracy's (scanned again: proven now), each whole.
  const FolderScan scan = scanOutputFolder(out, spec);
  refuseForeignFiles(out, scan, spec);
  OutputJournal journal(out, spec.command, scan.own);
  {
    std::ostringstream csv;
    csv << "case,solver,particles,cfl,error_name,error,mean_density_error,max_density_error,wall_s_per_sim_s,ms_per_step\n";
    for (const Run& r : runs)
      csv << r.caseName << ',' << r.solver << ',' << r.particles << ',' << r.cfl << ',' << r.errorName << ',' << r.error << ','
          << r.meanDensityError << ',' << r.maxDensityError << ',' << r.wallPerSim << ',' << r.msPerStep << '\n';
    writeNoted(journal, out, "accuracy.csv", csv.str());
  }
  {
    std::ostringstream md;
    md << "| case | solver | particles | cfl | error | value | mean density error | max density error | wall s / sim s | ms / step |\n"
          "|---|---|---|---|---|---|---|---|---|---|\n";
    char line[512];
    for (const Run& r : runs) {
      std::snprintf(line, sizeof line, "| %s | %s | %zu | %.3f | %s | %.4f | %.3f %% | %.3f %% | %.3f | %.3f |\n",
                    r.caseName.c_str(), r.solver.c_str(), r.particles, r.cfl, r.errorName.c_str(), r.error,
                    100 * r.meanDensityError, 100 * r.maxDensityError, r.wallPerSim, r.msPerStep);
      md << line;
    }
    writeNoted(journal, out, "accuracy.md", md.str());
  }
  chart(runs, "dam_break", journal, out);
  chart(runs, "hydrostatic", journal, out);
  chart(runs, "taylor_green", journal, out);
  chart(runs, "poiseuille", journal, out);
  std::printf("bench accuracy: %zu runs; wrote %s/accuracy.csv, accuracy.md, dam_break.png, hydrostatic.png, taylor_green.png, "
              "poiseuille.png\n", runs.size(), out.c_str());
  return runs.empty() ? 1 : 0;
}

}  // namespace sph2d::cli
