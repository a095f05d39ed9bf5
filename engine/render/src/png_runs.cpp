// png_runs.cpp — sph2d's deflate coder for rendered frames (png_runs.hpp): the SUB filter,
// runs of the pixel to the left or above, dynamic Huffman blocks, two strips on two threads.
#include "png_runs.hpp"

#include <libdeflate.h>
#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>

namespace sph2d {
namespace {

/// Symbols a block holds before its codes are built and it is written (at a row's end): large
/// enough that the codes' description (about 150 bytes) costs nothing, small enough that the
/// symbols stay in the cache between the counting and the writing.
constexpr std::size_t kBlockSymbols = std::size_t(1) << 16;

/// Images of fewer bytes than this are coded in one strip on the calling thread (a thread costs
/// more than coding them).
constexpr std::size_t kStripBytes = std::size_t(1) << 18;

/// The deflate window (RFC 1951): no match reaches further back.
constexpr std::size_t kWindow = 32768;

/// Bits into a byte buffer, least significant first (RFC 1951 3.1.1).
struct BitWriter {
  std::uint8_t* p;
  std::uint64_t acc = 0;
  int n = 0;
  void put(std::uint32_t bits, int count) {
    acc |= std::uint64_t(bits) << n;
    n += count;
    if (n >= 32) {
      for (int b = 0; b < 4; ++b) p[b] = std::uint8_t(acc >> (8 * b));
      p += 4;
      acc >>= 32;
      n -= 32;
    }
  }
  /// Pads to a byte boundary.
  void align() {
    while (n > 0) {
      *p++ = std::uint8_t(acc);
      acc >>= 8;
      n = n > 8 ? n - 8 : 0;
    }
    acc = 0;
    n = 0;
  }
};

/// Huffman code lengths, at most `maxLen`, for the counts freq[0, n) (0 for a count of 0). The
/// optimal lengths by the two-queue method over the counts sorted; any deeper than maxLen are
/// lifted to it and, while the Kraft sum exceeds 1, a leaf at maxLen goes up beside the deepest
/// shorter leaf (which goes down one level): the sum falls by exactly one unit of 2^-maxLen per
/// move, so it ends exact (a complete code). The most frequent symbols take the shortest.
void codeLengths(const std::uint32_t* freq, int n, int maxLen, std::uint8_t* len) {
  struct Leaf {
    std::uint32_t f;
    int sym;
  };
  Leaf leaves[288];
  int m = 0;
  for (int s = 0; s < n; ++s) {
    len[s] = 0;
    if (freq[s]) leaves[m++] = Leaf{freq[s], s};
  }
  if (m == 0) return;
  if (m == 1) {
    len[leaves[0].sym] = 1;
    return;
  }
  std::sort(leaves, leaves + m,
            [](const Leaf& a, const Leaf& b) { return a.f < b.f || (a.f == b.f && a.sym < b.sym); });
  std::uint64_t weight[2 * 288];
  int parent[2 * 288];
  for (int i = 0; i < m; ++i) weight[i] = leaves[i].f;
  int leaf = 0, inner = m, next = m;
  auto smallest = [&]() { return leaf < m && (inner >= next || weight[leaf] <= weight[inner]) ? leaf++ : inner++; };
  for (; next < 2 * m - 1; ++next) {
    const int a = smallest(), b = smallest();
    weight[next] = weight[a] + weight[b];
    parent[a] = parent[b] = next;
  }
  int depth[2 * 288];
  depth[2 * m - 2] = 0;
  for (int k = 2 * m - 3; k >= 0; --k) depth[k] = depth[parent[k]] + 1;
  int count[2 * 288 + 1] = {0};
  for (int i = 0; i < m; ++i) ++count[std::min(depth[i], maxLen)];
  std::uint64_t kraft = 0;
  for (int l = 1; l <= maxLen; ++l) kraft += std::uint64_t(count[l]) << (maxLen - l);
  for (; kraft > (std::uint64_t(1) << maxLen); --kraft) {
    --count[maxLen];
    for (int l = maxLen - 1; l > 0; --l)
      if (count[l]) {
        --count[l];
        count[l + 1] += 2;
        break;
      }
  }
  int at = m - 1;
  for (int l = 1; l <= maxLen; ++l)
    for (int k = 0; k < count[l]; ++k) len[leaves[at--].sym] = std::uint8_t(l);
}

/// The canonical codes of lengths len[0, n) (RFC 1951 3.2.2), bit-reversed for the writer.
void canonicalCodes(const std::uint8_t* len, int n, std::uint16_t* code) {
  int perLength[16] = {0};
  for (int s = 0; s < n; ++s) ++perLength[len[s]];
  perLength[0] = 0;
  int nextCode[16] = {0};
  for (int l = 1, c = 0; l < 16; ++l) nextCode[l] = c = (c + perLength[l - 1]) << 1;
  for (int s = 0; s < n; ++s) {
    code[s] = 0;
    if (!len[s]) continue;
    int v = nextCode[len[s]]++, r = 0;
    for (int b = 0; b < len[s]; ++b, v >>= 1) r = (r << 1) | (v & 1);
    code[s] = std::uint16_t(r);
  }
}

/// A match length's symbol (257..285), extra bits and their value (RFC 1951 3.2.5).
struct LengthCode {
  std::uint16_t sym = 0;
  std::uint8_t bits = 0, extra = 0;
};

struct LengthTable {
  LengthCode of[259];
  LengthTable() {
    static const int base[29] = {3,  4,  5,  6,  7,  8,  9,  10, 11,  13,  15,  17,  19,  23, 27,
                                 31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
    static const int extra[29] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                  2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
    for (int s = 0; s < 29; ++s) {
      const int last = s == 28 ? 258 : std::min(257, base[s] + (1 << extra[s]) - 1);
      for (int L = base[s]; L <= last; ++L)
        of[L] = LengthCode{std::uint16_t(257 + s), std::uint8_t(extra[s]), std::uint8_t(L - base[s])};
    }
  }
};

/// A distance's symbol (0..29), extra bits and their value.
void distanceCode(std::uint32_t d, int& sym, int& bits, std::uint32_t& extra) {
  static const std::uint32_t base[30] = {1,    2,    3,    4,    5,    7,    9,    13,    17,    25,
                                         33,   49,   65,   97,   129,  193,  257,  385,   513,   769,
                                         1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
  static const int extraBits[30] = {0, 0, 0, 0, 1, 1, 2, 2,  3,  3,  4,  4,  5,  5,  6,
                                    6, 7, 7, 8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13};
  int s = 29;
  while (base[s] > d) --s;
  sym = s;
  bits = extraBits[s];
  extra = d - base[s];
}

/// One strip's scratch, kept between frames (a frame allocates nothing once it has run).
struct Strip {
  std::vector<std::uint8_t> bytes;      ///< the strip's deflate blocks
  std::vector<std::uint32_t> symbols;   ///< a block's literals and matches
  std::vector<std::uint32_t> filtered;  ///< two filtered rows (this one and the one above)
  std::vector<std::uint8_t> packed;     ///< a filtered row as the stream's bytes (for Adler-32)
  std::size_t size = 0;                 ///< bytes used
  std::uint32_t adler = 1;              ///< Adler-32 of the strip's scanlines
};

constexpr std::uint32_t kMatch = 0x80000000u;  ///< a symbol is a match of length (s & 0x1FF) …
constexpr std::uint32_t kUp = 0x200u;          ///< … of the row above (else of the pixel to the left)

/// How many of a[0, n) equal b[0, n) from the start (two words at a time).
std::size_t sameRun(const std::uint32_t* a, const std::uint32_t* b, std::size_t n) {
  std::size_t k = 0;
  for (; k + 2 <= n; k += 2) {
    std::uint64_t x, y;
    std::memcpy(&x, a + k, 8);
    std::memcpy(&y, b + k, 8);
    if (x != y) {
      std::uint32_t first;
      std::memcpy(&first, reinterpret_cast<const unsigned char*>(&x), 4);
      std::uint32_t other;
      std::memcpy(&other, reinterpret_cast<const unsigned char*>(&y), 4);
      return k + (first == other ? 1 : 0);
    }
  }
  return k < n && a[k] == b[k] ? k + 1 : k;
}

/// How many of a[0, n) equal v from the start.
std::size_t valueRun(const std::uint32_t* a, std::uint32_t v, std::size_t n) {
  const std::uint64_t two = std::uint64_t(v) | std::uint64_t(v) << 32;
  std::size_t k = 0;
  for (; k + 2 <= n; k += 2) {
    std::uint64_t x;
    std::memcpy(&x, a + k, 8);
    if (x != two) return k + (a[k] == v ? 1 : 0);
  }
  return k < n && a[k] == v ? k + 1 : k;
}

/// Filters a row of RGBA8 pixels (SUB: each byte less the same byte of the pixel to its left)
/// into `out`, 4 bytes a pixel in the source's order, the A bytes 0 when the file drops them.
/// Compared as words, a pixel's bytes stay bytes: nothing depends on the host's byte order.
template <int bpp>
void filterRow(const std::uint8_t* src, std::size_t w, std::uint32_t* out) {
  unsigned char* f = reinterpret_cast<unsigned char*>(out);
  for (std::size_t j = 0; j < 4; ++j) f[j] = src[j];
  for (std::size_t j = 4; j < 4 * w; ++j) f[j] = std::uint8_t(src[j] - src[j - 4]);
  if (bpp == 3)
    for (std::size_t i = 0; i < w; ++i) f[4 * i + 3] = 0;
}

/// Codes rows [y0, y1) into `s` as deflate blocks (the last one final when `last`; otherwise
/// ended by an empty stored block on a byte boundary), with their Adler-32.
template <int bpp>
void codeStrip(const std::uint8_t* image, std::size_t w, int y0, int y1, bool last, Strip& s) {
  static const LengthTable lengths;
  const std::size_t rowBytes = 1 + w * std::size_t(bpp), rows = std::size_t(y1 - y0);
  const bool upFits = rowBytes <= kWindow;
  int upSym = 0, upBits = 0, leftSym = 0, leftBits = 0;
  std::uint32_t upExtra = 0, leftExtra = 0;
  if (upFits) distanceCode(std::uint32_t(rowBytes), upSym, upBits, upExtra);
  distanceCode(std::uint32_t(bpp), leftSym, leftBits, leftExtra);
  // At most 2 bytes a byte (a literal's code is ≤ 15 bits; a match of ≥ 3 bytes ≤ 48 bits), a
  // block's codes and the closing stored block.
  const std::size_t capacity = 2 * rowBytes * rows + 512 * (rowBytes * rows / kBlockSymbols + 2) + 64;
  if (s.bytes.size() < capacity) s.bytes.resize(capacity);
  if (s.symbols.size() < kBlockSymbols + rowBytes) s.symbols.resize(kBlockSymbols + rowBytes);
  s.filtered.resize(2 * w);
  s.packed.resize(rowBytes + 1);
  BitWriter out{s.bytes.data()};
  std::uint32_t* sym = s.symbols.data();
  std::size_t n = 0;
  std::uint32_t litFreq[286] = {0}, distFreq[30] = {0};

  auto writeBlock = [&](bool final) {
    litFreq[256] = 1;  // the end of the block
    // Two codes at least in each alphabet, so that every code is complete.
    if (!distFreq[0]) distFreq[0] = 1;
    if (!distFreq[1]) distFreq[1] = 1;
    if (!litFreq[0]) litFreq[0] = 1;
    std::uint8_t litLen[286], distLen[30];
    std::uint16_t litCode[286], distCodeOf[30];
    codeLengths(litFreq, 286, 15, litLen);
    codeLengths(distFreq, 30, 15, distLen);
    canonicalCodes(litLen, 286, litCode);
    canonicalCodes(distLen, 30, distCodeOf);
    int nLit = 286, nDist = 30;
    while (nLit > 257 && !litLen[nLit - 1]) --nLit;
    while (nDist > 1 && !distLen[nDist - 1]) --nDist;
    // The code lengths, each sent as itself (symbols 0..15 of the code-length code).
    std::uint8_t seq[286 + 30];
    int nSeq = 0;
    for (int k = 0; k < nLit; ++k) seq[nSeq++] = litLen[k];
    for (int k = 0; k < nDist; ++k) seq[nSeq++] = distLen[k];
    std::uint32_t clFreq[19] = {0};
    for (int k = 0; k < nSeq; ++k) ++clFreq[seq[k]];
    if (!clFreq[0]) clFreq[0] = 1;  // two codes at least (the literal code has several lengths)
    std::uint8_t clLen[19];
    std::uint16_t clCode[19];
    codeLengths(clFreq, 19, 7, clLen);
    canonicalCodes(clLen, 19, clCode);
    static const int order[19] = {16, 17, 18, 0, 8, 7, 9, 6, 10, 5, 11, 4, 12, 3, 13, 2, 14, 1, 15};
    int nCl = 19;
    while (nCl > 4 && !clLen[order[nCl - 1]]) --nCl;
    out.put(final ? 1 : 0, 1);
    out.put(2, 2);  // dynamic Huffman codes
    out.put(std::uint32_t(nLit - 257), 5);
    out.put(std::uint32_t(nDist - 1), 5);
    out.put(std::uint32_t(nCl - 4), 4);
    for (int k = 0; k < nCl; ++k) out.put(clLen[order[k]], 3);
    for (int k = 0; k < nSeq; ++k) out.put(clCode[seq[k]], clLen[seq[k]]);
    const std::uint32_t up = distCodeOf[upSym] | (upExtra << distLen[upSym]);
    const std::uint32_t left = distCodeOf[leftSym] | (leftExtra << distLen[leftSym]);
    const int upLength = distLen[upSym] + upBits, leftLength = distLen[leftSym] + leftBits;
    for (std::size_t k = 0; k < n; ++k) {
      const std::uint32_t t = sym[k];
      if (!(t & kMatch)) {
        out.put(litCode[t], litLen[t]);
        continue;
      }
      const LengthCode& L = lengths.of[t & 0x1FF];
      out.put(std::uint32_t(litCode[L.sym]) | (std::uint32_t(L.extra) << litLen[L.sym]), litLen[L.sym] + L.bits);
      if (t & kUp)
        out.put(up, upLength);
      else
        out.put(left, leftLength);
    }
    out.put(litCode[256], litLen[256]);
    n = 0;
    std::memset(litFreq, 0, sizeof litFreq);
    std::memset(distFreq, 0, sizeof distFreq);
  };
  // A run of `bytes` (a multiple of bpp, ≥ 3) as matches of at most 258 bytes, none under 3.
  auto run = [&](std::size_t bytes, bool up) {
    while (bytes >= 3) {
      const std::size_t len = bytes <= 258 ? bytes : bytes - 258 < 3 ? bytes - 3 : 258;
      sym[n++] = kMatch | (up ? kUp : 0) | std::uint32_t(len);
      ++litFreq[lengths.of[len].sym];
      ++distFreq[up ? upSym : leftSym];
      bytes -= len;
    }
  };

  std::uint32_t adler = 1;
  if (y0 > 0) filterRow<bpp>(image + std::size_t(y0 - 1) * w * 4, w, &s.filtered[std::size_t((y0 - 1) & 1) * w]);
  for (int y = y0; y < y1; ++y) {
    std::uint32_t* cur = &s.filtered[std::size_t(y & 1) * w];
    filterRow<bpp>(image + std::size_t(y) * w * 4, w, cur);
    const unsigned char* bytes = reinterpret_cast<const unsigned char*>(cur);
    const std::uint32_t* above = y > 0 && upFits ? &s.filtered[std::size_t((y + 1) & 1) * w] : nullptr;
    sym[n++] = 1;  // the row's filter byte: SUB
    ++litFreq[1];
    for (std::size_t x = 0; x < w;) {
      // The longer run: the same filtered pixels as the pixel to the left, or as the row above.
      // The left one on a tie, and without looking up past a long one: its distance has no
      // extra bits (the row above's has 10 to 12 for every 258 bytes).
      std::size_t up = 0, left = 0;
      if (x > 0) left = valueRun(cur + x, cur[x - 1], w - x);
      if (above && left < 64) up = sameRun(cur + x, above + x, w - x);
      if (up > 1 && up > left) {
        // At a row's start or a new colour, one or two literal pixels and then the run from the
        // left are cheaper than the run from above when they reach as far.
        auto leftRun = [&](std::size_t at) { return valueRun(cur + at, cur[at - 1], w - at); };
        std::size_t reach = x + 1 < w ? 1 + leftRun(x + 1) : 1;
        if (reach == 1 && x + 2 < w) reach = 2 + leftRun(x + 2);
        if (reach >= up) up = 0;
      }
      if (up | left) {
        const bool fromAbove = up > left;
        const std::size_t k = fromAbove ? up : left;
        run(k * std::size_t(bpp), fromAbove);
        x += k;
        continue;
      }
      for (int b = 0; b < bpp; ++b) {
        const std::uint32_t byte = bytes[4 * x + std::size_t(b)];
        sym[n++] = byte;
        ++litFreq[byte];
      }
      ++x;
    }
    // The row's bytes as the stream holds them, for the checksum.
    std::uint8_t* p = s.packed.data();
    p[0] = 1;
    if (bpp == 4)
      std::memcpy(p + 1, bytes, 4 * w);
    else
      for (std::size_t i = 0; i < w; ++i) std::memcpy(p + 1 + 3 * i, bytes + 4 * i, 4);  // a spare byte at the end
    adler = std::uint32_t(libdeflate_adler32(adler, p, rowBytes));
    if (n >= kBlockSymbols || y + 1 == y1) writeBlock(last && y + 1 == y1);
  }
  if (!last) {  // an empty stored block: the next strip starts on a byte boundary
    out.put(0, 3);
    out.align();
    const std::uint8_t empty[4] = {0, 0, 0xFF, 0xFF};
    std::memcpy(out.p, empty, 4);
    out.p += 4;
  } else {
    out.align();
  }
  s.size = std::size_t(out.p - s.bytes.data());
  s.adler = adler;
}

}  // namespace

void deflateRunsPng(int width, int height, const std::uint8_t* rgba, int bpp, std::vector<std::uint8_t>& out) {
  if (width < 1 || height < 1 || (bpp != 3 && bpp != 4))
    throw std::invalid_argument("deflateRunsPng: a " + std::to_string(width) + " x " + std::to_string(height) +
                                " image of " + std::to_string(bpp) + " bytes a pixel (at least 1 x 1, 3 or 4)");
  const std::size_t w = std::size_t(width), rowBytes = 1 + w * std::size_t(bpp);
  // The strips depend on the image alone, never on the threads at hand.
  const int strips = rowBytes * std::size_t(height) >= kStripBytes && height >= 2 ? 2 : 1;
  thread_local Strip own[2];
  Strip* scratch = own;  // the helper thread codes into this thread's scratch (its own is another)
  const int mid = strips == 2 ? height / 2 : height;
  if (strips == 2) {
    std::exception_ptr failed;
    auto second = [&] {
      try {
        bpp == 4 ? codeStrip<4>(rgba, w, mid, height, true, scratch[1])
                 : codeStrip<3>(rgba, w, mid, height, true, scratch[1]);
      } catch (...) {
        failed = std::current_exception();
      }
    };
    std::thread helper;
    try {
      helper = std::thread(second);
    } catch (const std::system_error&) {  // no thread to be had: the same bytes on this one
      second();
    }
    try {
      bpp == 4 ? codeStrip<4>(rgba, w, 0, mid, false, scratch[0]) : codeStrip<3>(rgba, w, 0, mid, false, scratch[0]);
    } catch (...) {
      if (helper.joinable()) helper.join();
      throw;
    }
    if (helper.joinable()) helper.join();
    if (failed) std::rethrow_exception(failed);
  } else {
    bpp == 4 ? codeStrip<4>(rgba, w, 0, height, true, scratch[0]) : codeStrip<3>(rgba, w, 0, height, true, scratch[0]);
  }
  std::uint32_t adler = scratch[0].adler;
  if (strips == 2)
    adler = std::uint32_t(adler32_combine(adler, scratch[1].adler, z_off_t(rowBytes * std::size_t(height - mid))));
  out.clear();
  out.reserve(2 + scratch[0].size + (strips == 2 ? scratch[1].size : 0) + 4);
  out.push_back(0x78);  // deflate, 32 KiB window
  out.push_back(0x01);  // the fastest level; (0x78·256 + 1) is a multiple of 31
  for (int k = 0; k < strips; ++k)
    out.insert(out.end(), scratch[k].bytes.data(), scratch[k].bytes.data() + scratch[k].size);
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(std::uint8_t(adler >> shift));
}

}  // namespace sph2d
