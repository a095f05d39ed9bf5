// The app end to end: `sph2d run` writes whole, non-blank PNG frames; bad input exits 2.
#include <doctest/doctest.h>

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "app_util.hpp"
#include "sph2d/render/png_io.hpp"

namespace fs = std::filesystem;

using namespace sph2d::apptest;

TEST_CASE("sph2d run writes the expected number of PNG frames, of the scene's size, not blank") {
  const std::string dir = std::string(SPH2D_TEST_TMP) + "/run_small";
  fs::remove_all(dir);
  const Result r = run("run \"" + asset("scenes/tests/small_dam_break.json") + "\" --frames 12 --threads 2 --out \"" +
                       dir + "\" --state-hash");
  INFO(r.out);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("sph2d: 12 frames") != std::string::npos);
  CHECK(r.out.find("state-hash: ") != std::string::npos);
  CHECK_FALSE(anyTemporary(dir));  // no temporary left behind
  CHECK(filesEnding(dir, ".png").size() == 12);
  CHECK(fs::exists(dir + "/manifest.json"));
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
    MESSAGE("frame " << f << ": water covers " << 100 * waterShare << " % of the image, " << colours.size()
                     << " colours");
    CHECK(waterShare > 0.03);
    CHECK(waterShare < 0.5);
    CHECK(colours.size() > 20);
  }
}

TEST_CASE("a scene with an unknown key exits 2 naming file, line and key") {
  const std::string path = freshDir("typo") + "/typo.json";
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
