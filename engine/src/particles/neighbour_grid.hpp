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
// A periodic axis (PeriodicBox) spans exactly its period with a whole number
// of cells (at least 2·reach + 1, so no cell is visited twice), and a query's
// cells wrap around it: a row's range that crosses the seam becomes two.
//
// Reads: positions. Writes: cellStart, sorted, cellOf.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/thread_pool.hpp"
#include "sph2d/math.hpp"

namespace sph2d {

/// The periodic box in the local frame (scene.hpp's PeriodicDef): pair
/// differences take the nearest image. Positions lie in [lo, lo + L).
struct PeriodicBox {
  bool x = false, y = false;
  Vec2 lo = Vec2::Zero();
  Real lx = 0, ly = 0;  ///< periods (0 on a non-periodic axis)
  /// True when some axis wraps.
  bool any() const { return x || y; }
  /// Turns a difference of two positions inside the box into its nearest image.
  void nearest(Real& dx, Real& dy) const {
    if (x) dx = dx > Real(0.5) * lx ? dx - lx : (dx < Real(-0.5) * lx ? dx + lx : dx);
    if (y) dy = dy > Real(0.5) * ly ? dy - ly : (dy < Real(-0.5) * ly ? dy + ly : dy);
  }
  /// The nearest image of a − b.
  Vec2 delta(const Vec2& a, const Vec2& b) const {
    Real dx = a.x() - b.x(), dy = a.y() - b.y();
    nearest(dx, dy);
    return Vec2(dx, dy);
  }
  /// Moves p into [lo, lo + L) on each periodic axis; returns the shift applied.
  Vec2 wrap(Vec2& p) const {
    Vec2 s = Vec2::Zero();
    if (x) s.x() = shiftInto(p.x(), lo.x(), lx);
    if (y) s.y() = shiftInto(p.y(), lo.y(), ly);
    return s;
  }

 private:
  static Real shiftInto(Real& v, Real l, Real L) {
    const Real before = v;
    if (v >= l && v < l + L) return 0;
    v -= L * std::floor((v - l) / L);
    if (!(v < l + L)) v = l;  // rounding put it on the upper edge
    if (!(v >= l)) v = l;
    return v - before;
  }
};

struct Grid {
  Real cell = 1, invCell = 1;  ///< cell width (x); also the height unless y is periodic
  Real invCellY = 1;           ///< 1 / cell height
  int reach = 1;               ///< cells per support radius: a query spans (2·reach + 1)² cells
  Vec2 lo = Vec2::Zero();
  int nx = 1, ny = 1;
  bool wrapX = false, wrapY = false;     ///< periodic axes
  std::vector<std::uint32_t> cellStart;  ///< nx·ny + 1 offsets into sorted
  std::vector<std::uint32_t> sorted;     ///< particle indices in cell order (stable)
  std::vector<std::uint32_t>
      cellOf;  ///< cell of each slot at the build (stageGrid does not permute it: only the next build reads it)
  bool inOrder = false;  ///< sorted[k] == k: the particles were just reordered along the grid (stageGrid)

  /// Rebuilds the grid over positions x[0..n) for neighbours within `support`,
  /// with cells of at least support / cellsPerSupport.
  /// With `periodic` (may be null), its axes wrap.
  void build(const Vec2* x, std::size_t n, Real support, ThreadPool& pool, int cellsPerSupport = 1,
             const PeriodicBox* periodic = nullptr);

  /// Cell coordinate along one axis (inverse cell size `inv`), clamped into the grid.
  static int coord(Real v, Real origin, Real inv, int count) {
    // Clamped first, then truncated: for c ≥ 0 truncation is floor, without a libm call.
    Real c = (v - origin) * inv;
    c = std::min(std::max(c, Real(0)), Real(count - 1));
    return static_cast<int>(c);
  }

  /// Sorts the slots by cellOf (stable) into sorted and cellStart, over `cells` cells.
  void countingSort(std::size_t cells, ThreadPool& pool);

  /// Calls f(begin, end) for each row of cells around p: positions
  /// begin..end of `sorted` (up to 2·reach + 1 ranges, in a fixed order).
  template <class F>
  void forCandidateRanges(const Vec2& p, F&& f) const {
    const int cx = coord(p.x(), lo.x(), invCell, nx), cy = coord(p.y(), lo.y(), invCellY, ny);
    if (wrapX || wrapY) return wrappedRanges(cx, cy, f);
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

 private:
  template <class F>
  void wrappedRanges(int cx, int cy, F& f) const {
    auto row = [&](int y, int x0, int x1) {
      const std::uint32_t b = cellStart[std::size_t(y) * nx + x0], e = cellStart[std::size_t(y) * nx + x1 + 1];
      if (b < e) f(b, e);
    };
    for (int dy = -reach; dy <= reach; ++dy) {
      int y = cy + dy;
      if (wrapY) {
        y = y < 0 ? y + ny : (y >= ny ? y - ny : y);
      } else if (y < 0 || y >= ny) {
        continue;
      }
      const int x0 = cx - reach, x1 = cx + reach;
      if (!wrapX) {
        row(y, std::max(x0, 0), std::min(x1, nx - 1));
      } else if (x0 < 0) {
        row(y, x0 + nx, nx - 1);
        row(y, 0, x1);
      } else if (x1 >= nx) {
        row(y, x0, nx - 1);
        row(y, 0, x1 - nx);
      } else {
        row(y, x0, x1);
      }
    }
  }
};

}  // namespace sph2d
