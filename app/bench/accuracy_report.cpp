// app/bench/accuracy_report.cpp — see accuracy_report.hpp.
#include "bench/accuracy_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <sstream>

#include "bench/accuracy_charts.hpp"
#include "bench/sweep.hpp"
#include "cli.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/render/particle_export.hpp"

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

int cflIndexOf(const std::string& id) {
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

FolderSpec accuracyFolderSpec() {
  FolderSpec spec;
  spec.command = "bench accuracy";
  spec.writes = [](const std::string& name) {
    return name == "accuracy.csv" || name == "accuracy.md" || isChartFile(name);
  };
  return spec;
}

std::string reportMarkdown(const std::vector<Run>& runs, const std::string& header) {
  std::ostringstream md;
  md << "<!-- " << header.substr(0, header.size() - 1) << " -->\n\n";
  md << "| run | case | solver | floor | particles | cfl | error | value | error 2 | value | mean density error | max density error | wall s / sim s | ms / step |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  char line[1024];
  for (const Run& r : runs) {
    if (r.status != "ok") {
      std::snprintf(line, sizeof line, "| %s | %s | %s | %s | %zu | %.3f | %s | %s | | | | | | |\n", r.id.c_str(),
                    r.caseName.c_str(), r.solver.c_str(), r.floor.c_str(), r.particles, r.cfl, r.errorName.c_str(),
                    r.status.c_str());
    } else {
      std::snprintf(line, sizeof line,
                    "| %s | %s | %s | %s | %zu | %.3f | %s | %.4f | %s | %s | %.3f %% | %.3f %% | %.3f | %.3f |\n",
                    r.id.c_str(), r.caseName.c_str(), r.solver.c_str(), r.floor.c_str(), r.particles, r.cfl,
                    r.errorName.c_str(), r.error, r.error2Name.c_str(),
                    std::isnan(r.error2) ? "" : num(std::round(r.error2 * 1e4) / 1e4).c_str(), 100 * r.meanDensityError,
                    100 * r.maxDensityError, r.wallPerSim, r.msPerStep);
    }
    md << line;
  }
  return md.str();
}

}  // namespace sph2d::cli::accuracy
