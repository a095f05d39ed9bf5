// Bad scene files through the app: `sph2d run` exits 2 with
// "sph2d: bad scene: FILE:LINE:COL: key 'K': message" and writes nothing.
// The loader's messages are tested class by class in tests/engine/test_scene_errors.cpp;
// here each class goes through the executable once.
#include <doctest/doctest.h>

#include <sys/resource.h>
#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "app_runner.hpp"

namespace fs = std::filesystem;
using namespace sph2d::apptest;

namespace {

/// Writes `content` as a scene, runs it, and checks exit code 2, the full
/// error line, and that no output directory was created.
void expectBadScene(const std::string& tag, const std::string& content, const std::string& expected) {
  const std::string dir = scratch("bad_" + tag);
  const std::string scene = dir + "/" + tag + ".json";
  {
    std::ofstream out(scene, std::ios::binary);
    out << content;
  }
  const std::string outDir = dir + "/frames";
  const Result r = runSph2d("run " + q(scene) + " --frames 2 --out " + q(outDir));
  INFO(r.out);
  CHECK(r.code == 2);
  CHECK(r.out.find("sph2d: bad scene: " + scene + expected) != std::string::npos);
  CHECK_FALSE(fs::exists(outDir));
  fs::remove_all(dir);
}

}  // namespace

TEST_CASE("app bad input: invalid JSON exits 2 naming file, line and column") {
  expectBadScene("syntax", "{\n  \"fps\": 60\n  \"duration\": 1\n}\n",
                 ":3:3: invalid JSON: unexpected character '\"', expected ',' or '}' in an object");
}

TEST_CASE("app bad input: an empty file and a whitespace-only file exit 2") {
  expectBadScene("empty", "", ":1:1: invalid JSON: the file is empty; a scene is a JSON object such as {}");
  expectBadScene("blank", "\n\n   \n",
                 ":1:1: invalid JSON: the file holds only whitespace; a scene is a JSON object such as {}");
}

TEST_CASE("app bad input: a top level that is not an object exits 2") {
  expectBadScene("array", "[{\"fps\": 60}]",
                 ":1:1: a scene is a JSON object ({ ... }) at the top level, got an array of 1 element");
}

TEST_CASE("app bad input: a wrong type and a wrong-length vector exit 2 at their key") {
  expectBadScene("type", "{\"render\": {\"width\": \"wide\"}}",
                 ":1:13: key 'render.width': expected an integer from 16 to 8192, got a string");
  expectBadScene("vector", "{\"gravity\": [0, -9.81, 0]}",
                 ":1:2: key 'gravity': expected [x, y] (two numbers), got an array of 3 elements");
}

TEST_CASE("app bad input: non-UTF-8 bytes exit 2 at the byte") {
  expectBadScene(
      "latin1", "{\"name\": \"d\xE9mo\"}",
      ":1:12: invalid JSON: byte 0xE9 is not valid UTF-8; scene files are UTF-8 text (save the file as UTF-8)");
}

TEST_CASE("app bad input: 1e400 and NaN exit 2 where they stand") {
  expectBadScene("huge", "{\"duration\": 1e400}",
                 ":1:14: invalid JSON: number 1e400 is too large (a double holds magnitudes up to about 1.8e308)");
  expectBadScene(
      "nan", "{\"duration\": NaN}",
      ":1:14: invalid JSON: unexpected character 'N', expected a value; NaN and Infinity are not JSON numbers");
}

TEST_CASE("app bad input: deep nesting and duplicate keys exit 2") {
  expectBadScene("deep", std::string(5000, '[') + std::string(5000, ']'),
                 ":1:201: invalid JSON: nested deeper than 200 levels");
  expectBadScene("duplicate", "{\"fps\": 60, \"fps\": 30}", ":1:13: invalid JSON: duplicate key 'fps'");
}

TEST_CASE("app bad input: geometry Box2D would abort on exits 2 instead") {
  // Without the loader's checks each of these reaches a Box2D assertion (SIGABRT).
  expectBadScene(
      "weld", "{\"boundaries\": [{\"fixtures\": [{\"shape\": \"polygon\", \"vertices\": [[0,0],[0.001,0],[0,1]]}]}]}",
      ":1:52: key 'boundaries[0].fixtures[0].vertices': vertices [0] and [1] are closer than 0.005 m (Box2D's linear slop)");
  expectBadScene(
      "sliver",
      "{\"boundaries\": [{\"fixtures\": [{\"shape\": \"polygon\", \"vertices\": [[0,0],[1,0],[0.5,1e-7]]}]}]}",
      ":1:52: key 'boundaries[0].fixtures[0].vertices': the polygon is too thin");
  expectBadScene(
      "chain", "{\"boundaries\": [{\"fixtures\": [{\"shape\": \"chain\", \"vertices\": [[0,0],[0.004,0],[1,1]]}]}]}",
      ":1:69: key 'boundaries[0].fixtures[0].vertices[1]': chain vertices [0] and [1] are closer than 0.005 m (Box2D's linear slop)");
  expectBadScene(
      "concave",
      "{\"boundaries\": [{\"fixtures\": [{\"shape\": \"polygon\", \"vertices\": [[0,0],[2,0],[1,0.2],[2,2],[0,2]]}]}]}",
      ":1:52: key 'boundaries[0].fixtures[0].vertices': the polygon must be convex");
}

TEST_CASE("app bad input: a fluid block that would hold no particle exits 2") {
  expectBadScene(
      "inside",
      "{\"boundaries\": [{\"fixtures\": [{\"shape\": \"box\", \"half_size\": [3, 3]}]}], \"fluid\": [{\"min\": [0, 0], \"max\": [1, 1]}]}",
      ":1:83: key 'fluid[0]': the block lies entirely inside boundaries[0].fixtures[0] (a box): every particle would be dropped");
}

