// app/bench/sweep.hpp — what `sph2d bench accuracy` and `sph2d bench game` share to split a sweep
// into single runs a scheduler can run anywhere and to gather their CSV files again
// (--list, --only, --merge; docs/ACCURACY.md "Running a sweep on many cores or machines"):
// the build's commit, shell quoting, the results' CSV read by column name, the check that
// merged rows come from one build and one set of settings, and the floor variants of the
// surge cases.
#pragma once

#include <cstdint>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "sph2d/scene.hpp"

namespace sph2d::cli {

/// The index of `v` in the array `a`, or -1.
template <class Array>
int indexOf(const Array& a, const std::string& v) {
  for (std::size_t i = 0; i < std::size(a); ++i)
    if (a[i] == v) return int(i);
  return -1;
}

/// The build's `git describe --always --dirty` at build time ("unknown" for a build outside git).
const char* buildCommit();

/// `s` quoted for a POSIX shell when it holds anything but [A-Za-z0-9_./=,:+@%-].
std::string shellQuote(const std::string& s);

/// This executable's absolute path (/proc/self/exe), "sph2d" when it cannot be read.
std::string selfExe();

/// `path` made absolute against the working directory (not resolved: links stay).
std::string absolutePath(const std::string& path);

/// XXH64 (16 hex digits) of the bytes of `files` in order (each file's name and size too):
/// the fingerprint of the assets a run reads. Throws UsageError naming a file it cannot read.
std::string filesHash(const std::vector<std::string>& files);

/// A CSV file of results, cells by column name (sph2d's CSVs: no quoting, no commas in cells).
struct CsvRows {
  std::string path;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  /// The column's index, or -1.
  int column(const std::string& name) const;
  /// The cell of column `name` in row `r` ("" when the file has no such column).
  std::string cell(std::size_t r, const std::string& name) const;
};

/// Reads a CSV of results. Throws UsageError when it cannot be opened or a row's cell count
/// differs from the header's.
CsvRows readCsvRows(const std::string& path);

/// The files DIR/*/NAME (one level of subfolders, the runs of --list's --out DIR/RUN_ID), sorted.
/// Throws UsageError (naming `flag`) when DIR is not a folder or holds none.
std::vector<std::string> mergeParts(const std::string& flag, const std::string& dir, const std::string& name);

/// Where a merged row came from: its build and settings (the CSV's `build` and `settings` cells).
struct RowOrigin {
  std::string file, build, settings;
};

/// Refuses (UsageError, exit 2) rows from more than one build or set of settings unless
/// `allowMixed`, naming the two files and what differs; with `allowMixed` returns the
/// distinct origins (for the report's note). `command` names the bench in the message.
std::vector<RowOrigin> checkOrigins(const std::string& command, const std::vector<RowOrigin>& origins, bool allowMixed);

/// A run id: [A-Za-z0-9._-] only, not starting with '.' or '-' (safe as a folder name).
bool safeRunId(const std::string& id);

/// The floor (and walls) of a surge case: "scene" (as the scene file says), "free" (free-slip,
/// friction 0), "muX" (Coulomb friction X at contact, e.g. mu0.5) or "noslip" (friction 0 and
/// solver.no_slip, the viscosity at least kReynoldsViscosity).
struct FloorVariant {
  std::string name = "scene";
  double friction = -1;  ///< < 0: the scene's
  bool noSlip = false;
};

/// The kinematic viscosity [m²/s] that gives a 1 m column Martin & Moyce's Reynolds number
/// (their column of a = 2.25 in = 0.05715 m of water, ν = 1.0e-6 m²/s, Re = sqrt(g a) a / ν,
/// the same at 1 m when ν = 1.0e-6 · (1 / 0.05715)^1.5): the no-slip variant's viscosity.
constexpr double kReynoldsViscosity = 7.3e-5;

/// Parses a floor variant; throws UsageError naming `flag` and the allowed forms.
FloorVariant parseFloorVariant(const std::string& flag, const std::string& v);

/// Sets the friction of every fixture of every static body of `s` and, for "noslip",
/// solver.no_slip with viscosity max(ν, kReynoldsViscosity).
void applyFloorVariant(SceneDef& s, const FloorVariant& f);

/// The ordering rank of a floor variant: scene, free, mu ascending, noslip.
double floorRank(const std::string& name);

/// The solver parameters that matter for a run, "key=value;..." (shared keys, then the solver's own).
std::string solverParamsText(const SolverDef& d);

}  // namespace sph2d::cli
