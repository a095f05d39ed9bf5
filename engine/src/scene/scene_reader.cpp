// The scene reader: SceneError, the message helpers and Reader's typed access
// (scene_reader.hpp). Every accessor checks the JSON type first, then the range
// or the allowed values, and words the failure as "expected X, got Y" or
// "value V is out of range; allowed: ..." so a message says what was found and
// what would do. Unknown keys get a "did you mean" from the edit distance
// (transpositions count as one edit) when it is small for the key's length.
#include "scene/scene_reader.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "sph2d/scene.hpp"

namespace sph2d {

using nlohmann::json;

SceneError::SceneError(std::string file_, int line_, int column_, std::string key_, std::string message_)
    : std::runtime_error([&] {
        std::string w = file_;
        if (line_ > 0) w += ":" + std::to_string(line_) + ":" + std::to_string(column_);
        w += ": ";
        if (!key_.empty()) w += "key '" + key_ + "': ";
        return w + message_;
      }()),
      file(std::move(file_)),
      line(line_),
      column(column_),
      key(std::move(key_)),
      message(std::move(message_)) {}

std::string typeName(const json& j) {
  switch (j.type()) {
    case json::value_t::null:
      return "null";
    case json::value_t::boolean:
      return "a boolean";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
      return "an integer";
    case json::value_t::number_float:
      return "a number";
    case json::value_t::string:
      return "a string";
    case json::value_t::array:
      return "an array";
    case json::value_t::object:
      return "an object";
    default:
      return "something else";
  }
}

std::string describe(const json& j) {
  if (!j.is_array()) return typeName(j);
  return "an array of " + std::to_string(j.size()) + (j.size() == 1 ? " element" : " elements");
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + v[i];
  return s;
}

std::string printable(const std::string& s) {
  std::string o;
  for (const char c : s) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7F) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", unsigned(u));
      o += buf;
    } else {
      o += c;
    }
  }
  return o;
}

namespace {

/// Edit distance with transpositions (optimal string alignment), for "did you mean".
std::size_t editDistance(const std::string& a, const std::string& b) {
  if (a.size() > 64 || b.size() > 64) return 99;
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i)
    for (std::size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[a.size()][b.size()];
}

}  // namespace

Reader::Reader(const JsonDoc& doc, std::string file) : doc_(doc), file_(std::move(file)) {}

void Reader::fail(const std::string& path, const std::string& msg) const {
  // Report the deepest known position along the path.
  std::string p = path;
  for (;;) {
    auto it = doc_.where.find(p);
    if (it != doc_.where.end()) throw SceneError(file_, it->second.first, it->second.second, path, msg);
    const auto cut = p.find_last_of(".[");
    if (cut == std::string::npos || cut == 0) break;
    p = p.substr(0, cut);
  }
  throw SceneError(file_, 0, 0, path, msg);
}

std::string Reader::sub(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

void Reader::requireObject(const json& j, const std::string& path) const {
  if (!j.is_object())
    fail(path, path.empty() ? "a scene is a JSON object ({ ... }) at the top level, got " + describe(j)
                            : "expected an object, got " + describe(j));
}

void Reader::checkKeys(const json& obj, const std::string& path, const std::vector<std::string>& allowed) const {
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    bool ok = false;
    for (const auto& a : allowed) ok = ok || a == it.key();
    if (ok) continue;
    const std::string key = printable(it.key());
    std::string hint;
    std::size_t best = 3;
    for (const auto& a : allowed) {
      const std::size_t d = editDistance(it.key(), a);
      if (d < best && d <= 1 + a.size() / 4) {
        best = d;
        hint = " (did you mean '" + a + "'?)";
      }
    }
    fail(sub(path, key), "unknown key '" + key + "'" + hint + "; allowed keys: " + join(allowed));
  }
}

double Reader::number(const json& obj, const std::string& path, const std::string& key, double def, double lo,
                      double hi, bool loOpen) const {
  if (!obj.contains(key)) return def;
  const json& j = obj.at(key);
  const std::string p = sub(path, key);
  if (!j.is_number()) fail(p, "expected a number, got " + describe(j));
  const double v = j.get<double>();
  if (const std::string why = rangeProblem(v, lo, hi, loOpen); !why.empty()) fail(p, why);
  return v;
}

