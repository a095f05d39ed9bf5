// app/bench/accuracy_report.hpp — the rows of `sph2d bench accuracy` and what is done with
// them apart from running: the cases and solvers in the sweep's order, each solver's CFL-type
// number, accuracy.csv written and read back (also the format before run ids), the rows in
// the sweep's order whatever order the runs finished in, the files the bench writes, and the
// charts (error against wall seconds per simulated second, Pareto front).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "output/output_dir.hpp"
#include "sph2d/scene.hpp"

namespace sph2d::cli::accuracy {

/// The validation cases, in the order they run; the first four run by default.
inline const char* const kCases[] = {"hydrostatic", "dam_break", "taylor_green", "poiseuille", "surge_long"};
inline constexpr std::size_t kDefaultCases = 4;
inline const char* const kSolvers[] = {"muller2003", "wcsph", "dfsph", "pbf", "game"};

/// One row of results: a run of the sweep.
struct Run {
  std::string id, caseName, solver, floor;
  std::size_t particles = 0;
  double cfl = 0;
  std::string errorName;
  double error = NAN;
  std::string error2Name;
  double error2 = NAN;
  double meanDensityError = NAN, maxDensityError = NAN, wallPerSim = NAN, msPerStep = NAN;
  std::string status = "ok";  ///< "ok" or "unstable" (the guard stopped it: no figures)
  std::string build, settings, params;
  std::string file;  ///< the CSV it was read from (merges)
};

/// Sets `solver` and its own CFL-type number to `scale` × its default; returns the number.
double setSolver(SceneDef& s, const std::string& solver, double scale);

/// The CSV's header (the columns of csvLine).
extern const char* const kCsvHeader;

/// `v` as the CSV writes it ("" for NaN).
std::string num(double v);

/// One row of accuracy.csv, newline included.
std::string csvLine(const Run& r);

/// The rows of an accuracy.csv (this format or the one before run ids, read as build and
/// settings "unknown"). Throws UsageError naming the file, the column and the cell.
std::vector<Run> readRuns(const std::string& path);

/// Rows in the sweep's order: solver (the default order, others by name), CFL index, case,
/// particles, floor.
void sortRuns(std::vector<Run>& runs);

/// Writes `bytes` to `out`/`name` whole, noted in the folder's journal first.
void writeNoted(OutputJournal& journal, const std::string& out, const std::string& name, const std::string& bytes);

/// The files `sph2d bench accuracy` writes into its --out folder.
FolderSpec accuracyFolderSpec();

/// Writes `out`/CASE.png: log-log chart of error against wall seconds per simulated second, one
/// colour per solver, the Pareto front drawn (nothing when the case has no measured run).
void chart(const std::vector<Run>& runs, const std::string& caseName, OutputJournal& journal, const std::string& out);

}  // namespace sph2d::cli::accuracy
