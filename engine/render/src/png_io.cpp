// png_io.cpp — PNG files: level 1 (the default) through our own fast encoder (png_fast.hpp),
// other levels and every read through libpng; files written to a temporary name and renamed.
#include "sph2d/render/png_io.hpp"

#include <png.h>
#include <zlib.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "png_fast.hpp"

namespace sph2d {
namespace {

// libpng reports errors by longjmp; these helpers keep C++ objects out of the
// functions that call setjmp.
bool writeRaw(FILE* f, int width, int height, const std::uint8_t* rgba, int level, char* err, std::size_t errLen) {
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
  png_init_io(png, f);
  png_set_compression_level(png, level);
  // Level 2: the SUB filter and run-length matching, which on our frames (flat background,
  // smooth water) is as fast as plain zlib level 2 and smaller. (Level 1 is png_fast.cpp's.)
  if (level <= 2) png_set_compression_strategy(png, Z_RLE);
  png_set_filter(png, 0, level <= 2 ? PNG_FILTER_SUB : PNG_ALL_FILTERS);
  png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_set_filler(png, 0, PNG_FILLER_AFTER);  // input rows are RGBA; drop A
  for (int y = 0; y < height; ++y)
    png_write_row(png, const_cast<png_bytep>(rgba + std::size_t(y) * std::size_t(width) * 4));
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

void writePngAtomic(const std::string& path, int width, int height, const std::uint8_t* rgba, int level) {
  const std::string tmp = path + ".tmp" + std::to_string(::getpid());
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw std::runtime_error("cannot create " + tmp + ": " + std::strerror(errno));
  char err[256] = {0};
  bool ok = true;
  if (level == 1) {
    thread_local std::vector<std::uint8_t> bytes;
    encodePngFast(width, height, rgba, bytes);
    if (std::fwrite(bytes.data(), 1, bytes.size(), f) != bytes.size()) {
      std::snprintf(err, sizeof err, "%s", std::strerror(errno));
      ok = false;
    }
  } else {
    ok = writeRaw(f, width, height, rgba, level, err, sizeof err);
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
