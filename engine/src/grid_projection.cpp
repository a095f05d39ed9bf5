// The coarse-grid pressure projection (grid_projection.hpp).
#include "grid_projection.hpp"
#include "state_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

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
  const Particles& P = c.P;
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
      [](Box a, Box q) { return Box{std::min(a.x0, q.x0), std::min(a.y0, q.y0), std::max(a.x1, q.x1), std::max(a.y1, q.y1)}; });
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
  const std::size_t cells = std::size_t(nx_) * std::size_t(ny_);
  type_.assign(cells, kAir);
  w_.assign(cells, 0);
  comp_.assign(cells, 0);
  kappa_.assign(cells, 0);
  index_.assign(cells, -1);
  u_.assign(std::size_t(nx_ + 1) * ny_, 0);
  uw_.assign(u_.size(), 0);
  du_.assign(u_.size(), 0);
  uNew_.assign(u_.size(), 0);
  uOpen_.assign(u_.size(), 0);
  fluidU_.assign(u_.size(), 0);
  v_.assign(std::size_t(nx_) * (ny_ + 1), 0);
  vw_.assign(v_.size(), 0);
  dv_.assign(v_.size(), 0);
  vNew_.assign(v_.size(), 0);
  vOpen_.assign(v_.size(), 0);
  fluidV_.assign(v_.size(), 0);
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
  const bool covers = cacheValid_ && I0_ >= cI0_ && J0_ >= cJ0_ && I0_ + nx_ + 1 <= cI0_ + cnx_ &&
                      J0_ + ny_ + 1 <= cJ0_ + cny_;
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
    const long nI1 = std::max(cI0_ + cnx_, I0_ + nx_ + 1 + nx_ / 2), nJ1 = std::max(cJ0_ + cny_, J0_ + ny_ + 1 + ny_ / 2);
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
  const Real full = cellRatio_ * cellRatio_;  // particle weight of a full cell
  for (int j = 0; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) {
      const std::size_t k = std::size_t(j) * nx_ + i;
      const bool border = i == 0 || j == 0 || i == nx_ - 1 || j == ny_ - 1;
      if (!(w_[k] > 0) || border) continue;  // empty and border cells stay air (solid neighbours are marked below)
      const std::uint8_t e = cacheEntry(c, I0_ + i, J0_ + j);
      type_[k] = (e & 2) ? kSolid : (w_[k] >= fluidFraction_ * full ? kFluid : kAir);
    }
  // Faces of fluid cells: open unless blocked; the neighbour's solidity from the cache.
  for (int j = 0; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) {
      const std::size_t k = std::size_t(j) * nx_ + i;
      if (type_[k] != kFluid) continue;
      const std::uint8_t e = cacheEntry(c, I0_ + i, J0_ + j);
      const std::uint8_t eR = cacheEntry(c, I0_ + i + 1, J0_ + j);
      const std::uint8_t eT = cacheEntry(c, I0_ + i, J0_ + j + 1);
      uOpen_[std::size_t(j) * (nx_ + 1) + i] = !(e & 4);
      uOpen_[std::size_t(j) * (nx_ + 1) + i + 1] = !(eR & 4);
      vOpen_[std::size_t(j) * nx_ + i] = !(e & 8);
      vOpen_[std::size_t(j + 1) * nx_ + i] = !(eT & 8);
      if (i > 0 && (cacheEntry(c, I0_ + i - 1, J0_ + j) & 2)) type_[k - 1] = kSolid;
      if (i + 1 < nx_ && (eR & 2)) type_[k + 1] = kSolid;
      if (j > 0 && (cacheEntry(c, I0_ + i, J0_ + j - 1) & 2)) type_[k - nx_] = kSolid;
      if (j + 1 < ny_ && (eT & 2)) type_[k + nx_] = kSolid;
    }
}

