// scene_reader.hpp (internal) — typed, position-aware access to a scene's JSON
// and the wording of its error messages.
//
// A Reader wraps a JsonDoc (json_reader.hpp: the parsed value and the position
// of every key path). Each accessor takes an object, its key path and a key,
// returns the value or the default when the key is absent, and otherwise fails
// with a SceneError naming the file, the line and column of the deepest known
// key along the path, the key path, what was found and what is allowed. The
// scene loader's section readers and checks and the event reader all report
// through it, so every message has the same shape.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/range_message.hpp"  // fmt, rangeProblem
#include "scene/json_reader.hpp"
#include "sph2d/math.hpp"

namespace sph2d {

/// The largest |x| and |y| of every [x, y] a scene may give [m]: floats stay exact to ~1 m.
constexpr double kMaxCoordinate = 1e7;

/// A JSON value's type as a message names it: "null", "a boolean", "an integer",
/// "a number", "a string", "an array", "an object".
std::string typeName(const nlohmann::json& j);

/// Like typeName, with the length of an array ("an array of 3 elements").
std::string describe(const nlohmann::json& j);

/// The strings separated by ", ".
std::string join(const std::vector<std::string>& v);

/// A user's text as it may appear in a message: control characters escaped as \xHH.
std::string printable(const std::string& s);

/// Typed, position-aware access to the JSON objects of one scene (or event) text.
class Reader {
 public:
  /// Reads `doc`; `file` names it in errors. `doc` must outlive the Reader.
  Reader(const JsonDoc& doc, std::string file);

  /// Throws SceneError for key path `path` with `msg`, at the position of the
  /// deepest key along the path the document knows (line 0 when none).
  [[noreturn]] void fail(const std::string& path, const std::string& msg) const;

  /// The key path of `key` inside `path` ("solver" + "spacing" → "solver.spacing").
  static std::string sub(const std::string& path, const std::string& key);

  /// Fails unless `j` is an object (at the top level, `path` ""), naming what it is.
  void requireObject(const nlohmann::json& j, const std::string& path) const;

  /// Fails at the first key of `obj` not in `allowed`, listing the allowed keys and
  /// suggesting the nearest one when it is a likely typo.
  void checkKeys(const nlohmann::json& obj, const std::string& path, const std::vector<std::string>& allowed) const;

  /// A finite number in [lo, hi] (in (lo, hi] when `loOpen`); `def` when absent.
  double number(const nlohmann::json& obj, const std::string& path, const std::string& key, double def, double lo,
                double hi, bool loOpen = false) const;

  /// An integer in [lo, hi]; a number with an integral value (1e3, 960.0) counts as one.
  long long integer64(const nlohmann::json& obj, const std::string& path, const std::string& key, long long def,
                      long long lo, long long hi) const;

  /// integer64 for values that fit an int.
  int integer(const nlohmann::json& obj, const std::string& path, const std::string& key, int def, int lo,
              int hi) const;

  /// true or false; `def` when absent.
  bool boolean(const nlohmann::json& obj, const std::string& path, const std::string& key, bool def) const;

  /// A string, one of `allowed` unless that is empty; `def` when absent.
  std::string string(const nlohmann::json& obj, const std::string& path, const std::string& key, const std::string& def,
                     const std::vector<std::string>& allowed) const;

  /// `j` as [x, y]: two finite numbers within ±kMaxCoordinate; `p` is its key path.
  Vec2d vec2(const nlohmann::json& j, const std::string& p) const;

  /// `obj[key]` as [x, y] (see above); `def` when absent.
  Vec2d vec2(const nlohmann::json& obj, const std::string& path, const std::string& key, const Vec2d& def) const;

  /// `obj[key]` as [x, y]; fails when absent.
  Vec2d requiredVec2(const nlohmann::json& obj, const std::string& path, const std::string& key) const;

  /// `obj[key]` as [r, g, b], each in 0..1; `def` when absent.
  std::array<double, 3> color(const nlohmann::json& obj, const std::string& path, const std::string& key,
                              const std::array<double, 3>& def) const;

  /// `obj[key]` as an array of [x, y] points (any number of them); fails when absent.
  std::vector<Vec2d> points(const nlohmann::json& obj, const std::string& path, const std::string& key) const;

 private:
  const JsonDoc& doc_;
  std::string file_;
};

}  // namespace sph2d
