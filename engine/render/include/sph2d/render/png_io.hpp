// sph2d/render/png_io.hpp — PNG files through libpng, written atomically.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sph2d {

/// How libpng encodes a frame: zlib's level, strategy and memory level, the PNG filters, libpng's
/// compression buffer, and how RGBA8 rows reach libpng. pngSettings(level) gives the settings of
/// a `--png-level` (the defaults are level 1's); the fields can be set one by one to measure them
/// (app/tools/png_settings.cpp, docs/RENDERING.md "PNG settings").
struct PngSettings {
  int level = 1;                  ///< zlib level 0..9
  int strategy = 0;               ///< zlib: 0 default, 1 Z_FILTERED, 2 Z_HUFFMAN_ONLY, 3 Z_RLE, 4 Z_FIXED
  int filters = 0x08;             ///< PNG_FILTER_* bits: 0x08 NONE, 0x10 SUB, 0x20 UP, 0x40 AVG, 0x80 PAETH
  int memLevel = 8;               ///< zlib's memory level 1..9: hash table 2^(m+7), blocks of 2^(m+6) symbols
  int windowBits = 15;            ///< zlib's window 9..15 (2^windowBits bytes)
  std::size_t bufferSize = 8192;  ///< libpng's compression buffer [bytes]: the size of each IDAT chunk
  /// How the RGBA8 rows become the file's pixels: libpng drops A (png_set_filler), sph2d packs
  /// RGB rows itself, or the file keeps A (an RGBA PNG).
  enum class Input { Filler, PackedRgb, Rgba } input = Input::Filler;
  bool wholeImage = false;  ///< every row in one png_write_image call (else png_write_row per row)
  /// The deflate coder: zlib through libpng; libdeflate (its level, filter NONE on every row,
  /// the whole image in one IDAT chunk); or sph2d's run coder (the SUB filter on every row,
  /// matches only of the pixel to the left and the row above, the image in two strips on two
  /// threads, one IDAT chunk; `level` does not apply either). For libdeflate and the run coder
  /// strategy, filters, memLevel, windowBits, bufferSize and wholeImage do not apply.
  enum class Deflater { Zlib, Libdeflate, Runs } deflater = Deflater::Zlib;
};

/// The settings of PNG level `level` 0..9: 1 (the default, the fastest measured on the dam
/// break's frames) is sph2d's run coder; 0 stores; 2 is zlib's SUB filter with run-length
/// matching (smaller files, slower); 3..9 are zlib's level with every filter.
PngSettings pngSettings(int level);

/// Encodes RGBA8 pixels (rows top-down) as a PNG with libpng into `out` (replaced).
/// Throws std::runtime_error.
void encodePng(int width, int height, const std::uint8_t* rgba, const PngSettings& settings,
               std::vector<std::uint8_t>& out);

/// Writes RGBA8 pixels (rows top-down) as an RGB PNG with libpng (pngSettings(level)). The file
/// is written to a temporary name beside `path` (created new: an existing file or symbolic link
/// of that name is refused) and renamed, so it exists whole or not at all.
/// Throws std::runtime_error with the path.
void writePngAtomic(const std::string& path, int width, int height, const std::uint8_t* rgba, int level = 1);

/// Writes PNG bytes made by encodePng to `path` as writePngAtomic does (a temporary file
/// PATH.tmpPID, created new, then a rename; a device or FIFO is written in place).
void writeEncodedPngAtomic(const std::string& path, const std::vector<std::uint8_t>& bytes);

/// Reads a PNG into RGBA8 (rows top-down). Throws std::runtime_error.
void readPng(const std::string& path, int& width, int& height, std::vector<std::uint8_t>& rgba);

}  // namespace sph2d