void GridProjection::transferToGrid(const StepContext& c) {
  const Particles& P = c.P;
  const Real rho0 = c.rho0;
  const int nu = nx_ + 1;
  // Adds the bilinear weights at (fx, fy), in the units of a field `stride` wide, to
  // `weight`, and `value` times them to `sum` when given (fx, fy ≥ 0: the grid has a
  // margin, so truncation is floor).
  auto splat = [](Real* sum, std::vector<Real>& weight, int stride, Real fx, Real fy, Real value) {
    const int i0 = int(fx), j0 = int(fy);
    const Real tx = fx - Real(i0), ty = fy - Real(j0);
    const Real wq[4] = {(1 - tx) * (1 - ty), tx * (1 - ty), (1 - tx) * ty, tx * ty};
    const std::size_t k = std::size_t(j0) * std::size_t(stride) + std::size_t(i0);
    const std::size_t ks[4] = {k, k + 1, k + std::size_t(stride), k + std::size_t(stride) + 1};
    for (int q = 0; q < 4; ++q) {
      if (sum) sum[ks[q]] += wq[q] * value;
      weight[ks[q]] += wq[q];
    }
  };
  // The cells' SPH compression is read only by the compression source.
  Real* comp = rate_ > 0 ? comp_.data() : nullptr;
  // Three sums, each serial in slot order (the same bits for any thread count), and
  // independent of each other: the cells, the u faces and the v faces run side by side.
  c.pool.parallelFor(3, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t task = b; task < e; ++task)
      for (std::size_t p = 0; p < P.size(); ++p) {
        const Real px = P.x[p].x() * invH_ - Real(I0_), py = P.x[p].y() * invH_ - Real(J0_);
        if (task == 0) splat(comp, w_, nx_, px - Real(0.5), py - Real(0.5), P.rho[p] / rho0 - Real(1));  // cell centres
        else if (task == 1) splat(u_.data(), uw_, nu, px, py - Real(0.5), P.v[p].x());               // u faces at (i, j + 1/2)
        else splat(v_.data(), vw_, nx_, px - Real(0.5), py, P.v[p].y());                              // v faces at (i + 1/2, j)
      }
  });
  for (std::size_t k = 0; k < u_.size(); ++k)
    if (uw_[k] > 0) u_[k] /= uw_[k];
  for (std::size_t k = 0; k < v_.size(); ++k)
    if (vw_[k] > 0) v_[k] /= vw_[k];
}

void GridProjection::assemble() {
  const int nu = nx_ + 1;
  cells_.clear();
  for (int j = 0; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) {
      const std::size_t k = std::size_t(j) * nx_ + i;
      if (type_[k] != kFluid) continue;
      index_[k] = std::int32_t(cells_.size());
      cells_.push_back(std::int32_t(k));
    }
  const std::size_t m = cells_.size();
  diag_.assign(m, 0);
  adj_.assign(4 * m, -1);
  for (std::size_t a = 0; a < m; ++a) {
    const int k = cells_[a], i = k % nx_, j = k / nx_;
    const bool open[4] = {uOpen_[std::size_t(j) * nu + i] != 0, uOpen_[std::size_t(j) * nu + i + 1] != 0,
                          vOpen_[std::size_t(j) * nx_ + i] != 0, vOpen_[std::size_t(j + 1) * nx_ + i] != 0};
    const int nb[4] = {k - 1, k + 1, k - nx_, k + nx_};
    Real dg = 0;
    for (int q = 0; q < 4; ++q) {
      if (open[q] && type_[std::size_t(nb[q])] != kSolid) dg += 1;
      adj_[4 * a + q] = open[q] ? index_[std::size_t(nb[q])] : -1;  // −1: air, solid or closed
    }
    diag_[a] = dg;
  }
  // MIC(0) (Bridson, "Fluid Simulation for Computer Graphics", 2nd ed., fig. 5.7):
  // the incomplete Cholesky factor of the 5-point Laplacian, in cell order.
  const Real tau = Real(0.97), sigma = Real(0.25);
  precon_.assign(m, 0);
  for (std::size_t a = 0; a < m; ++a) {
    if (!(diag_[a] > 0)) continue;
    Real e = diag_[a];
    const std::int32_t l = adj_[4 * a + 0], d = adj_[4 * a + 2];
    if (l >= 0) {  // A(left, a) = −1; the left cell's "plus j" entry: its up neighbour
      const Real pl = precon_[std::size_t(l)];
      const Real aUpL = adj_[4 * std::size_t(l) + 3] >= 0 ? Real(-1) : Real(0);
      e -= pl * pl + tau * (-1) * aUpL * pl * pl;
    }
    if (d >= 0) {
      const Real pd = precon_[std::size_t(d)];
      const Real aRightD = adj_[4 * std::size_t(d) + 1] >= 0 ? Real(-1) : Real(0);
      e -= pd * pd + tau * (-1) * aRightD * pd * pd;
    }
    if (e < sigma * diag_[a]) e = diag_[a];
    precon_[a] = Real(1) / std::sqrt(e);
  }
  precon2_.resize(m);
  for (std::size_t a = 0; a < m; ++a) precon2_[a] = precon_[a] * precon_[a];
}