TEST_CASE("app bad input: a spacing too small for the particle budget exits 2 before allocating") {
  expectBadScene(
      "budget", "{\"solver\": {\"spacing\": 0.0001}, \"fluid\": [{\"min\": [0, 0], \"max\": [1, 1]}]}",
      ":1:13: key 'solver.spacing': spacing 0.0001 fills the fluid blocks with 100000000 particles, more than max_particles = 4000000");
}

TEST_CASE("app bad input: a missing scene file and a directory exit 2 naming the path") {
  const std::string dir = scratch("bad_missing");
  Result r = runSph2d("run " + q(dir + "/nope.json") + " --out " + q(dir + "/frames"));
  CHECK(r.code == 2);
  CHECK(r.out.find("sph2d: bad scene: " + dir + "/nope.json: cannot open the scene file: No such file or directory") !=
        std::string::npos);
  r = runSph2d("info " + q(dir));
  CHECK(r.code == 2);
  CHECK(r.out.find("sph2d: bad scene: " + dir + ": is a directory, not a scene file") != std::string::npos);
  CHECK_FALSE(fs::exists(dir + "/frames"));
  fs::remove_all(dir);
}

TEST_CASE("bad input: a scene whose estimated peak memory exceeds the limit is refused before allocating") {
  // Before (issue 18): 50M or 99M particles under max_particles 1e8, or an emitter of 1e8
  // particles/s, failed after 9–27 s with std::bad_alloc at 5–7 GB, while info said 28.6 MB.
  const std::string dir = scratch("memory_estimate");
  const std::string huge = dir + "/huge.json", emitter = dir + "/emitter.json";
  std::ofstream(huge) << R"({"name": "huge", "max_particles": 100000000,
    "solver": {"type": "wcsph", "spacing": 0.0002},
    "boundaries": [{"fixtures": [{"shape": "box", "center": [2, -0.1], "half_size": [2.2, 0.1]}]}],
    "fluid": [{"min": [0, 0], "max": [1, 2]}]})";
  std::ofstream(emitter) << R"({"name": "emitter", "max_particles": 100000000, "duration": 4,
    "solver": {"type": "wcsph", "spacing": 0.02},
    "boundaries": [{"fixtures": [{"shape": "box", "center": [2, -0.1], "half_size": [2.2, 0.1]}]}],
    "effects": {"emitters": [{"position": [1, 1], "direction": [1, 0], "rate": 1e8, "speed": 1}]}})";
  for (const std::string& scene : {huge, emitter}) {
    const std::string out = dir + "/frames";
    // --max-memory makes the limit the same on every machine (the default is the memory available).
    const Result r = runSph2d("run " + q(scene) + " --frames 2 --max-memory 1G --out " + q(out));
    INFO(r.out);
    CHECK(r.code == 2);
    CHECK(r.out.find("sph2d: the scene would hold about ") != std::string::npos);
    CHECK(r.out.find("more than --max-memory (1000 MB)") != std::string::npos);
    CHECK_FALSE(fs::exists(out));
    const Result info = runSph2d("info " + q(scene) + " --max-memory 1G");
    CHECK(info.code == 2);
    CHECK(info.out.find("memory       about ") != std::string::npos);
  }
  CHECK(runSph2d("info " + q(huge) + " --max-memory 1G").out.find("50000000 particles at most") != std::string::npos);
  CHECK(runSph2d("info " + q(emitter) + " --max-memory 1G").out.find("100000000 particles at most") !=
        std::string::npos);
  CHECK(runSph2d("run " + q(huge) + " --max-memory lots").code == 2);
  fs::remove_all(dir);
}

TEST_CASE("info's memory estimate is within a factor of 2 of the run's measured peak") {
#if defined(__SANITIZE_ADDRESS__)
  MESSAGE("skipped under AddressSanitizer: its shadow memory and quarantine are not the run's own");
  return;
#endif
  // The default scene, and the dam break at about 100k particles (spacing 0.0045).
  const std::string dir = scratch("memory_peak");
  std::string text;
  {
    std::ifstream in(asset("scenes/dam_break.json"));
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const std::string big = dir + "/dam_break_100k.json";
  {
    std::string t = text;
    const auto at = t.find("\"spacing\": 0.014");
    REQUIRE(at != std::string::npos);
    t.replace(at, 16, "\"spacing\": 0.0045");
    std::ofstream(big) << t;
  }
  for (const std::string& scene : {asset("scenes/dam_break.json"), big}) {
    const Result info = runSph2d("info " + q(scene));
    const auto at = info.out.find("memory       about ");
    REQUIRE(at != std::string::npos);
    const double estimate = std::stod(info.out.substr(at + 19)) * 1e6;
    const std::string log = dir + "/run.log", out = dir + "/frames";
    const pid_t pid = spawnSph2d({"run", scene, "--frames", "30", "--quiet", "--out", out}, log);
    REQUIRE(pid > 0);
    int status = 0;
    struct rusage ru {};
    REQUIRE(::wait4(pid, &status, 0, &ru) == pid);
    REQUIRE(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 0);
    const double peak = double(ru.ru_maxrss) * 1024.0;
    MESSAGE(scene << ": estimate " << estimate / 1e6 << " MB, measured peak " << peak / 1e6 << " MB");
    CHECK(peak <= 2 * estimate);
    CHECK(estimate <= 2 * peak);
  }
  fs::remove_all(dir);
}
