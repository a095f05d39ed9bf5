// app/bench/accuracy_report.cpp — see accuracy_report.hpp.
#include "bench/accuracy_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <map>
#include <sstream>

#include "bench/sweep.hpp"
#include "cli.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/render/image.hpp"
#include "sph2d/render/particle_export.hpp"
#include "sph2d/render/png_io.hpp"

namespace fs = std::filesystem;

namespace sph2d::cli::accuracy {

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

const char* const kCsvHeader =
    "run_id,case,solver,floor,particles,cfl,error_name,error,error2_name,error2,mean_density_error,max_density_error,"
    "wall_s_per_sim_s,ms_per_step,status,build,settings,solver_params";
/// The columns of the CSV before run ids (10 columns): read as rows of an unknown build.
const char* const kLegacyHeader =
    "case,solver,particles,cfl,error_name,error,mean_density_error,max_density_error,wall_s_per_sim_s,ms_per_step";

std::string num(double v) {
  if (std::isnan(v)) return "";
  std::ostringstream o;
  o << v;
  return o.str();
}

static double parseCell(const std::string& path, const std::string& column, const std::string& v) {
  if (v.empty()) return NAN;
  try {
    std::size_t used = 0;
    const double d = std::stod(v, &used);
    if (used == v.size()) return d;
  } catch (const std::exception&) {
  }
  throw UsageError(path + ": column " + column + ": '" + v + "' is not a number");
}

std::string csvLine(const Run& r) {
  std::ostringstream o;
  o << r.id << ',' << r.caseName << ',' << r.solver << ',' << r.floor << ',' << r.particles << ',' << num(r.cfl) << ','
    << r.errorName << ',' << num(r.error) << ',' << r.error2Name << ',' << num(r.error2) << ','
    << num(r.meanDensityError) << ',' << num(r.maxDensityError) << ',' << num(r.wallPerSim) << ',' << num(r.msPerStep)
    << ',' << r.status << ',' << r.build << ',' << r.settings << ',' << r.params << '\n';
  return o.str();
}

/// The rows of an accuracy.csv (this format or the one before run ids).
std::vector<Run> readRuns(const std::string& path) {
  const CsvRows t = readCsvRows(path);
  std::string header;
  for (const std::string& h : t.header) header += (header.empty() ? "" : ",") + h;
  const bool legacy = header == kLegacyHeader;
  if (!legacy && header != kCsvHeader)
    throw UsageError(path + ": not an accuracy.csv of sph2d bench accuracy (its header: " + header + ")");
  std::vector<Run> runs;
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    Run r;
    r.file = path;
    r.caseName = t.cell(i, "case");
    r.solver = t.cell(i, "solver");
    const std::string particles = t.cell(i, "particles");
    r.particles = std::size_t(parseCell(path, "particles", particles));
    r.cfl = parseCell(path, "cfl", t.cell(i, "cfl"));
    r.errorName = t.cell(i, "error_name");
    r.error = parseCell(path, "error", t.cell(i, "error"));
    r.meanDensityError = parseCell(path, "mean_density_error", t.cell(i, "mean_density_error"));
    r.maxDensityError = parseCell(path, "max_density_error", t.cell(i, "max_density_error"));
    r.wallPerSim = parseCell(path, "wall_s_per_sim_s", t.cell(i, "wall_s_per_sim_s"));
    r.msPerStep = parseCell(path, "ms_per_step", t.cell(i, "ms_per_step"));
    if (legacy) {
      // Its id from the figures: the CFL-type number over the solver's default.
      SceneDef probe;
      double base = 0.25;
      try {
        base = setSolver(probe, r.solver, 1.0);
      } catch (const std::exception&) {
      }
      r.id = r.caseName + "-" + r.solver + "-" + particles + "-cfl" + std::to_string(std::lround(r.cfl / base));
      r.build = "unknown";
      r.settings = "unknown";
    } else {
      r.id = t.cell(i, "run_id");
      r.floor = t.cell(i, "floor");
      r.error2Name = t.cell(i, "error2_name");
      r.error2 = parseCell(path, "error2", t.cell(i, "error2"));
      r.status = t.cell(i, "status");
      r.build = t.cell(i, "build");
      r.settings = t.cell(i, "settings");
      r.params = t.cell(i, "solver_params");
      if (!safeRunId(r.id)) throw UsageError(path + ": '" + r.id + "' is not a run id");
    }
    runs.push_back(r);
  }
  return runs;
}

/// The CFL index of a run id ("…-cfl2-…" → 2; 0 when it has none).
static int cflIndexOf(const std::string& id) {
  const auto at = id.find("-cfl");
  return at == std::string::npos ? 0 : std::atoi(id.c_str() + at + 4);
}

/// Rows in the sweep's order: solver (the default order, others by name), CFL index, case,
/// particles, floor.
void sortRuns(std::vector<Run>& runs) {
  std::stable_sort(runs.begin(), runs.end(), [](const Run& a, const Run& b) {
    const int sa = indexOf(kSolvers, a.solver), sb = indexOf(kSolvers, b.solver);
    const int ra = sa < 0 ? int(std::size(kSolvers)) : sa, rb = sb < 0 ? int(std::size(kSolvers)) : sb;
    if (ra != rb) return ra < rb;
    if (a.solver != b.solver) return a.solver < b.solver;
    if (cflIndexOf(a.id) != cflIndexOf(b.id)) return cflIndexOf(a.id) < cflIndexOf(b.id);
    const int ca = indexOf(kCases, a.caseName), cb = indexOf(kCases, b.caseName);
    if (ca != cb) return ca < cb;
    if (a.particles != b.particles) return a.particles < b.particles;
    return floorRank(a.floor) < floorRank(b.floor);
  });
}

/// Writes `bytes` to `out`/`name` whole, noted in the folder's journal first.
void writeNoted(OutputJournal& journal, const std::string& out, const std::string& name, const std::string& bytes) {
  const std::string path = out + "/" + name;
  journal.note(name, fs::path(tempPathFor(path)).filename().string(), xxh64(bytes.data(), bytes.size()));
  writeFileAtomic(path, bytes);
}

/// The files `sph2d bench accuracy` writes into its --out folder.
const char* const kOutputs[] = {"accuracy.csv",     "accuracy.md",    "dam_break.png", "hydrostatic.png",
                                "taylor_green.png", "poiseuille.png", "surge_long.png"};

FolderSpec accuracyFolderSpec() {
  FolderSpec spec;
  spec.command = "bench accuracy";
  spec.writes = [](const std::string& name) {
    return std::find(std::begin(kOutputs), std::end(kOutputs), name) != std::end(kOutputs);
  };
  return spec;
}

/// Log-log chart of error against wall seconds per simulated second, one colour per solver, Pareto front.
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
  const Rgba8 palette[] = {
      {200, 40, 40, 255}, {40, 120, 200, 255}, {40, 160, 60, 255}, {200, 140, 0, 255}, {140, 60, 180, 255}};
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

}  // namespace sph2d::cli::accuracy