void GridProjection::precondition(const std::vector<Real>& r, std::vector<Real>& z, std::vector<Real>& y) const {
  // z = (L Lᵀ)⁻¹ r with L = MIC(0)'s factor (p = precon_ = 1/diag(L), p2 = p²). Each
  // substitution is a chain from one cell to the next in cell order: written so that
  // the chain is one multiply and one add (the rest is computed beside it), and the
  // left neighbour's value is carried in a register.
  const std::size_t m = cells_.size();
  const Real* p = precon_.data();
  const Real* p2 = precon2_.data();
  const std::int32_t* A = adj_.data();
  y.resize(m);
  // Forward: q = L⁻¹ r, kept as z (= q) and y = q·p (what the right and up cells read).
  Real yPrev = 0;
  for (std::size_t a = 0; a < m; ++a) {
    const std::int32_t l = A[4 * a + 0], d = A[4 * a + 2];
    const Real t = r[a] + (d >= 0 ? y[std::size_t(d)] : Real(0));
    const Real yl = l < 0 ? Real(0) : (std::size_t(l) + 1 == a ? yPrev : y[std::size_t(l)]);
    z[a] = (t + yl) * p[a];
    yPrev = y[a] = t * p2[a] + yl * p2[a];
  }
  // Backward: z = L⁻ᵀ q.
  Real zNext = 0;
  for (std::size_t a = m; a-- > 0;) {
    const std::int32_t rt = A[4 * a + 1], u = A[4 * a + 3];
    const Real s = z[a] * p[a] + (u >= 0 ? z[std::size_t(u)] : Real(0)) * p2[a];
    const Real zr = rt < 0 ? Real(0) : (std::size_t(rt) == a + 1 ? zNext : z[std::size_t(rt)]);
    zNext = z[a] = s + zr * p2[a];
  }
}

void GridProjection::apply(const std::vector<Real>& in, std::vector<Real>& out) const {
  const std::size_t m = cells_.size();
  const std::int32_t* A = adj_.data();
  for (std::size_t a = 0; a < m; ++a) {
    Real s = diag_[a] * in[a];
    for (int q = 0; q < 4; ++q)
      if (A[4 * a + q] >= 0) s -= in[std::size_t(A[4 * a + q])];
    out[a] = s;
  }
}

int GridProjection::pcg(std::vector<Real>& x, const std::vector<Real>& b, Real tol, Real& res, CgWork& w) const {
  // Conjugate gradients with the MIC(0) preconditioner; sums in cell order.
  const std::size_t m = cells_.size();
  std::vector<Real>&r_ = w.r, &z_ = w.z, &d_ = w.d, &q_ = w.q;
  r_.resize(m);
  z_.resize(m);
  d_.resize(m);
  q_.resize(m);
  apply(x, q_);
  for (std::size_t a = 0; a < m; ++a) r_[a] = b[a] - q_[a];
  auto worst = [&] {
    Real mx = 0;
    for (std::size_t a = 0; a < m; ++a) mx = std::max(mx, std::fabs(r_[a]));
    return mx;
  };
  double rz = 0;
  precondition(r_, z_, w.y);
  for (std::size_t a = 0; a < m; ++a) {
    d_[a] = z_[a];
    rz += double(r_[a]) * double(z_[a]);
  }
  int it = 0;
  res = worst();
  while (it < maxIt_ && res > tol && rz > 0) {
    apply(d_, q_);
    double dq = 0;
    for (std::size_t a = 0; a < m; ++a) dq += double(d_[a]) * double(q_[a]);
    if (!(dq > 0)) break;
    const Real alpha = Real(rz / dq);
    for (std::size_t a = 0; a < m; ++a) {
      x[a] += alpha * d_[a];
      r_[a] -= alpha * q_[a];
    }
    double rzNew = 0;
    precondition(r_, z_, w.y);
    for (std::size_t a = 0; a < m; ++a) rzNew += double(r_[a]) * double(z_[a]);
    const Real beta = Real(rzNew / rz);
    rz = rzNew;
    for (std::size_t a = 0; a < m; ++a) d_[a] = z_[a] + beta * d_[a];
    ++it;
    res = worst();
  }
  return it;
}

