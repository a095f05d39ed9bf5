// The manifest reader (app/output/manifest_reader.cpp) on its own: a manifest is input from
// elsewhere, so every value is read with its type and range, a refusal names the file
// and the key, and nothing it says sizes an allocation. The same reader runs under the
// fuzz target (tests/fuzz/fuzz_scene.cpp).
#include <doctest/doctest.h>

#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "output/manifest_reader.hpp"

using json = nlohmann::ordered_json;
using namespace sph2d::cli;

namespace {

/// The checked-in manifest of a real three-frame run (also a fuzz seed).
json realManifest() {
  std::ifstream in(std::string(SPH2D_SOURCE_DIR) + "/tests/fuzz/corpus/manifest_complete.json");
  REQUIRE(in);
  std::stringstream s;
  s << in.rdbuf();
  return json::parse(s.str());
}

/// parseManifest's refusal message for `m` ("" when it is accepted).
std::string refusal(const json& m) {
  try {
    (void)parseManifest(m.dump(), "m.json");
  } catch (const UsageError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("manifest reader: a real run's manifest reads back with its frames, render options and environment") {
  const ManifestView v = parseManifest(realManifest().dump(), "m.json");
  CHECK(v.frames == 3);
  CHECK(v.every == 1);
  REQUIRE(v.expected.size() == 3);
  CHECK(v.expected.at(2).at("file") == "frame_00002.png");
  CHECK(v.listProblems.empty());
  CHECK(v.render.mode.empty());
  CHECK(v.render.colorBy == sph2d::ColorField::Speed);
  const std::vector<ManifestEnv> env = manifestEnvironment(v.json);
  REQUIRE(env.size() == 8);
  for (const ManifestEnv& e : env) CHECK_MESSAGE(e.problem.empty(), e.name);
}

TEST_CASE("manifest reader: numbers of the wrong type or range are refused naming the file and key, never converted") {
  // Before (issue 18): get<int>() converted 1e20 (undefined behaviour) and 2.5 (to 2), and
  // run.every 0 became 1.
  const json good = realManifest();
  struct Case {
    const char* key;
    json value;
  };
  for (const Case& c : {Case{"frames", 1e20}, Case{"frames", 2.5}, Case{"frames", -1}, Case{"frames", "five"},
                        Case{"every", 0}, Case{"every", 1e300}}) {
    json m = good;
    m["run"][c.key] = c.value;
    const std::string r = refusal(m);
    INFO(c.key, " = ", c.value.dump(), ": ", r);
    CHECK(r.rfind("m.json: the key 'run.", 0) == 0);
    CHECK(r.find("' is missing or not an integer in ") != std::string::npos);
  }
  json m = good;
  m["frames"][1]["frame"] = 1e300;
  CHECK(refusal(m).find("the key 'frames[1].frame' is missing or not an integer") != std::string::npos);
  m = good;
  m["stop"] = {{"reason", "guard"}, {"frames_written", -3}};
  CHECK(refusal(m).find("the key 'stop.frames_written'") != std::string::npos);
  m = good;
  m["frames"][0] = 7;
  CHECK(refusal(m).find("the key 'frames[0]' is missing or not an object") != std::string::npos);
}

TEST_CASE("manifest reader: render options outside what sph2d run writes are refused naming the file") {
  // Before (issue 18): an unknown color_by threw "bad color_by", naming neither file nor key,
  // and any mode string was passed on to the renderer.
  const json good = realManifest();
  json m = good;
  m["render"]["color_by"] = "rainbow";
  std::string r = refusal(m);
  CHECK(r.rfind("m.json: the key 'render.color_by' is missing or not \"speed\"", 0) == 0);
  m = good;
  m["render"]["mode"] = "wireframe";
  CHECK(refusal(m).find("'render.mode'") != std::string::npos);
  m = good;
  m["render"]["range"] = json::array({0, "x"});
  CHECK(refusal(m).find("'render.range' is missing or not null or two finite numbers") != std::string::npos);
  m = good;
  m["render"]["foam_speed"] = -1;
  CHECK(refusal(m).find("'render.foam_speed'") != std::string::npos);
  m = good;
  m["render"]["splat"] = "vulkan";
  CHECK(refusal(m).find("'render.splat' is missing or not \"auto\", \"cpu\" or \"gl\"") != std::string::npos);
  m = good;
  m["render"]["splat"] = 1;
  CHECK(refusal(m).find("'render.splat'") != std::string::npos);
  m = good;
  m["render"]["splat"] = "cpu";  // the path the run summed its splat by, taken by a check
  CHECK(parseManifest(m.dump(), "m.json").render.splat == sph2d::SplatPath::Cpu);
  m["render"].erase("splat");  // a manifest from before the CPU's splat: its frames are the GL's
  CHECK(parseManifest(m.dump(), "m.json").render.splat == sph2d::SplatPath::Gl);
  m = good;
  m["render"]["range"] = json::array({0, 2.5});
  m["render"]["mode"] = "particles";
  const ManifestView v = parseManifest(m.dump(), "m.json");
  REQUIRE(v.render.range.has_value());
  CHECK((*v.render.range)[1] == 2.5);
}

TEST_CASE("manifest reader: a huge run.frames is counted, not listed, and the first missing kept frame is named") {
  // Before (issue 18): the kept frames were listed in a vector, so run.frames 1e8 took
  // 400 MB before any check.
  json m = realManifest();
  m["run"]["frames"] = 100000000;
  ManifestView v = parseManifest(m.dump(), "m.json");
  REQUIRE(v.listProblems.size() == 1);
  CHECK(
      v.listProblems[0] ==
      "the manifest says the run is complete, but it lists 3 of the run's 100000000 kept frames (the first missing: frame 3)");
  m["run"]["every"] = 2;
  m["run"]["frames"] = 9;
  m["frames"].erase(1);  // frames 0 and 2 of 0, 2, 4, 6, 8
  v = parseManifest(m.dump(), "m.json");
  REQUIRE(v.listProblems.size() == 1);
  CHECK(v.listProblems[0].find("lists 2 of the run's 5 kept frames (the first missing: frame 4)") != std::string::npos);
  m["complete"] = false;
  m["stop"] = {{"reason", "interrupted"}, {"frames_written", 2}};
  CHECK(parseManifest(m.dump(), "m.json").listProblems.empty());  // stopped after writing its first two
  m["stop"]["frames_written"] = 3;
  v = parseManifest(m.dump(), "m.json");
  REQUIRE(v.listProblems.size() == 2);
  CHECK(v.listProblems[0] == "the run stopped after writing 3 frames, but the manifest lists 2");
}

TEST_CASE("manifest reader: only the variables sph2d records, with plain values, pass the environment check") {
  json m = realManifest();
  m["environment"] = json::array({{{"name", "LD_PRELOAD"}, {"value", "/tmp/x.so"}},
                                  {{"name", "GALLIUM_DRIVER"}, {"value", "llvmpipe"}},
                                  {{"name", "LP_NUM_THREADS"}, {"value", "$(rm -rf ~)"}},
                                  {{"name", "LP\x01X"}, {"value", "1"}},
                                  {{"name", 5}}});
  const std::vector<ManifestEnv> env = manifestEnvironment(parseManifest(m.dump(), "m.json").json);
  REQUIRE(env.size() == 5);
  CHECK(env[0].problem.find("records only its renderer's settings") != std::string::npos);
  CHECK(env[1].problem.empty());
  CHECK(env[1].value == "llvmpipe");
  CHECK(env[2].problem.find("not a plain setting") != std::string::npos);
  CHECK(env[3].name == "LP?X");  // printed without the control character
  CHECK(env[4].name == "(malformed)");
  m["environment"] = "GALLIUM_TRACE=x";
  CHECK(refusal(m).find("the key 'environment' is missing or not an array") != std::string::npos);
}
