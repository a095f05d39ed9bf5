// app/examples/game.cpp, the embedding tutorial's program, builds and runs: its
// its crates float on the bucket's pool, and its frames exist, are whole and show water.
#include <doctest/doctest.h>

#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "app_util.hpp"
#include "sph2d/render/png_io.hpp"

using namespace sph2d::apptest;

#ifdef SPH2D_EXAMPLE_GAME_EXE
TEST_CASE("the example game runs, its crates float, and it writes non-blank frames") {
  const std::string dir = freshDir("example_game");
  const std::string log = dir + ".log";
  const int status =
      std::system((std::string("\"") + SPH2D_EXAMPLE_GAME_EXE + "\" " + q(dir) + " 150 > " + q(log) + " 2>&1").c_str());
  const std::string out = readText(log);
  INFO(out);
  REQUIRE(status == 0);
  // The bucket's pool (224 particles beside the paddle), 1 s of the hose (258: 266 a second, 90 %
  // on) and the toys' 100 (the sand heap, the jelly and the wooden ball).
  CHECK(out.find("t = 1.0 s: 582 particles") != std::string::npos);
  CHECK(out.find("150 frames in") != std::string::npos);
  CHECK(out.find(", 0 on the bumper, crates at ") != std::string::npos);  // no water reaches the bumper within 1 s
  // Both crates float in the bucket (x 3.05..4) from the first second to the last: resting on
  // its floor they would stand at 0.09 m; on the pool at rest (0.21 m) Archimedes puts them
  // at 0.23 and 0.18 m.
  std::size_t lines = 0;
  for (std::size_t at = out.find("crates at "); at != std::string::npos; at = out.find("crates at ", at + 1)) {
    double x[2] = {0, 0}, y[2] = {0, 0};
    REQUIRE(std::sscanf(out.c_str() + at, "crates at (%lf, %lf) m and (%lf, %lf) m", &x[0], &y[0], &x[1], &y[1]) == 4);
    for (int k = 0; k < 2; ++k) {
      CHECK(x[k] > 3.05);
      CHECK(x[k] < 4.0);
      CHECK(y[k] > 0.13);
      CHECK(y[k] < 1.0);
    }
    // The ball floats in the bucket between the player's throws.
    double jx = 0, jy = 0, bx = 0, by = 0;
    const std::size_t toys = out.find("jelly at ", at);
    REQUIRE(toys != std::string::npos);
    REQUIRE(std::sscanf(out.c_str() + toys, "jelly at (%lf, %lf) m, ball at (%lf, %lf) m", &jx, &jy, &bx, &by) == 4);
    CHECK(bx > 3.05);
    CHECK(bx < 4.0);
    CHECK(by > 0.1);
    ++lines;
  }
  CHECK(lines == 5);
  const auto pngs = filesEnding(dir, ".png");
  REQUIRE(pngs.size() == 150);
  CHECK(pngs.front() == "frame_00000.png");
  CHECK(pngs.back() == "frame_00149.png");
  CHECK_FALSE(anyTemporary(dir));
  int w = 0, h = 0;
  std::vector<std::uint8_t> rgba;
  sph2d::readPng(dir + "/frame_00149.png", w, h, rgba);
  CHECK(w == 320);
  CHECK(h == 240);
  std::size_t water = 0, solid = 0;
  std::set<std::uint32_t> colours;
  for (std::size_t p = 0; p < rgba.size(); p += 4) {
    if (rgba[p + 2] > rgba[p] + 60) ++water;
    if (rgba[p] > 120 && rgba[p] < 160 && rgba[p + 2] < rgba[p]) ++solid;  // the level's grey-brown
    colours.insert(std::uint32_t(rgba[p]) << 16 | std::uint32_t(rgba[p + 1]) << 8 | rgba[p + 2]);
  }
  MESSAGE("frame 149: water " << water << " px, solids " << solid << " px, " << colours.size() << " colours");
  CHECK(water > 300);
  CHECK(solid > 3000);
  CHECK(colours.size() > 50);
}
#endif
