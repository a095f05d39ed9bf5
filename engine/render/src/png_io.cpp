// png_io.cpp — PNG files through libpng: encoded in memory with the settings of their level,
// written to a temporary name and renamed.
#include "sph2d/render/png_io.hpp"

#include "file_io.hpp"
#include "png_runs.hpp"
#include "sph2d/render/particle_export.hpp"

#include <libdeflate.h>
#include <png.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace sph2d {
namespace {

// libpng reports errors by longjmp; these helpers keep C++ objects out of the
// functions that call setjmp.

/// libpng's write callback: appends to the std::vector<std::uint8_t> behind the io pointer.
void appendBytes(png_structp png, png_bytep data, png_size_t n) {
  auto* out = static_cast<std::vector<std::uint8_t>*>(png_get_io_ptr(png));
  bool ok = true;
  try {
    out->insert(out->end(), data, data + n);
  } catch (...) {
    ok = false;
  }
  if (!ok) png_error(png, "out of memory");
}

void flushNothing(png_structp) {}

/// Encodes with `s` into `out`; `rows` points at each row libpng is given (RGBA, or packed RGB
/// with Input::PackedRgb).
bool encodeRaw(std::vector<std::uint8_t>* out, int width, int height, png_bytepp rows, const PngSettings& s, char* err,
               std::size_t errLen) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (!png) {
    std::snprintf(err, errLen, "png_create_write_struct failed");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::snprintf(err, errLen, "libpng could not encode the image");
    return false;
  }
  png_set_write_fn(png, out, appendBytes, flushNothing);
  png_set_compression_level(png, s.level);
  png_set_compression_strategy(png, s.strategy);
  png_set_compression_mem_level(png, s.memLevel);
  png_set_compression_window_bits(png, s.windowBits);
  png_set_compression_buffer_size(png, png_size_t(s.bufferSize));
  png_set_filter(png, 0, s.filters);
  const bool rgba = s.input == PngSettings::Input::Rgba;
  const int colorType = rgba ? PNG_COLOR_TYPE_RGB_ALPHA : PNG_COLOR_TYPE_RGB;
  png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), 8, colorType, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (s.input == PngSettings::Input::Filler) png_set_filler(png, 0, PNG_FILLER_AFTER);  // rows are RGBA; drop A
  if (s.wholeImage) {
    png_write_image(png, rows);
  } else {
    for (int y = 0; y < height; ++y) png_write_row(png, rows[y]);
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

bool readRaw(FILE* f, int* width, int* height, std::uint8_t** out, char* err, std::size_t errLen) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  std::uint8_t* volatile buffer = nullptr;
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    std::free(buffer);
    std::snprintf(err, errLen, "not a readable PNG");
    return false;
  }
  png_init_io(png, f);
  png_read_info(png, info);
  png_set_expand(png);
  png_set_strip_16(png);
  png_set_gray_to_rgb(png);
  png_set_filler(png, 0xff, PNG_FILLER_AFTER);
  png_read_update_info(png, info);
  const int w = int(png_get_image_width(png, info)), h = int(png_get_image_height(png, info));
  buffer = static_cast<std::uint8_t*>(std::malloc(std::size_t(w) * std::size_t(h) * 4));
  for (int y = 0; y < h; ++y) png_read_row(png, buffer + std::size_t(y) * std::size_t(w) * 4, nullptr);
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  *width = w;
  *height = h;
  *out = buffer;
  return true;
}

/// Test hook: with SPH2D_TEST_FAIL_WRITE_AFTER=N in the environment, the
/// first N writes of the process succeed and every later one fails as a full
/// disk would (after its temporary file was written). Tests use it to check
/// that a failing writer stops the run, names the file and leaves whole PNGs.
bool injectedWriteFailure() {
  static const long long failAfter = [] {
    const char* e = std::getenv("SPH2D_TEST_FAIL_WRITE_AFTER");
    return e && *e ? std::atoll(e) : -1LL;
  }();
  static std::atomic<long long> writes{0};
  return failAfter >= 0 && writes.fetch_add(1) >= failAfter;
}

}  // namespace

