// sph2d/render/png_io.hpp — PNG files through libpng, written atomically.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace sph2d {

/// Writes RGBA8 pixels (rows top-down) as an RGB PNG. The file is written to a
/// temporary name beside `path` and renamed, so it exists whole or not at all.
/// `level` 1 (the default) is sph2d's own fast encoder (SUB filter, run-length deflate with
/// dynamic Huffman codes: about 3× faster than libpng at level 1, files within a few %);
/// 0 and 2..9 are libpng with zlib's level (2: SUB filter and Z_RLE; 3..9: every filter).
/// Throws std::runtime_error with the path.
void writePngAtomic(const std::string& path, int width, int height, const std::uint8_t* rgba, int level = 1);

/// Reads a PNG into RGBA8 (rows top-down). Throws std::runtime_error.
void readPng(const std::string& path, int& width, int& height, std::vector<std::uint8_t>& rgba);

}  // namespace sph2d
