// The coarse-grid projection's pressure system on its own (grid_pcg.hpp): the rows of the
// fluid cells, the sealed pockets grounded, the right-hand side balanced, and the solve by
// conjugate gradients preconditioned by MIC(0) on vertical strips.
#include "solvers/game/grid_pcg.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sph2d {

void GridPcg::assemble(int nx, int ny, const std::vector<std::uint8_t>& type, const std::vector<std::uint8_t>& uOpen,
                       const std::vector<std::uint8_t>& vOpen, const std::vector<Real>* thetaUp,
                       const std::vector<Real>* uBeta, const std::vector<Real>* vBeta) {
  nx_ = nx;
  ny_ = ny;
  const int nu = nx_ + 1;
  // The unknowns in cell order, and each row's first (rowStart_[ny] = m): the loops over
  // unknowns go row by row (no division to find a cell's row).
  index_.assign(type.size(), -1);
  cells_.clear();
  rowStart_.resize(std::size_t(ny_) + 1);
  for (int j = 0; j < ny_; ++j) {
    rowStart_[std::size_t(j)] = std::int32_t(cells_.size());
    for (int i = 0; i < nx_; ++i) {
      const std::size_t k = std::size_t(j) * nx_ + i;
      if (type[k] != kFluid) continue;
      index_[k] = std::int32_t(cells_.size());
      cells_.push_back(std::int32_t(k));
    }
  }
  const std::size_t m = cells_.size();
  rowStart_[std::size_t(ny_)] = std::int32_t(m);
  diag_.assign(m, 0);
  adj_.assign(4 * m, -1);
  vented_.assign(m, 0);
  const bool weighted = uBeta && vBeta;
  if (weighted)
    beta_.assign(4 * m, 0);
  else
    beta_.clear();
  forUnknowns([&](std::size_t a, int i, int j) {
    const int k = cells_[a];
    const std::size_t faces[4] = {std::size_t(j) * nu + i, std::size_t(j) * nu + i + 1, std::size_t(j) * nx_ + i,
                                  std::size_t(j + 1) * nx_ + i};
    const bool open[4] = {uOpen[faces[0]] != 0, uOpen[faces[1]] != 0, vOpen[faces[2]] != 0, vOpen[faces[3]] != 0};
    const int nb[4] = {k - 1, k + 1, k - nx_, k + nx_};
    Real dg = 0;
    for (int q = 0; q < 4; ++q) {
      const std::uint8_t t = type[std::size_t(nb[q])];
      const Real b = weighted ? (q < 2 ? *uBeta : *vBeta)[faces[q]] : Real(1);
      if (q == 3 && open[q] && t == kAir && thetaUp) {
        dg += b / (*thetaUp)[std::size_t(k)];  // the ghost-fluid surface θ of the way up
        vented_[a] = 1;
      } else if (open[q] && (t == kFluid || t == kAir)) {
        dg += b;
        if (t == kAir) vented_[a] = 1;
      }
      adj_[4 * a + q] = open[q] ? index_[std::size_t(nb[q])] : -1;  // −1: air, solid or closed
      if (weighted && adj_[4 * a + q] >= 0) beta_[4 * a + q] = b;
    }
    diag_[a] = dg;
  });
}

void GridPcg::factor() {
  const std::size_t m = cells_.size();
  groundPockets();
  nbrPad_.resize(adj_.size());
  for (std::size_t e = 0; e < adj_.size(); ++e) nbrPad_[e] = adj_[e] >= 0 ? adj_[e] : std::int32_t(m);
  if (beta_.empty())
    factorRows<false>();
  else
    factorRows<true>();
  precon2_.resize(m);
  for (std::size_t a = 0; a < m; ++a) precon2_[a] = precon_[a] * precon_[a];
}

