// XXH64 against the published test vectors, and streaming = one-shot.
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "sph2d/hash.hpp"

using namespace sph2d;

TEST_CASE("xxh64 matches the reference vectors") {
  CHECK(xxh64("", 0) == 0xEF46DB3751D8E999ULL);
  CHECK(xxh64("abc", 3) == 0x44BC2CF5AD770999ULL);
  CHECK(hex64(0xEF46DB3751D8E999ULL) == "ef46db3751d8e999");
}

TEST_CASE("xxh64 streaming in pieces equals one shot, at every split") {
  std::vector<unsigned char> data(301);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<unsigned char>(i * 37 + 11);
  const auto whole = xxh64(data.data(), data.size(), 7);
  for (std::size_t split : {0u, 1u, 31u, 32u, 33u, 64u, 100u, 300u}) {
    Xxh64 h(7);
    h.update(data.data(), split);
    h.update(data.data() + split, data.size() - split);
    CHECK(h.digest() == whole);
  }
  CHECK(xxh64(data.data(), data.size(), 8) != whole);
}
