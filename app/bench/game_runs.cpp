// app/bench/game_runs.cpp — see game_runs.hpp.
#include "bench/game_runs.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <tuple>

#include "bench/sweep.hpp"
#include "cli.hpp"
#include "sph2d/scene.hpp"

namespace sph2d::cli::game_bench {

std::string fmt(double v, const char* f) {
  if (std::isnan(v)) return "-";
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

const char* const kCsvHeader =
    "run_id,name,floor,particles,threads,wall_s_per_sim_s,ratio_to_peer,substeps_per_frame,iterations_per_frame,"
    "mean_compression,max_compression,energy_gain,surge_rms,outside,end_compression,end_surface_m,build,settings";

bool splitPreset(const std::string& preset, std::string& base, std::string& second) {
  const auto cut = preset.find('_');
  base = preset.substr(0, cut);
  second = cut == std::string::npos ? "" : preset.substr(cut + 1);
  return indexOf(kPresets, base) >= 0 && (second.empty() || indexOf(kSecondMaterials, second) >= 0);
}

std::string presetProblem(const std::string& preset) {
  std::string base, second;
  if (!splitPreset(preset, base, second))
    return "unknown preset '" + preset +
           "'; presets: game, balanced, accurate, each alone or with _oil (oil of 800 kg/m³ over the water: "
           "game and balanced) or _dye (a second material of the water's density), e.g. balanced_oil, game_dye";
  if (second == "oil" && !takesDensityContrast(qualityPreset(base).type))
    return "'" + preset + "': the " + base + " preset's solver (" + qualityPreset(base).type +
           ") takes materials of one density; oil over water runs on game and balanced, and " + base +
           "_dye measures a second material of one density";
  return "";
}

std::string specId(const Spec& p) {
  if (!p.peer.empty()) return p.peer + "-" + std::to_string(p.particles);
  return p.preset + "-" + std::to_string(p.particles) + "-t" + std::to_string(p.threads) +
         (p.floor == "scene" ? "" : "-" + p.floor);
}

/// Parses a run id back into its run; throws UsageError saying what an id is.
Spec parseId(const std::string& id, bool havePeer) {
  const std::string form =
      "; ids are PRESET-PARTICLES-tTHREADS[-FLOOR] (presets game, balanced, accurate, with _dye or (balanced) "
      "_oil for a second material; particles 100..50000000; threads "
      "1..256; floors free, muX, noslip), e.g. game-20000-t2 or balanced-5000-t1-mu0.5, and with --peer "
      "liquidfun-PARTICLES or liquidfun_static-PARTICLES; `sph2d bench game --list-ids` lists the default sweep";
  std::vector<std::string> parts;
  std::string cur;
  for (char c : id) {
    if (c == '-') {
      parts.push_back(cur);
      cur.clear();
    } else
      cur += c;
  }
  parts.push_back(cur);
  auto integer = [&](const std::string& v, int lo, int hi) {
    if (v.empty() || v.size() > 9 ||
        !std::all_of(v.begin(), v.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); }))
      throw UsageError("--only: '" + id + "' is not a run of bench game" + form);
    const int n = std::atoi(v.c_str());
    if (n < lo || n > hi) throw UsageError("--only: '" + id + "' is not a run of bench game" + form);
    return n;
  };
  Spec p;
  if (parts.size() == 2 && indexOf(kPeers, parts[0]) >= 0) {
    if (!havePeer) throw UsageError("--only " + id + ": a peer run needs --peer PATH (the LiquidFun harness)");
    p.peer = parts[0];
    p.particles = integer(parts[1], 100, 50000000);
  } else if ((parts.size() == 3 || parts.size() == 4) && presetProblem(parts[0]).empty() && parts[2].size() > 1 &&
             parts[2][0] == 't') {
    p.preset = parts[0];
    p.particles = integer(parts[1], 100, 50000000);
    p.threads = integer(parts[2].substr(1), 1, 256);
    if (parts.size() == 4) {
      if (parts[3] == "scene") throw UsageError("--only: '" + id + "' is not a run of bench game" + form);
      try {
        p.floor = parseFloorVariant("--only " + id, parts[3]).name;
      } catch (const UsageError&) {
        throw UsageError("--only: '" + id + "' is not a run of bench game" + form);
      }
    }
  } else {
    std::string base, second;
    if (splitPreset(parts[0], base, second) && !presetProblem(parts[0]).empty())  // a name it cannot run (game_oil)
      throw UsageError("--only " + id + ": " + presetProblem(parts[0]));
    throw UsageError("--only: '" + id + "' is not a run of bench game" + form);
  }
  if (specId(p) != id)
    throw UsageError("--only: '" + id + "' is not a run of bench game (did you mean " + specId(p) + "?)" + form);
  p.id = id;
  return p;
}

