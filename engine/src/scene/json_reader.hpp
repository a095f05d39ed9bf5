// json_reader.hpp (internal) — a strict JSON parser that remembers where
// every value stands in the file.
//
// nlohmann::json gives no positions for keys, and a scene error must name the
// line and column. This recursive-descent parser builds the same json value
// and a map from key path ("solver.spacing", "blocks[0].min") to the 1-based
// line and column of the key (or of the array element). Syntax errors throw
// SceneError with the position of the offending character.
#pragma once

#include <map>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

namespace sph2d {

/// Parsed JSON plus the position of every key path.
struct JsonDoc {
  nlohmann::json root;
  std::map<std::string, std::pair<int, int>> where;  ///< path → (line, column)
};

/// Parses `text`; `file` names it in errors. Throws SceneError.
JsonDoc parseJsonWithPositions(const std::string& text, const std::string& file);

}  // namespace sph2d
