// sph2d/id_range.hpp — the ids of the particles one call of a World added (IdRange).
#pragma once

#include <cstddef>
#include <cstdint>
#include <iterator>
#include <vector>

namespace sph2d {

/// The ids of the particles one call added (World::addBlock, addDrop, addShape, addParticles):
/// `count` consecutive ids from `first`. A World gives each particle it makes the next id, one
/// after the other, so those one call adds are consecutive, the budget cutting it short or not
/// (the points it skips take no id). A range of ids: `for (std::uint32_t id : added)`,
/// `added[k]`, `added.contains(id)`; `ids()` copies them into a vector.
struct IdRange {
  std::uint32_t first = 0;  ///< the first id added (when none was: the id the next particle will get)
  std::size_t count = 0;    ///< how many were added

  /// True when the call added nothing.
  bool empty() const { return count == 0; }
  /// How many were added (count).
  std::size_t size() const { return count; }
  /// The k-th id added (k < count).
  std::uint32_t operator[](std::size_t k) const { return first + std::uint32_t(k); }
  /// True when `id` is one of the ids added.
  bool contains(std::uint32_t id) const { return id >= first && std::size_t(id - first) < count; }
  /// The same ids.
  bool operator==(const IdRange& o) const { return first == o.first && count == o.count; }
  /// Other ids.
  bool operator!=(const IdRange& o) const { return !(*this == o); }
  /// The ids, in increasing order, as a vector (for removeParticles, setVelocities, ...).
  std::vector<std::uint32_t> ids() const {
    std::vector<std::uint32_t> out(count);
    for (std::size_t k = 0; k < count; ++k) out[k] = (*this)[k];
    return out;
  }
  /// Walks the ids in increasing order.
  class iterator {
   public:
    using iterator_category = std::forward_iterator_tag;
    using value_type = std::uint32_t;
    using difference_type = std::ptrdiff_t;
    using pointer = const std::uint32_t*;
    using reference = std::uint32_t;
    iterator() = default;
    explicit iterator(std::uint32_t id) : id_(id) {}
    std::uint32_t operator*() const { return id_; }
    iterator& operator++() {
      ++id_;
      return *this;
    }
    iterator operator++(int) {
      iterator t = *this;
      ++id_;
      return t;
    }
    bool operator==(const iterator& o) const { return id_ == o.id_; }
    bool operator!=(const iterator& o) const { return id_ != o.id_; }

   private:
    std::uint32_t id_ = 0;
  };
  /// The first id.
  iterator begin() const { return iterator(first); }
  /// One past the last id.
  iterator end() const { return iterator(first + std::uint32_t(count)); }
};

}  // namespace sph2d
