// app/bench/sweep.cpp — see sweep.hpp.
#include "bench/sweep.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli.hpp"
#include "sph2d/hash.hpp"

namespace fs = std::filesystem;

// Generated at build time by cmake/build_info.cmake (build_info.cpp in the build tree).
extern "C" const char* sph2d_build_commit();

namespace sph2d::cli {

const char* buildCommit() { return sph2d_build_commit(); }

std::string shellQuote(const std::string& s) {
  const bool plain = !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || std::string("_./=,:+@%-").find(c) != std::string::npos;
  });
  if (plain) return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string selfExe() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("sph2d") : p.string();
}

std::string absolutePath(const std::string& path) {
  std::error_code ec;
  const fs::path p = fs::absolute(path, ec);
  return ec ? path : p.lexically_normal().string();
}

std::string filesHash(const std::vector<std::string>& files) {
  std::string all;
  for (const std::string& f : files) {
    std::ifstream in(f, std::ios::binary);
    if (!in) throw UsageError("cannot read " + f);
    std::ostringstream ss;
    ss << in.rdbuf();
    const std::string bytes = ss.str();
    all += fs::path(f).filename().string() + ":" + std::to_string(bytes.size()) + ":" + bytes;
  }
  return hex64(xxh64(all.data(), all.size()));
}

int CsvRows::column(const std::string& name) const {
  const auto it = std::find(header.begin(), header.end(), name);
  return it == header.end() ? -1 : int(it - header.begin());
}

std::string CsvRows::cell(std::size_t r, const std::string& name) const {
  const int c = column(name);
  return c < 0 ? std::string() : rows.at(r).at(std::size_t(c));
}

namespace {
std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> f;
  std::string cell;
  std::stringstream ls(line);
  while (std::getline(ls, cell, ',')) f.push_back(cell);
  if (!line.empty() && line.back() == ',') f.push_back("");  // a last empty cell
  return f;
}
}  // namespace

CsvRows readCsvRows(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw UsageError("cannot open " + path);
  CsvRows t;
  t.path = path;
  std::string line;
  if (!std::getline(in, line)) throw UsageError(path + ": empty (no header line)");
  t.header = cells(line);
  int number = 1;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty()) continue;
    std::vector<std::string> f = cells(line);
    if (f.size() != t.header.size())
      throw UsageError(path + ":" + std::to_string(number) + ": " + std::to_string(f.size()) +
                       " cells, the header has " + std::to_string(t.header.size()));
    t.rows.push_back(std::move(f));
  }
  return t;
}

std::vector<std::string> mergeParts(const std::string& flag, const std::string& dir, const std::string& name) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw UsageError(flag + " " + dir + ": not a folder");
  std::vector<std::string> parts;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    std::error_code e2;
    if (!e.is_directory(e2)) continue;
    const fs::path p = e.path() / name;
    if (fs::is_regular_file(p, e2)) parts.push_back(p.string());
  }
  if (ec) throw UsageError(flag + " " + dir + ": cannot be listed (" + ec.message() + ")");
  if (parts.empty())
    throw UsageError(flag + " " + dir + ": no " + dir + "/*/" + name + " (the runs of --list write RUN_ID/" + name +
                     ")");
  std::sort(parts.begin(), parts.end());
  return parts;
}

std::vector<RowOrigin> checkOrigins(const std::string& command, const std::vector<RowOrigin>& origins,
                                    bool allowMixed) {
  std::vector<RowOrigin> distinct;
  for (const RowOrigin& o : origins) {
    const auto same = [&](const RowOrigin& d) { return d.build == o.build && d.settings == o.settings; };
    if (std::find_if(distinct.begin(), distinct.end(), same) == distinct.end()) distinct.push_back(o);
  }
  if (distinct.size() > 1 && !allowMixed) {
    const RowOrigin& a = distinct[0];
    const RowOrigin& b = distinct[1];
    std::string what;
    if (a.build != b.build) what = "build " + a.build + " against " + b.build;
    if (a.settings != b.settings)
      what += std::string(what.empty() ? "" : ", ") + "settings " + a.settings + " against " + b.settings;
    throw UsageError(
        command + ": " + a.file + " and " + b.file + " come from different runs (" + what + "; " +
        std::to_string(distinct.size()) +
        " kinds in all): their wall times and figures do not belong in one report. Merge each kind on its own, or "
        "pass --allow-mixed to merge them anyway (each row keeps its build and settings, and the report names them)");
  }
  return distinct;
}

bool safeRunId(const std::string& id) {
  if (id.empty() || id.size() > 200 || id[0] == '.' || id[0] == '-') return false;
  return std::all_of(id.begin(), id.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  });
}

FloorVariant parseFloorVariant(const std::string& flag, const std::string& v) {
  FloorVariant f;
  f.name = v;
  if (v == "scene") return f;
  if (v == "free") {
    f.friction = 0;
    return f;
  }
  if (v == "noslip") {
    f.friction = 0;
    f.noSlip = true;
    return f;
  }
  if (v.size() > 2 && v.compare(0, 2, "mu") == 0) {
    const std::string num = v.substr(2);
    char* end = nullptr;
    const double mu = std::strtod(num.c_str(), &end);
    const bool digits = std::all_of(num.begin(), num.end(),
                                    [](char c) { return std::isdigit(static_cast<unsigned char>(c)) || c == '.'; });
    if (digits && end && *end == '\0' && mu > 0 && mu <= 10) {
      f.friction = mu;
      return f;
    }
  }
  throw UsageError(flag + ": unknown floor '" + v +
                   "'; floors: scene, free, muX (Coulomb friction X in (0, 10], e.g. mu0.5), noslip");
}

void applyFloorVariant(SceneDef& s, const FloorVariant& f) {
  if (f.friction >= 0)
    for (BodyDef& b : s.bodies)
      if (b.type == BodyDef::Type::Static)
        for (ShapeDef& fx : b.fixtures) fx.friction = f.friction;
  if (f.noSlip) {
    s.solver.noSlip = true;
    s.solver.viscosity = std::max(s.solver.viscosity, kReynoldsViscosity);
  }
}

double floorRank(const std::string& name) {
  if (name == "scene" || name.empty()) return -2;
  if (name == "free") return -1;
  if (name == "noslip") return 1e9;
  if (name.compare(0, 2, "mu") == 0) return std::atof(name.c_str() + 2);
  return 2e9;
}

std::string solverParamsText(const SolverDef& d) {
  char b[64];
  auto num = [&](double v) {
    std::snprintf(b, sizeof b, "%.9g", v);
    return std::string(b);
  };
  std::string t = "spacing=" + num(d.spacing) + ";support_ratio=" + num(d.supportRatio) +
                  ";rest_density=" + num(d.restDensity) + ";sound_speed=" + num(d.soundSpeed) +
                  ";viscosity=" + num(d.viscosity) + ";no_slip=" + (d.noSlip ? "1" : "0") + ";cfl=" + num(d.cfl) +
                  ";max_substeps=" + std::to_string(d.maxSubsteps) +
                  ";clamp_negative_pressure=" + (d.clampNegativePressure ? "1" : "0");
  for (const auto& p : d.params) t += ";" + p.first + "=" + num(p.second);
  return t;
}

}  // namespace sph2d::cli
