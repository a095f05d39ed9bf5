// png_fast.hpp — a PNG encoder for rendered frames that costs a fraction of libpng + zlib's
// level 1 for the same size.
//
// Design: the frames are RGB with large flat areas (background rows of one colour, solids) and
// smooth water. Each row gets PNG's SUB filter (left neighbour), which turns flat areas into
// runs of zeros; the filtered stream is then deflated (RFC 1951) the way zlib's Z_RLE strategy
// does it — only matches at distance 1 (runs of one byte value, 3..258 long), everything else
// literals — but without zlib's general machinery: row by row, one pass filters, one finds the
// runs, blocks of up to 32768 symbols get their own dynamic Huffman codes (limited to 15 bits by
// halving the counts until they fit), and a 64-bit bit buffer writes them straight into the
// IDAT chunk (memory: one row, one block of symbols and the file). The zlib wrapper's Adler-32 is
// computed 16 bytes at a time with SSE2 (psadbw, pmaddwd). Output is a plain,
// standard PNG (IHDR, one IDAT, IEND); every decoder reads it. Deterministic: the bytes depend
// only on the pixels.
#pragma once

#include <cstdint>
#include <vector>

namespace sph2d {

/// Encodes RGBA8 pixels (rows top-down; alpha dropped) as an 8-bit RGB PNG file's bytes
/// into `out` (replacing its contents).
void encodePngFast(int width, int height, const std::uint8_t* rgba, std::vector<std::uint8_t>& out);

/// Adler-32 of `n` bytes continued from `adler` (1 to start), as zlib's adler32().
std::uint32_t adler32Fast(std::uint32_t adler, const std::uint8_t* data, std::size_t n);

}  // namespace sph2d
