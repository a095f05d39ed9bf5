// `sph2d bench game`: the game end of the accuracy/cost trade-off (issue 15).
// Runs the default dam break (a 1 m × 2 m column in a 4 m × 3 m tank) at N
// particles for each quality preset and thread count, frame by frame as a
// game does, and reports what a game developer asks of it: wall seconds per
// simulated second, substeps and pressure iterations per frame, the worst
// mean and single-particle compression over the frames, the largest gain of
// kinetic plus potential energy over the initial, particles outside the tank,
// and the surge front against Martin & Moyce 1952. With --peer it runs the
// LiquidFun harness (benchmarks/peers/liquidfun) on the same dam break in the
// same invocation and prints sph2d's time as a ratio of the peer's.
//
// A benchmark, not a test: rerun it, and compare figures as ratios within one
// run (the machines are shared and noisy).
//
// Every run has an id (preset-particles-tthreads[-floor], liquidfun[_static]-particles);
// --list prints each run as a command of its own (--only ID --out DIR/ID) for a scheduler,
// and --merge DIR gathers their game.csv files into one (app/bench/sweep.hpp).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "bench/game_runs.hpp"
#include "bench/sweep.hpp"
#include "bench/validation.hpp"
#include "cli.hpp"
#include "commands.hpp"
#include "core/kernels.hpp"
#include "output/output_dir.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/render/particle_export.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace sph2d::cli {
namespace {

using namespace game_bench;

const char* kHelp =
    "Usage: sph2d bench game [--particles N[,N...]] [--threads T[,T...]] [--seconds S] [--presets P[,P...]]\n"
    "                        [--floors F[,F...]] [--set KEY=VALUE]... [--peer [PATH]] [--csv FILE] [--out DIR]\n"
    "                        [--assets DIR] [--list | --list-ids | --only ID[,ID...]]\n"
    "       sph2d bench game --merge DIR | --from-csv A.csv[,B.csv...] [--allow-mixed] (--out DIR | --csv FILE)\n"
    "\n"
    "The default dam break (assets/scenes/dam_break.json: a 1 m x 2 m column in a 4 m x 3 m\n"
    "tank) with the spacing set so the column holds about N particles (default 20000), for S\n"
    "simulated seconds (default 4), once per quality preset P (default game,balanced,accurate),\n"
    "particle count N, floor F and thread count T (default 1,2). Each run prints: wall seconds\n"
    "per simulated second,\n"
    "substeps and pressure iterations per frame, the worst per-frame mean compression and the\n"
    "worst single-particle compression, the largest gain of kinetic plus potential energy over\n"
    "the initial (a fraction of it), the most particles outside the tank in any frame, the RMS\n"
    "of the surge front Z = x/a against Martin & Moyce 1952, and the compression and surface\n"
    "height at the end measured from positions alone (as for the peer).\n"
    "A preset with _oil (game_oil, balanced_oil: their solvers take a density contrast) or _dye\n"
    "(game_dye, ...) runs the column in two materials, water below and oil of 800 kg/m3 or a dye\n"
    "of the water's density above: the second material's cost, against the preset alone in the\n"
    "same run.\n"
    "--floors: the tank's walls: scene (as the scene says, the default), free (friction 0),\n"
    "muX (Coulomb friction X at contact, e.g. mu0.5), noslip (friction 0, solver.no_slip with\n"
    "the viscosity at least 7.3e-5 m2/s, Martin & Moyce's Reynolds number at a = 1 m).\n"
    "--set KEY=VALUE changes the solver of every run: a shared key (viscosity, support_ratio,\n"
    "cfl, max_substeps) or one of the preset solver's own parameters.\n"
    "--peer runs the LiquidFun harness (lf_dam_break: cmake -DSPH2D_PEER_LIQUIDFUN=ON, target\n"
    "lf_dam_break; benchmarks/peers/liquidfun) on the same dam break, with its default iterations\n"
    "and with --static, and prints the ratio of each sph2d run's time to the peer's; --peer PATH\n"
    "runs the harness at PATH instead.\n"
    "A run measured at more than one N ends with its cost growth: the wall time's ratio, per particle\n"
    "too, and the substeps and iterations per frame at the smallest and each larger N.\n"
    "--csv FILE writes one row per run (fractions, not percent); --out DIR writes DIR/game.csv\n"
    "(replacing only a game.csv an earlier bench game wrote there).\n"
    "\n"
    "One run at a time, for a scheduler (docs/PERFORMANCE.md, docs/ACCURACY.md):\n"
    "--list prints every run the other options select as one command line,\n"
    "  `sph2d bench game --only ID --out DIR/ID ...` (default DIR: out/bench_game); --list-ids\n"
    "  the ids alone: PRESET-PARTICLES-tTHREADS[-FLOOR] (game-20000-t2, balanced-5000-t1-mu0.5)\n"
    "  and, with --peer, liquidfun-PARTICLES and liquidfun_static-PARTICLES.\n"
    "--only ID[,ID...] runs exactly those runs (not with --presets, --particles, --threads, --floors).\n"
    "--merge DIR gathers every DIR/*/game.csv, --from-csv the files named, into --out or --csv,\n"
    "  rows in the sweep's order, the peer ratio taken from the liquidfun_static row of the same\n"
    "  particle count. Rows record the build's commit and the settings (seconds, --set, the\n"
    "  assets' hash): rows of different builds or settings are refused (exit 2) unless --allow-mixed.\n";

/// Positions-only measures of a final state, the same for sph2d and the peer:
/// the mean compression max(ρ/ρ0 − 1, 0) with ρ summed by Wendland C2 of
/// support 2.5 dx, the mass calibrated so a square lattice of spacing dx has
/// ρ0 (the tank's walls are not counted: wall rows read low, for both), and the
/// mean height of the free surface over x in [0.5, 3.5] (highest particle per
/// 5 cm bin, as the peer harness measures it).
void endMeasures(const std::vector<Vec2d>& pos, double dx, double& compression, double& surface) {
  const double R = 2.5 * dx;
  const WendlandC2<double> W(R);
  double lattice = 0;
  const int n = int(std::ceil(R / dx)) + 1;
  for (int j = -n; j <= n; ++j)
    for (int i = -n; i <= n; ++i) lattice += W.value(std::sqrt(double(i * i + j * j)) * dx);
  // A uniform grid of cells of size R over the points.
  std::map<std::pair<long, long>, std::vector<std::size_t>> cells;
  for (std::size_t k = 0; k < pos.size(); ++k)
    cells[{long(std::floor(pos[k].x() / R)), long(std::floor(pos[k].y() / R))}].push_back(k);
  double sum = 0;
  for (std::size_t k = 0; k < pos.size(); ++k) {
    const long cx = long(std::floor(pos[k].x() / R)), cy = long(std::floor(pos[k].y() / R));
    double s = 0;
    for (long dy = -1; dy <= 1; ++dy)
      for (long dxc = -1; dxc <= 1; ++dxc) {
        auto it = cells.find({cx + dxc, cy + dy});
        if (it == cells.end()) continue;
        for (std::size_t j : it->second) s += W.value((pos[k] - pos[j]).norm());
      }
    sum += std::max(0.0, s / lattice - 1);
  }
  compression = pos.empty() ? 0 : sum / double(pos.size());
  std::map<int, double> top;
  for (const Vec2d& p : pos)
    if (p.x() >= 0.5 && p.x() < 3.5) {
      const int b = int((p.x() - 0.5) / 0.05);
      auto it = top.find(b);
      if (it == top.end() || it->second < p.y()) top[b] = p.y();
    }
  surface = 0;
  for (const auto& kv : top) surface += kv.second;
  surface = top.empty() ? 0 : surface / double(top.size());
}

/// The dam break's column in two materials: water below, `second` (oil of 800 kg/m³, or dye of
/// the water's density) above, split at the lattice row nearest half the column's height (the
/// particles where the one block would put them).
void addSecondMaterial(SceneDef& s, const std::string& second) {
  MaterialDef water, other;
  water.name = "water";
  water.density = s.solver.restDensity;
  other.name = second;
  other.density = second == "oil" ? 800 : s.solver.restDensity;
  other.color = {0.95, 0.70, 0.15};
  s.materials = {water, other};
  std::vector<FluidBlockDef> blocks;
  for (const FluidBlockDef& b : s.blocks) {
    FluidBlockDef lower = b, upper = b;
    const double dx = s.solver.spacing;
    lower.max.y() = upper.min.y() = b.min.y() + dx * std::round(0.5 * (b.max.y() - b.min.y()) / dx);
    upper.material = 1;
    blocks.push_back(lower);
    blocks.push_back(upper);
  }
  s.blocks = blocks;
}

Row runSph2d(const SceneDef& base, const std::string& preset, int threads, double seconds,
             const std::vector<std::vector<double>>& surgeTable) {
  SceneDef s = base;
  Row r;
  r.name = "sph2d_" + preset;
  r.threads = threads;
  World w(s, WorldOptions{threads});
  w.takeWarnings();
  r.particles = w.particleCount();
  const double g = 9.81, m = double(w.particleMass()), a = 1.0;
  auto energy = [&] {
    double e = w.kineticEnergy();
    for (std::size_t i = 0; i < w.particleCount(); ++i) e += m * g * w.worldPosition(i).y();
    return e;
  };
  auto front = [&] {
    double f = 0;
    for (std::size_t i = 0; i < w.particleCount(); ++i) f = std::max(f, w.worldPosition(i).x());
    return f;
  };
  const double e0 = energy();
  std::vector<double> times = {0}, fronts = {front()};
  const int frames = int(std::lround(seconds * s.fps));
  double wall = 0, worstMean = 0, worstMax = 0, gain = 0, outside = 0;
  const std::uint64_t it0 = w.counters().solverIterations;
  for (int f = 0; f < frames; ++f) {
    const auto t0 = std::chrono::steady_clock::now();
    w.stepFrame();
    wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const DensityStats d = w.densityStats();
    worstMean = std::max(worstMean, d.meanError);
    worstMax = std::max(worstMax, d.maxError);
    gain = std::max(gain, (energy() - e0) / e0);
    double out = 0;
    for (std::size_t i = 0; i < w.particleCount(); ++i) {
      const Vec2d p = w.worldPosition(i);
      out += !(p.x() >= 0 && p.x() <= 4 && p.y() >= 0 && p.y() <= 3);
    }
    outside = std::max(outside, out);
    times.push_back(w.time());
    fronts.push_back(front());
  }
  r.wallPerSim = wall / w.time();
  r.substepsPerFrame = double(w.counters().substeps) / frames;
  r.iterationsPerFrame = double(w.counters().solverIterations - it0) / frames;
  r.meanCompression = worstMean;
  r.maxCompression = worstMax;
  r.energyGain = gain;
  r.outside = outside;
  // Surge front over the table's times within the run (the front reaches the far wall at T ≈ 3.4).
  double se = 0;
  int n = 0;
  for (const auto& row : surgeTable) {
    const double t = row[0] / std::sqrt(2 * g / a);
    if (t > times.back() || row[1] >= 4.0 - 1e-9) continue;
    std::size_t k = 1;
    while (k + 1 < times.size() && times[k] < t) ++k;
    const double u = (t - times[k - 1]) / (times[k] - times[k - 1]);
    const double x = fronts[k - 1] + u * (fronts[k] - fronts[k - 1]);
    se += (x / a - row[1]) * (x / a - row[1]);
    ++n;
  }
  r.surgeRms = n ? std::sqrt(se / n) : NAN;
  std::vector<Vec2d> pos;
  for (std::size_t i = 0; i < w.particleCount(); ++i) pos.push_back(w.worldPosition(i));
  endMeasures(pos, s.solver.spacing, r.endCompression, r.endSurface);
  return r;
}

/// Runs the LiquidFun harness and parses its summary line; false when it cannot run.
bool runPeer(const std::string& exe, double spacing, double seconds, bool stat, Row& r) {
  const std::string csv = "/tmp/sph2d_bench_game_peer_" + std::to_string(::getpid()) + ".csv";
  const std::string cmd = "'" + exe + "' --spacing " + std::to_string(spacing) + " --seconds " +
                          std::to_string(seconds) + (stat ? " --static" : "") + " --csv '" + csv + "' 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return false;
  std::string out;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  const int rc = ::pclose(p);
  int particles = 0;
  double wps = NAN;
  const auto at = out.find("liquidfun: ");
  if (rc != 0 || at == std::string::npos || std::sscanf(out.c_str() + at, "liquidfun: %d particles", &particles) != 1)
    throw std::runtime_error("the peer " + exe + " failed: " + out);
  const auto w = out.find(" wall s per simulated s");
  if (w != std::string::npos) {
    const std::size_t b = out.rfind(", ", w);
    if (b != std::string::npos) wps = std::atof(out.c_str() + b + 2);
  }
  if (!(wps > 0)) throw std::runtime_error("the peer " + exe + " printed no wall time per simulated second: " + out);
  r.name = stat ? "liquidfun_static" : "liquidfun";
  r.particles = std::size_t(particles);
  r.threads = 1;
  r.wallPerSim = wps;
  r.substepsPerFrame = NAN;
  std::vector<Vec2d> pos;
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    double x, y;
    if (std::sscanf(line.c_str(), "%lf,%lf", &x, &y) == 2) pos.emplace_back(x, y);
  }
  std::remove(csv.c_str());
  endMeasures(pos, spacing, r.endCompression, r.endSurface);
  return true;
}

