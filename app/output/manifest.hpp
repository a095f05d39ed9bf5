// app/output/manifest.hpp — manifest.json: what `sph2d run` writes beside its frames and
// `sph2d check` reads back (the reader: manifest_reader.hpp).
//
// A manifest names the scene (path, name, XXH64 of the file), the engine version,
// the renderer, the CPU and the Mesa settings, the image, the render options, the
// run's settings, and per kept frame its number, simulated time, PNG file, the
// XXH64 of its RGBA pixels and the World's state hash; then every applied event
// stamped with its frame, every file the run wrote into its folder with the XXH64
// of its bytes ("files": the frames, exports, and the video or record when they are
// in the folder; what lets a later run prove they are sph2d's, output_dir.hpp), and
// whether the run completed (else why it stopped).
// Design: the run fills it as frames are rendered and events applied and writes it
// once at the end, whole or not at all (writeFileAtomic), listing only the frames
// whose PNG exists. Keys keep their insertion order, so equal runs give equal bytes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "output/manifest_reader.hpp"
#include "output/output_dir.hpp"
#include "run/run_args.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"

namespace sph2d::cli {

/// XXH64 of a file's bytes as 16 hex digits (read in pieces). Throws UsageError when it cannot be read.
std::string fileHash(const std::string& path);
/// The llvmpipe environment as recorded in a manifest (pins it first).
nlohmann::ordered_json environmentJson();
/// The render options as recorded in a manifest.
nlohmann::ordered_json renderOptionsJson(const RenderOptions& o);

/// The manifest of one `sph2d run`, filled while it runs.
class RunManifest {
 public:
  /// The header of a run of `scene` with options `a`, `frames` frames on `threads`
  /// threads, rendered by `renderer`.
  RunManifest(const RunArgs& a, const SceneDef& scene, const Renderer& renderer, int frames, int threads);
  /// Lists kept frame `frame`: simulated time, pixel hash, state hash.
  void addFrame(std::int64_t frame, double time, std::uint64_t pixels, std::uint64_t state);
  /// Lists an applied event (a recordLine()).
  void addEvent(const std::string& line);
  /// Keeps the first `written` frames (those whose PNG exists), lists `files` (what the run
  /// wrote into its folder, with hashes) and says how the run ended: complete when `status`
  /// is 0, else `reason` ("interrupted", "guard", "error") and `message`.
  void finish(int written, const std::vector<OwnedFile>& files, int status, const std::string& reason,
              const std::string& message, std::int64_t simulated);
  /// Writes DIR/manifest.json whole or not at all. Throws std::runtime_error.
  void write(const std::string& dir) const;
  /// Writes DIR/manifest.json as a run under way: no frames, complete false, stop reason
  /// "running" (what a run killed before its end leaves). Throws std::runtime_error.
  void writeRunning(const std::string& dir) const;

 private:
  nlohmann::ordered_json j_;
};

}  // namespace sph2d::cli