PngSettings pngSettings(int level) {
  PngSettings s;
  s.level = level;
  if (level == 0) {  // stored: no filter, no compression
    s.strategy = Z_DEFAULT_STRATEGY;
    s.filters = PNG_FILTER_NONE;
  } else if (level == 2) {  // the SUB filter and run-length matching: smaller files than level 1
    s.strategy = Z_RLE;
    s.filters = PNG_FILTER_SUB;
  } else if (level >= 3) {  // zlib's level, libpng choosing each row's filter
    s.strategy = Z_DEFAULT_STRATEGY;
    s.filters = PNG_ALL_FILTERS;
  } else {  // 1: the fastest measured on the dam break's frames (docs/RENDERING.md "PNG settings")
    s.strategy = Z_DEFAULT_STRATEGY;
    s.filters = PNG_FILTER_SUB;
    s.deflater = PngSettings::Deflater::Runs;
  }
  return s;
}

namespace {

/// Appends a PNG chunk: length, type, data, CRC-32 of type and data.
void putChunk(std::vector<std::uint8_t>& out, const char type[4], const std::uint8_t* data, std::size_t n) {
  auto be32 = [&](std::uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) out.push_back(std::uint8_t(v >> s));
  };
  be32(std::uint32_t(n));
  const std::size_t at = out.size();
  out.insert(out.end(), type, type + 4);
  if (n) out.insert(out.end(), data, data + n);
  be32(libdeflate_crc32(0, out.data() + at, n + 4));
}

/// A PNG of one IDAT chunk holding the zlib stream `z` (n bytes) into `out` (replaced).
void putPng(int width, int height, bool keepAlpha, const std::uint8_t* z, std::size_t n,
            std::vector<std::uint8_t>& out) {
  out.clear();
  out.reserve(n + 64);
  static const std::uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  out.insert(out.end(), signature, signature + 8);
  std::uint8_t ihdr[13];
  for (int k = 0; k < 4; ++k) {
    ihdr[k] = std::uint8_t(std::uint32_t(width) >> (24 - 8 * k));
    ihdr[4 + k] = std::uint8_t(std::uint32_t(height) >> (24 - 8 * k));
  }
  ihdr[8] = 8;                         // bit depth
  ihdr[9] = keepAlpha ? 6 : 2;         // RGBA or RGB
  ihdr[10] = ihdr[11] = ihdr[12] = 0;  // deflate, adaptive filtering, no interlace
  putChunk(out, "IHDR", ihdr, sizeof ihdr);
  putChunk(out, "IDAT", z, n);
  putChunk(out, "IEND", nullptr, 0);
}

/// encodePng with the run coder (png_runs.hpp).
void encodeRuns(int width, int height, const std::uint8_t* rgba, const PngSettings& s, std::vector<std::uint8_t>& out) {
  const bool keepAlpha = s.input == PngSettings::Input::Rgba;
  thread_local std::vector<std::uint8_t> z;
  deflateRunsPng(width, height, rgba, keepAlpha ? 4 : 3, z);
  putPng(width, height, keepAlpha, z.data(), z.size(), out);
}

/// encodePng with libdeflate: filter NONE, RGB (or RGBA with Input::Rgba) rows behind their
/// filter byte, one zlib stream in one IDAT chunk.
void encodeLibdeflate(int width, int height, const std::uint8_t* rgba, const PngSettings& s,
                      std::vector<std::uint8_t>& out) {
  const bool keepAlpha = s.input == PngSettings::Input::Rgba;
  const std::size_t w = std::size_t(width), h = std::size_t(height), bpp = keepAlpha ? 4 : 3, stride = 1 + w * bpp;
  thread_local std::vector<std::uint8_t> raw, z;
  raw.resize(stride * h + 1);  // a spare byte: each pixel copies four
  for (std::size_t y = 0; y < h; ++y) {
    std::uint8_t* row = &raw[y * stride];
    row[0] = 0;  // filter NONE
    const std::uint8_t* src = rgba + y * w * 4;
    if (keepAlpha)
      std::memcpy(row + 1, src, w * 4);
    else
      for (std::size_t x = 0; x < w; ++x) std::memcpy(row + 1 + 3 * x, src + 4 * x, 4);
  }
  // One compressor per thread and level (allocating one costs more than a frame).
  struct Compressor {
    int level = -1;
    libdeflate_compressor* c = nullptr;
    ~Compressor() { libdeflate_free_compressor(c); }
  };
  thread_local Compressor comp;
  const int level = std::clamp(s.level, 0, 12);
  if (comp.level != level) {
    libdeflate_free_compressor(comp.c);
    comp.c = libdeflate_alloc_compressor(level);
    comp.level = comp.c ? level : -1;
    if (!comp.c) throw std::runtime_error("libdeflate could not allocate a compressor");
  }
  const std::size_t n = stride * h;
  z.resize(libdeflate_zlib_compress_bound(comp.c, n));
  const std::size_t zn = libdeflate_zlib_compress(comp.c, raw.data(), n, z.data(), z.size());
  if (zn == 0) throw std::runtime_error("libdeflate could not compress the image");
  putPng(width, height, keepAlpha, z.data(), zn, out);
}

}  // namespace