template <bool Weighted>
void GridPcg::factorRows() {
  // MIC(0) (Bridson, "Fluid Simulation for Computer Graphics", 2nd ed., fig. 5.7):
  // the incomplete Cholesky factor of the 5-point Laplacian, in cell order. The entry of
  // face q of unknown a is −β (−1 unweighted).
  const std::size_t m = cells_.size();
  auto beta = [&](std::size_t a, int q) { return Weighted ? beta_[4 * a + std::size_t(q)] : Real(1); };
  const Real tau = Real(0.97), sigma = Real(0.25);
  precon_.assign(m, 0);
  for (std::size_t a = 0; a < m; ++a) {
    if (!(diag_[a] > 0)) continue;
    Real e = diag_[a];
    const std::int32_t l = adj_[4 * a + 0], d = adj_[4 * a + 2];
    if (l >= 0) {  // A(left, a) = −β; the left cell's "plus j" entry: its up neighbour
      const Real pl = precon_[std::size_t(l)];
      const Real aL = -beta(a, 0);
      const Real aUpL = adj_[4 * std::size_t(l) + 3] >= 0 ? -beta(std::size_t(l), 3) : Real(0);
      e -= (aL * pl) * (aL * pl) + tau * aL * aUpL * pl * pl;  // unweighted: aL = −1, the same bits
    }
    if (d >= 0) {
      const Real pd = precon_[std::size_t(d)];
      const Real aD = -beta(a, 2);
      const Real aRightD = adj_[4 * std::size_t(d) + 1] >= 0 ? -beta(std::size_t(d), 1) : Real(0);
      e -= (aD * pd) * (aD * pd) + tau * aD * aRightD * pd * pd;
    }
    if (e < sigma * diag_[a]) e = diag_[a];
    precon_[a] = Real(1) / std::sqrt(e);
  }
}

void GridPcg::groundPockets() {
  // A pocket: fluid cells joined by open faces with no open face to air (no κ = 0 anywhere)
  // and no dynamic body to push. Its rows are a pure Neumann Laplacian: singular, κ only up
  // to a constant, solvable only when its right-hand side sums to zero. Fluid cut off by a
  // wall from the rest (the cells between the teeth of an acute chain, or a sealed tank
  // filled to the lid) makes one; conjugate gradients on it divide by a vanishing d·Ad and
  // return infinities (a 50 m/s jet into a zigzag funnel stopped with a NaN shift). Each
  // pocket's last cell is grounded (diagonal + 1, so the system is definite), and
  // balance() takes the pocket's mean out of each right-hand side: then the grounded row's
  // κ is 0 and every row's equation holds as before. A sealed pocket cannot change its
  // volume; the mean compression it cannot shed stays with the particle solve.
  const std::size_t m = cells_.size();
  std::vector<std::int32_t>& root = pocketOf_;
  root.resize(m);
  auto find = [&](std::int32_t a) {
    while (root[std::size_t(a)] != a) a = root[std::size_t(a)] = root[std::size_t(root[std::size_t(a)])];
    return a;
  };
  for (std::size_t a = 0; a < m; ++a) {
    root[a] = std::int32_t(a);
    for (int q : {0, 2}) {  // left and down: already labelled
      const std::int32_t b = adj_[4 * a + std::size_t(q)];
      if (b < 0) continue;
      const std::int32_t ra = find(std::int32_t(a)), rb = find(b);
      if (ra != rb) root[std::size_t(std::max(ra, rb))] = std::min(ra, rb);  // the lower index is the root
    }
  }
  regionOf_.resize(m);
  regions_ = 0;
  for (std::size_t a = 0; a < m; ++a) {
    const std::int32_t r = find(std::int32_t(a));
    if (vented_[a]) vented_[std::size_t(r)] = 1;
    root[a] = r;
    // Regions numbered in order of their roots (a root is its region's first unknown).
    regionOf_[a] = std::size_t(r) == a ? std::int32_t(regions_++) : regionOf_[std::size_t(r)];
  }
  // Pocket numbers in order of their roots; −1 for cells of a vented region.
  pocketCells_.clear();
  pocketLast_.clear();
  for (std::size_t a = 0; a < m; ++a) {
    const std::int32_t r = root[a];
    if (vented_[std::size_t(r)]) {
      root[a] = -1;
      continue;
    }
    std::int32_t id;
    if (std::size_t(r) == a) {
      id = std::int32_t(pocketCells_.size());
      pocketCells_.push_back(0);
      pocketLast_.push_back(0);
    } else {
      id = root[std::size_t(r)];  // the root, visited first, holds its pocket's number
    }
    root[a] = id;
    ++pocketCells_[std::size_t(id)];
    pocketLast_[std::size_t(id)] = std::int32_t(a);
  }
  for (const std::int32_t a : pocketLast_) diag_[std::size_t(a)] += 1;
}

