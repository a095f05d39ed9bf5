// The coarse-grid projection's way back to the particles (grid_projection.hpp): face weights
// and samples, extrapolation past the fluid, the compression shift's moves, and the FLIP/PIC
// transfer of the velocity change (with the static walls' impulse and the optional clamp).
#include "bodies/moving_solid.hpp"
#include "core/state_io.hpp"
#include "solvers/game/grid_projection.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace sph2d {

GridProjection::FaceWeights GridProjection::faceWeights(Real px, Real py) const {
  // Bilinear over the MAC faces: u at (i, j + 1/2), v at (i + 1/2, j), in cell units of the
  // grid (px, py ≥ 0: the grid has a margin, so truncation is floor).
  FaceWeights w;
  {
    const Real fx = px, fy = py - Real(0.5);
    const int i0 = int(fx), j0 = int(fy);
    const Real tx = fx - Real(i0), ty = fy - Real(j0);
    w.ku = std::size_t(j0) * std::size_t(nx_ + 1) + std::size_t(i0);
    w.u[0] = (1 - tx) * (1 - ty);
    w.u[1] = tx * (1 - ty);
    w.u[2] = (1 - tx) * ty;
    w.u[3] = tx * ty;
  }
  {
    const Real fx = px - Real(0.5), fy = py;
    const int i0 = int(fx), j0 = int(fy);
    const Real tx = fx - Real(i0), ty = fy - Real(j0);
    w.kv = std::size_t(j0) * std::size_t(nx_) + std::size_t(i0);
    w.v[0] = (1 - tx) * (1 - ty);
    w.v[1] = tx * (1 - ty);
    w.v[2] = (1 - tx) * ty;
    w.v[3] = tx * ty;
  }
  return w;
}

