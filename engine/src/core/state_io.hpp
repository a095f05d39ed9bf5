// state_io.hpp (internal) — the byte streams of World::save and World::load: plain
// values and arrays in the machine's byte order, each array behind its length.
// StateIn trusts nothing it reads: every read is bounds-checked against the bytes
// that are there, every length against a limit its caller gives, and a failure is
// one SaveError naming what was being read.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "sph2d/world.hpp"

namespace sph2d {

/// Appends values to a byte buffer.
class StateOut {
 public:
  /// A trivially copyable value, as its bytes.
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    const auto* b = reinterpret_cast<const std::uint8_t*>(&v);
    bytes.insert(bytes.end(), b, b + sizeof(T));
  }
  /// An array: its length, then its elements.
  template <class T>
  void putVector(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    put(std::uint64_t(v.size()));
    const auto* b = reinterpret_cast<const std::uint8_t*>(v.data());
    bytes.insert(bytes.end(), b, b + v.size() * sizeof(T));
  }
  /// `size` raw bytes behind their count (an array of fixed-size elements, e.g. Vec2).
  void putBytes(const void* data, std::size_t size) {
    put(std::uint64_t(size));
    const auto* b = static_cast<const std::uint8_t*>(data);
    bytes.insert(bytes.end(), b, b + size);
  }
  /// A string: its length, then its bytes.
  void putString(const std::string& s) {
    put(std::uint64_t(s.size()));
    bytes.insert(bytes.end(), s.begin(), s.end());
  }
  std::vector<std::uint8_t> bytes;
};

/// Reads values back from a byte buffer, checking every length.
class StateIn {
 public:
  StateIn(const std::uint8_t* data, std::size_t size) : p_(data), end_(data + size) {}
  /// A trivially copyable value; `what` names it in the error when the bytes end.
  template <class T>
  T get(const char* what) {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    need(sizeof(T), what);
    T v;
    std::memcpy(&v, p_, sizeof(T));
    p_ += sizeof(T);
    return v;
  }
  /// An array of at most `most` elements into `v`.
  template <class T>
  void getVector(std::vector<T>& v, std::size_t most, const char* what) {
    const std::uint64_t n = get<std::uint64_t>(what);
    if (n > most)
      throw SaveError(std::string("the saved state is malformed: ") + what + " holds " + std::to_string(n) +
                      " entries, at most " + std::to_string(most) + " allowed");
    need(std::size_t(n) * sizeof(T), what);
    v.resize(std::size_t(n));
    if (n) std::memcpy(v.data(), p_, std::size_t(n) * sizeof(T));
    p_ += std::size_t(n) * sizeof(T);
  }
  /// A string of at most `most` bytes.
  std::string getString(std::size_t most, const char* what) {
    std::vector<char> c;
    getVector(c, most, what);
    return std::string(c.begin(), c.end());
  }
  /// True when every byte was read.
  bool done() const { return p_ == end_; }

 private:
  void need(std::size_t n, const char* what) const {
    if (std::size_t(end_ - p_) < n)
      throw SaveError(std::string("the saved state is truncated: it ends inside ") + what);
  }
  const std::uint8_t* p_;
  const std::uint8_t* end_;
};

}  // namespace sph2d
