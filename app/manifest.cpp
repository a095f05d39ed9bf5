// app/manifest.cpp — writing and reading manifest.json; see manifest.hpp.
#include "manifest.hpp"

#include <fstream>
#include <sstream>

#include "cli.hpp"
#include "sph2d/hash.hpp"

namespace sph2d::cli {

using json = nlohmann::ordered_json;

std::string fileHash(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UsageError("cannot read " + path);
  std::ostringstream ss;
  ss << in.rdbuf();
  const std::string bytes = ss.str();
  return hex64(xxh64(bytes.data(), bytes.size()));
}

json environmentJson() {
  json env = json::array();
  for (const EnvSetting& e : pinRenderEnvironment())
    env.push_back({{"name", e.name}, {"value", e.value}, {"source", e.source}});
  return env;
}

json renderOptionsJson(const RenderOptions& o) {
  json j;
  j["mode"] = o.mode;
  j["color_by"] = colorFieldName(o.colorBy);
  j["range"] = o.range ? json::array({(*o.range)[0], (*o.range)[1]}) : json(nullptr);
  j["overlay"] = o.overlay;
  j["foam_speed"] = o.foamSpeed;
  j["depth_scale"] = o.depthScale;
  return j;
}

RenderOptions renderOptionsFromJson(const json& j) {
  RenderOptions o;
  try {
    o.mode = j.at("mode").get<std::string>();
    if (!parseColorField(j.at("color_by").get<std::string>(), o.colorBy)) throw UsageError("bad color_by");
    if (!j.at("range").is_null()) o.range = std::array<double, 2>{j.at("range").at(0).get<double>(), j.at("range").at(1).get<double>()};
    o.overlay = j.at("overlay").get<bool>();
    o.foamSpeed = j.at("foam_speed").get<double>();
    o.depthScale = j.at("depth_scale").get<double>();
  } catch (const json::exception& e) {
    throw UsageError(std::string("the manifest's render options are malformed: ") + e.what());
  }
  return o;
}

}  // namespace sph2d::cli
