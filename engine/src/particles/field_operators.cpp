// NeighbourSearch::build — the uniform grid of sph2d/field_operators.hpp.
#include "particles/field_operators.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace sph2d {

template <class P>
void NeighbourSearch::buildImpl(const P* x, std::size_t n, double radius) {
  using S = typename P::Scalar;
  if (!(radius > 0) || !std::isfinite(radius)) throw std::invalid_argument("NeighbourSearch: radius must be positive");
  if (n >= std::size_t(std::numeric_limits<std::uint32_t>::max()))
    throw std::invalid_argument("NeighbourSearch: too many points");
  radius_ = radius;
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0, maxAbs = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double px = double(x[i].x()), py = double(x[i].y());
    if (!std::isfinite(px) || !std::isfinite(py))
      throw std::invalid_argument("NeighbourSearch: position " + std::to_string(i) + " is not finite");
    if (i == 0) {
      x0 = x1 = px;
      y0 = y1 = py;
    }
    x0 = std::min(x0, px);
    y0 = std::min(y0, py);
    x1 = std::max(x1, px);
    y1 = std::max(y1, py);
    maxAbs = std::max(maxAbs, std::max(std::fabs(px), std::fabs(py)));
  }
  // Callers measure distances in the positions' own precision: x_i − x_j can be
  // off by a few ulps of the coordinates, so the cell gets that margin on top of
  // the radius (and a relative 1e-9 for the cell arithmetic below).
  const double eps = double(std::numeric_limits<S>::epsilon());
  double c = radius * (1 + 1e-9) + 8 * eps * (maxAbs + radius);
  loX_ = x0;
  loY_ = y0;
  const double ex = x1 - x0, ey = y1 - y0;
  const double maxCells = std::max(4.0 * double(n), 4096.0);
  for (;;) {
    const double cx = std::floor(ex / c) + 1, cy = std::floor(ey / c) + 1;
    if (cx * cy <= maxCells) break;
    c *= std::sqrt(cx * cy / maxCells) * 1.01;  // too many cells: grow them (still exact)
  }
  cell_ = c;
  invCell_ = 1 / c;
  nx_ = int(std::floor(ex * invCell_)) + 1;
  ny_ = int(std::floor(ey * invCell_)) + 1;
  const std::size_t cells = std::size_t(nx_) * std::size_t(ny_);

  // Stable counting sort of point indices by cell.
  std::vector<std::uint32_t> cellOf(n);
  for (std::size_t i = 0; i < n; ++i)
    cellOf[i] = std::uint32_t(coord(double(x[i].y()), loY_, ny_)) * std::uint32_t(nx_) +
                std::uint32_t(coord(double(x[i].x()), loX_, nx_));
  cellStart_.assign(cells + 1, 0);
  for (std::size_t i = 0; i < n; ++i) ++cellStart_[cellOf[i] + 1];
  for (std::size_t k = 0; k < cells; ++k) cellStart_[k + 1] += cellStart_[k];
  std::vector<std::uint32_t> cursor(cellStart_.begin(), cellStart_.end() - 1);
  sorted_.resize(n);
  for (std::size_t i = 0; i < n; ++i) sorted_[cursor[cellOf[i]]++] = std::uint32_t(i);
}

template void NeighbourSearch::buildImpl<Vec2>(const Vec2*, std::size_t, double);
template void NeighbourSearch::buildImpl<Vec2d>(const Vec2d*, std::size_t, double);

}  // namespace sph2d
