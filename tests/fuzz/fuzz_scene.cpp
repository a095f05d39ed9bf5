// libFuzzer target for the scene loader, the event parser and the manifest reader
// (built by -DSPH2D_FUZZ=ON with clang; run it with tests/fuzz/run.sh, see
// docs/STABILITY.md).
//
// Every input is also read as a manifest (what `sph2d check` trusts from elsewhere):
// it must be accepted or refused with a UsageError naming the file, and what is
// accepted keeps the reader's promises (listed frames are kept frames of the run in
// order, each naming only its own file, hashes of 16 hex digits; an environment
// entry without a problem is a variable sph2d records, with a plain value).
//
// Every input is also read as one line of events (an events file, live input,
// a manifest's events replayed by check): it must parse or throw SceneError with
// a message and a sane position, and what parses must write back (eventToJson)
// to a line that parses to the same line, bit for bit.
//
// Every input must either load or throw SceneError with a message and a sane
// position; anything else (another exception, a crash, a leak, undefined
// behaviour, a hang) is a finding. A scene that loads and is small enough is
// also built into a World and stepped once, so that what the loader lets
// through is known to be acceptable to Box2D (whose assertions abort) and to
// the engine.
#include <algorithm>
#include <cctype>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "cli.hpp"
#include "output/manifest_reader.hpp"
#include "sph2d/render/render_env.hpp"

#include "sph2d/events.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace {

[[noreturn]] void finding(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz_scene: %s: %s\n", what, detail.c_str());
  std::abort();
}

/// Work a World would do for this scene, in boundary segments of one spacing.
double worldCost(const sph2d::SceneDef& s) {
  double len = 0, vertices = 0;
  for (const auto& b : s.bodies)
    for (const auto& f : b.fixtures) {
      vertices += double(f.vertices.size()) + 1;
      len += 4 * (f.halfSize.x() + f.halfSize.y()) + 6.3 * f.radius;
      for (std::size_t i = 0; i + 1 < f.vertices.size(); ++i) len += (f.vertices[i + 1] - f.vertices[i]).norm();
      if (!f.vertices.empty()) len += (f.vertices.front() - f.vertices.back()).norm();
    }
  return vertices * 50 + len / s.solver.spacing;
}

void checkError(const sph2d::SceneError& e, const char* file) {
  if (e.message.empty()) finding("SceneError without a message", e.what());
  if (e.file != file) finding("SceneError names another file", e.what());
  if (e.line < 0 || e.column < 0 || (e.line == 0) != (e.column == 0))
    finding("SceneError with a bad position", e.what());
  if (std::string(e.what()).rfind(file, 0) != 0) finding("what() does not start with the file", e.what());
}

/// The scene events are read against: an emitter and an effect to name.
const sph2d::SceneDef& eventScene() {
  static const sph2d::SceneDef s = sph2d::parseScene(
      R"({"solver": {"type": "wcsph", "spacing": 0.05}, "fluid": [{"min": [0, 0], "max": [1, 1]}],
          "effects": {"xsph": {"c": 0.1}, "emitters": [{"position": [0.5, 2], "direction": [0, -1]}]}})",
      "event_scene.json");
  return s;
}

void fuzzEvent(const std::string& text) {
  sph2d::EventDef e;
  try {
    e = sph2d::parseEvent(text, "fuzz.jsonl", 1, eventScene(), sph2d::EventStamp::Optional);
  } catch (const sph2d::SceneError& err) {
    checkError(err, "fuzz.jsonl");
    return;
  }
  const std::string once = sph2d::eventToJson(e);
  std::string twice;
  try {
    twice = sph2d::eventToJson(sph2d::parseEvent(once, "again.jsonl", 1, eventScene(), sph2d::EventStamp::Optional));
  } catch (const sph2d::SceneError& err) {
    finding("an accepted event does not read back", once + " -> " + err.what());
  }
  if (twice != once) finding("an event does not read back to itself", once + " -> " + twice);
}

void fuzzManifest(const std::string& text) {
  sph2d::cli::ManifestView v;
  try {
    v = sph2d::cli::parseManifest(text, "fuzz_manifest.json");
  } catch (const sph2d::cli::UsageError& e) {
    if (std::string(e.what()).rfind("fuzz_manifest.json", 0) != 0)
      finding("a manifest error does not name the file", e.what());
    return;
  }
  if (v.frames < 0 || v.every < 1) finding("accepted manifest with a bad run", text);
  int last = -1;
  for (const auto& [frame, entry] : v.expected) {
    if (frame <= last || frame >= v.frames || frame % v.every != 0)
      finding("accepted manifest lists a frame the run did not keep", text);
    if (entry.at("file").get<std::string>() != sph2d::cli::frameFileName(frame))
      finding("accepted manifest names another file", text);
    last = frame;
  }
  for (const std::string& p : v.listProblems)
    if (p.empty()) finding("an empty list problem", text);
  const std::vector<std::string> known = sph2d::recordedEnvironmentNames();
  for (const sph2d::cli::ManifestEnv& e : sph2d::cli::manifestEnvironment(v.json)) {
    if (!e.problem.empty()) {
      for (const char ch : e.name)
        if (ch < 0x20 || ch == 0x7f) finding("an ignored environment name is printed with a control character", text);
      continue;
    }
    if (std::find(known.begin(), known.end(), e.name) == known.end())
      finding("a manifest variable sph2d does not record is accepted", e.name);
    for (const char ch : e.value)
      if (!std::isalnum(static_cast<unsigned char>(ch)) && !std::strchr("_.,:=+-", ch))
        finding("a manifest value is not plain", e.value);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  fuzzEvent(text);
  fuzzManifest(text);
  sph2d::SceneDef scene;
  try {
    scene = sph2d::parseScene(text, "fuzz.json");
  } catch (const sph2d::SceneError& e) {
    checkError(e, "fuzz.json");
    return 0;
  }
  // What the loader promises about an accepted scene.
  if (!(scene.solver.spacing > 0) || !(scene.fps >= 1 && scene.fps <= 1000) || !(scene.duration * scene.fps <= 1e6))
    finding("accepted scene out of range", text);
  const std::size_t particles = sph2d::countBlockParticles(scene);
  if (particles > scene.maxParticles) finding("accepted scene over max_particles", text);
  if (particles > 2000 || worldCost(scene) > 20000 || scene.effects.emitters.size() > 4) return 0;
  try {
    sph2d::World world(scene, sph2d::WorldOptions{1});
    sph2d::bench::stepSubstep(world);
  } catch (const sph2d::SimulationError&) {
    // The guard stopping a wild scene is a correct outcome.
  } catch (const sph2d::SceneError& e) {
    // So is the World refusing what needs its solver to judge (an effect whose step limit is
    // below the solver's smallest substep), if the error names the file and the key.
    checkError(e, "fuzz.json");
    if (e.key.empty()) finding("SceneError from World without a key", e.what());
  }
  return 0;
}
