// PNG files through libpng: round trips at every level and input mode, the chunks and the zlib
// stream checked by zlib itself, the run coder of level 1 on the runs it looks for, and the
// size of the default level on a rendered frame.
#include <doctest/doctest.h>

#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <thread>
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
  PngSettings libdeflate = pngSettings(1);
  libdeflate.deflater = PngSettings::Deflater::Libdeflate;
  const auto before = roundTrip(frame, dir + "/ld.png", 1, &libdeflate, "rendered frame, libdeflate level 1");
  MESSAGE("rendered frame: " << fast << " bytes at level 1 (the run coder), " << small << " at level 2, " << before
                             << " with libdeflate's level 1");
  CHECK(double(fast) < 1.5 * double(small));
  CHECK(double(fast) < 1.15 * double(before));  // the run coder's speed does not cost size
  std::filesystem::remove_all(dir);
}

TEST_CASE("PNG run coder: every image decodes to its pixels, in one strip and in two") {
  // The run coder (level 1's) takes only runs of the pixel to the left and of the row above, so
  // its cases are the runs: none, every length, across the middle of a two-strip image, out of
  // deflate's window (a row longer than 32 KiB), and literals whose counts fall off so steeply that
  // unlimited Huffman codes would be longer than deflate's 15 bits.
  const std::string dir = tempDir();
  std::mt19937 rng(11);
  std::vector<std::pair<Frame, std::string>> images;
  for (auto [w, h] : {std::pair{1, 1}, {2, 1}, {1, 2}, {1, 700}, {3, 3}, {700, 1}})
    images.emplace_back(image(w, h), std::to_string(w) + "x" + std::to_string(h) + " black");
  Frame gradient = image(640, 480);  // two strips (≥ 256 KiB of rows); SUB turns ramps into runs
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x) {
      std::uint8_t* p = &gradient.rgba[(std::size_t(y) * 640 + std::size_t(x)) * 4];
      p[0] = std::uint8_t(x);
      p[1] = std::uint8_t(y / 3);
      p[2] = std::uint8_t(x + y);
      p[3] = std::uint8_t(x * 7);
    }
  images.emplace_back(gradient, "gradients");
  Frame blocks = image(600, 451);  // odd height, two strips, rectangles straddling the middle row
  for (int k = 0; k < 40; ++k) {
    const int x0 = int(rng() % 560), y0 = int(rng() % 400), x1 = x0 + 1 + int(rng() % 40),
              y1 = y0 + 1 + int(rng() % 50);
    const std::uint32_t colour = std::uint32_t(rng());
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) std::memcpy(&blocks.rgba[(std::size_t(y) * 600 + std::size_t(x)) * 4], &colour, 4);
  }
  for (int y = 220; y < 230; ++y)  // noise in the rows around the strips' boundary
    for (int x = 0; x < 600; x += 3) blocks.rgba[(std::size_t(y) * 600 + std::size_t(x)) * 4] = std::uint8_t(rng());
  images.emplace_back(blocks, "blocks");
  // Rows at deflate's window: 32,767 and 32,765 bytes (the longest distances, 10 to 13 extra
  // bits), then 32,770 and 32,769 (just past it: no match of the row above), each row repeated.
  for (auto [w, bpp] : {std::pair{10922, 3}, {8191, 4}, {10923, 3}, {8192, 4}}) {
    Frame f = image(w, 3);
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 4; ++c) f.rgba[std::size_t(x) * 4 + std::size_t(c)] = std::uint8_t(rng());
    for (int y = 1; y < 3; ++y)
      std::copy(f.rgba.begin(), f.rgba.begin() + 4 * w, f.rgba.begin() + std::ptrdiff_t(y) * 4 * w);
    images.emplace_back(f, std::to_string(w) + " wide, repeated rows (" + std::to_string(bpp) + " bytes a pixel)");
  }
  Frame low = image(65536, 2);  // two strips of one row each
  for (std::size_t p = 0; p < low.rgba.size(); ++p) low.rgba[p] = std::uint8_t(p % 4 == 0 ? rng() % 4 : p / 4096);
  images.emplace_back(low, "65536x2");
  Frame wide = image(11000, 3);  // a row of 33,001 bytes: no match reaches the row above
  for (std::size_t p = 0; p < wide.rgba.size(); ++p) wide.rgba[p] = std::uint8_t(p / 4000 * 37 + (p % 4 == 1));
  images.emplace_back(wide, "11000 wide");
  Frame steep = image(512, 600);  // filtered bytes of counts ∝ 2^-k, k up to 24
  for (int y = 0; y < 600; ++y) {
    std::uint8_t acc[4] = {0, 0, 0, 0};
    for (int x = 0; x < 512; ++x)
      for (int c = 0; c < 4; ++c) {
        int k = 0;
        while (k < 24 && (rng() & 1)) ++k;
        acc[c] = std::uint8_t(acc[c] + std::uint8_t(k * 11));
        steep.rgba[(std::size_t(y) * 512 + std::size_t(x)) * 4 + std::size_t(c)] = acc[c];
      }
  }
  images.emplace_back(steep, "steep counts");
  using In = PngSettings::Input;
  for (const auto& [f, name] : images)
    for (In input : {In::PackedRgb, In::Rgba}) {
      PngSettings s = pngSettings(1);
      REQUIRE(s.deflater == PngSettings::Deflater::Runs);
      s.input = input;
      const std::string what = name + (input == In::Rgba ? ", RGBA" : ", RGB");
      roundTrip(f, dir + "/r.png", 1, &s, what);
      // The same stream whichever thread codes it (the strips depend on the image alone).
      std::vector<std::uint8_t> here, there;
      encodePng(f.width, f.height, f.rgba.data(), s, here);
      std::thread([&] { encodePng(f.width, f.height, f.rgba.data(), s, there); }).join();
      CHECK_MESSAGE(here == there, what);
    }
  // A flat frame is a handful of bytes a row: the runs are found.
  std::vector<std::uint8_t> bytes;
  Frame flat = image(960, 540);
  std::fill(flat.rgba.begin(), flat.rgba.end(), std::uint8_t(90));
  encodePng(flat.width, flat.height, flat.rgba.data(), pngSettings(1), bytes);
  CHECK(bytes.size() < 960 * 540 * 3 / 300);
  // libdeflate, no level's coder now, still writes what it reads.
  PngSettings libdeflate = pngSettings(1);
  libdeflate.deflater = PngSettings::Deflater::Libdeflate;
  for (const auto& [f, name] : images) roundTrip(f, dir + "/l.png", 1, &libdeflate, name + ", libdeflate");
  std::filesystem::remove_all(dir);
}