/// Applies KEY=VALUE to a solver definition (a shared key or a solver parameter).
void applySet(SolverDef& d, const std::string& kv) {
  const auto eq = kv.find('=');
  if (eq == std::string::npos) throw UsageError("--set expects KEY=VALUE, got '" + kv + "'");
  const std::string k = kv.substr(0, eq);
  const double v = parseNumber("--set " + k, kv.substr(eq + 1));
  if (k == "viscosity")
    d.viscosity = v;
  else if (k == "support_ratio")
    d.supportRatio = v;
  else if (k == "cfl")
    d.cfl = v;
  else if (k == "max_substeps")
    d.maxSubsteps = int(v);
  else if (d.params.count(k))
    d.params[k] = v;
  else {
    std::string keys = "viscosity, support_ratio, cfl, max_substeps";
    for (const auto& p : d.params) keys += ", " + p.first;
    throw UsageError("--set: '" + k + "' is not a key of the " + d.type + " solver; keys: " + keys);
  }
}

}  // namespace

int cmdBenchGame(const std::vector<std::string>& args) {
  std::vector<int> particles = {20000};
  std::vector<int> threads = {1, 2};
  double seconds = 4;
  std::vector<std::string> presets = {"game", "balanced", "accurate"}, sets, floors = {"scene"}, only, fromCsv,
                           mergeDirs;
  std::string peer, csvPath, out, assetsPath = "assets";
  bool list = false, listIds = false, allowMixed = false, shaped = false;
  for (ArgReader opt(args, "bench game"); opt.next();) {
    const std::string a = opt.arg();
    if (opt.help()) {
      std::fputs(kHelp, stdout);
      return 0;
    } else if (opt.is("--particles")) {
      particles = opt.intListValue(100, 50000000);
      shaped = true;
    } else if (opt.is("--threads")) {
      threads = opt.intListValue(1, 256);
      shaped = true;
    } else if (opt.is("--seconds")) {
      seconds = opt.numberValue();
      // At least one frame of 1/60 s, so that every figure measures something.
      if (!(seconds >= 1.0 / 60 && seconds <= 60)) throw UsageError("--seconds must be in [1/60, 60]");
    } else if (opt.is("--presets")) {
      presets = opt.listValue();
      shaped = true;
      for (const std::string& p : presets)
        if (const std::string why = game_bench::presetProblem(p); !why.empty()) throw UsageError("--presets: " + why);
      if (presets.empty()) throw UsageError("--presets needs at least one preset");
    } else if (opt.is("--floors")) {
      floors.clear();
      shaped = true;
      for (const std::string& f : opt.listValue()) floors.push_back(parseFloorVariant(a, f).name);
      if (floors.empty()) throw UsageError("--floors needs at least one floor (scene, free, muX, noslip)");
    } else if (opt.is("--set"))
      sets.push_back(opt.value());
    else if (opt.is("--peer")) {
      // `--peer` alone: the harness this build tree builds (-DSPH2D_PEER_LIQUIDFUN=ON); `--peer PATH`: that one.
      peer = opt.valueOr(SPH2D_PEER_EXE);
    } else if (opt.is("--assets"))
      assetsPath = opt.value();
    else if (opt.is("--csv"))
      csvPath = opt.value();
    else if (opt.is("--out"))
      out = opt.value();
    else if (opt.is("--list"))
      list = true;
    else if (opt.is("--list-ids"))
      listIds = true;
    else if (opt.is("--only")) {
      only = opt.listValue();
      if (only.empty()) throw UsageError("--only needs a run id (sph2d bench game --list-ids lists them)");
    } else if (opt.is("--merge"))
      mergeDirs.push_back(opt.value());
    else if (opt.is("--from-csv")) {
      for (const std::string& f : opt.listValue()) fromCsv.push_back(f);
    } else if (opt.is("--allow-mixed"))
      allowMixed = true;
    else
      opt.unknown();
  }
  const bool merging = !fromCsv.empty() || !mergeDirs.empty();
  if (int(list) + int(listIds) + int(!only.empty()) + int(merging) > 1)
    throw UsageError("--list, --list-ids, --only and --merge/--from-csv are one each: give one of them");
  if (!only.empty() && shaped)
    throw UsageError(
        "--only names its runs: not with --presets, --particles, --threads or --floors (they select what --list prints)");
  if (allowMixed && !merging) throw UsageError("--allow-mixed is for --merge and --from-csv");
  if (merging && out.empty() && csvPath.empty())
    throw UsageError("--merge and --from-csv write --out DIR or --csv FILE: give one");
  if (peer.find('\'') != std::string::npos)  // it goes into a shell command between single quotes
    throw UsageError("--peer " + peer + ": a path with a single quote is not accepted");
  if (!peer.empty() && !list && !listIds && ::access(peer.c_str(), X_OK) != 0)
    throw UsageError("--peer " + peer +
                     ": not an executable (build the peer: cmake -S . -B build -DSPH2D_PEER_LIQUIDFUN=ON && "
                     "cmake --build build --target lf_dam_break; benchmarks/peers/liquidfun/README.md)");

  // --out: held by this bench alone, and refused when it holds a game.csv an earlier bench game did not write.
  const FolderSpec spec = gameFolderSpec();
  std::optional<OutputLock> lock;
  auto holdFolder = [&] {
    if (out.empty()) return;
    if (holdsLockFile(out)) lock.emplace(out);
    refuseForeignFiles(out, scanOutputFolder(out, spec), spec);
    makeOutputDir(out);
    if (!lock) lock.emplace(out);
  };
  auto writeOutputs = [&](std::vector<Row> rows) {
    sortRows(rows);
    const std::string text = csvText(rows);
    if (!out.empty()) {
      const FolderScan scan = scanOutputFolder(out, spec);
      refuseForeignFiles(out, scan, spec);
      OutputJournal journal(out, spec.command, scan.own);
      const std::string path = out + "/game.csv";
      journal.note("game.csv", std::filesystem::path(tempPathFor(path)).filename().string(),
                   xxh64(text.data(), text.size()));
      writeFileAtomic(path, text);
      std::printf("wrote %s\n", path.c_str());
    }
    if (!csvPath.empty()) {
      writeFileAtomic(csvPath, text);
      std::printf("wrote %s\n", csvPath.c_str());
    }
  };

  if (merging) {
    for (const std::string& d : mergeDirs)
      for (const std::string& f : mergeParts("--merge", d, "game.csv")) fromCsv.push_back(f);
    std::vector<Row> rows;
    std::map<std::string, std::string> seen;
    std::vector<RowOrigin> origins;
    for (const std::string& path : fromCsv)
      for (Row& r : readRows(path)) {
        const auto [it, fresh] = seen.emplace(r.id, path);
        if (!fresh)
          throw UsageError("bench game: run " + r.id + " is in " + it->second +
                           (it->second == path ? " twice" : " and in " + path) + ": merge each run once");
        origins.push_back(RowOrigin{path, r.build, r.settings});
        rows.push_back(std::move(r));
      }
    const std::vector<RowOrigin> kinds = checkOrigins("bench game", origins, allowMixed);
    std::printf("bench game: %zu rows from %zu files", rows.size(), fromCsv.size());
    for (const RowOrigin& k : kinds) std::printf("; build %s, settings %s", k.build.c_str(), k.settings.c_str());
    std::printf("\n");
    std::fputs(costGrowth(rows).c_str(), stdout);
    holdFolder();
    writeOutputs(rows);
    return 0;
  }

  // The runs: the sweep's, or --only's.
  std::vector<Spec> specs;
  if (!only.empty()) {
    for (const std::string& id : only) specs.push_back(parseId(id, !peer.empty()));
  } else {
    for (int n : particles) {
      if (!peer.empty())
        for (const char* pn : kPeers) {
          Spec p;
          p.peer = pn;
          p.particles = n;
          specs.push_back(p);
        }
      for (const std::string& preset : presets)
        for (const std::string& f : floors)
          for (int t : threads) {
            Spec p;
            p.preset = preset;
            p.particles = n;
            p.floor = f;
            p.threads = t;
            specs.push_back(p);
          }
    }
    for (Spec& p : specs) p.id = specId(p);
  }
  // --set: each run's solver with every --set applied is one the World takes (ranges,
  // combinations), before any run starts.
  for (const Spec& p : specs) {
    if (!p.peer.empty()) continue;
    std::string base, second;
    game_bench::splitPreset(p.preset, base, second);
    SolverDef d = qualityPreset(base);
    for (const std::string& kv : sets) applySet(d, kv);
    if (const std::string why = solverDefProblem(d); !why.empty())
      throw UsageError("--set (preset " + p.preset + "): " + why);
  }
  const std::string assets = assetsPath;
  const std::string scenePath = assets + "/scenes/dam_break.json",
                    surgePath = assets + "/reference/martin_moyce_1952_surge_front.csv";
  std::string setText;
  for (const std::string& kv : sets) setText += (setText.empty() ? "" : "|") + kv;
  const std::string settings = "seconds=" + fmt(seconds, "%g") + ";set=" + (setText.empty() ? "none" : setText) +
                               ";assets=" + filesHash({scenePath, surgePath});
  if (list || listIds) {
    const std::string exe = shellQuote(selfExe()), root = absolutePath(out.empty() ? "out/bench_game" : out);
    for (const Spec& p : specs) {
      if (listIds) {
        std::printf("%s\n", p.id.c_str());
        continue;
      }
      std::string cmd = exe + " bench game --only " + p.id + " --out " + shellQuote(root + "/" + p.id) + " --assets " +
                        shellQuote(absolutePath(assets)) + " --seconds " + fmt(seconds, "%.17g");
      for (const std::string& kv : sets) cmd += " --set " + shellQuote(kv);
      if (!p.peer.empty()) cmd += " --peer " + shellQuote(absolutePath(peer));
      std::printf("%s\n", cmd.c_str());
    }
    return 0;
  }
  const SceneDef scene = loadScene(scenePath);
  const auto surge = validation::readReferenceCsv(surgePath);
  holdFolder();
  std::printf(
      "bench game: dam break, 1 m x 2 m column, spacing sqrt(2/N) m, %g simulated s, one stepFrame of 1/%g s per frame\n",
      seconds, scene.fps);
  std::printf("%-22s %-18s %9s %3s %9s %8s %8s %8s %8s %8s %7s %8s %5s %8s %8s\n", "id", "run", "particles", "thr",
              "wall/sim", "vs peer", "substp/f", "iter/f", "mean cmp", "max cmp", "E gain", "surge", "out", "end cmp",
              "surface");
  std::fflush(stdout);
  std::vector<Row> rows;
  std::map<int, double> peerTime;  // requested particles → liquidfun_static's wall time, this run
  auto print = [&](const Row& r, int n) {
    const auto pt = peerTime.find(n);
    std::printf("%-22s %-18s %9zu %3d %9s %8s %8s %8s %8s %8s %7s %8s %5s %8s %8s\n", r.id.c_str(), r.name.c_str(),
                r.particles, r.threads, fmt(r.wallPerSim, "%.3f").c_str(),
                fmt(pt == peerTime.end() ? NAN : r.wallPerSim / pt->second, "%.2fx").c_str(),
                fmt(r.substepsPerFrame, "%.2f").c_str(), fmt(r.iterationsPerFrame, "%.1f").c_str(),
                fmt(100 * r.meanCompression, "%.2f%%").c_str(), fmt(100 * r.maxCompression, "%.1f%%").c_str(),
                fmt(100 * r.energyGain, "%.2f%%").c_str(), fmt(r.surgeRms, "%.3f").c_str(),
                fmt(r.outside, "%.0f").c_str(), fmt(100 * r.endCompression, "%.2f%%").c_str(),
                fmt(r.endSurface, "%.3f").c_str());
    std::fflush(stdout);
  };
  for (const Spec& p : specs) {
    const double spacing = std::sqrt(2.0 / double(p.particles));
    Row r;
    if (!p.peer.empty()) {
      runPeer(peer, spacing, seconds, p.peer == "liquidfun_static", r);
      if (p.peer == "liquidfun_static") peerTime[p.particles] = r.wallPerSim;
      r.floor = "";
    } else {
      SceneDef s = scene;
      std::string base, second;
      game_bench::splitPreset(p.preset, base, second);
      s.solver = qualityPreset(base);
      s.solver.spacing = spacing;
      for (const std::string& kv : sets) applySet(s.solver, kv);
      if (!second.empty()) addSecondMaterial(s, second);  // after --set: the water is the solver's fluid
      s.maxParticles = std::size_t(p.particles) * 2 + 1000;
      applyFloorVariant(s, parseFloorVariant("--floors", p.floor));
      r = runSph2d(s, p.preset, p.threads, seconds, surge);
      r.floor = p.floor;
    }
    r.id = p.id;
    r.build = buildCommit();
    r.settings = settings;
    rows.push_back(r);
    print(r, p.particles);
  }
  if (!peer.empty() && !peerTime.empty())
    std::printf("vs peer: sph2d's wall time per simulated second over LiquidFun --static's, measured in this run\n");
  std::fputs(costGrowth(rows).c_str(), stdout);
  writeOutputs(rows);
  return 0;
}

}  // namespace sph2d::cli