Vec2 GridProjection::sampleFaces(const std::vector<Real>& u, const std::vector<Real>& v, const FaceWeights& w) const {
  const std::size_t nu = std::size_t(nx_ + 1), k = w.ku, kv = w.kv, nv = std::size_t(nx_);
  const Real ux = w.u[0] * u[k] + w.u[1] * u[k + 1] + w.u[2] * u[k + nu] + w.u[3] * u[k + nu + 1];
  const Real uy = w.v[0] * v[kv] + w.v[1] * v[kv + 1] + w.v[2] * v[kv + nv] + w.v[3] * v[kv + nv + 1];
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

void GridProjection::shiftMoves(const StepContext& c) {
  // The shift's face moves: −dt²∇φ across open faces between fluid and air cells (none
  // through a wall or a moving body), extrapolated one layer as the velocity change is.
  const Real dt = c.dt;
  const int nu = nx_ + 1;
  const Real k2 = -dt * dt * invH_;
  auto phi = [&](int i, int j) {  // φ in a fluid cell, 0 elsewhere (air holds 0)
    return type_[std::size_t(j) * nx_ + i] == kFluid ? kappaS_[std::size_t(j) * nx_ + i] : Real(0);
  };
  su_.assign(u_.size(), 0);
  sv_.assign(v_.size(), 0);
  for (int j = 0; j < ny_; ++j)
    for (int i = 1; i < nx_; ++i) {
      const std::size_t f = std::size_t(j) * nu + i;
      if (!fluidU_[f]) continue;
      const std::size_t kl = std::size_t(j) * nx_ + i - 1, kr = kl + 1;
      const bool solidSide = type_[kl] == kSolid || type_[kr] == kSolid;
      if (uOpen_[f] && !solidSide && bodyAcross(kl, kr) < 0) su_[f] = k2 * (phi(i, j) - phi(i - 1, j)) * beta(0, f);
    }
  extrapolate(su_, nu, ny_, fluidU_);
  for (int j = 1; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) {
      const std::size_t f = std::size_t(j) * nx_ + i;
      if (!fluidV_[f]) continue;
      const std::size_t kd = std::size_t(j - 1) * nx_ + i, ku = kd + std::size_t(nx_);
      const bool solidSide = type_[kd] == kSolid || type_[ku] == kSolid;
      // Under the ghost surface the gradient spans θ of a cell (the matrix's 1/θ).
      const Real span = surface_ && type_[ku] == kAir ? thetaUp_[kd] : Real(1);
      if (vOpen_[f] && !solidSide && bodyAcross(kd, ku) < 0)
        sv_[f] = k2 * (phi(i, j) - phi(i, j - 1)) / span * beta(1, f);
    }
  extrapolate(sv_, nx_, ny_ + 1, fluidV_);
}

std::size_t GridProjection::transferToParticles(StepContext& c) {
  const Real dt = c.dt;
  const int nu = nx_ + 1;
  // κ in a fluid cell, 0 elsewhere (air holds 0; solid faces are not read).
  auto kap = [&](int i, int j) {
    return type_[std::size_t(j) * nx_ + i] == kFluid ? kappa_[std::size_t(j) * nx_ + i] : Real(0);
  };
  const bool shifting = shiftDef_.on();
  // The static solids' impulse on the fluid (World::wallImpulse, WallImpulse::grid), per axis in
  // face order within its task: on each face closed by a static solid (a solid cell beside it, or
  // a wall across it) next to a fluid cell, the cell's pressure ρ0κ over the face's length h for
  // dt, pushing away from the face; and the normal velocity the face removes, −u_f, times the
  // particle mass on the face (m × its splat weight). Between fluid cells the pressure gradient
  // telescopes to these end terms on a grid of uniform mass ρ0h² a face; a moving body's faces
  // are not static (the body takes their impulse).
  const bool countWall = c.wall != nullptr;
  const double wallM = double(c.momentumMass), wallP = wallM / (double(c.dx) * double(c.dx)) * double(h_) * double(dt);
  double wallAxis[2] = {0, 0};
  // The u faces and the v faces are independent: two tasks, each serial. Open faces
  // next to fluid take the pressure gradient; closed faces next to fluid lose their
  // normal velocity (the wall).
  c.pool.parallelFor(2, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t task = b; task < e; ++task) {
      if (task == 0) {
        for (int j = 0; j < ny_; ++j)
          for (int i = 1; i < nx_; ++i) {
            const std::size_t f = std::size_t(j) * nu + i;
            if (!fluidU_[f]) continue;
            const std::size_t kl = std::size_t(j) * nx_ + i - 1, kr = kl + 1;
            const bool solidSide = type_[kl] == kSolid || type_[kr] == kSolid;
            const int body = solidSide ? -1 : bodyAcross(kl, kr);
            du_[f] = body >= 0                 ? bodyFaceVelocity(body, 0, i, j) - u_[f]  // a moving body's face
                     : uOpen_[f] && !solidSide ? -dt * (kap(i, j) - kap(i - 1, j)) * invH_ * beta(0, f)
                                               : -u_[f];
            if (countWall && body < 0 && !(uOpen_[f] && !solidSide))
              wallAxis[0] += wallP * (double(kap(i, j)) - double(kap(i - 1, j))) +
                             wallM * double(uw_[f]) * double(du_[f]) / double(beta(0, f));
          }
        extrapolate(du_, nu, ny_, fluidU_);
        if (pic_ > 0)  // the projected face velocities (closed faces: 0)
          for (std::size_t f = 0; f < u_.size(); ++f) uNew_[f] = u_[f] + du_[f];
      } else {
        for (int j = 1; j < ny_; ++j)
          for (int i = 0; i < nx_; ++i) {
            const std::size_t f = std::size_t(j) * nx_ + i;
            if (!fluidV_[f]) continue;
            const std::size_t kd = std::size_t(j - 1) * nx_ + i, ku = kd + std::size_t(nx_);
            const bool solidSide = type_[kd] == kSolid || type_[ku] == kSolid;
            const int body = solidSide ? -1 : bodyAcross(kd, ku);
            // Under the ghost surface the gradient spans θ of a cell (the matrix's 1/θ).
            const Real span = surface_ && type_[ku] == kAir ? thetaUp_[kd] : Real(1);
            dv_[f] = body >= 0                 ? bodyFaceVelocity(body, 1, i, j) - v_[f]
                     : vOpen_[f] && !solidSide ? -dt * (kap(i, j) - kap(i, j - 1)) * invH_ / span * beta(1, f)
                                               : -v_[f];
            if (countWall && body < 0 && !(vOpen_[f] && !solidSide))
              wallAxis[1] += wallP * (double(kap(i, j)) - double(kap(i, j - 1))) +
                             wallM * double(vw_[f]) * double(dv_[f]) / double(beta(1, f));
          }
        extrapolate(dv_, nx_, ny_ + 1, fluidV_);
        if (pic_ > 0)
          for (std::size_t f = 0; f < v_.size(); ++f) vNew_[f] = v_[f] + dv_[f];
      }
    }
  });
  if (countWall) c.wall->sum.grid += Vec2d(wallAxis[0], wallAxis[1]);
  ParticleStore& P = c.P;
  const Real vmax2 = c.maxSpeed * c.maxSpeed;
  const Real logKeep = std::log(Real(1) - std::min(pic_, Real(0.999999f)));
  if (shifting)
    shift_.resize(P.size());
  else
    shift_.clear();
  const bool balancing = conserve_ && momentumClusters();
  if (balancing) {
    partCluster_.resize(P.size());
    partDelta_.resize(P.size());
  }
  const std::size_t badSlot = firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
    std::size_t bad = kNone;
    for (std::size_t p = b; p < e; ++p) {
      const Real px = P.x[p].x() * invH_ - Real(I0_), py = P.x[p].y() * invH_ - Real(J0_);
      const FaceWeights w = faceWeights(px, py);  // the same for every face field
      const Vec2 v0 = P.v[p];
      Vec2 vp = v0 + sampleFaces(du_, dv_, w);  // FLIP: the change of the grid velocity
      if (pic_ > 0) {
        // PIC share: towards the projected grid velocity itself (smooths particle noise), once
        // per cell its velocity carries it in the substep, at least once: 1 − (1 − pic)^n. FLIP
        // keeps the part of a particle's velocity the grid does not carry, and with it the
        // projection's noise; a 50 m/s jet crosses six cells a substep, and with the share
        // once per substep that noise built up along a stream two cells wide (particles at
        // 1.6 times the jet's specific energy, 2.6 at 80 m/s; tests/stability/test_impacts.cpp).
        const Vec2 ug = sampleFaces(uNew_, vNew_, w);
        const Real cells = std::sqrt(v0.squaredNorm()) * dt * invH_;
        const Real share = cells > 1 && pic_ < 1 ? Real(1) - std::exp(cells * logKeep) : pic_;
        vp += (ug - vp) * share;
      }
      if (flipClamp_) vp = clampToFaces(vp, v0, w);
      P.v[p] = vp;
      if (shifting) shift_[p] = sampleFaces(su_, sv_, w);
      if (balancing) {
        partCluster_[p] = clusterAt(px, py);
        partDelta_[p] = vp - v0;
      }
      if (bad == kNone && (!allFinite(P.v[p]) || P.v[p].squaredNorm() > vmax2)) bad = p;
    }
    return bad;
  });
  if (balancing && badSlot == kNone) return balanceMomentum(c);
  return badSlot;
}