void GridProjection::solve(const StepContext& c) {
  const Real dt = c.dt;
  const int nu = nx_ + 1;
  const std::size_t m = cells_.size();
  stats_ = GridProjectionStats{};
  stats_.fluidCells = int(m);
  if (m == 0) return;
  rhs_.assign(m, 0);
  std::vector<Real>& x = x_;  // the unknowns, in cell order (kept: no allocation in the step)
  x.assign(m, 0);
  // Warm start from the last substep's κ of the same anchored cells (none when the cells
  // grew to hold spray: the same index is then another place).
  const bool sameCells = h_ == pH_;
  for (std::size_t a = 0; a < m; ++a) {
    const int i = cells_[a] % nx_, j = cells_[a] / nx_;
    const long I = I0_ + i - pI0_, J = J0_ + j - pJ0_;
    if (sameCells && I >= 0 && J >= 0 && I < pnx_ && J < pny_) x[a] = prevKappa_[std::size_t(J) * pnx_ + std::size_t(I)];
  }
  auto uf = [&](int i, int j) { return uOpen_[std::size_t(j) * nu + i] ? u_[std::size_t(j) * nu + i] : Real(0); };
  auto vf = [&](int i, int j) { return vOpen_[std::size_t(j) * nx_ + i] ? v_[std::size_t(j) * nx_ + i] : Real(0); };
  for (std::size_t a = 0; a < m; ++a) {
    const int k = cells_[a], i = k % nx_, j = k / nx_;
    const Real div = (uf(i + 1, j) - uf(i, j) + vf(i, j + 1) - vf(i, j)) * invH_;
    const Real comp = std::max(Real(0), comp_[std::size_t(k)] / w_[std::size_t(k)]);
    const Real src = div - rate_ * comp / dt;  // a compressed cell is to expand by rate·comp over the substep
    rhs_[a] = -(h_ * h_ / dt) * src;
  }
  // The compression shift's right-hand side: −∇²φ = rate·(comp − above)/dt² per fluid cell,
  // comp = the cell's particle weight over a full cell's, − 1 (a count, as Kugelstadt et al.:
  // the SPH density of a disordered packing reads high, and removing that lifted the water:
  // 1.5 % energy gain at 40k, 2.8 % at 80k). The particles move by −dt²∇φ in
  // transferToParticles, their velocities unchanged.
  const bool shifting = shiftDef_.rate > 0;
  const Real invFull = Real(1) / (cellRatio_ * cellRatio_);
  if (shifting) {
    rhsS_.resize(m);
    xs_.assign(m, 0);
    for (std::size_t a = 0; a < m; ++a) {
      const std::size_t k = std::size_t(cells_[a]);
      const Real comp = std::max(Real(0), w_[k] * invFull - Real(1) - shiftDef_.above);
      rhsS_[a] = (h_ * h_ / dt) * shiftDef_.rate * comp / dt;
    }
  }
  // The two solves share the matrix and nothing else: with two threads they run side by
  // side, each in cell order on one thread (the same bits for any thread count). The
  // residual stands for a density change of |r| dt²/h² over the substep.
  Real res = 0, resS = 0;
  int itS = 0;
  const Real scale = h_ * h_ / (dt * dt);
  c.pool.parallelFor(shifting ? 2 : 1, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      if (k == 0) stats_.iterations = pcg(x, rhs_, tol_ * scale, res, cgMain_);
      else itS = pcg(xs_, rhsS_, shiftDef_.tolerance * scale, resS, cgShift_);
    }
  });
  stats_.iterations += itS;
  stats_.residual = double(res * dt * dt * invH_ * invH_);
  std::fill(kappa_.begin(), kappa_.end(), Real(0));
  for (std::size_t a = 0; a < m; ++a) kappa_[std::size_t(cells_[a])] = x[a];
  pH_ = h_;
  pI0_ = I0_;
  pJ0_ = J0_;
  pnx_ = nx_;
  pny_ = ny_;
  prevKappa_ = kappa_;
  if (shifting) {
    kappaS_.assign(kappa_.size(), 0);
    for (std::size_t a = 0; a < m; ++a) kappaS_[std::size_t(cells_[a])] = xs_[a];
  }
}

