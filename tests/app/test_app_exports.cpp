// sph2d run's exports: CSV and VTK particles and bodies, video, PNG level, sph2d render of an
// exported frame, and images written to a device.
#include <doctest/doctest.h>
#include <cstdio>

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>

#include <nlohmann/json.hpp>

#include "app_util.hpp"
#include "sph2d/render/particle_export.hpp"
#include "sph2d/render/png_io.hpp"

using namespace sph2d;
using namespace sph2d::apptest;
using nlohmann::json;

namespace {

const std::string kSmall = asset("scenes/tests/small_dam_break.json");

json readManifest(const std::string& dir) { return json::parse(readText(dir + "/manifest.json")); }

/// The rows of a bodies_NNNNN.csv (body, x, y, angle, vx, vy, omega), after its comment and header.
std::vector<std::vector<double>> bodyRows(const std::string& path) {
  std::vector<std::vector<double>> out;
  std::istringstream in(readText(path));
  std::string line;
  std::getline(in, line);  // the comment
  std::getline(in, line);
  CHECK(line == "body,x,y,angle,vx,vy,omega");
  while (std::getline(in, line)) {
    std::vector<double> r;
    std::istringstream cells(line);
    std::string c;
    while (std::getline(cells, c, ',')) r.push_back(std::stod(c));
    out.push_back(r);
  }
  return out;
}

}  // namespace

TEST_CASE("--export csv writes bodies_NNNNN.csv with each kinematic body's pose and velocity, in scene order") {
  const std::string dir = freshDir("export_bodies");
  REQUIRE(run("run " + q(asset("scenes/tests/kinematic_paddle.json")) +
              " --frames 31 --every 30 --quiet --export csv --out " + q(dir))
              .code == 0);
  CHECK(filesEnding(dir, ".csv") ==
        std::vector<std::string>{"bodies_00000.csv", "bodies_00030.csv", "frame_00000.csv", "frame_00030.csv"});
  // body, x, y, angle, vx, vy, omega per row; boundaries[1] the paddle, boundaries[2] the turning arm.
  const auto a = bodyRows(dir + "/bodies_00000.csv"), b = bodyRows(dir + "/bodies_00030.csv");
  REQUIRE(a.size() == 2);
  REQUIRE(b.size() == 2);
  CHECK(a[0][0] == 1);
  CHECK(a[1][0] == 2);
  CHECK(b[0][1] == doctest::Approx(0.5 + 1.0 * 0.5).epsilon(1e-4));  // x = x0 + v t after 30 frames
  CHECK(b[0][4] == doctest::Approx(1.0));
  CHECK(b[1][3] == doctest::Approx(2.0 * 0.5).epsilon(1e-4));  // angle = ω t
  CHECK(b[1][6] == doctest::Approx(2.0));
}

TEST_CASE("--export csv writes the dynamic crates of floating_crates.json too, each row's velocity that of its x, y") {
  // Every frame kept: a row's (vx, vy) is the velocity of the point (x, y) (the body origin),
  // so it matches the origin's move over the frame (Box2D moves a body by its new velocity:
  // x(n+1) = x(n) + dt v(n+1), the rotation's part included up to its second order). Not on a
  // frame where Box2D's position correction separates two bodies in contact (a crate against
  // the turning bar: 3 of 195 rows here, up to 0.5 m/s), so the rows are counted, frame by frame.
  const std::string dir = freshDir("export_crates");
  REQUIRE(run("run " + q(asset("scenes/floating_crates.json")) + " --frames 40 --quiet --export csv --out " + q(dir))
              .code == 0);
  const double dt = 1.0 / 60;
  int rows = 0, matching = 0, moving = 0;
  for (int f = 1; f < 40; ++f) {
    char name[64];
    std::snprintf(name, sizeof name, "/bodies_%05d.csv", f - 1);
    const auto a = bodyRows(dir + name);
    std::snprintf(name, sizeof name, "/bodies_%05d.csv", f);
    const auto b = bodyRows(dir + name);
    REQUIRE(a.size() == 5);  // the turning bar and four crates, boundaries[1..5]
    REQUIRE(b.size() == 5);
    for (std::size_t k = 0; k < b.size(); ++k) {
      CHECK(b[k][0] == double(k + 1));
      const double vx = (b[k][1] - a[k][1]) / dt, vy = (b[k][2] - a[k][2]) / dt;
      ++rows;
      matching += std::abs(vx - b[k][4]) < 0.01 + 0.02 * std::abs(b[k][4]) &&
                  std::abs(vy - b[k][5]) < 0.01 + 0.02 * std::abs(b[k][5]);
      moving += std::abs(b[k][4]) + std::abs(b[k][5]) > 0.01;
    }
  }
  MESSAGE(matching << " of " << rows << " rows match the origin's move, " << moving << " moving");
  CHECK(matching >= rows * 9 / 10);
  CHECK(moving >= rows / 2);  // most bodies are moving
}

