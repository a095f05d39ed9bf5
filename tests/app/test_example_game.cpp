// app/examples/game.cpp, the embedding tutorial's program, builds and runs: its
// frames exist, are whole and show water.
#include <doctest/doctest.h>

#include <set>
#include <string>
#include <vector>

#include "app_util.hpp"
#include "sph2d/render/png_io.hpp"

using namespace sph2d::apptest;

#ifdef SPH2D_EXAMPLE_GAME_EXE
TEST_CASE("the example game runs and writes non-blank frames") {
  const std::string dir = freshDir("example_game");
  const std::string log = dir + ".log";
  const int status = std::system((std::string("\"") + SPH2D_EXAMPLE_GAME_EXE + "\" " + q(dir) + " 30 > " + q(log) + " 2>&1").c_str());
  const std::string out = readText(log);
  INFO(out);
  REQUIRE(status == 0);
  CHECK(out.find("t = 1.0 s: 258 particles") != std::string::npos);  // 30 frames of the hose at 2400 particles/s, 90 % on
  CHECK(out.find("30 frames in") != std::string::npos);
  CHECK(out.find(", 0 on the bumper, the crate at ") != std::string::npos);  // no water reaches the bumper within 1 s
  const auto pngs = filesEnding(dir, ".png");
  REQUIRE(pngs.size() == 30);
  CHECK(pngs.front() == "frame_00000.png");
  CHECK(pngs.back() == "frame_00029.png");
  CHECK_FALSE(anyTemporary(dir));
  int w = 0, h = 0;
  std::vector<std::uint8_t> rgba;
  sph2d::readPng(dir + "/frame_00029.png", w, h, rgba);
  CHECK(w == 320);
  CHECK(h == 240);
  std::size_t water = 0, solid = 0;
  std::set<std::uint32_t> colours;
  for (std::size_t p = 0; p < rgba.size(); p += 4) {
    if (rgba[p + 2] > rgba[p] + 60) ++water;
    if (rgba[p] > 120 && rgba[p] < 160 && rgba[p + 2] < rgba[p]) ++solid;  // the level's grey-brown
    colours.insert(std::uint32_t(rgba[p]) << 16 | std::uint32_t(rgba[p + 1]) << 8 | rgba[p + 2]);
  }
  MESSAGE("frame 29: water " << water << " px, solids " << solid << " px, " << colours.size() << " colours");
  CHECK(water > 300);
  CHECK(solid > 3000);
  CHECK(colours.size() > 50);
}
#endif
