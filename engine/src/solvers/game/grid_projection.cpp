// The coarse-grid pressure projection (grid_projection.hpp): the grid's layout, the cells'
// classification and the particles splatted to cells and faces; the projection's order
// (project) and its saved state. Body coupling: grid_bodies.cpp; the pressure system and its
// solve: grid_solve.cpp and grid_pcg.cpp; the velocity change back to the particles: grid_transfer.cpp.
#include "solvers/game/grid_projection.hpp"
#include "bodies/moving_solid.hpp"
#include "core/state_io.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <type_traits>

namespace sph2d {

GridProjection::GridProjection(Real cellInSpacings, Real fluidFraction, Real compressionRate, Real tolerance,
                               int maxIterations, GridShift shift)
    : cellRatio_(cellInSpacings),
      fluidFraction_(fluidFraction),
      rate_(compressionRate),
      tol_(tolerance),
      maxIt_(maxIterations),
      shiftDef_(shift) {}

void GridProjection::layout(const StepContext& c) {
  const ParticleStore& P = c.P;
  const std::size_t n = P.size();
  struct Box {
    Real x0, y0, x1, y1;
  };
  const Real inf = std::numeric_limits<Real>::infinity();
  const Box init{inf, inf, -inf, -inf};
  const Box b = c.pool.reduce(
      n, kStreamBlock, init,
      [&](std::size_t s, std::size_t e) {
        Box r = init;
        for (std::size_t i = s; i < e; ++i) {
          r.x0 = std::min(r.x0, P.x[i].x());
          r.y0 = std::min(r.y0, P.x[i].y());
          r.x1 = std::max(r.x1, P.x[i].x());
          r.y1 = std::max(r.y1, P.x[i].y());
        }
        return r;
      },
      [](Box a, Box q) {
        return Box{std::min(a.x0, q.x0), std::min(a.y0, q.y0), std::max(a.x1, q.x1), std::max(a.y1, q.y1)};
      });
  h_ = cellRatio_ * c.dx;
  // Spray far from the bulk must not make the grid huge: above the budget the cells grow.
  const double budget = std::max(16.0 * double(n), 4096.0);
  for (;;) {
    invH_ = Real(1) / h_;
    I0_ = long(std::floor(b.x0 * invH_)) - 1;
    J0_ = long(std::floor(b.y0 * invH_)) - 1;
    nx_ = int(long(std::floor(b.x1 * invH_)) + 1 - I0_ + 1);
    ny_ = int(long(std::floor(b.y1 * invH_)) + 1 - J0_ + 1);
    if (double(nx_) * double(ny_) <= budget) break;
    h_ *= Real(std::sqrt(double(nx_) * double(ny_) / budget) * 1.01);
  }
}

void GridProjection::resetCells(bool contrast) {
  // The cells' fields and the faces' flags (classify and assemble write them).
  const std::size_t cells = std::size_t(nx_) * std::size_t(ny_);
  type_.assign(cells, kAir);
  w_.assign(cells, 0);
  if (contrast) {
    wr_.assign(cells, 0);
    uBeta_.assign(std::size_t(nx_ + 1) * std::size_t(ny_), Real(1));
    vBeta_.assign(std::size_t(nx_) * std::size_t(ny_ + 1), Real(1));
  } else {
    wr_.clear();
    uBeta_.clear();
    vBeta_.clear();
  }
  comp_.assign(cells, 0);
  if (surface_) top_.assign(cells, -std::numeric_limits<Real>::infinity());
  uOpen_.assign(std::size_t(nx_ + 1) * std::size_t(ny_), 0);
  fluidU_.assign(uOpen_.size(), 0);
  vOpen_.assign(std::size_t(nx_) * std::size_t(ny_ + 1), 0);
  fluidV_.assign(vOpen_.size(), 0);
}

void GridProjection::resetFaces(int axis) {
  // One axis's face velocities, weights and changes.
  const std::size_t faces =
      axis == 0 ? std::size_t(nx_ + 1) * std::size_t(ny_) : std::size_t(nx_) * std::size_t(ny_ + 1);
  for (std::vector<Real>* f : axis == 0 ? std::array<std::vector<Real>*, 4>{&u_, &uw_, &du_, &uNew_}
                                        : std::array<std::vector<Real>*, 4>{&v_, &vw_, &dv_, &vNew_})
    f->assign(faces, 0);
}

std::uint8_t GridProjection::cacheEntry(const StepContext& c, long I, long J) {
  const bool inside = I >= cI0_ && J >= cJ0_ && I < cI0_ + cnx_ && J < cJ0_ + cny_;
  std::uint8_t* slot = inside ? &cache_[std::size_t(J - cJ0_) * cnx_ + std::size_t(I - cI0_)] : nullptr;
  if (slot && (*slot & 1)) return *slot;
  const Vec2 ctr((Real(I) + Real(0.5)) * h_, (Real(J) + Real(0.5)) * h_);
  std::uint8_t e = 1;
  if (c.boundary.insideDepth(ctr) > 0) e |= 2;
  if (c.boundary.blocks(ctr - Vec2(h_, 0), ctr)) e |= 4;
  if (c.boundary.blocks(ctr - Vec2(0, h_), ctr)) e |= 8;
  if (slot) *slot = e;
  return e;
}

void GridProjection::classify(const StepContext& c) {
  // The cache covers the grid plus one cell (the right and top faces of the last cells).
  const std::uint64_t version = c.boundaryVersion ^ std::uint64_t(std::lround(double(h_) * 1e9));
  const bool covers =
      cacheValid_ && I0_ >= cI0_ && J0_ >= cJ0_ && I0_ + nx_ + 1 <= cI0_ + cnx_ && J0_ + ny_ + 1 <= cJ0_ + cny_;
  if (!cacheValid_ || version != cacheVersion_) {
    cacheValid_ = true;
    cacheVersion_ = version;
    cI0_ = I0_ - nx_ / 2;
    cJ0_ = J0_ - ny_ / 2;
    cnx_ = 2 * nx_ + 2;
    cny_ = 2 * ny_ + 2;
    cache_.assign(std::size_t(cnx_) * cny_, 0);
  } else if (!covers) {  // grow to the union (with room), keeping what is known
    const long nI0 = std::min(cI0_, I0_ - nx_ / 2), nJ0 = std::min(cJ0_, J0_ - ny_ / 2);
    const long nI1 = std::max(cI0_ + cnx_, I0_ + nx_ + 1 + nx_ / 2),
               nJ1 = std::max(cJ0_ + cny_, J0_ + ny_ + 1 + ny_ / 2);
    std::vector<std::uint8_t> grown(std::size_t(nI1 - nI0) * std::size_t(nJ1 - nJ0), 0);
    for (int j = 0; j < cny_; ++j)
      for (int i = 0; i < cnx_; ++i)
        grown[std::size_t(cJ0_ + j - nJ0) * std::size_t(nI1 - nI0) + std::size_t(cI0_ + i - nI0)] =
            cache_[std::size_t(j) * cnx_ + i];
    cache_.swap(grown);
    cI0_ = nI0;
    cJ0_ = nJ0;
    cnx_ = int(nI1 - nI0);
    cny_ = int(nJ1 - nJ0);
  }
  // Cell (i, j) of the grid (−1 ≤ i ≤ nx, −1 ≤ j ≤ ny) from the cache, computed when not yet known.
  std::uint8_t* const base = cache_.data() + std::size_t(J0_ - cJ0_) * std::size_t(cnx_) + std::size_t(I0_ - cI0_);
  auto entry = [&](int i, int j) {
    const std::uint8_t e = base[std::ptrdiff_t(j) * cnx_ + i];
    return (e & 1) ? e : cacheEntry(c, I0_ + i, J0_ + j);
  };
  const Real full = cellRatio_ * cellRatio_;  // particle weight of a full cell
  for (int j = 1; j + 1 < ny_; ++j)           // border cells stay air (solid neighbours are marked below)
    for (int i = 1; i + 1 < nx_; ++i) {
      const std::size_t k = std::size_t(j) * nx_ + i;
      if (!(w_[k] > 0)) continue;  // empty cells stay air
      const std::uint8_t e = entry(i, j);
      type_[k] = (e & 2) ? kSolid : (w_[k] >= fluidFraction_ * full ? kFluid : kAir);
    }
  markBodies(c);
  // Faces of fluid cells: open unless blocked; the neighbour's solidity from the cache.
  for (int j = 0; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) {
      const std::size_t k = std::size_t(j) * nx_ + i;
      if (type_[k] != kFluid) continue;
      const std::uint8_t e = entry(i, j);
      const std::uint8_t eR = entry(i + 1, j);
      const std::uint8_t eT = entry(i, j + 1);
      uOpen_[std::size_t(j) * (nx_ + 1) + i] = !(e & 4);
      uOpen_[std::size_t(j) * (nx_ + 1) + i + 1] = !(eR & 4);
      vOpen_[std::size_t(j) * nx_ + i] = !(e & 8);
      vOpen_[std::size_t(j + 1) * nx_ + i] = !(eT & 8);
      // A face beside a solid cell is closed, whatever the segment between the centres met: with
      // a floor at a cell centre's height, the solid cell's centre, computed from the cell above
      // as its centre less h, can round onto the surface (0.1 with cells of 0.04: 0.099999994 as
      // its own, 0.100000001 from above), the segment then only touched the surface, and the
      // open face let the column above stand on nothing (resting water fell at g·dt every
      // substep, held up by the collisions alone: tests/engine/solvers/game/test_grid_projection.cpp).
      if (i > 0 && (entry(i - 1, j) & 2)) {
        type_[k - 1] = kSolid;
        uOpen_[std::size_t(j) * (nx_ + 1) + i] = 0;
      }
      if (i + 1 < nx_ && (eR & 2)) {
        type_[k + 1] = kSolid;
        uOpen_[std::size_t(j) * (nx_ + 1) + i + 1] = 0;
      }
      if (j > 0 && (entry(i, j - 1) & 2)) {
        type_[k - nx_] = kSolid;
        vOpen_[std::size_t(j) * nx_ + i] = 0;
      }
      if (j + 1 < ny_ && (eT & 2)) {
        type_[k + nx_] = kSolid;
        vOpen_[std::size_t(j + 1) * nx_ + i] = 0;
      }
    }
}

namespace {
/// Adds the bilinear weights at (fx, fy), in the units of a field `stride` wide, to
/// `weight`, and `value` times them to `sum` when given (fx, fy ≥ 0: the grid has a
/// margin, so truncation is floor).
inline void splat(Real* sum, std::vector<Real>& weight, int stride, Real fx, Real fy, Real value) {
  const int i0 = int(fx), j0 = int(fy);
  const Real tx = fx - Real(i0), ty = fy - Real(j0);
  const Real wq[4] = {(1 - tx) * (1 - ty), tx * (1 - ty), (1 - tx) * ty, tx * ty};
  const std::size_t k = std::size_t(j0) * std::size_t(stride) + std::size_t(i0);
  const std::size_t ks[4] = {k, k + 1, k + std::size_t(stride), k + std::size_t(stride) + 1};
  for (int q = 0; q < 4; ++q) {
    if (sum) sum[ks[q]] += wq[q] * value;
    weight[ks[q]] += wq[q];
  }
}
}  // namespace

void GridProjection::splatCells(const StepContext& c) {
  // Serial in slot order (the same bits for any thread count).
  const ParticleStore& P = c.P;
  const Real rho0 = c.rho0;
  // The cells' SPH compression is read only by the compression source; with a density
  // contrast it counts particles (ρ_i/(r_i ρ0)), and the cells' rest ratios are splatted too.
  Real* comp = rate_ > 0 ? comp_.data() : nullptr;
  const std::vector<Real>* ratioField = wr_.empty() ? nullptr : P.find(ParticleStore::kRestRatio);
  const Real* ratio = ratioField ? ratioField->data() : nullptr;
  // The loop, compiled once with a density contrast and once without.
  auto loop = [&](auto contrastTag) {
    constexpr bool kContrast = decltype(contrastTag)::value;
    for (std::size_t p = 0; p < P.size(); ++p) {
      const Real px = P.x[p].x() * invH_ - Real(I0_), py = P.x[p].y() * invH_ - Real(J0_);
      Real compression;
      if constexpr (kContrast)
        compression = P.rho[p] / (rho0 * ratio[p]) - Real(1);
      else
        compression = P.rho[p] / rho0 - Real(1);
      splat(comp, w_, nx_, px - Real(0.5), py - Real(0.5), compression);  // cell centres
      if constexpr (kContrast) {                                          // Σ w r with splat()'s weights
        const Real fx = px - Real(0.5), fy = py - Real(0.5);
        const int i0 = int(fx), j0 = int(fy);
        const Real tx = fx - Real(i0), ty = fy - Real(j0);
        const std::size_t k = std::size_t(j0) * std::size_t(nx_) + std::size_t(i0);
        wr_[k] += (1 - tx) * (1 - ty) * ratio[p];
        wr_[k + 1] += tx * (1 - ty) * ratio[p];
        wr_[k + std::size_t(nx_)] += (1 - tx) * ty * ratio[p];
        wr_[k + std::size_t(nx_) + 1] += tx * ty * ratio[p];
      }
      if (surface_) {  // the highest particle of each cell (the ghost surface's height)
        const std::size_t k = std::size_t(int(py)) * std::size_t(nx_) + std::size_t(int(px));
        top_[k] = std::max(top_[k], P.x[p].y());
      }
    }
  };
  if (ratio)
    loop(std::true_type{});
  else
    loop(std::false_type{});
}

void GridProjection::splatFaces(const StepContext& c, int axis) {
  // Serial in slot order (the same bits for any thread count); then the mean velocity.
  const ParticleStore& P = c.P;
  std::vector<Real>& f = axis == 0 ? u_ : v_;
  std::vector<Real>& fw = axis == 0 ? uw_ : vw_;
  for (std::size_t p = 0; p < P.size(); ++p) {
    const Real px = P.x[p].x() * invH_ - Real(I0_), py = P.x[p].y() * invH_ - Real(J0_);
    if (axis == 0)
      splat(f.data(), fw, nx_ + 1, px, py - Real(0.5), P.v[p].x());  // u faces at (i, j + 1/2)
    else
      splat(f.data(), fw, nx_, px - Real(0.5), py, P.v[p].y());  // v faces at (i + 1/2, j)
  }
  for (std::size_t k = 0; k < f.size(); ++k)
    if (fw[k] > 0) f[k] /= fw[k];
  // A face no particle reaches (fluid cells are made by their neighbours' weight too) takes
  // the mean of its neighbours that one reaches: read as 0 it made the divergence of a
  // fluid cell moving with the flow, and the pressure that removed it slowed the fluid (a free
  // blob lost 7 % of its momentum a second; docs/notes/free-blob-momentum.md).
  std::vector<std::uint8_t>& known = axis == 0 ? uKnown_ : vKnown_;
  known.resize(f.size());
  for (std::size_t k = 0; k < f.size(); ++k) known[k] = fw[k] > 0;
  if (axis == 0)
    extrapolate(f, nx_ + 1, ny_, known);
  else
    extrapolate(f, nx_, ny_ + 1, known);
}

std::size_t GridProjection::project(StepContext& c) {
  if (c.P.size() == 0 || !(c.dt > 0)) return kNone;
  dx_ = c.dx;
  layout(c);
  // The cells' particle weights decide the cell types and the matrix; the face
  // velocities are read only by the solve. Three tasks, each serial: the cells with the
  // classification and the matrix (the longest), the u faces, the v faces.
  c.pool.parallelFor(3, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t task = b; task < e; ++task) {
      if (task == 0) {
        resetCells(c.P.find(ParticleStore::kRestRatio) != nullptr);
        splatCells(c);
        classify(c);
        assemble();
      } else {
        resetFaces(int(task) - 1);
        splatFaces(c, int(task) - 1);
      }
    }
  });
  solve(c);
  return transferToParticles(c);
}

void GridProjection::saveState(StateOut& out) const {
  out.put(pH_);
  out.put(std::int64_t(pI0_));
  out.put(std::int64_t(pJ0_));
  out.put(std::int32_t(pnx_));
  out.put(std::int32_t(pny_));
  out.putVector(prevKappa_);
}

void GridProjection::loadState(StateIn& in, std::size_t maxCells) {
  const Real h = in.get<Real>("the grid's cell size");
  const std::int64_t i0 = in.get<std::int64_t>("the grid's origin"), j0 = in.get<std::int64_t>("the grid's origin");
  const std::int32_t nx = in.get<std::int32_t>("the grid's size"), ny = in.get<std::int32_t>("the grid's size");
  std::vector<Real> k;
  in.getVector(k, maxCells, "the grid's pressure");
  if (!(h >= 0) || nx < 0 || ny < 0 || std::uint64_t(nx) * std::uint64_t(ny) != k.size())
    throw SaveError("the saved state is malformed: the grid's pressure does not fit its size");
  pH_ = h;
  pI0_ = long(i0);
  pJ0_ = long(j0);
  pnx_ = nx;
  pny_ = ny;
  prevKappa_ = std::move(k);
}

}  // namespace sph2d