TEST_CASE("--export csv and vtk write each kept frame's particles in id order, world coordinates") {
  const std::string dir = freshDir("export_csv"), vdir = freshDir("export_vtk"), adir = freshDir("export_vtka");
  REQUIRE(run("run " + q(kSmall) + " --frames 5 --every 4 --quiet --export csv --out " + q(dir)).code == 0);
  CHECK(filesEnding(dir, ".csv") == std::vector<std::string>{"frame_00000.csv", "frame_00004.csv"});
  const ParticleSnapshot s = readParticlesCsv(dir + "/frame_00004.csv");
  REQUIRE(s.size() == 1250);
  CHECK(s.frame == 4);
  CHECK(s.time == doctest::Approx(4.0 / 60.0));
  for (std::size_t k = 0; k < s.size(); ++k) CHECK(s.id[k] == k);
  // The column stands in 0 < x < 1, 0 < y < 2 (plus what moved in 4 frames).
  const auto [xlo, xhi] = std::minmax_element(s.x.begin(), s.x.end());
  CHECK(*xlo > 0.0);
  CHECK(*xhi < 1.1);
  CHECK(*std::max_element(s.rho.begin(), s.rho.end()) > 900.0f);

  REQUIRE(run("run " + q(kSmall) + " --frames 1 --quiet --export vtk --out " + q(vdir)).code == 0);
  REQUIRE(run("run " + q(kSmall) + " --frames 1 --quiet --export vtk-ascii --out " + q(adir)).code == 0);
  const std::string bin = readText(vdir + "/frame_00000.vtk"), asc = readText(adir + "/frame_00000.vtk");
  const std::size_t n = 1250;
  for (const std::string* t : {&bin, &asc}) {
    CHECK(t->rfind("# vtk DataFile Version 3.0\n", 0) == 0);
    CHECK(t->find("DATASET POLYDATA\nPOINTS 1250 double\n") != std::string::npos);
    CHECK(t->find("VERTICES 1250 2500\n") != std::string::npos);
    CHECK(t->find("POINT_DATA 1250\nSCALARS id int 1\nLOOKUP_TABLE default\n") != std::string::npos);
    CHECK(t->find("VECTORS velocity float\n") != std::string::npos);
    CHECK(t->find("SCALARS density float 1\n") != std::string::npos);
    CHECK(t->find("SCALARS pressure float 1\n") != std::string::npos);
  }
  CHECK(bin.find("BINARY\n") != std::string::npos);
  CHECK(asc.find("ASCII\n") != std::string::npos);
  // Binary payload: points 24 B, vertices 8 B, id 4 B, velocity 12 B, density 4 B, pressure 4 B per particle.
  const std::size_t headers = bin.find("POINTS");
  CHECK(bin.size() > n * (24 + 8 + 4 + 12 + 4 + 4) + headers);
  CHECK(bin.size() < n * (24 + 8 + 4 + 12 + 4 + 4) + headers + 400);
  // The first point is big-endian x of particle 0, equal to the CSV's.
  const std::size_t p0 = bin.find("POINTS 1250 double\n") + std::strlen("POINTS 1250 double\n");
  unsigned char be[8];
  for (int k = 0; k < 8; ++k) be[k] = static_cast<unsigned char>(bin[p0 + 7 - std::size_t(k)]);
  double x0 = 0;
  std::memcpy(&x0, be, 8);
  const ParticleSnapshot s0 = readParticlesCsv(dir + "/frame_00000.csv");
  CHECK(x0 == s0.x[0]);
}