Vec2 GridProjection::sampleFaces(const std::vector<Real>& u, const std::vector<Real>& v, Real px, Real py) const {
  // Bilinear over the MAC faces: u at (i, j + 1/2), v at (i + 1/2, j), in cell units of the
  // grid (px, py ≥ 0: the grid has a margin, so truncation is floor).
  const int nu = nx_ + 1;
  Real ux, uy;
  {
    const Real fx = px, fy = py - Real(0.5);
    const int i0 = int(fx), j0 = int(fy);
    const Real tx = fx - Real(i0), ty = fy - Real(j0);
    const std::size_t k = std::size_t(j0) * nu + i0;
    ux = (1 - tx) * (1 - ty) * u[k] + tx * (1 - ty) * u[k + 1] + (1 - tx) * ty * u[k + nu] + tx * ty * u[k + nu + 1];
  }
  {
    const Real fx = px - Real(0.5), fy = py;
    const int i0 = int(fx), j0 = int(fy);
    const Real tx = fx - Real(i0), ty = fy - Real(j0);
    const std::size_t k = std::size_t(j0) * nx_ + i0;
    uy = (1 - tx) * (1 - ty) * v[k] + tx * (1 - ty) * v[k + 1] + (1 - tx) * ty * v[k + nx_] + tx * ty * v[k + nx_ + 1];
  }
  return Vec2(ux, uy);
}

void GridProjection::extrapolate(std::vector<Real>& d, int w, int h, const std::vector<std::uint8_t>& known) {
  // One layer: an unknown face next to known ones (along either axis) takes their
  // mean, so a particle between a fluid cell and a solid or air cell gets the
  // fluid's full velocity change (Bridson's extrapolation, ch. 4.1). Reads only
  // the known faces: the result does not depend on the visiting order.
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const std::size_t f = std::size_t(j) * w + i;
      if (known[f]) continue;
      Real sum = 0;
      int n = 0;
      if (i > 0 && known[f - 1]) sum += d[f - 1], ++n;
      if (i + 1 < w && known[f + 1]) sum += d[f + 1], ++n;
      if (j > 0 && known[f - std::size_t(w)]) sum += d[f - std::size_t(w)], ++n;
      if (j + 1 < h && known[f + std::size_t(w)]) sum += d[f + std::size_t(w)], ++n;
      if (n > 0) d[f] = sum / Real(n);
    }
}

