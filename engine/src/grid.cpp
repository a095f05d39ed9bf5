#include "grid.hpp"

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
      n, 4096, init,
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
      [](Box a, Box b) { return Box{std::min(a.x0, b.x0), std::min(a.y0, b.y0), std::max(a.x1, b.x1), std::max(a.y1, b.y1)}; });

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
  pool.parallelFor(n, 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i)
      cellOf[i] = std::uint32_t(coord(x[i].y(), lo.y(), invCellY, ny)) * std::uint32_t(nx) +
                  std::uint32_t(coord(x[i].x(), lo.x(), invCell, nx));
  });
  // Stable counting sort (serial: it is a few ms at a million particles).
  cellStart.assign(cells + 1, 0);
  for (std::size_t i = 0; i < n; ++i) ++cellStart[cellOf[i] + 1];
  for (std::size_t c = 0; c < cells; ++c) cellStart[c + 1] += cellStart[c];
  sorted.resize(n);
  // cellStart[c + 1] is the end of cell c: filled from the last particle down (stable),
  // it becomes the start of cell c, and one shift puts the starts in place (no cursor
  // array: the grid holds only cellStart, sorted and cellOf).
  for (std::size_t i = n; i-- > 0;) sorted[--cellStart[cellOf[i] + 1]] = std::uint32_t(i);
  for (std::size_t c = 0; c < cells; ++c) cellStart[c] = cellStart[c + 1];
  cellStart[cells] = std::uint32_t(n);
}

}  // namespace sph2d
