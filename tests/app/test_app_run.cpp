// The app end to end: `sph2d run` writes whole, non-blank PNG frames; bad input exits 2.
#include <doctest/doctest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "sph2d/render/png_io.hpp"

namespace fs = std::filesystem;

namespace {

struct Result {
  int code;
  std::string out;
};

Result run(const std::string& args) {
  // CTest runs test cases in parallel processes: one log per process and call.
  static int calls = 0;
  const std::string log = std::string(SPH2D_TEST_TMP) + "/cmd_" + std::to_string(::getpid()) + "_" + std::to_string(++calls) + ".log";
  fs::create_directories(SPH2D_TEST_TMP);
  const std::string cmd = std::string("\"") + SPH2D_EXE + "\" " + args + " > \"" + log + "\" 2>&1";
  const int status = std::system(cmd.c_str());
  std::ifstream in(log);
  std::stringstream ss;
  ss << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ss.str()};
}

std::string asset(const std::string& rel) { return std::string(SPH2D_ASSETS) + "/" + rel; }

}  // namespace

TEST_CASE("sph2d run writes the expected number of PNG frames, of the scene's size, not blank") {
  const std::string dir = std::string(SPH2D_TEST_TMP) + "/run_small";
  fs::remove_all(dir);
  const Result r = run("run \"" + asset("scenes/tests/small_dam_break.json") + "\" --frames 12 --threads 2 --out \"" + dir +
                       "\" --state-hash");
  INFO(r.out);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("sph2d: 12 frames") != std::string::npos);
  CHECK(r.out.find("state-hash: ") != std::string::npos);
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    CHECK(name.find(".tmp") == std::string::npos);  // no temporary left behind
    ++files;
  }
  CHECK(files == 12);
  for (int f : {0, 11}) {
    char name[32];
    std::snprintf(name, sizeof name, "/frame_%05d.png", f);
    int w = 0, h = 0;
    std::vector<std::uint8_t> rgba;
    sph2d::readPng(dir + name, w, h, rgba);
    CHECK(w == 192);
    CHECK(h == 144);
    // Not blank: water-blue pixels (b clearly above r) and several distinct colours.
    std::size_t blue = 0;
    std::set<std::uint32_t> colours;
    for (std::size_t p = 0; p < rgba.size(); p += 4) {
      if (rgba[p + 2] > rgba[p] + 60) ++blue;
      colours.insert(std::uint32_t(rgba[p]) << 16 | std::uint32_t(rgba[p + 1]) << 8 | rgba[p + 2]);
    }
    const double waterShare = double(blue) / double(w * h);
    MESSAGE("frame " << f << ": water covers " << 100 * waterShare << " % of the image, " << colours.size() << " colours");
    CHECK(waterShare > 0.03);
    CHECK(waterShare < 0.5);
    CHECK(colours.size() > 20);
  }
}

TEST_CASE("a scene with an unknown key exits 2 naming file, line and key") {
  const std::string path = std::string(SPH2D_TEST_TMP) + "/typo.json";
  fs::create_directories(SPH2D_TEST_TMP);
  std::ofstream(path) << "{\n  \"name\": \"typo\",\n  \"fsp\": 60\n}\n";
  const Result r = run("run \"" + path + "\" --frames 1 --out \"" + std::string(SPH2D_TEST_TMP) + "/typo_out\"");
  CHECK(r.code == 2);
  CHECK(r.out.find(path + ":3:3: key 'fsp': unknown key") != std::string::npos);
  CHECK(r.out.find("allowed keys:") != std::string::npos);
}

TEST_CASE("command-line misuse exits 2 with a message") {
  Result r = run("run \"" + asset("scenes/tests/small_dam_break.json") + "\" --framez 3");
  CHECK(r.code == 2);
  CHECK(r.out.find("unknown option '--framez'") != std::string::npos);
  r = run("run \"" + asset("scenes/tests/small_dam_break.json") + "\" --frames -3");
  CHECK(r.code == 2);
  r = run("frobnicate");
  CHECK(r.code == 2);
  r = run("run --help");
  CHECK(r.code == 0);
  CHECK(r.out.find("--frames N") != std::string::npos);
}