void GridPcg::balance(std::vector<Real>& rhs) const {
  if (pocketLast_.empty()) return;
  std::vector<double> sum(pocketLast_.size(), 0.0);  // the two solves balance side by side: no shared scratch
  for (std::size_t a = 0; a < cells_.size(); ++a)
    if (pocketOf_[a] >= 0) sum[std::size_t(pocketOf_[a])] += double(rhs[a]);
  for (std::size_t a = 0; a < cells_.size(); ++a)
    if (pocketOf_[a] >= 0) {
      const std::size_t id = std::size_t(pocketOf_[a]);
      rhs[a] -= Real(sum[id] / double(pocketCells_[id]));
    }
}

template <bool Weighted>
void GridPcg::precondition(const std::vector<Real>& r, std::vector<Real>& z, std::vector<Real>& y) const {
  // z = (L Lᵀ)⁻¹ r with L = MIC(0)'s factor (p = precon_ = 1/diag(L), p2 = p²). Each
  // substitution is a chain from one cell to the next along a row (a left neighbour is
  // always the unknown before, a right one the unknown after), fed by the row below
  // (forward) or above (backward). Each cell's arithmetic is fixed; only the schedule is
  // free: two rows run side by side, the second a cell or more behind the first, so two
  // chains are in flight (the chain is one multiply and one add per cell, and with one
  // row at a time the core waits on it). Each cursor carries its row's last value in a
  // register. The same bits as one cell after the other. Weighted, each neighbour's share
  // is taken times its face's β.
  const std::size_t m = cells_.size();
  const Real* p = precon_.data();
  const Real* p2 = precon2_.data();
  const std::int32_t* A = adj_.data();
  const std::int32_t* rows = rowStart_.data();
  const Real* R = r.data();
  const Real* Bt = beta_.data();
  y.resize(m);
  Real* Y = y.data();
  Real* Z = z.data();
  // Forward: q = L⁻¹ r, kept as z (= q) and y = q·p (what the right and up cells read).
  auto forward = [&](std::int32_t a, Real& yPrev) {
    const std::int32_t l = A[4 * a + 0], d = A[4 * a + 2];
    const Real t = R[a] + (d >= 0 ? (Weighted ? Bt[4 * a + 2] * Y[d] : Y[d]) : Real(0));
    const Real yl = l < 0 ? Real(0) : Weighted ? Bt[4 * a + 0] * yPrev : yPrev;
    Z[a] = (t + yl) * p[a];
    yPrev = Y[a] = t * p2[a] + yl * p2[a];
  };
  for (int j = 0; j < ny_; j += 2) {
    // Row j (cursor a) and row j + 1 (cursor b): b's cell waits for the cell below it.
    std::int32_t a = rows[j], b = rows[j + 1];
    const std::int32_t ae = rows[j + 1], be = rows[std::min(j + 2, ny_)];
    Real ya = 0, yb = 0;
    while (a < ae) {
      forward(a++, ya);
      if (b < be && A[4 * b + 2] < a) forward(b++, yb);  // below: done (or none, −1)
    }
    while (b < be) forward(b++, yb);
  }
  // Backward: z = L⁻ᵀ q, from the top row down.
  auto backward = [&](std::int32_t a, Real& zNext) {
    const std::int32_t rt = A[4 * a + 1], u = A[4 * a + 3];
    const Real s = Z[a] * p[a] + (u >= 0 ? (Weighted ? Bt[4 * a + 3] * Z[u] : Z[u]) : Real(0)) * p2[a];
    const Real zr = rt < 0 ? Real(0) : Weighted ? Bt[4 * a + 1] * zNext : zNext;
    zNext = Z[a] = s + zr * p2[a];
  };
  for (int j = ny_ - 1; j >= 0; j -= 2) {
    // Row j (cursor a, descending) and row j − 1 (cursor b): b's cell waits for the cell above.
    std::int32_t a = rows[j + 1] - 1, b = rows[j] - 1;
    const std::int32_t as = rows[j], bs = rows[std::max(j - 1, 0)];
    Real za = 0, zb = 0;
    while (a >= as) {
      backward(a--, za);
      if (b >= bs && (A[4 * b + 3] < 0 || A[4 * b + 3] > a)) backward(b--, zb);  // above: done, or none
    }
    while (b >= bs) backward(b--, zb);
  }
  (void)m;
}

