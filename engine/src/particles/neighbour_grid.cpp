#include "particles/neighbour_grid.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace sph2d {

void Grid::build(const Vec2* x, std::size_t n, Real support, ThreadPool& pool, int cellsPerSupport,
                 const PeriodicBox* periodic) {
  reach = std::max(1, cellsPerSupport);
  const Real minCell = support / Real(reach);
  struct Box {
    Real x0, y0, x1, y1;
  };
  const Real inf = std::numeric_limits<Real>::infinity();
  const Box init{inf, inf, -inf, -inf};
  const Box box = pool.reduce(
      n, 1024, init,
      [&](std::size_t b, std::size_t e) {
        Box bx = init;
        for (std::size_t i = b; i < e; ++i) {
          bx.x0 = std::min(bx.x0, x[i].x());
          bx.y0 = std::min(bx.y0, x[i].y());
          bx.x1 = std::max(bx.x1, x[i].x());
          bx.y1 = std::max(bx.y1, x[i].y());
        }
        return bx;
      },
      [](Box a, Box b) {
        return Box{std::min(a.x0, b.x0), std::min(a.y0, b.y0), std::max(a.x1, b.x1), std::max(a.y1, b.y1)};
      });

  cell = minCell;
  if (n == 0) {
    lo = Vec2::Zero();
    nx = ny = 1;
  } else {
    lo = Vec2(box.x0, box.y0);
    const double ex = double(box.x1) - double(box.x0), ey = double(box.y1) - double(box.y0);
    const double maxCells = std::max<double>(16.0 * double(n), 4096.0);
    const bool px = periodic && periodic->x, py = periodic && periodic->y;
    double c = minCell;
    for (;;) {
      // A periodic axis spans its whole period (however few particles it holds).
      const double cx = px ? std::floor(double(periodic->lx) / c) : std::floor(ex / c) + 1;
      const double cy = py ? std::floor(double(periodic->ly) / c) : std::floor(ey / c) + 1;
      if (cx * cy <= maxCells) break;
      c *= std::sqrt(cx * cy / maxCells) * 1.01;
    }
    cell = static_cast<Real>(c);
    if (cell < minCell) cell = minCell;
    invCell = Real(1) / cell;
    nx = static_cast<int>(std::floor(ex * invCell)) + 1;
    ny = static_cast<int>(std::floor(ey * invCell)) + 1;
  }
  invCell = Real(1) / cell;
  invCellY = invCell;
  wrapX = n > 0 && periodic && periodic->x;  // an empty grid has nothing to wrap
  wrapY = n > 0 && periodic && periodic->y;
  if (wrapX || wrapY) {
    // A periodic axis: the period in a whole number of cells of at least
    // minCell (the loader guarantees a period of at least 3 R, so at least
    // 2·reach + 1 cells and no cell is visited twice by one query).
    const Real c = cell;
    if (wrapX) {
      nx = std::max(2 * reach + 1, static_cast<int>(std::floor(periodic->lx / c)));
      lo.x() = periodic->lo.x();
      cell = periodic->lx / Real(nx);
      invCell = Real(nx) / periodic->lx;
    }
    if (wrapY) {
      ny = std::max(2 * reach + 1, static_cast<int>(std::floor(periodic->ly / c)));
      lo.y() = periodic->lo.y();
      invCellY = Real(ny) / periodic->ly;
    } else {
      // y keeps cells of the original size c over the bounding box.
      invCellY = Real(1) / c;
      if (n == 0) ny = 1;
    }
  }
  const std::size_t cells = std::size_t(nx) * std::size_t(ny);

  inOrder = false;
  cellOf.resize(n);
  pool.parallelFor(n, 1024, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i)
      cellOf[i] = std::uint32_t(coord(x[i].y(), lo.y(), invCellY, ny)) * std::uint32_t(nx) +
                  std::uint32_t(coord(x[i].x(), lo.x(), invCell, nx));
  });
  countingSort(cells, pool);
}

void Grid::countingSort(std::size_t cells, ThreadPool& pool) {
  // Stable counting sort of the slots by cellOf. The cells are cut into one band of
  // consecutive cells per thread; each thread reads every cellOf and counts, places and
  // shifts only its own band's cells, so no two threads write one entry, and the result (the
  // one stable order) is the same for any number of bands. The bands' edges are the cells of
  // evenly spaced slots: the particles were put in cell order at the last reordering, so the
  // bands hold about as many particles each.
  const std::size_t n = cellOf.size();
  if (cellStart.capacity() < cells + 1) cellStart.reserve(cells + 1);  // exactly: resize alone would double it
  cellStart.resize(cells + 1);
  sorted.resize(n);
  constexpr std::size_t kMaxBands = 64;  // on the stack: no allocation in the step
  const std::size_t bands = std::max<std::size_t>(1, std::min({std::size_t(pool.size()), n / 4096, kMaxBands}));
  std::array<std::size_t, kMaxBands + 1> band{};  // band t: cells band[t] .. band[t + 1] − 1
  for (std::size_t t = 1; t < bands; ++t)
    band[t] = std::max<std::size_t>(band[t - 1], std::min<std::size_t>(cellOf[t * n / bands], cells));
  band[bands] = cells;
  std::array<std::uint32_t, kMaxBands> total{}, edge{};
  // cellStart[c + 1] counts cell c, then (a prefix within the band) ends it within the band.
  pool.parallelFor(bands, 1, [&](std::size_t t, std::size_t) {
    const std::size_t a = band[t], w = band[t + 1] - band[t];
    std::fill(cellStart.begin() + std::ptrdiff_t(a) + 1, cellStart.begin() + std::ptrdiff_t(a + w) + 1, 0u);
    for (std::size_t i = 0; i < n; ++i)
      if (std::size_t(cellOf[i]) - a < w) ++cellStart[cellOf[i] + 1];
    for (std::size_t c = a + 1; c < a + w; ++c) cellStart[c + 1] += cellStart[c];
    total[t] = w ? cellStart[a + w] : 0;
  });
  std::uint32_t offset = 0;
  for (std::size_t t = 0; t < bands; ++t) {
    const std::uint32_t mine = total[t];
    total[t] = offset;  // now the particles before the band
    offset += mine;
  }
  // cellStart[c + 1] is the end of cell c: filled from the last particle down (stable), it
  // becomes the start of cell c (no cursor array: the grid holds only cellStart, sorted and
  // cellOf); the band's last entry, which the next band's shift overwrites, is kept aside.
  pool.parallelFor(bands, 1, [&](std::size_t t, std::size_t) {
    const std::size_t a = band[t], w = band[t + 1] - band[t];
    if (!w) return;
    for (std::size_t c = a; c < a + w; ++c) cellStart[c + 1] += total[t];
    for (std::size_t i = n; i-- > 0;)
      if (std::size_t(cellOf[i]) - a < w) sorted[--cellStart[cellOf[i] + 1]] = std::uint32_t(i);
    edge[t] = cellStart[a + w];
  });
  // One shift puts the starts in place, band by band.
  pool.parallelFor(bands, 1, [&](std::size_t t, std::size_t) {
    const std::size_t a = band[t], w = band[t + 1] - band[t];
    if (!w) return;
    for (std::size_t c = a; c + 1 < a + w; ++c) cellStart[c] = cellStart[c + 1];
    cellStart[a + w - 1] = edge[t];
  });
  cellStart[cells] = std::uint32_t(n);
}

}  // namespace sph2d
