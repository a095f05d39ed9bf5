// The coarse-grid projection's two systems (grid_projection.hpp): the matrix of the cells it
// classified (the ghost-fluid surface and the dynamic bodies' rows added), the pressure's and
// the compression shift's right-hand sides, and their solves side by side (the system and its
// conjugate gradients: grid_pcg.cpp).
#include "bodies/moving_solid.hpp"
#include "solvers/game/grid_projection.hpp"

#include <algorithm>
#include <cmath>

namespace sph2d {

void GridProjection::assemble() {
  const int nu = nx_ + 1;
  // The faces next to a fluid cell (their change is known; the others are extrapolated).
  auto isFluid = [&](int i, int j) { return type_[std::size_t(j) * nx_ + i] == kFluid; };
  for (int j = 0; j < ny_; ++j)
    for (int i = 1; i < nx_; ++i) fluidU_[std::size_t(j) * nu + i] = isFluid(i - 1, j) || isFluid(i, j);
  for (int j = 1; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) fluidV_[std::size_t(j) * nx_ + i] = isFluid(i, j - 1) || isFluid(i, j);
  if (surface_) {
    // Ghost fluid (Gibou, Fedkiw, Cheng & Kang 2002): κ = 0 on the surface, a fraction θ of
    // the way from a fluid cell to the centre of the air cell above it: half a spacing above
    // the highest particle of the two cells (the fill would say it too, but beside a wall or
    // over a compressed layer its reading differs by a tenth of a cell, and that difference
    // drives a flow). Fluid cells never touch the border: the cell above is in the grid.
    thetaUp_.assign(type_.size(), Real(1));
    for (int j = 0; j < ny_; ++j)
      for (int i = 0; i < nx_; ++i) {
        const std::size_t k = std::size_t(j) * nx_ + std::size_t(i), up = k + std::size_t(nx_);
        if (type_[k] != kFluid || !vOpen_[std::size_t(j + 1) * nx_ + i] || type_[up] != kAir) continue;
        const double ya = (double(J0_ + j) + 0.5) * double(h_);
        const Real ytop = std::max(top_[k], top_[up]);
        thetaUp_[k] =
            std::clamp(Real((double(ytop) + 0.5 * double(dx_) - ya) * double(invH_)), kMinSurfaceFraction, Real(1));
      }
  }
  const bool contrast = !uBeta_.empty();
  if (contrast) faceCoefficients();
  pcg_.assemble(nx_, ny_, type_, uOpen_, vOpen_, surface_ ? &thetaUp_ : nullptr, contrast ? &uBeta_ : nullptr,
                contrast ? &vBeta_ : nullptr);
  assembleCoupling();  // vents the regions a dynamic body touches
  pcg_.factor();
}

void GridProjection::faceCoefficients() {
  // r_face: the mean of the two cells' mass-weighted rest ratios (Σ w r / Σ w), or the one
  // cell's that holds particles; β = 1/r_face (1 where neither does).
  auto cellRatio = [&](std::size_t k) { return w_[k] > 0 ? wr_[k] / w_[k] : Real(0); };
  auto coefficient = [&](std::size_t k1, std::size_t k2) {
    const Real r1 = cellRatio(k1), r2 = cellRatio(k2);
    const Real r = r1 > 0 && r2 > 0 ? Real(0.5) * (r1 + r2) : std::max(r1, r2);
    return r > 0 ? Real(1) / r : Real(1);
  };
  const int nu = nx_ + 1;
  for (int j = 0; j < ny_; ++j)
    for (int i = 1; i < nx_; ++i) {
      const std::size_t k = std::size_t(j) * nx_ + std::size_t(i);
      uBeta_[std::size_t(j) * nu + i] = coefficient(k - 1, k);
    }
  for (int j = 1; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) {
      const std::size_t k = std::size_t(j) * nx_ + std::size_t(i);
      vBeta_[k] = coefficient(k - std::size_t(nx_), k);
    }
}

void GridProjection::addCoupled(const std::vector<Real>& in, std::vector<Real>& out) const {
  if (coupling_.empty()) return;
  // The dynamic bodies' response (Batty, Bertails & Bridson 2007, "A fast variational
  // framework for accurate solid-fluid coupling", on a voxelized body): the pressure's
  // impulse Gᵀκ moves a body by W Gᵀκ (W = M⁻¹, less what its resting contacts hold:
  // BodyState::W), which changes the flux through its faces by G·that. W is symmetric: the
  // system stays so.
  bodySum_.assign(3 * bodies_.size(), 0.0);
  for (const Coupling& e : coupling_)
    for (int q = 0; q < 3; ++q)
      bodySum_[3 * std::size_t(e.body) + std::size_t(q)] += e.g[q] * double(in[std::size_t(e.unknown)]);
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const double s[3] = {bodySum_[3 * b], bodySum_[3 * b + 1], bodySum_[3 * b + 2]};
    const auto& W = bodies_[b].W;
    for (int r = 0; r < 3; ++r)
      bodySum_[3 * b + std::size_t(r)] = couplingScale_ * (W[r][0] * s[0] + W[r][1] * s[1] + W[r][2] * s[2]);
  }
  for (const Coupling& e : coupling_) {
    const double* t = &bodySum_[3 * std::size_t(e.body)];
    out[std::size_t(e.unknown)] += Real(e.g[0] * t[0] + e.g[1] * t[1] + e.g[2] * t[2]);
  }
}

