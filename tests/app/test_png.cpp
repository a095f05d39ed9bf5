// PNG files through libpng: round trips at every level and input mode, the chunks and the zlib
// stream checked by zlib itself, and the size of the default level on a rendered frame.
#include <doctest/doctest.h>

#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "sph2d/render/png_io.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

using namespace sph2d;

namespace {

/// The concatenated IDAT payload of a PNG file (a zlib stream); checks every chunk's CRC.
std::vector<std::uint8_t> idatOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::vector<std::uint8_t> b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::uint8_t> idat;
  auto u32 = [&](std::size_t at) {
    return std::uint32_t(b[at]) << 24 | std::uint32_t(b[at + 1]) << 16 | std::uint32_t(b[at + 2]) << 8 | b[at + 3];
  };
  REQUIRE(b.size() > 8);
  for (std::size_t at = 8; at + 12 <= b.size();) {
    const std::uint32_t n = u32(at);
    REQUIRE(at + 12 + n <= b.size());
    CHECK(crc32(0L, b.data() + at + 4, uInt(4 + n)) == u32(at + 8 + n));
    if (std::equal(b.begin() + long(at) + 4, b.begin() + long(at) + 8, "IDAT"))
      idat.insert(idat.end(), b.begin() + long(at) + 8, b.begin() + long(at) + 8 + n);
    at += 12 + n;
  }
  return idat;
}

Frame image(int w, int h) {
  Frame f;
  f.width = w;
  f.height = h;
  f.rgba.assign(std::size_t(w) * std::size_t(h) * 4, 0);
  return f;
}

std::string tempDir() {
  const auto d = std::filesystem::temp_directory_path() / ("sph2d-png-test-" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d.string();
}

/// Writes `f` at `level` (or with `settings`), reads it back and checks the pixels (alpha is
/// 255 unless the file keeps it), every chunk's CRC and the zlib stream (zlib's own inflate,
/// which also checks the Adler-32). Returns the file's size.
std::uintmax_t roundTrip(const Frame& f, const std::string& path, int level, const PngSettings* settings,
                         const std::string& what) {
  if (settings) {
    std::vector<std::uint8_t> bytes;
    encodePng(f.width, f.height, f.rgba.data(), *settings, bytes);
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), long(bytes.size()));
  } else {
    writePngAtomic(path, f.width, f.height, f.rgba.data(), level);
  }
  const bool keepsAlpha = settings && settings->input == PngSettings::Input::Rgba;
  int w = 0, h = 0;
  std::vector<std::uint8_t> back;
  readPng(path, w, h, back);
  CHECK_MESSAGE(w == f.width, what);
  CHECK_MESSAGE(h == f.height, what);
  std::vector<std::uint8_t> want = f.rgba;
  if (!keepsAlpha)
    for (std::size_t k = 3; k < want.size(); k += 4) want[k] = 255;
  CHECK_MESSAGE(back == want, what);
  const std::vector<std::uint8_t> z = idatOf(path);
  const std::size_t channels = keepsAlpha ? 4 : 3;
  std::vector<std::uint8_t> raw(std::size_t(f.height) * (channels * std::size_t(f.width) + 1) + 1);
  uLongf rawLen = uLongf(raw.size());
  CHECK_MESSAGE(uncompress(raw.data(), &rawLen, z.data(), uLong(z.size())) == Z_OK, what);
  CHECK_MESSAGE(rawLen == raw.size() - 1, what);
  return std::filesystem::file_size(path);
}

}  // namespace

TEST_CASE("PNG files (libpng): pixels survive at every level and input mode, chunks and zlib stream check") {
  const std::string dir = tempDir();
  std::mt19937 rng(7);
  std::vector<std::pair<Frame, std::string>> images;
  Frame noise = image(333, 77);  // no runs, every byte value
  for (auto& b : noise.rgba) b = std::uint8_t(rng());
  images.emplace_back(noise, "noise");
  Frame flat = image(1000, 20);  // runs far longer than deflate's 258
  std::fill(flat.rgba.begin(), flat.rgba.end(), std::uint8_t(7));
  images.emplace_back(flat, "flat");
  Frame bands = image(257, 9);  // runs of every length 1..40 between changes
  for (std::size_t p = 0, run = 1, left = 1; p < bands.rgba.size(); ++p) {
    if (--left == 0) {
      run = run % 40 + 1;
      left = run;
    }
    bands.rgba[p] = std::uint8_t(run * 6);
  }
  images.emplace_back(bands, "bands");
  images.emplace_back(image(1, 1), "1x1");
  Frame skewed = image(640, 64);  // one dominant byte value: very uneven Huffman codes
  for (auto& b : skewed.rgba) b = rng() % 200 ? 0 : std::uint8_t(rng());
  images.emplace_back(skewed, "skewed");
  for (const auto& [f, name] : images)
    for (int level : {0, 1, 2, 6, 9})
      roundTrip(f, dir + "/f.png", level, nullptr, name + " at level " + std::to_string(level));
  // Every way of handing rows to libpng, and the other settings the measurements vary.
  using In = PngSettings::Input;
  for (In input : {In::Filler, In::PackedRgb, In::Rgba})
    for (bool whole : {false, true}) {
      PngSettings s = pngSettings(1);
      s.input = input;
      s.wholeImage = whole;
      s.memLevel = whole ? 9 : 4;
      s.bufferSize = whole ? (1 << 20) : 512;
      s.strategy = whole ? 3 : 1;  // Z_RLE, Z_FILTERED
      s.filters = whole ? 0x10 : 0xf8;
      const std::string what = "input mode " + std::to_string(int(input)) + (whole ? ", one call" : ", per row");
      roundTrip(noise, dir + "/s.png", 1, &s, "noise, " + what);
      roundTrip(bands, dir + "/s.png", 1, &s, "bands, " + what);
    }
  std::filesystem::remove_all(dir);
}

TEST_CASE("PNG level 1 on a rendered frame: within 1.5x the size of level 2 (SUB filter, run-length matching)") {
  SceneDef s;
  s.name = "block";
  s.solver.spacing = 0.02;
  BodyDef floor;
  ShapeDef box;
  box.type = ShapeDef::Type::Box;
  box.center = Vec2d(0.1, -0.05);
  box.halfSize = Vec2d(0.2, 0.05);
  floor.fixtures.push_back(box);
  s.bodies.push_back(floor);
  FluidBlockDef b;
  b.min = Vec2d(0, 0);
  b.max = Vec2d(0.2, 0.2);
  s.blocks.push_back(b);
  s.render.width = 480;
  s.render.height = 270;
  s.render.camera.automatic = false;
  s.render.camera.min = Vec2d(-0.1, -0.1);
  s.render.camera.max = Vec2d(0.3, 0.3);
  World world(s, WorldOptions{1});
  Renderer r(s.render);
  const Frame frame = r.render(world);
  const std::string dir = tempDir();
  const auto fast = roundTrip(frame, dir + "/l1.png", 1, nullptr, "rendered frame, level 1");
  const auto small = roundTrip(frame, dir + "/l2.png", 2, nullptr, "rendered frame, level 2");
  MESSAGE("rendered frame: " << fast << " bytes at level 1, " << small << " bytes at level 2");
  CHECK(double(fast) < 1.5 * double(small));
  std::filesystem::remove_all(dir);
}
