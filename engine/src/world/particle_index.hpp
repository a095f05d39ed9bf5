// particle_index.hpp (internal) — the World's indexes of its particles for the API's lookups:
// slots by id (World::slotOf and the bulk calls by id) and a uniform grid for the searches by
// region (World::slotsInBox, slotsInRadius, slotsInShape, idsTouching, sampleAt). Both
// are built on the first lookup after the particles changed (a step, or an edit between
// steps), so a game that never asks pays nothing (particle_index.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "core/constants.hpp"
#include "particles/particle_store.hpp"

namespace sph2d {

class ParticleIndex {
 public:
  static constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();

  /// Marks both indexes stale after a change of the particles made between steps (an add, a
  /// removal, a move): a step marks them by its count.
  void noteEdit() { ++edits_; }
  /// Forgets both (a load replaced the particles).
  void clear() {
    ids_.clear();
    ++edits_;
  }

  /// The slot of particle `id` in P, or npos: looked up, and rebuilt once when stale.
  std::size_t slotOf(const ParticleStore& P, std::uint32_t id) const;
  /// Calls f(k, slot) for each ids[k] a particle has (the id index rebuilt once first); returns
  /// how many calls returned true.
  template <class F>
  std::size_t forEachId(const ParticleStore& P, const std::vector<std::uint32_t>& ids, F&& f) const {
    rebuildIds(P);
    std::size_t n = 0;
    for (std::size_t k = 0; k < ids.size(); ++k) {
      const std::size_t i = findId(ids[k]);
      if (i != npos && f(k, i)) ++n;
    }
    return n;
  }

  /// Calls f(slot) for every particle whose position (local + origin) may lie in the world box
  /// [lo, hi] (the cells the box touches), in no particular order. `steps` is the World's step
  /// count and `cell` the grid's cell side (the kernel support).
  template <class F>
  void forCandidates(const ParticleStore& P, std::uint64_t steps, double cell, const Vec2d& origin, const Vec2d& lo,
                     const Vec2d& hi, F&& f) const {
    const Grid& g = grid(P, steps, cell);
    if (g.nx == 0) return;
    // Local = world − origin, up to rounding: the box grows by a micrometre so that a particle
    // on a cell's edge is never missed (callers test each candidate exactly).
    const double ox = origin.x(), oy = origin.y();
    const Vec2d lo2 = lo - Vec2d(1e-6, 1e-6), hi2 = hi + Vec2d(1e-6, 1e-6);
    auto at = [&](double v, double v0, long n) { return std::clamp(long(std::floor((v - v0) / g.h)), 0L, n - 1); };
    if (!(hi2.x() - ox >= g.x0 && hi2.y() - oy >= g.y0 && lo2.x() - ox <= g.x0 + double(g.nx) * g.h &&
          lo2.y() - oy <= g.y0 + double(g.ny) * g.h))
      return;  // outside the particles' bounds (or NaN)
    const long i0 = at(lo2.x() - ox, g.x0, g.nx), i1 = at(hi2.x() - ox, g.x0, g.nx);
    const long j0 = at(lo2.y() - oy, g.y0, g.ny), j1 = at(hi2.y() - oy, g.y0, g.ny);
    for (long j = j0; j <= j1; ++j)
      for (long i = i0; i <= i1; ++i) {
        const std::size_t k = std::size_t(j * g.nx + i);
        for (std::uint32_t q = g.start[k]; q < g.start[k + 1]; ++q) f(std::size_t(g.items[q]));
      }
  }

  /// The world box the search grid covers (every particle is in it); false when it has no
  /// cell (no particle).
  bool bounds(const ParticleStore& P, std::uint64_t steps, double cell, const Vec2d& origin, Vec2d& lo,
              Vec2d& hi) const {
    const Grid& g = grid(P, steps, cell);
    if (g.nx == 0) return false;
    lo = Vec2d(g.x0, g.y0) + origin;
    hi = Vec2d(g.x0 + double(g.nx) * g.h, g.y0 + double(g.ny) * g.h) + origin;
    return true;
  }

  /// Bytes the indexes hold (nothing until a game looks a particle up or searches).
  std::size_t bytes() const {
    return ids_.capacity() * sizeof(ids_[0]) +
           (grid_.start.capacity() + grid_.items.capacity()) * sizeof(std::uint32_t);
  }

 private:
  /// Cells of side `h` from (x0, y0) over the particles' bounds, slots counting-sorted by cell.
  struct Grid {
    std::uint64_t steps = ~std::uint64_t(0), edits = 0;
    std::size_t count = 0;
    double x0 = 0, y0 = 0, h = 1;
    long nx = 0, ny = 0;
    std::vector<std::uint32_t> start, items;  ///< cell k holds items[start[k] .. start[k + 1])
  };
  /// The grid of the current particles (rebuilt when stale).
  const Grid& grid(const ParticleStore& P, std::uint64_t steps, double cell) const;
  /// Rebuilds the id index from P.
  void rebuildIds(const ParticleStore& P) const;
  /// The slot the id index holds for `id`, or npos.
  std::size_t findId(std::uint32_t id) const;

  std::uint64_t edits_ = 0;
  /// (id, slot) of every particle sorted by id; mutable: a lookup on a const World refreshes it.
  mutable std::vector<std::pair<std::uint32_t, std::uint32_t>> ids_;
  mutable Grid grid_;
};

}  // namespace sph2d