Vec2 GridProjection::clampToFaces(const Vec2& vp, const Vec2& v0, const FaceWeights& w) const {
  // The particle no faster than it was, or than the projected velocity (u + Δu) of the faces
  // it samples can make it (the largest |u| and |v| of its stencil together): the transfer
  // makes no new extreme of speed. Only the speed is limited, not the direction (a clamp per
  // axis made a resting tank creep sideways, 4 mm in 333 s).
  const std::size_t nu = std::size_t(nx_ + 1), nv = std::size_t(nx_);
  const std::size_t ku[4] = {w.ku, w.ku + 1, w.ku + nu, w.ku + nu + 1};
  const std::size_t kv[4] = {w.kv, w.kv + 1, w.kv + nv, w.kv + nv + 1};
  Real u2 = 0, v2 = 0;
  for (int q = 0; q < 4; ++q) {
    const Real u = u_[ku[q]] + du_[ku[q]], v = v_[kv[q]] + dv_[kv[q]];
    u2 = std::max(u2, u * u);
    v2 = std::max(v2, v * v);
  }
  const Real limit2 = std::max(v0.squaredNorm(), u2 + v2), s2 = vp.squaredNorm();
  return s2 > limit2 ? Vec2(vp * std::sqrt(limit2 / s2)) : vp;
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
    if (type_[ks[q]] == kSolid || type_[ks[q]] == kBody) continue;
    wsum += wq[q];
    if (type_[ks[q]] == kFluid) sum += wq[q] * kappa_[ks[q]];
  }
  return wsum > 0 ? sum / wsum : Real(0);
}

}  // namespace sph2d