/// Rows in the sweep's order: particles, the peer's runs first, preset, floor, threads.
void sortRows(std::vector<Row>& rows) {
  auto rank = [](const Row& r) {
    const int peer = indexOf(kPeers, r.name);
    if (peer >= 0) return peer;
    std::string base, second;
    const bool ours = r.name.rfind("sph2d_", 0) == 0;
    if (ours) splitPreset(r.name.substr(std::string("sph2d_").size()), base, second);
    const int preset = ours ? indexOf(kPresets, base) : -1;
    return 10 + (preset < 0 ? 9 : preset);
  };
  std::stable_sort(rows.begin(), rows.end(), [&](const Row& a, const Row& b) {
    if (a.particles != b.particles) return a.particles < b.particles;
    if (rank(a) != rank(b)) return rank(a) < rank(b);
    if (a.name != b.name) return a.name < b.name;
    if (floorRank(a.floor) != floorRank(b.floor)) return floorRank(a.floor) < floorRank(b.floor);
    return a.threads < b.threads;
  });
}

/// The particle count a run id asks for (its second field: game-20000-t2, liquidfun_static-20000).
static std::string idParticles(const std::string& id) {
  const auto a = id.find('-');
  if (a == std::string::npos) return "";
  const auto b = id.find('-', a + 1);
  return id.substr(a + 1, b == std::string::npos ? std::string::npos : b - a - 1);
}

/// The CSV of `rows`, the peer ratio from the liquidfun_static row of the same requested particle count.
std::string csvText(const std::vector<Row>& rows) {
  std::map<std::string, double> peerTime;  // particle count of the id → liquidfun_static's wall time
  for (const Row& r : rows)
    if (r.name == "liquidfun_static") peerTime[idParticles(r.id)] = r.wallPerSim;
  std::ostringstream o;
  o << kCsvHeader << '\n';
  auto v = [](double x) { return std::isnan(x) ? std::string("") : fmt(x, "%.6g"); };
  for (const Row& r : rows) {
    const auto pt = peerTime.find(idParticles(r.id));
    const double ratio = pt == peerTime.end() ? NAN : r.wallPerSim / pt->second;
    o << r.id << ',' << r.name << ',' << r.floor << ',' << r.particles << ',' << r.threads << ',' << v(r.wallPerSim)
      << ',' << v(ratio) << ',' << v(r.substepsPerFrame) << ',' << v(r.iterationsPerFrame) << ','
      << v(r.meanCompression) << ',' << v(r.maxCompression) << ',' << v(r.energyGain) << ',' << v(r.surgeRms) << ','
      << v(r.outside) << ',' << v(r.endCompression) << ',' << v(r.endSurface) << ',' << r.build << ',' << r.settings
      << '\n';
  }
  return o.str();
}

static double cellNumber(const std::string& path, const std::string& column, const std::string& v) {
  if (v.empty()) return NAN;
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (!end || *end != '\0') throw UsageError(path + ": column " + column + ": '" + v + "' is not a number");
  return d;
}

