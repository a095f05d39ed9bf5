// app/output/manifest_reader.hpp — reading manifest.json back (`sph2d check`).
//
// A manifest is input from elsewhere (a CI artefact, a colleague's run): the reader
// trusts none of it. Every field check needs is read with its type and range, a
// frame entry may name only its own frame's file, and nothing the manifest says
// sizes an allocation. The reader needs no GL and no World, so the fuzz target
// (tests/fuzz/fuzz_scene.cpp) runs it on every input.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sph2d/render/renderer.hpp"

namespace sph2d::cli {

/// "frame_NNNNN.png", the file name of frame `frame`.
std::string frameFileName(std::int64_t frame);

/// The render options a manifest recorded (`mode` "", liquid or particles; finite, non-negative
/// speeds and depths). Throws UsageError naming the first malformed entry.
RenderOptions renderOptionsFromJson(const nlohmann::ordered_json& j);

/// A manifest as `sph2d check` reads it.
struct ManifestView {
  nlohmann::ordered_json json;                     ///< the whole manifest
  int frames = 0;                                  ///< run.frames
  int every = 1;                                   ///< run.every
  std::map<int, nlohmann::ordered_json> expected;  ///< the listed frames by number
  std::string renderer, cpu, sceneHash;            ///< what it was made with
  RenderOptions render;                            ///< the render options of the run
  /// Why the frame list is not the run's (empty when it is): a complete run lists every
  /// kept frame (0, every, 2·every, … below frames; a real-time run may have dropped
  /// some), a stopped one the first frames_written of them.
  std::vector<std::string> listProblems;
};

/// One entry of a manifest's `environment`, checked: `problem` says why it is ignored.
struct ManifestEnv {
  std::string name, value, problem;
};

/// The environment entries of manifest `m` (none when it has no array). Only a name sph2d
/// records (recordedEnvironmentNames) is accepted, with a value of at most 64 characters
/// from [A-Za-z0-9_.,:=+-]; anything else (LD_PRELOAD, GALLIUM_TRACE, a path, a control
/// character) gets a problem and is never to be set.
std::vector<ManifestEnv> manifestEnvironment(const nlohmann::ordered_json& m);

/// Reads the manifest text `text` (`path` names it in messages). Throws UsageError, its
/// message starting with `path`, when the text is not JSON, is not an sph2d frames
/// manifest, lacks a field check needs or holds one of the wrong type or range, or a
/// frame entry is malformed (its number not a kept frame of the run or out of order, its
/// file not the frame's own name, a hash not 16 hex digits): a manifest names no other file.
ManifestView parseManifest(const std::string& text, const std::string& path);

/// Reads the manifest file `path` (parseManifest). Throws UsageError when it cannot be read.
ManifestView readManifest(const std::string& path);

}  // namespace sph2d::cli
