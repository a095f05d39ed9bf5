// app/manifest.cpp — writing and reading manifest.json; see manifest.hpp.
#include "manifest.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "cli.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/render/particle_export.hpp"

namespace sph2d::cli {

using json = nlohmann::ordered_json;

std::string frameFileName(std::int64_t frame) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.png", int(frame));
  return name;
}

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
  } catch (const json::exception&) {
    throw UsageError("the manifest's render options are malformed: mode, color_by, range, overlay, foam_speed and "
                     "depth_scale are read as sph2d run writes them");
  }
  return o;
}

RunManifest::RunManifest(const RunArgs& a, const SceneDef& scene, const Renderer& renderer, int frames, int threads) {
  std::string exportName = "none";
  if (a.exportFormat) exportName = exportExtension(*a.exportFormat) + (*a.exportFormat == ExportFormat::VtkAscii ? "-ascii" : "");
  j_["format"] = "sph2d-frames";
  j_["format_version"] = 1;
  j_["engine_version"] = SPH2D_VERSION;
  j_["scene"] = {{"path", a.scene}, {"name", scene.name}, {"xxh64", fileHash(a.scene)}};
  j_["renderer"] = renderer.rendererString();
  j_["cpu"] = cpuSummary();
  j_["environment"] = environmentJson();
  j_["image"] = {{"width", scene.render.width}, {"height", scene.render.height}, {"format", "png"},
                 {"png_level", a.pngLevel}, {"mode", renderer.mode()}};
  j_["render"] = renderOptionsJson(a.render);
  j_["run"] = {{"frames", frames}, {"every", a.every}, {"threads", threads}, {"fps", scene.fps}, {"export", exportName},
               {"video", a.video}, {"realtime", a.realtime}, {"inputs", a.inputs}};
  j_["frames"] = json::array();
  j_["events"] = json::array();
}

void RunManifest::addFrame(std::int64_t frame, double time, std::uint64_t pixels, std::uint64_t state) {
  j_["frames"].push_back({{"frame", frame},
                          {"time", time},
                          {"file", frameFileName(frame)},
                          {"rgba_xxh64", hex64(pixels)},
                          {"state_hash", hex64(state)}});
}

void RunManifest::addEvent(const std::string& line) { j_["events"].push_back(json::parse(line)); }

void RunManifest::finish(int written, int status, const std::string& reason, const std::string& message,
                         std::int64_t simulated) {
  json& list = j_["frames"];
  while (int(list.size()) > written) list.erase(list.size() - 1);
  j_["complete"] = status == 0;
  j_["stop"] = status == 0 ? json(nullptr)
                           : json{{"reason", reason}, {"message", message}, {"frames_simulated", simulated},
                                  {"frames_written", written}};
}

void RunManifest::write(const std::string& dir) const { writeFileAtomic(dir + "/manifest.json", j_.dump(1) + "\n"); }

void RunManifest::writeRunning(const std::string& dir) const {
  json j = j_;
  j["complete"] = false;
  j["stop"] = {{"reason", "running"},
               {"message", "the run had not ended when this was written (killed, or still running)"},
               {"frames_simulated", 0},
               {"frames_written", 0}};
  writeFileAtomic(dir + "/manifest.json", j.dump(1) + "\n");
}