std::vector<Row> readRows(const std::string& path) {
  const CsvRows t = readCsvRows(path);
  std::string header;
  for (const std::string& h : t.header) header += (header.empty() ? "" : ",") + h;
  if (header != kCsvHeader)
    throw UsageError(path + ": not a game.csv of this sph2d bench game (its header: " + header + ")");
  std::vector<Row> rows;
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    Row r;
    r.file = path;
    r.id = t.cell(i, "run_id");
    if (!safeRunId(r.id)) throw UsageError(path + ": '" + r.id + "' is not a run id");
    r.name = t.cell(i, "name");
    r.floor = t.cell(i, "floor");
    r.particles = std::size_t(cellNumber(path, "particles", t.cell(i, "particles")));
    r.threads = int(cellNumber(path, "threads", t.cell(i, "threads")));
    r.wallPerSim = cellNumber(path, "wall_s_per_sim_s", t.cell(i, "wall_s_per_sim_s"));
    r.substepsPerFrame = cellNumber(path, "substeps_per_frame", t.cell(i, "substeps_per_frame"));
    r.iterationsPerFrame = cellNumber(path, "iterations_per_frame", t.cell(i, "iterations_per_frame"));
    r.meanCompression = cellNumber(path, "mean_compression", t.cell(i, "mean_compression"));
    r.maxCompression = cellNumber(path, "max_compression", t.cell(i, "max_compression"));
    r.energyGain = cellNumber(path, "energy_gain", t.cell(i, "energy_gain"));
    r.surgeRms = cellNumber(path, "surge_rms", t.cell(i, "surge_rms"));
    r.outside = cellNumber(path, "outside", t.cell(i, "outside"));
    r.endCompression = cellNumber(path, "end_compression", t.cell(i, "end_compression"));
    r.endSurface = cellNumber(path, "end_surface_m", t.cell(i, "end_surface_m"));
    r.build = t.cell(i, "build");
    r.settings = t.cell(i, "settings");
    rows.push_back(r);
  }
  return rows;
}

FolderSpec gameFolderSpec() {
  FolderSpec spec;
  spec.command = "bench game";
  spec.writes = [](const std::string& name) { return name == "game.csv"; };
  return spec;
}

std::string costGrowth(const std::vector<Row>& rows) {
  std::map<std::tuple<std::string, std::string, int>, std::vector<const Row*>> runs;
  for (const Row& r : rows)
    if (r.particles > 0 && r.wallPerSim > 0) runs[{r.name, r.floor, r.threads}].push_back(&r);
  std::string out;
  char line[400];
  for (auto& [key, list] : runs) {
    std::stable_sort(list.begin(), list.end(), [](const Row* a, const Row* b) { return a->particles < b->particles; });
    const Row& a = *list.front();
    for (std::size_t k = 1; k < list.size(); ++k) {
      const Row& b = *list[k];
      if (b.particles == a.particles) continue;
      const double n = double(b.particles) / double(a.particles), t = b.wallPerSim / a.wallPerSim;
      std::snprintf(line, sizeof line,
                    "cost growth, %s%s%s t%d: %zu -> %zu particles (x%.2f): wall/sim x%.2f, per particle x%.2f; "
                    "substeps/frame %s -> %s, iterations/frame %s -> %s\n",
                    a.name.c_str(), a.floor == "scene" || a.floor.empty() ? "" : " ",
                    a.floor == "scene" ? "" : a.floor.c_str(), a.threads, a.particles, b.particles, n, t, t / n,
                    fmt(a.substepsPerFrame, "%.2f").c_str(), fmt(b.substepsPerFrame, "%.2f").c_str(),
                    fmt(a.iterationsPerFrame, "%.1f").c_str(), fmt(b.iterationsPerFrame, "%.1f").c_str());
      out += line;
    }
  }
  return out;
}

}  // namespace sph2d::cli::game_bench