TEST_CASE("--export csv and vtk write each particle's material when the scene has more than one") {
  const std::string scene = asset("scenes/tests/two_materials.json");
  const std::string dir = freshDir("export_materials_csv"), vdir = freshDir("export_materials_vtk");
  REQUIRE(run("run " + q(scene) + " --frames 20 --every 19 --quiet --export csv --out " + q(dir)).code == 0);
  CHECK(readText(dir + "/frame_00019.csv").find("id,x,y,vx,vy,density,pressure,material\n") != std::string::npos);
  const ParticleSnapshot s = readParticlesCsv(dir + "/frame_00019.csv");
  REQUIRE(s.material.size() == s.size());
  // The blocks: ids 0-624 water (0) below y = 1, 625-1249 dye (1) above; then the emitter's and
  // the timeline drop's particles, all dye.
  std::size_t dye = 0;
  for (std::size_t k = 0; k < s.size(); ++k) {
    CHECK(s.material[k] == (s.id[k] < 625 ? 0u : 1u));
    dye += s.material[k] == 1;
  }
  CHECK(s.size() > 1250 + 50);
  CHECK(dye == s.size() - 625);
  // `sph2d render` reads the column back: the dye drawn in its colour (0.85, 0.20, 0.25).
  const std::string png = dir + "/redrawn.png";
  REQUIRE(run("render " + q(scene) + " --particles " + q(dir + "/frame_00019.csv") + " --out " + q(png) +
              " --mode particles --color-by material")
              .code == 0);
  int w = 0, h = 0;
  std::vector<std::uint8_t> rgba;
  readPng(png, w, h, rgba);
  std::size_t red = 0;
  for (std::size_t k = 0; k + 3 < rgba.size(); k += 4) red += rgba[k] > 150 && rgba[k + 1] < 90 && rgba[k + 2] < 110;
  CHECK(red > 100);
  REQUIRE(run("run " + q(scene) + " --frames 1 --quiet --export vtk-ascii --out " + q(vdir)).code == 0);
  const std::string vtk = readText(vdir + "/frame_00000.vtk");
  const std::size_t at = vtk.find("SCALARS material int 1\nLOOKUP_TABLE default\n0\n");
  CHECK(at != std::string::npos);
  // A scene of one fluid writes no material column.
  const std::string one = freshDir("export_one_material");
  REQUIRE(run("run " + q(kSmall) + " --frames 1 --quiet --export csv --out " + q(one)).code == 0);
  CHECK(readText(one + "/frame_00000.csv").find("material") == std::string::npos);
}