long long Reader::integer64(const json& obj, const std::string& path, const std::string& key, long long def,
                            long long lo, long long hi) const {
  if (!obj.contains(key)) return def;
  const json& j = obj.at(key);
  const std::string p = sub(path, key);
  const std::string range = "an integer from " + std::to_string(lo) + " to " + std::to_string(hi);
  if (!j.is_number()) fail(p, "expected " + range + ", got " + describe(j));
  if (j.is_number_integer()) {
    const long long v = j.get<long long>();
    if (v < lo || v > hi) fail(p, "value " + std::to_string(v) + " is out of range; allowed: " + range);
    return v;
  }
  const double d = j.get<double>();
  if (!(d == std::floor(d))) fail(p, "expected " + range + ", got " + fmt(d));
  if (!(d >= double(lo) && d <= double(hi))) fail(p, "value " + fmt(d) + " is out of range; allowed: " + range);
  return static_cast<long long>(d);
}

int Reader::integer(const json& obj, const std::string& path, const std::string& key, int def, int lo, int hi) const {
  return static_cast<int>(integer64(obj, path, key, def, lo, hi));
}

bool Reader::boolean(const json& obj, const std::string& path, const std::string& key, bool def) const {
  if (!obj.contains(key)) return def;
  const json& j = obj.at(key);
  if (!j.is_boolean()) fail(sub(path, key), "expected true or false, got " + describe(j));
  return j.get<bool>();
}

std::string Reader::string(const json& obj, const std::string& path, const std::string& key, const std::string& def,
                           const std::vector<std::string>& allowed) const {
  if (!obj.contains(key)) return def;
  const json& j = obj.at(key);
  const std::string p = sub(path, key);
  if (!j.is_string()) fail(p, "expected a string, got " + describe(j));
  const std::string v = j.get<std::string>();
  if (allowed.empty()) return v;
  for (const auto& a : allowed)
    if (a == v) return v;
  fail(p, "'" + printable(v) + "' is not allowed; allowed values: " + join(allowed));
}

Vec2d Reader::vec2(const json& j, const std::string& p) const {
  if (!j.is_array() || j.size() != 2) fail(p, "expected [x, y] (two numbers), got " + describe(j));
  for (std::size_t k = 0; k < 2; ++k)
    if (!j[k].is_number())
      fail(p, "expected [x, y] (two numbers), got " + typeName(j[k]) + " at [" + std::to_string(k) + "]");
  const Vec2d v(j[0].get<double>(), j[1].get<double>());
  if (!std::isfinite(v.x()) || !std::isfinite(v.y())) fail(p, "coordinates must be finite");
  if (std::fabs(v.x()) > kMaxCoordinate || std::fabs(v.y()) > kMaxCoordinate)
    fail(p, "[" + fmt(v.x()) + ", " + fmt(v.y()) + "] is out of range; each component must be within +-" +
                fmt(kMaxCoordinate));
  return v;
}

Vec2d Reader::vec2(const json& obj, const std::string& path, const std::string& key, const Vec2d& def) const {
  if (!obj.contains(key)) return def;
  return vec2(obj.at(key), sub(path, key));
}

Vec2d Reader::requiredVec2(const json& obj, const std::string& path, const std::string& key) const {
  if (!obj.contains(key)) fail(sub(path, key), "missing; expected [x, y]");
  return vec2(obj.at(key), sub(path, key));
}

std::array<double, 3> Reader::color(const json& obj, const std::string& path, const std::string& key,
                                    const std::array<double, 3>& def) const {
  if (!obj.contains(key)) return def;
  const json& j = obj.at(key);
  const std::string p = sub(path, key);
  if (!j.is_array() || j.size() != 3) fail(p, "expected [r, g, b] with components in 0..1, got " + describe(j));
  std::array<double, 3> c{};
  for (std::size_t k = 0; k < 3; ++k) {
    if (!j[k].is_number())
      fail(p, "expected [r, g, b] with components in 0..1, got " + typeName(j[k]) + " at [" + std::to_string(k) + "]");
    c[k] = j[k].get<double>();
    if (!(c[k] >= 0 && c[k] <= 1))
      fail(p, "colour components must be in 0..1, got " + fmt(c[k]) + " at [" + std::to_string(k) + "]");
  }
  return c;
}

std::vector<Vec2d> Reader::points(const json& obj, const std::string& path, const std::string& key) const {
  const std::string p = sub(path, key);
  if (!obj.contains(key)) fail(p, "missing; expected an array of [x, y] points");
  const json& j = obj.at(key);
  if (!j.is_array()) fail(p, "expected an array of [x, y] points, got " + describe(j));
  std::vector<Vec2d> out;
  for (std::size_t i = 0; i < j.size(); ++i) out.push_back(vec2(j[i], p + "[" + std::to_string(i) + "]"));
  return out;
}

}  // namespace sph2d