double GridPcg::dot(const std::vector<Real>& a, const std::vector<Real>& b) const {
  double s = 0;  // in cell order
  for (std::size_t k = 0; k < cells_.size(); ++k) s += double(a[k]) * double(b[k]);
  return s;
}

template <bool Weighted>
double GridPcg::applyDot(const std::vector<Real>& in, std::vector<Real>& out) const {
  // apply(in, out, false), and in·out summed in cell order as it goes. `in` holds m + 1
  // values, the last 0: a missing neighbour (nbrPad_ = m) subtracts that 0, as exact as
  // subtracting none (s − 0 = s), and the loop has no branch to mispredict.
  const std::size_t m = cells_.size();
  const std::int32_t* A = nbrPad_.data();
  const Real* I = in.data();
  const Real* D = diag_.data();
  Real* O = out.data();
  double dsum = 0;
  const Real* Bt = beta_.data();
  for (std::size_t a = 0; a < m; ++a) {
    Real s = D[a] * I[a];
    if (Weighted) {
      s -= Bt[4 * a + 0] * I[A[4 * a + 0]];
      s -= Bt[4 * a + 1] * I[A[4 * a + 1]];
      s -= Bt[4 * a + 2] * I[A[4 * a + 2]];
      s -= Bt[4 * a + 3] * I[A[4 * a + 3]];
    } else {
      s -= I[A[4 * a + 0]];
      s -= I[A[4 * a + 1]];
      s -= I[A[4 * a + 2]];
      s -= I[A[4 * a + 3]];
    }
    O[a] = s;
    dsum += double(I[a]) * double(s);
  }
  return dsum;
}

void GridPcg::apply(const std::vector<Real>& in, std::vector<Real>& out) const {
  const std::size_t m = cells_.size();
  const std::int32_t* A = adj_.data();
  for (std::size_t a = 0; a < m; ++a) {
    Real s = diag_[a] * in[a];
    for (int q = 0; q < 4; ++q)
      if (A[4 * a + q] >= 0)
        s -= (beta_.empty() ? Real(1) : beta_[4 * a + std::size_t(q)]) * in[std::size_t(A[4 * a + q])];
    out[a] = s;
  }
}