TEST_CASE("--video: exit 2 with a message without ffmpeg, and frames reach ffmpeg's input when present") {
  const std::string dir = freshDir("video");
  Result r = run("run " + q(kSmall) + " --frames 3 --quiet --video " + q(dir + "/out.mp4") + " --out " + q(dir),
                 "PATH=" + dir + "/nothing-here");
  INFO(r.out);
  CHECK(r.code == 2);
  CHECK(r.out.find("--video needs ffmpeg, which is not installed") != std::string::npos);
  // A stand-in ffmpeg that stores its standard input in its last argument.
  const std::string bin = freshDir("fakebin");
  {
    std::ofstream f(bin + "/ffmpeg");
    f << "#!/bin/sh\nfor a in \"$@\"; do out=\"$a\"; done\ncat > \"$out\"\n";
  }
  ::chmod((bin + "/ffmpeg").c_str(), 0755);
  r = run("run " + q(kSmall) + " --frames 5 --every 2 --quiet --video " + q(dir + "/out.raw") + " --out " + q(dir),
          "PATH=" + bin + ":/usr/bin:/bin");
  INFO(r.out);
  CHECK(r.code == 0);
  CHECK(r.out.find("3 frames encoded into") != std::string::npos);
  CHECK(fs::file_size(dir + "/out.raw") == 3u * 192u * 144u * 4u);
}

TEST_CASE("--png-level changes the file size, never the pixels, and bad render flags exit 2") {
  const std::string a = freshDir("lvl0"), b = freshDir("lvl9");
  REQUIRE(run("run " + q(kSmall) + " --frames 1 --quiet --png-level 0 --out " + q(a)).code == 0);
  REQUIRE(run("run " + q(kSmall) + " --frames 1 --quiet --png-level 9 --out " + q(b)).code == 0);
  CHECK(fs::file_size(a + "/frame_00000.png") > 2 * fs::file_size(b + "/frame_00000.png"));
  CHECK(pngHash(a + "/frame_00000.png") == pngHash(b + "/frame_00000.png"));
  CHECK(readManifest(a)["frames"][0]["rgba_xxh64"] == readManifest(b)["frames"][0]["rgba_xxh64"]);
  CHECK(run("run " + q(kSmall) + " --png-level 10").code == 2);
  CHECK(run("run " + q(kSmall) + " --mode smoke").code == 2);
  CHECK(run("run " + q(kSmall) + " --color-by vorticity").code == 2);
  const Result age = run("run " + q(kSmall) + " --frames 1 --mode particles --color-by age --out " + q(a));
  CHECK(age.code == 2);
  CHECK(age.out.find("needs particle ages") != std::string::npos);
  CHECK(run("run " + q(kSmall) + " --range 5,1").code == 2);
}

TEST_CASE("sph2d render redraws an exported CSV frame bit-identically to the run's frame") {
  const std::string dir = freshDir("rerender");
  REQUIRE(run("run " + q(kSmall) + " --frames 11 --every 10 --quiet --export csv --out " + q(dir)).code == 0);
  const Result r =
      run("render " + q(kSmall) + " --particles " + q(dir + "/frame_00010.csv") + " --out " + q(dir + "/again.png"));
  INFO(r.out);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("1250 particles of frame 10") != std::string::npos);
  CHECK(pngHash(dir + "/again.png") == readManifest(dir)["frames"][1]["rgba_xxh64"].get<std::string>());
  // Another mode from the same file: a different image of the same size.
  REQUIRE(run("render " + q(kSmall) + " --particles " + q(dir + "/frame_00010.csv") + " --out " +
              q(dir + "/discs.png") + " --mode particles --color-by density")
              .code == 0);
  CHECK(pngHash(dir + "/discs.png") != pngHash(dir + "/again.png"));
}

