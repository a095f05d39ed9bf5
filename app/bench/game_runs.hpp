// app/bench/game_runs.hpp — the runs and rows of `sph2d bench game` apart from running them:
// run ids (preset[_second]-particles-tthreads[-floor], liquidfun[_static]-particles) made and parsed back,
// game.csv written (the peer ratio from the liquidfun_static row of the same particle count)
// and read back, the rows in the sweep's order, and the file the bench writes.
#pragma once

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "output/output_dir.hpp"

namespace sph2d::cli::game_bench {

inline const char* const kPresets[] = {"game", "balanced", "accurate"};
inline const char* const kPeers[] = {"liquidfun", "liquidfun_static"};
/// A run's second material: none, oil (800 kg/m³ over the water: presets whose solver takes a
/// density contrast) or dye (a second material of the water's density).
inline const char* const kSecondMaterials[] = {"oil", "dye"};

/// A run's preset: BASE or BASE_SECOND (kPresets, kSecondMaterials), e.g. balanced_oil. Sets
/// `base` and `second` ("" for none); false when it is no such name.
bool splitPreset(const std::string& preset, std::string& base, std::string& second);

/// Why `preset` cannot run ("" when it can): an unknown name, or oil on a preset whose solver
/// takes materials of one density.
std::string presetProblem(const std::string& preset);

/// One row of game.csv: a run's figures (NaN: not measured).
struct Row {
  std::string id, name, floor = "scene";
  std::size_t particles = 0;
  int threads = 1;
  double wallPerSim = NAN, substepsPerFrame = NAN, iterationsPerFrame = NAN;
  double meanCompression = NAN, maxCompression = NAN, energyGain = NAN, surgeRms = NAN;
  double outside = NAN, endCompression = NAN, endSurface = NAN;
  std::string build, settings, file;
};

/// One run of the sweep: a preset's (or the peer's) dam break at a particle count.
struct Spec {
  std::string id, preset, peer, floor = "scene";  ///< preset or peer ("liquidfun", "liquidfun_static")
  int particles = 20000, threads = 1;
};

/// `v` printed with the printf format `f`, "-" for NaN.
std::string fmt(double v, const char* f);

/// The id of a run: preset-particles-tthreads[-floor] or peer-particles.
std::string specId(const Spec& p);

/// How the cost grows with the particle count: for each run (name, floor, threads) measured at
/// more than one count, a line per larger count against the smallest: the counts' ratio, the
/// wall time's and the wall time per particle's, and the substeps and iterations per frame at
/// both ends ("" when no run has two counts).
std::string costGrowth(const std::vector<Row>& rows);

/// Parses a run id back into its run; throws UsageError saying what an id is and how to list them.
Spec parseId(const std::string& id, bool havePeer);

/// Rows in the sweep's order: particles, the peer's runs first, preset, floor, threads.
void sortRows(std::vector<Row>& rows);

/// The CSV of `rows`, the peer ratio from the liquidfun_static row of the same requested particle count.
std::string csvText(const std::vector<Row>& rows);

/// The rows of a game.csv; throws UsageError naming the file, the column and the cell.
std::vector<Row> readRows(const std::string& path);

/// The file `sph2d bench game --out DIR` writes: DIR/game.csv.
FolderSpec gameFolderSpec();

}  // namespace sph2d::cli::game_bench