void GridProjection::pressureSystem(const StepContext& c) {
  const Real dt = c.dt;
  const int nu = nx_ + 1;
  const std::size_t m = pcg_.size();
  rhs_.assign(m, 0);
  std::vector<Real>& x = x_;
  x.assign(m, 0);
  // Warm start from the last substep's κ of the same anchored cells (none when the cells
  // grew to hold spray: the same index is then another place).
  const bool sameCells = h_ == pH_;
  if (sameCells)
    pcg_.forUnknowns([&](std::size_t a, int i, int j) {
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
  pcg_.forUnknowns([&](std::size_t a, int i, int j) {
    const int k = pcg_.cells()[a];
    const Real div = (uf(i + 1, j) - uf(i, j) + vf(i, j + 1) - vf(i, j)) * invH_;
    const Real comp = std::max(Real(0), comp_[std::size_t(k)] / w_[std::size_t(k)]);
    const Real src = div - rate_ * comp / dt;  // a compressed cell is to expand by rate·comp over the substep
    rhs_[a] = -(h_ * h_ / dt) * src;
  });
  pcg_.balance(rhs_);
}

void GridProjection::shiftSystem(const StepContext& c) {
  // The compression shift's right-hand side: −∇²φ = rate·(comp − above)/dt² per fluid cell,
  // comp = the cell's particle weight over a full cell's, − 1 (a count, as Kugelstadt et al.:
  // the SPH density of a disordered packing reads high, and removing that lifted the water:
  // 1.5 % energy gain at 40k, 2.8 % at 80k). The particles move by −dt²∇φ in
  // transferToParticles, their velocities unchanged.
  const Real dt = c.dt;
  const std::size_t m = pcg_.size();
  const Real invFull = Real(1) / (cellRatio_ * cellRatio_);
  rhsS_.resize(m);
  xs_.assign(m, 0);
  const std::size_t nx = std::size_t(nx_);
  for (std::size_t a = 0; a < m; ++a) {
    const std::size_t k = std::size_t(pcg_.cells()[a]);
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
  pcg_.balance(rhsS_);
}

void GridProjection::solve(const StepContext& c) {
  const Real dt = c.dt;
  const std::size_t m = pcg_.size();
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
  const GridPcg::Extra bodies = [this](const std::vector<Real>& in, std::vector<Real>& out) { addCoupled(in, out); };
  c.pool.parallelFor(shifting ? 2 : 1, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      if (k == 0) {
        pressureSystem(c);
        stats_.iterations = pcg_.solve(x, rhs_, tol_ * scale, maxIt_, res, cgMain_, coupled ? &bodies : nullptr);
      } else {
        shiftSystem(c);
        itS = pcg_.solve(xs_, rhsS_, shiftDef_.tolerance * scale, maxIt_, resS, cgShift_);
        kappaS_.assign(type_.size(), 0);
        for (std::size_t a = 0; a < m; ++a) kappaS_[std::size_t(pcg_.cells()[a])] = xs_[a];
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
  stats_.pockets = int(pcg_.pockets());
  stats_.residual = double(res * dt * dt * invH_ * invH_);
  for (std::size_t a = 0; a < m; ++a) kappa_[std::size_t(pcg_.cells()[a])] = x[a];
  pH_ = h_;
  pI0_ = I0_;
  pJ0_ = J0_;
  pnx_ = nx_;
  pny_ = ny_;
  prevKappa_ = kappa_;
}

}  // namespace sph2d
