// png_runs.hpp (internal) — sph2d's own deflate coder for rendered frames (PngSettings::Deflater::Runs).
//
// A rendered frame is mostly runs: flat backdrop, tiles, bodies, the same row as the one above.
// The coder applies PNG's SUB filter to every row (a smooth gradient becomes a run of equal
// differences) and looks for two matches only, the pixel to the left (distance bpp) and the
// pixel above (distance one row), taking the longer run; everything else is a literal. Each
// block of about 64k symbols gets its own Huffman codes (RFC 1951 dynamic blocks, lengths limited
// to 15 bits by moving leaves up until the Kraft sum is exact). No hashing and no search: on the
// dam break's 960×540 frames it takes 0.78 of libdeflate level 1's CPU time for files 1.05× as
// large, and on two threads 0.35–0.5 of its wall time (docs/RENDERING.md, "PNG settings").
// Large images are cut into two strips of rows coded on two threads; each
// strip ends on a byte boundary (an empty stored block) and the strips' matches may reach back
// into the rows before them, so the bytes do not depend on the thread count.
#pragma once

#include <cstdint>
#include <vector>

namespace sph2d {

/// The zlib stream (RFC 1950) of the PNG scanlines of an image of RGBA8 pixels (rows top-down,
/// 4 bytes a pixel): each row is filter byte 1 (SUB) and the row's filtered bytes, RGB (`bpp` 3:
/// the A bytes dropped) or RGBA (`bpp` 4). Replaces `out`. Each thread that codes keeps its
/// scratch (about twice the largest image's scanlines) for the next frame. Without a second
/// thread to be had, both strips are coded on the calling one (the same bytes). Throws
/// std::invalid_argument for an empty image or another `bpp`, and std::bad_alloc.
void deflateRunsPng(int width, int height, const std::uint8_t* rgba, int bpp, std::vector<std::uint8_t>& out);

}  // namespace sph2d