TEST_CASE("sph2d render redraws grains and particle groups from a CSV as the run drew them") {
  // The sandbox with its jelly in a colour of its own: the CSV carries each particle's material,
  // own colour and group, and the frame drawn from it has the run's pixels. (Without its crate:
  // a redraw shows the scene's bodies where the scene puts them, not where they moved.)
  const std::string dir = freshDir("rerender_groups");
  json scene = json::parse(readText(asset("scenes/sandbox.json")));
  scene["groups"][0]["color"] = {0.9, 0.3, 0.5};
  json statics = json::array();
  for (const json& b : scene["boundaries"])
    if (b.value("type", "static") == "static") statics.push_back(b);
  scene["boundaries"] = statics;
  const std::string path = dir + "/sandbox_pink.json";
  std::ofstream(path) << scene.dump(1);
  REQUIRE(run("run " + q(path) + " --frames 61 --every 60 --quiet --export csv --out " + q(dir + "/out")).code == 0);
  const std::string csv = readText(dir + "/out/frame_00060.csv");
  CHECK(csv.find(",material,color,group\n") != std::string::npos);
  const Result r =
      run("render " + q(path) + " --particles " + q(dir + "/out/frame_00060.csv") + " --out " + q(dir + "/again.png"));
  INFO(r.out);
  REQUIRE(r.code == 0);
  CHECK(pngHash(dir + "/again.png") == readManifest(dir + "/out")["frames"][1]["rgba_xxh64"].get<std::string>());
}

TEST_CASE("sph2d render refuses a CSV with a NaN or infinite value, naming the line and the column") {
  // Before (issue 18): NaN and infinite positions were accepted and a picture was written.
  const std::string dir = freshDir("rerender_nan");
  REQUIRE(run("run " + q(kSmall) + " --frames 1 --quiet --export csv --out " + q(dir)).code == 0);
  const std::string text = readText(dir + "/frame_00000.csv");
  // Line 4 is the second particle: replace one value at a time.
  const auto lineStart = [&](int n) {
    std::size_t at = 0;
    for (int k = 1; k < n; ++k) at = text.find('\n', at) + 1;
    return at;
  };
  struct Bad {
    int column;  // 1 = x, 2 = y, 4 = vy
    const char* value;
    const char* name;
  };
  for (const Bad b :
       {Bad{1, "nan", "x"}, Bad{2, "inf", "y"}, Bad{4, "-inf", "vy"}, Bad{1, "1e999", "x"}, Bad{4, "1e300", "vy"}}) {
    std::string t = text;
    std::size_t at = lineStart(4);
    for (int c = 0; c < b.column; ++c) at = t.find(',', at) + 1;
    t.replace(at, t.find_first_of(",\n", at) - at, b.value);
    const std::string bad = dir + "/bad.csv", png = dir + "/bad.png";
    std::ofstream(bad) << t;
    const Result r = run("render " + q(kSmall) + " --particles " + q(bad) + " --out " + q(png));
    INFO(b.value, " ", r.out);
    CHECK(r.code == 2);
    CHECK(r.out.find(bad + ":4: column " + b.name + " is ") != std::string::npos);
    CHECK(r.out.find("every value must be a finite number") != std::string::npos);
    CHECK_FALSE(fs::exists(png));
  }
}

TEST_CASE(
    "an image written to a device is written in place: /dev/full says No space left on device and stays a device") {
  // Before: the atomic writer renamed its temporary file over the target, so as root
  // `--out /dev/full` replaced the device node with a PNG file and reported success.
  if (!fs::exists("/dev/full") || !fs::is_character_file("/dev/full")) return;
  const std::string dir = freshDir("render_device");
  REQUIRE(run("run " + q(kSmall) + " --frames 1 --quiet --export csv --out " + q(dir)).code == 0);
  const Result r = run("render " + q(kSmall) + " --particles " + q(dir + "/frame_00000.csv") + " --out /dev/full");
  INFO(r.out);
  CHECK(r.code == 1);
  CHECK(r.out.find("cannot write /dev/full: No space left on device") != std::string::npos);
  CHECK(fs::is_character_file("/dev/full"));
}

