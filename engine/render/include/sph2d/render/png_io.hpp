// sph2d/render/png_io.hpp — PNG files through libpng, written atomically.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace sph2d {

/// Writes RGBA8 pixels (rows top-down) as an RGB PNG. The file is written to a
/// temporary name beside `path` and renamed, so it exists whole or not at all.
/// `level` is zlib's 0..9 (1 = fast; levels ≤ 2 use the SUB filter and Z_RLE). Throws std::runtime_error with the path.
void writePngAtomic(const std::string& path, int width, int height, const std::uint8_t* rgba, int level = 1);

/// Reads a PNG into RGBA8 (rows top-down). Throws std::runtime_error.
void readPng(const std::string& path, int& width, int& height, std::vector<std::uint8_t>& rgba);

}  // namespace sph2d
