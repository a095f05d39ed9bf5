// app/manifest.hpp — manifest.json: what `sph2d run` writes beside its frames and
// `sph2d check` reads back.
//
// A manifest names the scene (path, name, XXH64 of the file), the engine version,
// the renderer, the CPU and the Mesa settings, the image, the render options, the
// run's settings, and per kept frame its number, simulated time, PNG file, the
// XXH64 of its RGBA pixels and the World's state hash; then every applied event
// stamped with its frame, and whether the run completed (else why it stopped).
// This file holds the pieces of it both commands use.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "sph2d/render/renderer.hpp"

namespace sph2d::cli {

/// XXH64 of a file's bytes as 16 hex digits. Throws UsageError when it cannot be read.
std::string fileHash(const std::string& path);
/// The llvmpipe environment as recorded in a manifest (pins it first).
nlohmann::ordered_json environmentJson();
/// The render options as recorded in a manifest.
nlohmann::ordered_json renderOptionsJson(const RenderOptions& o);
/// The render options a manifest recorded. Throws UsageError on a malformed entry.
RenderOptions renderOptionsFromJson(const nlohmann::ordered_json& j);

}  // namespace sph2d::cli
