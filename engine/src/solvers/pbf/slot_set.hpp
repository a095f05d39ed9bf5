// solvers/pbf/slot_set.hpp (internal) — a set of particle slots, one bit each,
// for the local iterations of the density solve (pbf.cpp): the particles still
// compressed, their neighbours, and every particle the phase moved.
//
// Adding is one bit set; listing walks the words in slot order, so a list comes
// out sorted without a sort (the local phase used to sort each list: most of
// its serial time on two threads). A second level of bits, one per word, lets
// listing and clearing skip the empty words: they cost in proportion to the
// members and to n/4096, not to the particle count n. The set is empty between
// substeps (clear() after use).
//
// Not thread-safe: one thread adds, except setBlock(), which writes whole
// words (a job block of a multiple of 64 slots owns its words, so blocks may
// run in parallel) and leaves the summary to summarise().
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace sph2d {

/// The index of the lowest set bit of b (b ≠ 0).
inline unsigned lowestBit(std::uint64_t b) {
#if defined(__GNUC__) || defined(__clang__)
  return unsigned(__builtin_ctzll(b));
#else
  unsigned k = 0;
  for (; !(b & 1); b >>= 1) ++k;
  return k;
#endif
}

class SlotSet {
 public:
  /// Room for slots [0, n); the set is empty afterwards.
  void reset(std::size_t n) {
    words_.assign((n + 63) / 64, 0);
    summary_.assign((words_.size() + 63) / 64, 0);
  }
  /// Adds slot i.
  void add(std::uint32_t i) {
    const std::size_t w = i >> 6;
    words_[w] |= std::uint64_t(1) << (i & 63);
    summary_[w >> 6] |= std::uint64_t(1) << (w & 63);
  }
  /// Slot i is a member.
  bool has(std::uint32_t i) const { return (words_[i >> 6] >> (i & 63)) & 1; }
  /// Sets word w (slots 64w .. 64w + 63) to `bits`, without the summary (parallel
  /// blocks may each write their own words; summarise() afterwards).
  void setWord(std::size_t w, std::uint64_t bits) { words_[w] = bits; }
  /// Rebuilds the summary from every word (after setWord()).
  void summarise() {
    for (std::size_t s = 0; s < summary_.size(); ++s) {
      std::uint64_t m = 0;
      const std::size_t w0 = 64 * s, w1 = w0 + 64 < words_.size() ? w0 + 64 : words_.size();
      for (std::size_t w = w0; w < w1; ++w) m |= std::uint64_t(words_[w] != 0) << (w - w0);
      summary_[s] = m;
    }
  }
  /// The members in increasing slot order, into `out` (replacing its contents).
  void list(std::vector<std::uint32_t>& out) const {
    out.clear();
    forWords([&](std::size_t w) {
      for (std::uint64_t b = words_[w]; b; b &= b - 1) out.push_back(std::uint32_t(64 * w + lowestBit(b)));
    });
  }
  /// Empties the set (touches only the words that hold members).
  void clear() {
    forWords([&](std::size_t w) { words_[w] = 0; });
    for (std::uint64_t& s : summary_) s = 0;
  }

 private:
  /// Calls f(w) for every word w whose summary bit is set, in increasing order.
  template <class F>
  void forWords(F f) const {
    for (std::size_t s = 0; s < summary_.size(); ++s)
      for (std::uint64_t m = summary_[s]; m; m &= m - 1) f(64 * s + lowestBit(m));
  }

  std::vector<std::uint64_t> words_;    ///< bit i & 63 of word i >> 6: slot i
  std::vector<std::uint64_t> summary_;  ///< bit w & 63 of summary w >> 6: word w may be non-zero
};

}  // namespace sph2d
