// grid.hpp (internal) — the uniform neighbour grid.
//
// Built every substep by a stable counting sort of particle indices by cell
// (no hash map, no allocation once the buffers have grown). The cell size is
// at least R/reach, so every neighbour within R lies in the (2·reach+1)² block
// of cells around a particle; in a row those cells are adjacent in the sorted
// array, so a neighbour query is 2·reach+1 contiguous ranges. reach = 2
// (cells of R/2) scans about 30 % fewer candidates than reach = 1.
// Positions outside the grid's box are impossible (the box is the particles'
// bounding box); if the box would need more than `maxCells` cells, the cell
// size grows instead, which keeps the search exact.
//
// Reads: positions. Writes: cellStart, sorted, cellOf.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "sph2d/math.hpp"
#include "sph2d/thread_pool.hpp"

namespace sph2d {

struct Grid {
  Real cell = 1, invCell = 1;
  int reach = 1;  ///< cells per support radius: a query spans (2·reach + 1)² cells
  Vec2 lo = Vec2::Zero();
  int nx = 1, ny = 1;
  std::vector<std::uint32_t> cellStart;  ///< nx·ny + 1 offsets into sorted
  std::vector<std::uint32_t> sorted;     ///< particle indices in cell order (stable)
  std::vector<std::uint32_t> cellOf;     ///< cell of each particle

  /// Rebuilds the grid over positions x[0..n) for neighbours within `support`,
  /// with cells of at least support / cellsPerSupport.
  void build(const Vec2* x, std::size_t n, Real support, ThreadPool& pool, int cellsPerSupport = 1);

  /// Cell coordinate along one axis, clamped into the grid.
  int coord(Real v, Real origin, int count) const {
    Real c = std::floor((v - origin) * invCell);
    c = std::min(std::max(c, Real(0)), Real(count - 1));
    return static_cast<int>(c);
  }

  /// Calls f(begin, end) for each row of cells around p: positions
  /// begin..end of `sorted` (up to 2·reach + 1 ranges, in a fixed order).
  template <class F>
  void forCandidateRanges(const Vec2& p, F&& f) const {
    const int cx = coord(p.x(), lo.x(), nx), cy = coord(p.y(), lo.y(), ny);
    const int x0 = std::max(cx - reach, 0), x1 = std::min(cx + reach, nx - 1);
    const int y0 = std::max(cy - reach, 0), y1 = std::min(cy + reach, ny - 1);
    for (int y = y0; y <= y1; ++y) {
      const std::uint32_t b = cellStart[std::size_t(y) * nx + x0], e = cellStart[std::size_t(y) * nx + x1 + 1];
      if (b < e) f(b, e);
    }
  }

  /// Calls f(j) for every particle j in the cells around p, in a fixed order.
  template <class F>
  void forCandidates(const Vec2& p, F&& f) const {
    forCandidateRanges(p, [&](std::uint32_t b, std::uint32_t e) {
      for (std::uint32_t k = b; k < e; ++k) f(sorted[k]);
    });
  }

  std::vector<std::uint32_t> scratch_;  ///< counting-sort cursors (kept to avoid allocation)
};

}  // namespace sph2d