TEST_CASE("--export surface writes each kept frame's outlines as JSON and SVG, listed in the manifest") {
  // The small dam break (1250 particles, spacing 0.04 m): at frame 0 a resting column, one
  // curve of the water's area; at frame 30 the surge, whose curves hold the same area within
  // a few percent (spray makes none).
  const std::string dir = freshDir("export_surface");
  const Result r = run("run " + q(kSmall) + " --frames 31 --every 30 --export surface --out " + q(dir));
  REQUIRE(r.code == 0);
  CHECK(r.out.find("2 surface outlines (json and svg)") != std::string::npos);
  CHECK(filesEnding(dir, ".json") == std::vector<std::string>{"frame_00000.json", "frame_00030.json", "manifest.json"});
  CHECK(filesEnding(dir, ".svg") == std::vector<std::string>{"frame_00000.svg", "frame_00030.svg"});
  const double water = 1250 * 0.04 * 0.04;
  for (const int frame : {0, 30}) {
    CAPTURE(frame);
    const std::string name = frame ? "frame_00030" : "frame_00000";
    const json s = json::parse(readText(dir + "/" + name + ".json"));
    CHECK(s.at("format") == "sph2d-surface");
    CHECK(s.at("frame") == frame);
    double area = 0;
    for (const json& c : s.at("curves")) {
      area += c.at("area").get<double>();
      CHECK(c.at("points").size() >= 4);
      CHECK(c.at("points").front() != c.at("points").back());  // closed without repeating its first point
    }
    if (frame == 0) CHECK(s.at("curves").size() == 1);
    CHECK(std::fabs(area / water - 1) < 0.05);
    const std::string svg = readText(dir + "/" + name + ".svg");
    CHECK(svg.rfind("<svg ", 0) == 0);
    CHECK(svg.find("fill-rule=\"evenodd\"") != std::string::npos);
  }
  const json m = readManifest(dir);
  std::vector<std::string> listed;
  for (const json& f : m.at("files")) listed.push_back(f.at("file").get<std::string>());
  for (const char* f : {"frame_00000.json", "frame_00000.svg", "frame_00030.json", "frame_00030.svg"})
    CHECK(std::find(listed.begin(), listed.end(), f) != listed.end());
  CHECK(run("run " + q(kSmall) + " --frames 1 --export outline --out " + q(dir + "_bad")).code == 2);
}

TEST_CASE("a headless run that steps ahead of its drawing writes the frames and exports of one that does not") {
  // With standard input open for live events the loop steps one frame while it draws the last;
  // without it, the stepping runs up to GameLoop::kAheadFrames kept frames ahead of the
  // drawing. The frames, both hashes and each frame's export (taken at its boundary, drawn
  // and written frames later) must be the same.
  const std::string a = freshDir("ahead_interleaved"), b = freshDir("ahead_runs_ahead");
  const std::string args = " --frames 40 --every 3 --export csv --state-hash --quiet";
  // The pipe stays open (and empty) while the loop starts (the run then reads it to its end).
  const Result ra = run("run " + q(kSmall) + args + " --input - --out " + q(a), "sleep 4 | ");
  INFO(ra.out);
  REQUIRE(ra.code == 0);
  CHECK(ra.out.find("ran up to") == std::string::npos);  // interleaved
  const Result rb = run("run " + q(kSmall) + args + " --threads 1 --out " + q(b));
  INFO(rb.out);
  REQUIRE(rb.code == 0);
  CHECK(rb.out.find("the simulation ran up to ") != std::string::npos);  // stepped ahead
  const json ma = readManifest(a), mb = readManifest(b);
  REQUIRE(ma.at("frames").size() == 14);
  REQUIRE(mb.at("frames").size() == 14);
  for (std::size_t k = 0; k < 14; ++k) {
    CHECK(ma["frames"][k].at("rgba_xxh64") == mb["frames"][k].at("rgba_xxh64"));
    CHECK(ma["frames"][k].at("state_hash") == mb["frames"][k].at("state_hash"));
    char name[32];
    std::snprintf(name, sizeof name, "/frame_%05d.csv", int(3 * k));
    CHECK(readText(b + name) == readText(a + name));
    CHECK(readParticlesCsv(b + name).frame == int(3 * k));
  }
  CHECK(filesEnding(b, ".csv").size() == 14);
}
