// png_fast.cpp — SUB filter, run-length deflate with dynamic Huffman codes, PNG chunks
// (see png_fast.hpp for the design).
#include "png_fast.hpp"

#include <zlib.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <array>
#include <cstring>

namespace sph2d {
namespace {

constexpr int kMaxBits = 15;         // deflate's longest literal/length and distance code
constexpr int kMaxCodeLenBits = 7;   // longest code of the code-length alphabet
constexpr std::size_t kBlockSymbols = 32768;

// Length codes 257..285: base length and extra bits (RFC 1951, 3.2.5).
constexpr std::array<int, 29> kLenBase = {3,  4,  5,  6,  7,  8,  9,  10, 11,  13,  15,  17,  19,  23, 27,
                                          31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
constexpr std::array<int, 29> kLenExtra = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                           2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
// The order in which the code-length code's lengths are sent.
constexpr std::array<int, 19> kCodeLenOrder = {16, 17, 18, 0, 8, 7, 9, 6, 10, 5, 11, 4, 12, 3, 13, 2, 14, 1, 15};

/// For each match length 3..258: its symbol (257..285), extra bits and their value.
struct LengthTable {
  std::array<std::uint16_t, 259> symbol{};
  std::array<std::uint8_t, 259> extraBits{};
  std::array<std::uint8_t, 259> extraValue{};
  LengthTable() {
    for (int code = 0; code < 29; ++code) {
      const int end = code == 28 ? 259 : kLenBase[std::size_t(code) + 1];
      for (int len = kLenBase[std::size_t(code)]; len < end; ++len) {
        symbol[std::size_t(len)] = std::uint16_t(257 + code);
        extraBits[std::size_t(len)] = std::uint8_t(kLenExtra[std::size_t(code)]);
        extraValue[std::size_t(len)] = std::uint8_t(len - kLenBase[std::size_t(code)]);
      }
    }
    // 258 has its own code (285, no extra bits) although 284 + 31 would also reach it.
    symbol[258] = 285;
    extraBits[258] = 0;
    extraValue[258] = 0;
  }
};
const LengthTable kLengths;

/// Writes bits least significant first, 32 at a time, at the end of a byte vector.
struct BitWriter {
  std::vector<std::uint8_t>& v;
  std::size_t pos;  // bytes written
  std::uint64_t buf = 0;
  int n = 0;
  /// Makes room for `bytes` more bytes (and the 4-byte steps of put()).
  void reserve(std::size_t bytes) {
    if (v.size() < pos + bytes + 8) v.resize(std::max(pos + bytes + 8, v.size() * 3 / 2));
  }
  void put(std::uint32_t bits, int len) {  // len <= 32
    buf |= std::uint64_t(bits) << n;
    n += len;
    if (n >= 32) {
      std::uint8_t* p = v.data() + pos;
      p[0] = std::uint8_t(buf);
      p[1] = std::uint8_t(buf >> 8);
      p[2] = std::uint8_t(buf >> 16);
      p[3] = std::uint8_t(buf >> 24);
      pos += 4;
      buf >>= 32;
      n -= 32;
    }
  }
  /// Pads with zero bits to a byte boundary and writes what is left.
  void flush() {
    reserve(8);
    while (n > 0) {
      v[pos++] = std::uint8_t(buf);
      buf >>= 8;
      n -= 8;
    }
    n = 0;
    buf = 0;
  }
};

/// A canonical Huffman code: lengths per symbol and the codes bit-reversed for LSB-first output.
template <std::size_t N>
struct Code {
  std::array<std::uint8_t, N> len{};
  std::array<std::uint16_t, N> bits{};
};

/// Code lengths of an optimal prefix code for `freq`, no longer than `maxBits`: Huffman's
/// construction with two queues over the symbols sorted by (count, symbol); when a length
/// exceeds the limit, the counts are halved (keeping them ≥ 1) and the code is rebuilt. At
/// least two symbols always get a code (deflate needs one bit even for a single symbol).
template <std::size_t N>
void buildLengths(const std::array<std::uint32_t, N>& freqIn, int maxBits, Code<N>& code) {
  std::array<std::uint32_t, N> freq = freqIn;
  int used = 0;
  for (std::uint32_t f : freq) used += f > 0;
  for (std::size_t s = 0; used < 2 && s < N; ++s)
    if (!freq[s]) {
      freq[s] = 1;
      ++used;
    }
  std::array<std::uint32_t, 2 * N> weight{};
  std::array<std::uint16_t, 2 * N> parent{}, leafSymbol{};
  std::array<std::uint8_t, 2 * N> depth{};
  for (;;) {
    int m = 0;
    for (std::size_t s = 0; s < N; ++s)
      if (freq[s]) leafSymbol[std::size_t(m++)] = std::uint16_t(s);
    std::sort(leafSymbol.begin(), leafSymbol.begin() + m, [&](std::uint16_t a, std::uint16_t b) {
      return freq[a] != freq[b] ? freq[a] < freq[b] : a < b;
    });
    // Nodes 0..m-1 are the leaves (ascending weight), m.. the internal nodes in creation order.
    for (int k = 0; k < m; ++k) weight[std::size_t(k)] = freq[leafSymbol[std::size_t(k)]];
    int leaf = 0, inner = m, next = m;
    auto pick = [&]() {
      if (leaf < m && (inner >= next || weight[std::size_t(leaf)] <= weight[std::size_t(inner)])) return leaf++;
      return inner++;
    };
    while (next < 2 * m - 1) {
      const int a = pick(), b = pick();
      weight[std::size_t(next)] = weight[std::size_t(a)] + weight[std::size_t(b)];
      parent[std::size_t(a)] = parent[std::size_t(b)] = std::uint16_t(next);
      ++next;
    }
    depth[std::size_t(2 * m - 2)] = 0;
    int longest = 0;
    for (int k = 2 * m - 3; k >= 0; --k) {
      depth[std::size_t(k)] = std::uint8_t(depth[parent[std::size_t(k)]] + 1);
      if (k < m) longest = std::max(longest, int(depth[std::size_t(k)]));
    }
    if (longest <= maxBits) {
      code.len.fill(0);
      for (int k = 0; k < m; ++k) code.len[leafSymbol[std::size_t(k)]] = depth[std::size_t(k)];
      break;
    }
    for (std::uint32_t& f : freq)
      if (f) f = (f >> 1) | 1u;
  }
  // Canonical codes (RFC 1951, 3.2.2), reversed for LSB-first output.
  std::array<int, kMaxBits + 2> count{}, nextCode{};
  for (std::uint8_t l : code.len) ++count[l];
  count[0] = 0;
  int c = 0;
  for (int b = 1; b <= kMaxBits; ++b) {
    c = (c + count[std::size_t(b - 1)]) << 1;
    nextCode[std::size_t(b)] = c;
  }
  for (std::size_t s = 0; s < N; ++s) {
    const int l = code.len[s];
    if (!l) continue;
    int v = nextCode[std::size_t(l)]++, r = 0;
    for (int k = 0; k < l; ++k) {
      r = (r << 1) | (v & 1);
      v >>= 1;
    }
    code.bits[s] = std::uint16_t(r);
  }
}

/// One token: a literal byte (< 256) or a run of the previous byte, 256 + its length (3..258).
using Token = std::uint16_t;

/// Writes one dynamic-Huffman block of `tokens` (distances are all 1).
void writeBlock(BitWriter& out, const Token* tokens, std::size_t n, bool final) {
  std::array<std::uint32_t, 286> litFreq{};
  std::array<std::uint32_t, 30> distFreq{};
  for (std::size_t k = 0; k < n; ++k) {
    const Token t = tokens[k];
    if (t < 256) ++litFreq[t];
    else ++litFreq[kLengths.symbol[t - 256]];
  }
  litFreq[256] = 1;  // end of block
  distFreq[0] = n ? 1 : 0;
  Code<286> lit;
  Code<30> dist;
  buildLengths(litFreq, kMaxBits, lit);
  buildLengths(distFreq, kMaxBits, dist);
  int hlit = 286, hdist = 30;
  while (hlit > 257 && !lit.len[std::size_t(hlit - 1)]) --hlit;
  while (hdist > 1 && !dist.len[std::size_t(hdist - 1)]) --hdist;
  // The code lengths of both codes as one sequence, run-length coded with symbols 16, 17, 18.
  std::array<std::uint8_t, 286 + 30> lens{};
  std::copy(lit.len.begin(), lit.len.begin() + hlit, lens.begin());
  std::copy(dist.len.begin(), dist.len.begin() + hdist, lens.begin() + hlit);
  const int total = hlit + hdist;
  std::array<std::uint8_t, 286 + 30> sym{}, extra{};
  int ns = 0;
  for (int i = 0; i < total;) {
    const std::uint8_t cur = lens[std::size_t(i)];
    int run = 1;
    while (i + run < total && lens[std::size_t(i + run)] == cur) ++run;
    i += run;
    if (cur == 0) {
      while (run >= 11) {
        const int k = std::min(run, 138);
        sym[std::size_t(ns)] = 18;
        extra[std::size_t(ns++)] = std::uint8_t(k - 11);
        run -= k;
      }
      if (run >= 3) {
        sym[std::size_t(ns)] = 17;
        extra[std::size_t(ns++)] = std::uint8_t(run - 3);
        run = 0;
      }
    } else {
      sym[std::size_t(ns++)] = cur;
      --run;
      while (run >= 3) {
        const int k = std::min(run, 6);
        sym[std::size_t(ns)] = 16;
        extra[std::size_t(ns++)] = std::uint8_t(k - 3);
        run -= k;
      }
    }
    while (run-- > 0) sym[std::size_t(ns++)] = cur;
  }
  std::array<std::uint32_t, 19> clFreq{};
  for (int k = 0; k < ns; ++k) ++clFreq[sym[std::size_t(k)]];
  Code<19> cl;
  buildLengths(clFreq, kMaxCodeLenBits, cl);
  int hclen = 19;
  while (hclen > 4 && !cl.len[std::size_t(kCodeLenOrder[std::size_t(hclen - 1)])]) --hclen;

  // At most: the header (3 + 14 bits, 19 × 3 bits, 316 code lengths of 7 + 7 bits: < 600 bytes)
  // and 35 bits per token (a literal takes 15, a run 15 + 5 + 15), and the end of the block.
  out.reserve(600 + (35 * n + 15) / 8 + 8);
  out.put(final ? 1 : 0, 1);
  out.put(2, 2);  // dynamic Huffman codes
  out.put(std::uint32_t(hlit - 257), 5);
  out.put(std::uint32_t(hdist - 1), 5);
  out.put(std::uint32_t(hclen - 4), 4);
  for (int k = 0; k < hclen; ++k) out.put(cl.len[std::size_t(kCodeLenOrder[std::size_t(k)])], 3);
  static constexpr int kClExtraBits[3] = {2, 3, 7};
  for (int k = 0; k < ns; ++k) {
    const std::uint8_t s = sym[std::size_t(k)];
    out.put(cl.bits[s], cl.len[s]);
    if (s >= 16) out.put(extra[std::size_t(k)], kClExtraBits[s - 16]);
  }
  // The data: literals, and runs as a length and distance 1 (distance code 0, no extra bits).
  const std::uint32_t d1Bits = dist.bits[0];
  const int d1Len = dist.len[0];
  for (std::size_t k = 0; k < n; ++k) {
    const Token t = tokens[k];
    if (t < 256) {
      out.put(lit.bits[t], lit.len[t]);
    } else {
      const int len = t - 256;
      const int s = kLengths.symbol[std::size_t(len)];
      out.put(lit.bits[std::size_t(s)], lit.len[std::size_t(s)]);
      out.put(kLengths.extraValue[std::size_t(len)], kLengths.extraBits[std::size_t(len)]);
      out.put(d1Bits, d1Len);
    }
  }
  out.put(lit.bits[256], lit.len[256]);
}

void putU32(std::vector<std::uint8_t>& v, std::uint32_t x) {
  v.push_back(std::uint8_t(x >> 24));
  v.push_back(std::uint8_t(x >> 16));
  v.push_back(std::uint8_t(x >> 8));
  v.push_back(std::uint8_t(x));
}

/// Appends a chunk: length, type, data, CRC-32 of type and data.
void putChunk(std::vector<std::uint8_t>& v, const char* type, const std::uint8_t* data, std::size_t n) {
  putU32(v, std::uint32_t(n));
  const std::size_t at = v.size();
  v.insert(v.end(), type, type + 4);
  if (n) v.insert(v.end(), data, data + n);
  putU32(v, std::uint32_t(crc32(crc32(0L, nullptr, 0), v.data() + at, uInt(4 + n))));
}

}  // namespace

std::uint32_t adler32Fast(std::uint32_t adler, const std::uint8_t* data, std::size_t n) {
  constexpr std::uint32_t kMod = 65521;
  std::uint64_t s1 = adler & 0xffff, s2 = adler >> 16;
#if defined(__SSE2__)
  // Chunks of M blocks of 16 bytes. Over a chunk of N = 16M bytes, s2 grows by N·s1 plus
  // Σ (N − i)·b_i = 16·Σ_b (M − 1 − b)·S_b + Σ_b Σ_j (16 − j)·b_bj, S_b the block's byte sum:
  // `prefix` accumulates the byte sums of the blocks before each block, `weighted` the second
  // term (pmaddwd with weights 16..1). M ≤ 1024 keeps every 32-bit lane below 2^31.
  const __m128i zero = _mm_setzero_si128();
  const __m128i wLo = _mm_setr_epi16(16, 15, 14, 13, 12, 11, 10, 9), wHi = _mm_setr_epi16(8, 7, 6, 5, 4, 3, 2, 1);
  while (n >= 16) {
    const std::size_t blocks = std::min<std::size_t>(n / 16, 1024);
    __m128i sums = zero, prefix = zero, weighted = zero;
    for (std::size_t b = 0; b < blocks; ++b) {
      const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(data + 16 * b));
      prefix = _mm_add_epi32(prefix, sums);
      sums = _mm_add_epi32(sums, _mm_sad_epu8(v, zero));
      weighted = _mm_add_epi32(weighted, _mm_madd_epi16(_mm_unpacklo_epi8(v, zero), wLo));
      weighted = _mm_add_epi32(weighted, _mm_madd_epi16(_mm_unpackhi_epi8(v, zero), wHi));
    }
    alignas(16) std::uint32_t a[4], p[4], w[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(a), sums);
    _mm_store_si128(reinterpret_cast<__m128i*>(p), prefix);
    _mm_store_si128(reinterpret_cast<__m128i*>(w), weighted);
    const std::uint64_t len = 16 * blocks;
    const std::uint64_t sumBytes = std::uint64_t(a[0]) + a[1] + a[2] + a[3];
    const std::uint64_t sumPrefix = std::uint64_t(p[0]) + p[1] + p[2] + p[3];
    const std::uint64_t sumWeighted = std::uint64_t(w[0]) + w[1] + w[2] + w[3];
    s2 = (s2 + len * s1 + 16 * sumPrefix + sumWeighted) % kMod;
    s1 = (s1 + sumBytes) % kMod;
    data += len;
    n -= len;
  }
#endif
  while (n > 0) {  // what is left (everything without SSE2), in zlib's chunks of 5552 bytes
    const std::size_t m = std::min<std::size_t>(n, 5552);
    for (std::size_t i = 0; i < m; ++i) {
      s1 += data[i];
      s2 += s1;
    }
    s1 %= kMod;
    s2 %= kMod;
    data += m;
    n -= m;
  }
  return std::uint32_t(s2 << 16 | s1);
}

void encodePngFast(int width, int height, const std::uint8_t* rgba, std::vector<std::uint8_t>& out) {
  const std::size_t w = std::size_t(width), h = std::size_t(height), stride = 3 * w + 1;
  out.clear();
  static const std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  out.insert(out.end(), kSignature, kSignature + 8);
  std::uint8_t ihdr[13];
  for (int k = 0; k < 4; ++k) {
    ihdr[k] = std::uint8_t(std::uint32_t(width) >> (24 - 8 * k));
    ihdr[4 + k] = std::uint8_t(std::uint32_t(height) >> (24 - 8 * k));
  }
  ihdr[8] = 8;   // bit depth
  ihdr[9] = 2;   // colour type RGB
  ihdr[10] = 0;  // deflate
  ihdr[11] = 0;  // adaptive filtering (each row names its filter)
  ihdr[12] = 0;  // not interlaced
  putChunk(out, "IHDR", ihdr, 13);
  // The IDAT chunk is written in place: its length is filled in at the end.
  const std::size_t idat = out.size();
  out.insert(out.end(), {0, 0, 0, 0, 'I', 'D', 'A', 'T', 0x78, 0x01});  // zlib: deflate, 32 KB window; check bits
  BitWriter bw{out, out.size()};

  // Row by row: the SUB filter (each byte minus the same channel one pixel left), the row's
  // share of the Adler-32, then its tokens — runs of the previous byte (distance 1), at least
  // 3 long, as zlib's Z_RLE finds them — written out a block at a time.
  thread_local std::vector<std::uint8_t> row;
  thread_local std::vector<Token> tokens;
  row.resize(stride);
  tokens.resize(kBlockSymbols);
  std::size_t nt = 0;
  std::uint32_t adler = 1;
  int prev = -1;  // the byte before the row (none before the first)
  for (std::size_t y = 0; y < h; ++y) {
    const std::uint8_t* src = rgba + y * w * 4;
    std::uint8_t* d = row.data();
    d[0] = 1;
    if (w > 0) {
      d[1] = src[0];
      d[2] = src[1];
      d[3] = src[2];
    }
    for (std::size_t x = 1; x < w; ++x) {  // no value carried from pixel to pixel
      d[1 + 3 * x] = std::uint8_t(src[4 * x] - src[4 * x - 4]);
      d[2 + 3 * x] = std::uint8_t(src[4 * x + 1] - src[4 * x - 3]);
      d[3 + 3 * x] = std::uint8_t(src[4 * x + 2] - src[4 * x - 2]);
    }
    adler = adler32Fast(adler, d, stride);
    for (std::size_t i = 0; i < stride;) {
      const int before = i > 0 ? d[i - 1] : prev;
      if (d[i] == before) {
        const std::uint8_t v = d[i];
        const std::size_t end = std::min(stride, i + 258);
        std::size_t e = i + 1;
        // Eight bytes at a time while they all equal v, then byte by byte.
        const std::uint64_t v8 = 0x0101010101010101ull * v;
        for (std::uint64_t word; e + 8 <= end; e += 8) {
          std::memcpy(&word, d + e, 8);
          if (word != v8) break;
        }
        while (e < end && d[e] == v) ++e;
        if (e - i >= 3) {
          tokens[nt++] = Token(256 + (e - i));
          i = e;
          if (nt == kBlockSymbols) {
            writeBlock(bw, tokens.data(), nt, false);
            nt = 0;
          }
          continue;
        }
      }
      tokens[nt++] = d[i++];
      if (nt == kBlockSymbols) {
        writeBlock(bw, tokens.data(), nt, false);
        nt = 0;
      }
    }
    prev = d[stride - 1];
  }
  writeBlock(bw, tokens.data(), nt, true);  // the last block (possibly empty: just its end)
  bw.flush();
  out.resize(bw.pos);
  for (int k = 3; k >= 0; --k) out.push_back(std::uint8_t(adler >> (8 * k)));
  const std::uint32_t len = std::uint32_t(out.size() - idat - 8);
  for (int k = 0; k < 4; ++k) out[idat + std::size_t(k)] = std::uint8_t(len >> (24 - 8 * k));
  putU32(out, std::uint32_t(crc32(crc32(0L, nullptr, 0), out.data() + idat + 4, uInt(4 + len))));
  putChunk(out, "IEND", nullptr, 0);
}

}  // namespace sph2d