std::size_t GridProjection::transferToParticles(StepContext& c) {
  const Real dt = c.dt;
  const int nu = nx_ + 1;
  // A cell field's value in a fluid cell, 0 elsewhere (air holds 0; solid faces are not read).
  auto inFluid = [&](const std::vector<Real>& field, int i, int j) {
    return type_[std::size_t(j) * nx_ + i] == kFluid ? field[std::size_t(j) * nx_ + i] : Real(0);
  };
  auto kap = [&](int i, int j) { return inFluid(kappa_, i, j); };
  auto isFluid = [&](int i, int j) { return type_[std::size_t(j) * nx_ + i] == kFluid; };
  const bool shifting = shiftDef_.rate > 0;
  const Real k2 = -dt * dt * invH_;
  auto phi = [&](int i, int j) { return inFluid(kappaS_, i, j); };
  if (shifting) {
    su_.assign(u_.size(), 0);
    sv_.assign(v_.size(), 0);
  }
  // The u faces and the v faces are independent: two tasks, each serial.
  c.pool.parallelFor(2, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t task = b; task < e; ++task) {
      if (task == 0) {
        // Face changes: open faces next to fluid take the pressure gradient; closed
        // faces next to fluid lose their normal velocity (the wall).
        for (int j = 0; j < ny_; ++j)
          for (int i = 1; i < nx_; ++i) {
            if (!isFluid(i - 1, j) && !isFluid(i, j)) continue;
            const std::size_t f = std::size_t(j) * nu + i;
            fluidU_[f] = 1;
            const bool solidSide = type_[std::size_t(j) * nx_ + i - 1] == kSolid || type_[std::size_t(j) * nx_ + i] == kSolid;
            du_[f] = uOpen_[f] && !solidSide ? -dt * (kap(i, j) - kap(i - 1, j)) * invH_ : -u_[f];
            // The shift's face moves: −dt²∇φ across open faces between fluid and air
            // cells (none through a wall), extrapolated one layer as the change is.
            if (shifting && uOpen_[f] && !solidSide) su_[f] = k2 * (phi(i, j) - phi(i - 1, j));
          }
        extrapolate(du_, nu, ny_, fluidU_);
        if (shifting) extrapolate(su_, nu, ny_, fluidU_);
      } else {
        for (int j = 1; j < ny_; ++j)
          for (int i = 0; i < nx_; ++i) {
            if (!isFluid(i, j - 1) && !isFluid(i, j)) continue;
            const std::size_t f = std::size_t(j) * nx_ + i;
            fluidV_[f] = 1;
            const bool solidSide = type_[std::size_t(j - 1) * nx_ + i] == kSolid || type_[std::size_t(j) * nx_ + i] == kSolid;
            dv_[f] = vOpen_[f] && !solidSide ? -dt * (kap(i, j) - kap(i, j - 1)) * invH_ : -v_[f];
            if (shifting && vOpen_[f] && !solidSide) sv_[f] = k2 * (phi(i, j) - phi(i, j - 1));
          }
        extrapolate(dv_, nx_, ny_ + 1, fluidV_);
        if (shifting) extrapolate(sv_, nx_, ny_ + 1, fluidV_);
      }
    }
  });
  Particles& P = c.P;
  const Real vmax2 = c.maxSpeed * c.maxSpeed;
  if (shifting) shift_.resize(P.size());
  else shift_.clear();
  if (pic_ > 0) {  // the projected face velocities (closed faces: 0)
    for (std::size_t f = 0; f < u_.size(); ++f) uNew_[f] = u_[f] + du_[f];
    for (std::size_t f = 0; f < v_.size(); ++f) vNew_[f] = v_[f] + dv_[f];
  }
  return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
    std::size_t bad = kNone;
    for (std::size_t p = b; p < e; ++p) {
      const Real px = P.x[p].x() * invH_ - Real(I0_), py = P.x[p].y() * invH_ - Real(J0_);
      Vec2 vp = P.v[p] + sampleFaces(du_, dv_, px, py);  // FLIP: the change of the grid velocity
      if (pic_ > 0) {
        // PIC share: towards the projected grid velocity itself (smooths particle noise).
        const Vec2 ug = sampleFaces(uNew_, vNew_, px, py);
        vp += (ug - vp) * pic_;
      }
      P.v[p] = vp;
      if (shifting) shift_[p] = sampleFaces(su_, sv_, px, py);
      if (bad == kNone && (!allFinite(P.v[p]) || P.v[p].squaredNorm() > vmax2)) bad = p;
    }
    return bad;
  });
}

Real GridProjection::kappaAt(const Vec2& x) const {
  if (nx_ < 2 || ny_ < 2 || kappa_.size() != std::size_t(nx_) * std::size_t(ny_)) return 0;
  const Real fx = x.x() * invH_ - Real(I0_) - Real(0.5), fy = x.y() * invH_ - Real(J0_) - Real(0.5);
  if (!(fx >= 0 && fy >= 0 && fx < Real(nx_ - 1) && fy < Real(ny_ - 1))) return 0;  // also NaN
  const int i0 = int(fx), j0 = int(fy);
  const Real tx = fx - Real(i0), ty = fy - Real(j0);
  const std::size_t k = std::size_t(j0) * nx_ + i0;
  const std::size_t ks[4] = {k, k + 1, k + nx_, k + nx_ + 1};
  const Real wq[4] = {(1 - tx) * (1 - ty), tx * (1 - ty), (1 - tx) * ty, tx * ty};
  Real sum = 0, wsum = 0;
  for (int q = 0; q < 4; ++q) {
    if (type_[ks[q]] == kSolid) continue;
    wsum += wq[q];
    if (type_[ks[q]] == kFluid) sum += wq[q] * kappa_[ks[q]];
  }
  return wsum > 0 ? sum / wsum : Real(0);
}

std::size_t GridProjection::project(StepContext& c) {
  if (c.P.size() == 0 || !(c.dt > 0)) return kNone;
  layout(c);
  transferToGrid(c);
  classify(c);
  assemble();
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
