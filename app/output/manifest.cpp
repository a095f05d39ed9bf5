// app/output/manifest.cpp — writing and reading manifest.json; see manifest.hpp.
#include "output/manifest.hpp"

#include <cstdio>
#include <fstream>
#include <sstream>

#include "cli.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/render/particle_export.hpp"

namespace sph2d::cli {

using json = nlohmann::ordered_json;

std::string fileHash(const std::string& path) {
  const auto h = hashFile(path);
  if (!h) throw UsageError("cannot read " + path);
  return hex64(*h);
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
  j["outline"] = o.outline;
  j["foam_speed"] = o.foamSpeed;
  j["depth_scale"] = o.depthScale;
  j["splat"] = splatPathName(o.splat);
  return j;
}

RunManifest::RunManifest(const RunArgs& a, const SceneDef& scene, const Renderer& renderer, int frames, int threads) {
  std::string exportName = "none";
  if (a.exportFormat)
    exportName = *a.exportFormat == ExportFormat::Surface
                     ? "surface"
                     : exportExtension(*a.exportFormat) + (*a.exportFormat == ExportFormat::VtkAscii ? "-ascii" : "");
  j_["format"] = "sph2d-frames";
  j_["format_version"] = 1;
  j_["engine_version"] = SPH2D_VERSION;
  j_["scene"] = {{"path", a.scene}, {"name", scene.name}, {"xxh64", fileHash(a.scene)}};
  j_["renderer"] = renderer.rendererString();
  j_["cpu"] = cpuSummary();
  j_["environment"] = environmentJson();
  j_["image"] = {{"width", scene.render.width},
                 {"height", scene.render.height},
                 {"format", "png"},
                 {"png_level", a.pngLevel},
                 {"mode", renderer.mode()}};
  j_["render"] = renderOptionsJson(a.render);
  // The splat's path as resolved for this renderer (RenderOptions::splat), so that a check
  // elsewhere sums the field as this run did; "auto" in particles mode (no splat).
  j_["render"]["splat"] = renderer.splatPath().empty() ? std::string("auto") : renderer.splatPath();
  j_["run"] = {{"frames", frames},     {"every", a.every}, {"threads", threads},     {"fps", scene.fps},
               {"export", exportName}, {"video", a.video}, {"realtime", a.realtime}, {"inputs", a.inputs}};
  j_["frames"] = json::array();
  j_["events"] = json::array();
  j_["files"] = json::array();
}

void RunManifest::addFrame(std::int64_t frame, double time, std::uint64_t pixels, std::uint64_t state) {
  j_["frames"].push_back({{"frame", frame},
                          {"time", time},
                          {"file", frameFileName(frame)},
                          {"rgba_xxh64", hex64(pixels)},
                          {"state_hash", hex64(state)}});
}

void RunManifest::addEvent(const std::string& line) { j_["events"].push_back(json::parse(line)); }

void RunManifest::finish(int written, const std::vector<OwnedFile>& files, int status, const std::string& reason,
                         const std::string& message, std::int64_t simulated) {
  json& list = j_["frames"];
  while (int(list.size()) > written) list.erase(list.size() - 1);
  for (const OwnedFile& f : files) j_["files"].push_back({{"file", f.name}, {"xxh64", f.xxh64}});
  j_["complete"] = status == 0;
  j_["stop"] =
      status == 0
          ? json(nullptr)
          : json{
                {"reason", reason}, {"message", message}, {"frames_simulated", simulated}, {"frames_written", written}};
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

}  // namespace sph2d::cli
