// The coarse-grid projection's pressure system (grid_projection.hpp): assembly, sealed pockets
// grounded, the right-hand side balanced, and its solve by conjugate gradients preconditioned
// by MIC(0) on vertical strips (the pressure and the compression-shift systems).
#include "bodies/moving_solid.hpp"
#include "core/state_io.hpp"
#include "solvers/game/grid_projection.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace sph2d {

void GridProjection::assemble() {
  const int nu = nx_ + 1;
  // The faces next to a fluid cell (their change is known; the others are extrapolated).
  auto isFluid = [&](int i, int j) { return type_[std::size_t(j) * nx_ + i] == kFluid; };
  for (int j = 0; j < ny_; ++j)
    for (int i = 1; i < nx_; ++i) fluidU_[std::size_t(j) * nu + i] = isFluid(i - 1, j) || isFluid(i, j);
  for (int j = 1; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) fluidV_[std::size_t(j) * nx_ + i] = isFluid(i, j - 1) || isFluid(i, j);
  // The unknowns in cell order, and each row's first (rowStart_[ny] = m): the loops over
  // unknowns go row by row (no division to find a cell's row).
  cells_.clear();
  rowStart_.resize(std::size_t(ny_) + 1);
  for (int j = 0; j < ny_; ++j) {
    rowStart_[std::size_t(j)] = std::int32_t(cells_.size());
    for (int i = 0; i < nx_; ++i) {
      const std::size_t k = std::size_t(j) * nx_ + i;
      if (type_[k] != kFluid) continue;
      index_[k] = std::int32_t(cells_.size());
      cells_.push_back(std::int32_t(k));
    }
  }
  const std::size_t m = cells_.size();
  rowStart_[std::size_t(ny_)] = std::int32_t(m);
  diag_.assign(m, 0);
  if (surface_) thetaUp_.assign(type_.size(), Real(1));
  adj_.assign(4 * m, -1);
  vented_.assign(m, 0);
  forUnknowns([&](std::size_t a, int i, int j) {
    const int k = cells_[a];
    const bool open[4] = {uOpen_[std::size_t(j) * nu + i] != 0, uOpen_[std::size_t(j) * nu + i + 1] != 0,
                          vOpen_[std::size_t(j) * nx_ + i] != 0, vOpen_[std::size_t(j + 1) * nx_ + i] != 0};
    const int nb[4] = {k - 1, k + 1, k - nx_, k + nx_};
    Real dg = 0;
    for (int q = 0; q < 4; ++q) {
      const std::uint8_t t = type_[std::size_t(nb[q])];
      if (q == 3 && open[q] && t == kAir && surface_) {
        // Ghost fluid (Gibou, Fedkiw, Cheng & Kang 2002): κ = 0 on the surface, a fraction θ
        // of the way to the air cell's centre: half a spacing above the highest particle of
        // the two cells (the fill would say it too, but beside a wall or over a compressed
        // layer its reading differs by a tenth of a cell, and that difference drives a flow).
        const double ya = (double(J0_ + j) + 0.5) * double(h_);
        const Real ytop = std::max(top_[std::size_t(k)], top_[std::size_t(nb[q])]);
        const Real theta =
            std::clamp(Real((double(ytop) + 0.5 * double(dx_) - ya) * double(invH_)), kMinSurfaceFraction, Real(1));
        dg += Real(1) / theta;
        thetaUp_[std::size_t(k)] = theta;
        vented_[a] = 1;
      } else if (open[q] && t != kSolid && t != kBody) {
        dg += 1;
        if (t == kAir) vented_[a] = 1;
      }
      adj_[4 * a + q] = open[q] ? index_[std::size_t(nb[q])] : -1;  // −1: air, solid or closed
    }
    diag_[a] = dg;
  });
  assembleCoupling();
  groundPockets();
  nbrPad_.resize(adj_.size());
  for (std::size_t e = 0; e < adj_.size(); ++e) nbrPad_[e] = adj_[e] >= 0 ? adj_[e] : std::int32_t(m);
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

void GridProjection::groundPockets() {
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
  for (const Coupling& e : coupling_) vented_[std::size_t(find(e.unknown))] = 1;  // a body can move: not sealed
  for (std::size_t a = 0; a < m; ++a) {
    const std::int32_t r = find(std::int32_t(a));
    if (vented_[a]) vented_[std::size_t(r)] = 1;
    root[a] = r;
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

void GridProjection::balance(std::vector<Real>& rhs) const {
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

void GridProjection::precondition(const std::vector<Real>& r, std::vector<Real>& z, std::vector<Real>& y) const {
  // z = (L Lᵀ)⁻¹ r with L = MIC(0)'s factor (p = precon_ = 1/diag(L), p2 = p²). Each
  // substitution is a chain from one cell to the next along a row (a left neighbour is
  // always the unknown before, a right one the unknown after), fed by the row below
  // (forward) or above (backward). Each cell's arithmetic is fixed; only the schedule is
  // free: two rows run side by side, the second a cell or more behind the first, so two
  // chains are in flight (the chain is one multiply and one add per cell, and with one
  // row at a time the core waits on it). Each cursor carries its row's last value in a
  // register. The same bits as one cell after the other.
  const std::size_t m = cells_.size();
  const Real* p = precon_.data();
  const Real* p2 = precon2_.data();
  const std::int32_t* A = adj_.data();
  const std::int32_t* rows = rowStart_.data();
  const Real* R = r.data();
  y.resize(m);
  Real* Y = y.data();
  Real* Z = z.data();
  // Forward: q = L⁻¹ r, kept as z (= q) and y = q·p (what the right and up cells read).
  auto forward = [&](std::int32_t a, Real& yPrev) {
    const std::int32_t l = A[4 * a + 0], d = A[4 * a + 2];
    const Real t = R[a] + (d >= 0 ? Y[d] : Real(0));
    const Real yl = l < 0 ? Real(0) : yPrev;
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
    const Real s = Z[a] * p[a] + (u >= 0 ? Z[u] : Real(0)) * p2[a];
    const Real zr = rt < 0 ? Real(0) : zNext;
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

double GridProjection::dot(const std::vector<Real>& a, const std::vector<Real>& b) const {
  double s = 0;  // in cell order
  for (std::size_t k = 0; k < cells_.size(); ++k) s += double(a[k]) * double(b[k]);
  return s;
}

double GridProjection::applyDot(const std::vector<Real>& in, std::vector<Real>& out) const {
  // apply(in, out, false), and in·out summed in cell order as it goes. `in` holds m + 1
  // values, the last 0: a missing neighbour (nbrPad_ = m) subtracts that 0, as exact as
  // subtracting none (s − 0 = s), and the loop has no branch to mispredict.
  const std::size_t m = cells_.size();
  const std::int32_t* A = nbrPad_.data();
  const Real* I = in.data();
  const Real* D = diag_.data();
  Real* O = out.data();
  double dsum = 0;
  for (std::size_t a = 0; a < m; ++a) {
    Real s = D[a] * I[a];
    s -= I[A[4 * a + 0]];
    s -= I[A[4 * a + 1]];
    s -= I[A[4 * a + 2]];
    s -= I[A[4 * a + 3]];
    O[a] = s;
    dsum += double(I[a]) * double(s);
  }
  return dsum;
}

void GridProjection::apply(const std::vector<Real>& in, std::vector<Real>& out, bool coupled) const {
  const std::size_t m = cells_.size();
  const std::int32_t* A = adj_.data();
  for (std::size_t a = 0; a < m; ++a) {
    Real s = diag_[a] * in[a];
    for (int q = 0; q < 4; ++q)
      if (A[4 * a + q] >= 0) s -= in[std::size_t(A[4 * a + q])];
    out[a] = s;
  }
  if (!coupled || coupling_.empty()) return;
  // The dynamic bodies' response (Batty, Bertails & Bridson 2007, "A fast variational
  // framework for accurate solid-fluid coupling", on a voxelized body): the pressure's
  // impulse Gᵀκ moves a body by M⁻¹Gᵀκ, which changes the flux through its faces by G·that.
  bodySum_.assign(3 * bodies_.size(), 0.0);
  for (const Coupling& e : coupling_)
    for (int q = 0; q < 3; ++q)
      bodySum_[3 * std::size_t(e.body) + std::size_t(q)] += e.g[q] * double(in[std::size_t(e.unknown)]);
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    bodySum_[3 * b + 0] *= couplingScale_ * bodies_[b].invMass;
    bodySum_[3 * b + 1] *= couplingScale_ * bodies_[b].invMass;
    bodySum_[3 * b + 2] *= couplingScale_ * bodies_[b].invInertia;
  }
  for (const Coupling& e : coupling_) {
    const double* t = &bodySum_[3 * std::size_t(e.body)];
    out[std::size_t(e.unknown)] += Real(e.g[0] * t[0] + e.g[1] * t[1] + e.g[2] * t[2]);
  }
}

int GridProjection::pcg(std::vector<Real>& x, const std::vector<Real>& b, Real tol, Real& res, CgWork& w,
                        bool coupled) const {
  // Conjugate gradients with the MIC(0) preconditioner; sums in cell order.
  const std::size_t m = cells_.size();
  std::vector<Real>&r_ = w.r, &z_ = w.z, &d_ = w.d, &q_ = w.q;
  r_.resize(m);
  z_.resize(m);
  d_.assign(m + 1, 0);  // d[m] = 0 stays: applyDot's missing neighbour
  q_.resize(m);
  apply(x, q_, coupled);
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
    // q = A d and d·q (in one pass when no body adds to q afterwards), the update of r
    // with the largest |r| in one pass: the same sums in the same order.
    const double dq = coupled ? (apply(d_, q_, true), dot(d_, q_)) : applyDot(d_, q_);
    if (!(dq > 0)) break;
    const Real alpha = Real(rz / dq);
    Real mx = 0;
    for (std::size_t a = 0; a < m; ++a) {
      r_[a] -= alpha * q_[a];
      mx = std::max(mx, std::fabs(r_[a]));
    }
    precondition(r_, z_, w.y);
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

void GridProjection::pressureSystem(const StepContext& c) {
  const Real dt = c.dt;
  const int nu = nx_ + 1;
  const std::size_t m = cells_.size();
  rhs_.assign(m, 0);
  std::vector<Real>& x = x_;
  x.assign(m, 0);
  // Warm start from the last substep's κ of the same anchored cells (none when the cells
  // grew to hold spray: the same index is then another place).
  const bool sameCells = h_ == pH_;
  if (sameCells)
    forUnknowns([&](std::size_t a, int i, int j) {
      const long I = I0_ + i - pI0_, J = J0_ + j - pJ0_;
      if (I >= 0 && J >= 0 && I < pnx_ && J < pny_) x[a] = prevKappa_[std::size_t(J) * pnx_ + std::size_t(I)];
    });
  // A face against a moving body's cell carries the body's velocity there.
  auto uf = [&](int i, int j) {
    const std::size_t k = std::size_t(j) * nx_ + std::size_t(i);
    const int b = i > 0 && i < nx_ ? bodyAcross(k - 1, k) : -1;
    if (b >= 0) return bodyFaceVelocity(b, 0, i, j);
    return uOpen_[std::size_t(j) * nu + i] ? u_[std::size_t(j) * nu + i] : Real(0);
  };
  auto vf = [&](int i, int j) {
    const std::size_t k = std::size_t(j) * nx_ + std::size_t(i);
    const int b = j > 0 && j < ny_ ? bodyAcross(k - std::size_t(nx_), k) : -1;
    if (b >= 0) return bodyFaceVelocity(b, 1, i, j);
    return vOpen_[std::size_t(j) * nx_ + i] ? v_[std::size_t(j) * nx_ + i] : Real(0);
  };
  forUnknowns([&](std::size_t a, int i, int j) {
    const int k = cells_[a];
    const Real div = (uf(i + 1, j) - uf(i, j) + vf(i, j + 1) - vf(i, j)) * invH_;
    const Real comp = std::max(Real(0), comp_[std::size_t(k)] / w_[std::size_t(k)]);
    const Real src = div - rate_ * comp / dt;  // a compressed cell is to expand by rate·comp over the substep
    rhs_[a] = -(h_ * h_ / dt) * src;
  });
  balance(rhs_);
}

void GridProjection::shiftSystem(const StepContext& c) {
  // The compression shift's right-hand side: −∇²φ = rate·(comp − above)/dt² per fluid cell,
  // comp = the cell's particle weight over a full cell's, − 1 (a count, as Kugelstadt et al.:
  // the SPH density of a disordered packing reads high, and removing that lifted the water:
  // 1.5 % energy gain at 40k, 2.8 % at 80k). The particles move by −dt²∇φ in
  // transferToParticles, their velocities unchanged.
  const Real dt = c.dt;
  const std::size_t m = cells_.size();
  const Real invFull = Real(1) / (cellRatio_ * cellRatio_);
  rhsS_.resize(m);
  xs_.assign(m, 0);
  const std::size_t nx = std::size_t(nx_);
  for (std::size_t a = 0; a < m; ++a) {
    const std::size_t k = std::size_t(cells_[a]);
    const Real excess = w_[k] * invFull - Real(1);
    const Real comp = std::max(Real(0), excess - shiftDef_.above);
    Real src = shiftDef_.rate * comp;
    if (shiftDef_.fill > 0 && excess < -shiftDef_.above) {
      const std::size_t i = k % nx, j = k / nx;
      const bool interior = i > 0 && j > 0 && i + 1 < nx && j + 1 < std::size_t(ny_) && type_[k - 1] == kFluid &&
                            type_[k + 1] == kFluid && type_[k - nx] == kFluid && type_[k + nx] == kFluid;
      if (interior) src = shiftDef_.fill * (excess + shiftDef_.above);  // negative: the cell draws particles in
    }
    rhsS_[a] = (h_ * h_ / dt) * src / dt;
  }
  balance(rhsS_);
}

void GridProjection::solve(const StepContext& c) {
  const Real dt = c.dt;
  const std::size_t m = cells_.size();
  stats_ = GridProjectionStats{};
  stats_.fluidCells = int(m);
  kappa_.assign(type_.size(), 0);  // air and solid cells hold 0
  const bool shifting = shiftDef_.on();
  if (m == 0) {
    if (shifting) shiftMoves(c);  // none: no fluid cell
    return;
  }
  // The two solves share the matrix and nothing else: with two threads they run side by
  // side, each with its right-hand side first and in cell order on one thread (the same
  // bits for any thread count); the shift's, the shorter, goes on to its face moves. The
  // residual stands for a density change of |r| dt²/h² over the substep.
  std::vector<Real>& x = x_;  // the unknowns, in cell order (kept: no allocation in the step)
  Real res = 0, resS = 0;
  int itS = 0;
  const Real scale = h_ * h_ / (dt * dt);
  couplingScale_ = double(c.rho0) * double(h_) * double(h_);
  const bool coupled = !coupling_.empty();
  c.pool.parallelFor(shifting ? 2 : 1, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      if (k == 0) {
        pressureSystem(c);
        stats_.iterations = pcg(x, rhs_, tol_ * scale, res, cgMain_, coupled);
      } else {
        shiftSystem(c);
        itS = pcg(xs_, rhsS_, shiftDef_.tolerance * scale, resS, cgShift_, false);
        kappaS_.assign(type_.size(), 0);
        for (std::size_t a = 0; a < m; ++a) kappaS_[std::size_t(cells_[a])] = xs_[a];
        shiftMoves(c);
      }
    }
  });
  if (coupled) {
    // Each dynamic body takes the pressure's impulse J = ρ0 h dt Σ κ G (force p·h per face,
    // along n into the body, and its torque about the centre of mass) at the substep's start.
    std::vector<double>& J = bodyImpulse_;
    J.assign(3 * bodies_.size(), 0.0);
    for (const Coupling& e : coupling_)
      for (int q = 0; q < 3; ++q)
        J[3 * std::size_t(e.body) + std::size_t(q)] += e.g[q] * double(x[std::size_t(e.unknown)]);
    const double f = double(c.rho0) * double(h_) * double(dt);
    const double tau0 = c.time - c.solids->time0;
    for (std::size_t b = 0; b < bodies_.size(); ++b) {
      if (!(bodies_[b].invMass > 0)) continue;
      const Vec2d Jl(f * J[3 * b], f * J[3 * b + 1]);
      const double L = f * J[3 * b + 2];
      c.solids->bodies[b].push(tau0, Jl, L);
      bodies_[b].v = c.solids->bodies[b].v;
      bodies_[b].omega = c.solids->bodies[b].omega;
    }
  }
  stats_.iterations += itS;
  stats_.pockets = int(pocketLast_.size());
  stats_.residual = double(res * dt * dt * invH_ * invH_);
  for (std::size_t a = 0; a < m; ++a) kappa_[std::size_t(cells_[a])] = x[a];
  pH_ = h_;
  pI0_ = I0_;
  pJ0_ = J0_;
  pnx_ = nx_;
  pny_ = ny_;
  prevKappa_ = kappa_;
}

}  // namespace sph2d