int GridPcg::solve(std::vector<Real>& x, const std::vector<Real>& b, Real tol, int maxIterations, Real& res, Work& w,
                   const Extra* extra) const {
  // Conjugate gradients with the MIC(0) preconditioner; sums in cell order.
  const std::size_t m = cells_.size();
  std::vector<Real>&r_ = w.r, &z_ = w.z, &d_ = w.d, &q_ = w.q;
  r_.resize(m);
  z_.resize(m);
  d_.assign(m + 1, 0);  // d[m] = 0 stays: applyDot's missing neighbour
  q_.resize(m);
  apply(x, q_);
  if (extra) (*extra)(x, q_);
  for (std::size_t a = 0; a < m; ++a) r_[a] = b[a] - q_[a];
  auto worst = [&] {
    Real mx = 0;
    for (std::size_t a = 0; a < m; ++a) mx = std::max(mx, std::fabs(r_[a]));
    return mx;
  };
  double rz = 0;
  const bool weighted = !beta_.empty();
  auto precondition = [&] {
    if (weighted)
      this->precondition<true>(r_, z_, w.y);
    else
      this->precondition<false>(r_, z_, w.y);
  };
  precondition();
  for (std::size_t a = 0; a < m; ++a) {
    d_[a] = z_[a];
    rz += double(r_[a]) * double(z_[a]);
  }
  int it = 0;
  res = worst();
  while (it < maxIterations && res > tol && rz > 0) {
    // q = A d and d·q (in one pass when no extra term adds to q afterwards), the update of r
    // with the largest |r| in one pass: the same sums in the same order.
    const double dq = extra      ? (apply(d_, q_), (*extra)(d_, q_), dot(d_, q_))
                      : weighted ? applyDot<true>(d_, q_)
                                 : applyDot<false>(d_, q_);
    if (!(dq > 0)) break;
    const Real alpha = Real(rz / dq);
    Real mx = 0;
    for (std::size_t a = 0; a < m; ++a) {
      r_[a] -= alpha * q_[a];
      mx = std::max(mx, std::fabs(r_[a]));
    }
    precondition();
    // r·z in cell order, and x's update beside it (d is still this iteration's: the same
    // x; the sum is a chain of additions, and the update fills the core's idle slots).
    double rzNew = 0;
    for (std::size_t a = 0; a < m; ++a) {
      rzNew += double(r_[a]) * double(z_[a]);
      x[a] += alpha * d_[a];
    }
    const Real beta = Real(rzNew / rz);
    rz = rzNew;
    for (std::size_t a = 0; a < m; ++a) d_[a] = z_[a] + beta * d_[a];
    ++it;
    res = mx;
  }
  return it;
}

GridPoissonResult solveGridPoisson(int nx, int ny, const std::vector<std::uint8_t>& cells, const std::vector<Real>& rhs,
                                   Real tolerance, int maxIterations) {
  const std::size_t n = std::size_t(std::max(nx, 0)) * std::size_t(std::max(ny, 0));
  if (nx < 1 || ny < 1 || cells.size() != n || rhs.size() != n)
    throw std::invalid_argument("solveGridPoisson: cells and rhs must hold nx * ny values");
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      if (cells[std::size_t(j) * std::size_t(nx) + std::size_t(i)] == GridPcg::kFluid &&
          (i == 0 || j == 0 || i + 1 == nx || j + 1 == ny))
        throw std::invalid_argument("solveGridPoisson: fluid cell (" + std::to_string(i) + ", " + std::to_string(j) +
                                    ") on the grid's border");
  const std::vector<std::uint8_t> uOpen(std::size_t(nx + 1) * std::size_t(ny), 1),
      vOpen(std::size_t(nx) * std::size_t(ny + 1), 1);
  GridPcg pcg;
  pcg.assemble(nx, ny, cells, uOpen, vOpen, nullptr);
  pcg.factor();
  const std::size_t m = pcg.size();
  std::vector<Real> b(m), x(m, 0);
  for (std::size_t a = 0; a < m; ++a) b[a] = rhs[std::size_t(pcg.cells()[a])];
  pcg.balance(b);
  GridPoissonResult r;
  GridPcg::Work w;
  r.iterations = pcg.solve(x, b, tolerance, maxIterations, r.residual, w);
  r.unknowns = int(m);
  r.pockets = int(pcg.pockets());
  r.pressure.assign(n, 0);
  for (std::size_t a = 0; a < m; ++a) r.pressure[std::size_t(pcg.cells()[a])] = x[a];
  return r;
}

}  // namespace sph2d