void encodePng(int width, int height, const std::uint8_t* rgba, const PngSettings& settings,
               std::vector<std::uint8_t>& out) {
  if (width <= 0 || height <= 0) throw std::runtime_error("encodePng: empty image");
  if (settings.deflater == PngSettings::Deflater::Libdeflate)
    return encodeLibdeflate(width, height, rgba, settings, out);
  if (settings.deflater == PngSettings::Deflater::Runs) return encodeRuns(width, height, rgba, settings, out);
  const std::size_t w = std::size_t(width), h = std::size_t(height);
  thread_local std::vector<std::uint8_t> packed;
  thread_local std::vector<png_bytep> rows;
  rows.resize(h);
  if (settings.input == PngSettings::Input::PackedRgb) {
    packed.resize(w * h * 3);
    // Four bytes copied per pixel, the fourth overwritten by the next pixel (one spare byte).
    packed.resize(w * h * 3 + 1);
    for (std::size_t p = 0; p < w * h; ++p) std::memcpy(&packed[3 * p], &rgba[4 * p], 4);
    for (std::size_t y = 0; y < h; ++y) rows[y] = packed.data() + y * w * 3;
  } else {
    for (std::size_t y = 0; y < h; ++y) rows[y] = const_cast<png_bytep>(rgba + y * w * 4);
  }
  out.clear();
  char err[256] = {0};
  if (!encodeRaw(&out, width, height, rows.data(), settings, err, sizeof err)) throw std::runtime_error(err);
}

void writePngAtomic(const std::string& path, int width, int height, const std::uint8_t* rgba, int level) {
  thread_local std::vector<std::uint8_t> bytes;
  try {
    encodePng(width, height, rgba, pngSettings(level), bytes);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot write " + path + ": " + e.what());
  }
  writeEncodedPngAtomic(path, bytes);
}

void writeEncodedPngAtomic(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  if (isSpecialFile(path))
    return writeInPlace(path, bytes.data(), bytes.size());  // a device, a FIFO: no rename over it
  const std::string tmp = tempPathFor(path);
  FILE* f = createTempFile(tmp);
  char err[256] = {0};
  bool ok = true;
  if (std::fwrite(bytes.data(), 1, bytes.size(), f) != bytes.size()) {
    std::snprintf(err, sizeof err, "%s", std::strerror(errno));
    ok = false;
  }
  if (std::fflush(f) != 0 || std::ferror(f)) {
    if (ok) std::snprintf(err, sizeof err, "%s", std::strerror(errno));
    ok = false;
  }
  if (ok && injectedWriteFailure()) {
    std::snprintf(err, sizeof err, "%s (injected by SPH2D_TEST_FAIL_WRITE_AFTER)", std::strerror(ENOSPC));
    ok = false;
  }
  if (std::fclose(f) != 0 && ok) {
    std::snprintf(err, sizeof err, "%s", std::strerror(errno));
    ok = false;
  }
  if (!ok) {
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot write " + path + ": " + err);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot rename " + tmp + " to " + path + ": " + why);
  }
}

void readPng(const std::string& path, int& width, int& height, std::vector<std::uint8_t>& rgba) {
  FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw std::runtime_error("cannot open " + path + ": " + std::strerror(errno));
  char err[256] = {0};
  std::uint8_t* buf = nullptr;
  int w = 0, h = 0;
  const bool ok = readRaw(f, &w, &h, &buf, err, sizeof err);
  std::fclose(f);
  if (!ok) throw std::runtime_error(path + ": " + err);
  width = w;
  height = h;
  rgba.assign(buf, buf + std::size_t(w) * std::size_t(h) * 4);
  std::free(buf);
}

}  // namespace sph2d