ManifestView readManifest(const std::string& path) {
  ManifestView v;
  json& m = v.json;
  {
    std::ifstream in(path);
    if (!in) throw UsageError("cannot read the manifest " + path);
    try {
      in >> m;
    } catch (const json::exception& e) {
      throw UsageError(path + " is not valid JSON: " + e.what());
    }
  }
  // `key` names what is read, so that a missing or mistyped value is reported by its key
  // and the type wanted, not by the JSON library's text.
  std::string key = "format", want = "the string \"sph2d-frames\"";
  try {
    if (!m.is_object() || m.at("format").get<std::string>() != "sph2d-frames") throw UsageError(path + " is not an sph2d frames manifest");
    key = "run.frames", want = "an integer";
    v.frames = m.at("run").at("frames").get<int>();
    key = "run.every";
    v.every = std::max(1, m.at("run").at("every").get<int>());
    key = "renderer", want = "a string";
    v.renderer = m.at("renderer").get<std::string>();
    key = "cpu";
    v.cpu = m.value("cpu", "");
    key = "scene.xxh64";
    v.sceneHash = m.at("scene").at("xxh64").get<std::string>();
    key = "render", want = "the render options sph2d run writes";
    v.render = renderOptionsFromJson(m.at("render"));
    key = "complete", want = "true or false";
    (void)m.value("complete", false);
    if (m.contains("stop") && !m["stop"].is_null()) {
      key = "stop", want = "an object with reason and message strings and frames_written";
      const json& st = m.at("stop");
      (void)st.at("reason").get<std::string>();
      (void)st.value("message", std::string());
      (void)st.value("frames_written", 0);
    }
    if (m.contains("events")) {
      key = "events", want = "an array";
      if (!m["events"].is_array()) throw json::type_error::create(302, "not an array", &m["events"]);
    }
    key = "frames", want = "an array of objects with frame, file, rgba_xxh64 and state_hash";
    if (v.frames < 0 || v.frames > 100000000) throw UsageError(path + ": run.frames must be 0..100000000");
    auto hex16 = [](const std::string& h) {
      return h.size() == 16 && std::all_of(h.begin(), h.end(), [](char c) { return std::isxdigit(static_cast<unsigned char>(c)); });
    };
    int last = -1;
    const json& list = m.at("frames");
    for (std::size_t k = 0; k < list.size(); ++k) {
      const json& f = list[k];
      const std::string at = path + ": frames[" + std::to_string(k) + "]";
      const int frame = f.at("frame").get<int>();
      if (frame < 0 || frame >= v.frames || frame % v.every != 0 || frame <= last)
        throw UsageError(at + ": frame " + std::to_string(frame) + " is not a kept frame of the run after frame " +
                         std::to_string(last) + " (frames 0.." + std::to_string(v.frames - 1) + ", every " +
                         std::to_string(v.every) + ", in order)");
      if (f.at("file").get<std::string>() != frameFileName(frame))
        throw UsageError(at + ": its file must be " + frameFileName(frame) + " (a manifest names only its own frames)");
      if (!hex16(f.at("rgba_xxh64").get<std::string>()) || !hex16(f.at("state_hash").get<std::string>()))
        throw UsageError(at + ": rgba_xxh64 and state_hash must be 16 hex digits");
      v.expected[frame] = f;
      last = frame;
    }
    // The list against the run: complete → every kept frame (a real-time run may have
    // dropped some); stopped → the first frames_written of them.
    const bool complete = m.value("complete", false);
    const bool realtime = m.at("run").value("realtime", false);
    std::vector<int> kept;
    for (int f = 0; f < v.frames; f += v.every) kept.push_back(f);
    std::size_t prefix = kept.size();
    if (!complete) {
      const json& stop = m.contains("stop") && m["stop"].is_object() ? m["stop"] : json::object();
      prefix = std::min(kept.size(), std::size_t(std::max(0, stop.value("frames_written", int(v.expected.size())))));
      if (!realtime && v.expected.size() != prefix)
        v.listProblems.push_back("the run stopped after writing " + std::to_string(prefix) + " frames, but the manifest lists " +
                                 std::to_string(v.expected.size()));
    }
    if (!realtime) {
      for (std::size_t k = 0; k < prefix; ++k)
        if (!v.expected.count(kept[k])) {
          v.listProblems.push_back(std::string(complete ? "the manifest says the run is complete, but " : "") +
                                   "it lists " + std::to_string(v.expected.size()) + " of the run's " +
                                   std::to_string(prefix) + " kept frames (the first missing: frame " +
                                   std::to_string(kept[k]) + ")");
          break;
        }
    }
  } catch (const json::exception&) {
    throw UsageError(path + ": the key '" + key + "' is missing or not " + want + " (as sph2d run writes it)");
  }
  return v;
}

}  // namespace sph2d::cli
