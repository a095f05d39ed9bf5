// sph2d/hash.hpp — XXH64, the named 64-bit hash of states and frames.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace sph2d {

/// Streaming XXH64 (Yann Collet's xxHash, 64-bit variant, seed 0 by default).
class Xxh64 {
 public:
  /// Starts a hash with the given seed.
  explicit Xxh64(std::uint64_t seed = 0);
  /// Feeds `size` bytes.
  void update(const void* data, std::size_t size);
  /// The hash of everything fed so far (the stream can continue).
  std::uint64_t digest() const;

 private:
  std::uint64_t v_[4];
  std::uint64_t total_ = 0;
  std::uint64_t seed_;
  unsigned char buf_[32];
  std::size_t bufLen_ = 0;
};

/// One-shot XXH64 of a byte range.
std::uint64_t xxh64(const void* data, std::size_t size, std::uint64_t seed = 0);

/// 16 lower-case hex digits.
std::string hex64(std::uint64_t h);

}  // namespace sph2d
