// app/bench/accuracy_report.hpp — the rows of `sph2d bench accuracy` and what is done with
// them apart from running: the cases and solvers in the sweep's order, each solver's CFL-type
// number, accuracy.csv written and read back (also the format before run ids), the rows in
// the sweep's order whatever order the runs finished in, the table, and the files the bench
// writes (the charts: accuracy_charts.hpp).
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

/// The CFL index of a run id ("…-cfl2-…" → 2; 0 when it has none).
int cflIndexOf(const std::string& id);

/// Rows in the sweep's order: solver (the default order, others by name), CFL index, case,
/// particles, floor.
void sortRuns(std::vector<Run>& runs);

/// Writes `bytes` to `out`/`name` whole, noted in the folder's journal first.
void writeNoted(OutputJournal& journal, const std::string& out, const std::string& name, const std::string& bytes);

/// The files `sph2d bench accuracy` writes into its --out folder.
FolderSpec accuracyFolderSpec();

/// accuracy.md: `header` (the builds and settings, one per line) as a comment, then one table row per run.
std::string reportMarkdown(const std::vector<Run>& runs, const std::string& header);

}  // namespace sph2d::cli::accuracy
