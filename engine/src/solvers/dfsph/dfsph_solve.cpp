// dfsph_solve.cpp — dfsph's two pressure solves (divergence-free and constant density): the
// warm start, the source pass A and the correction pass B with Chebyshev semi-iteration, and
// the dynamic bodies' response within them (dfsph.hpp, steps 2 and 4, A and B).
#include "solvers/dfsph/dfsph.hpp"

namespace sph2d {

/// One solve: warm start, then iterations of (B, A) until the mean error is small.
/// divergence: the divergence-free solve (source Dρ/Dt), else the constant-density solve.
void Dfsph::solve(StepContext& c, bool divergence) {
  ParticleStore& P = c.P;
  const std::size_t n = P.size();
  std::vector<Real>& kappa = *P.find(divergence ? "dfsph.kappa_v" : "dfsph.kappa");
  const Real dt = c.dt;
  const double limit =
      divergence ? divTol_ * double(c.rho0) / double(dt) : tol_ * double(c.rho0);  // on the mean residual
  double err = 0;
  // The walls' share of the velocity change, Σ_i of what pass B gave particle i through its
  // wall term −dt q_i Σ_b ρ0Ψ_b∇W_ib since the solve began, combined by the same Chebyshev
  // weights as the velocities (linear in them, so the sum follows the particles' recurrence).
  Vec2d wall(0, 0);
  {
    // Stored κ_v is κ_v·dt of the previous substep (an impulse); κ is p/ρ.
    const Real scale = divergence ? Real(1) / dt : Real(1);
    if (cheb_ > 0) {
      vPrev_.resize(n);
      kPrev_.resize(n);
    }
    if (moving_) {  // the bodies as the previous solve left them
      dv_ = dvBase_;
      dw_ = dwBase_;
    }
    wall = warmStart(c, kappa, scale);
    err = sourceMean(c, kappa, divergence);
  }
  int it = 0;
  if (cheb_ > 0) {
    vPrev_.assign(P.v.begin(), P.v.end());
    kPrev_.assign(kappa.begin(), kappa.end());
    if (moving_) qAccPrev_.assign(qAcc_.begin(), qAcc_.end());
  }
  Vec2d wallPrev = wall;  // the wall's Σ Δv at the iterate vPrev_ holds
  Real w = 1;
  int chebStart = kChebDelay;
  double lastErr = err;
  // With dynamic bodies also until the mean residual of the particles beside them is small:
  // the bodies' response is a global mode the mean over all particles hides.
  while (it < maxIt_ && (it < minIt_ || err > limit || bodyErr_ > limit)) {
    // Chebyshev weights (Wang 2015): 1 for the first kChebDelay iterations,
    // then 2/(2 − ρ²), then 4/(4 − ρ² w).
    if (cheb_ > 0 && it >= chebStart)
      w = it == chebStart ? Real(2) / (Real(2) - cheb_ * cheb_) : Real(4) / (Real(4) - cheb_ * cheb_ * w);
    else
      w = 1;
    const Vec2d step = wall + correctPass(c, kappa, w);  // the Jacobi iterate's
    const Vec2d next = cheb_ > 0 && w != 1 ? Vec2d((step - wallPrev) * double(w) + wallPrev) : step;
    if (cheb_ > 0) wallPrev = wall;
    wall = next;
    err = sourceMean(c, kappa, divergence);
    ++it;
    // Safeguard: a residual that grows restarts the acceleration (plain steps first).
    if (cheb_ > 0 && it > chebStart && err > lastErr) chebStart = it + kChebDelay;
    lastErr = err;
  }
  if (c.wall) c.wall->sum.samples += wall * double(c.momentumMass);
  if (moving_) {
    react(c);
    dvBase_ = dv_;
    dwBase_ = dw_;
  }
  if (divergence) {
    c.pool.parallelFor(n, 4096, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) kappa[i] *= dt;
    });
    stats_.divergenceIterations = it;
    stats_.divergenceError = err * double(dt) / double(c.rho0);
  } else {
    stats_.pressureIterations = it;
    stats_.densityError = err / double(c.rho0);
  }
}

/// v_i −= dt [Σ_j m (κ_i/ρ_i + κ_j/ρ_j) ∇W_ij + Σ_b ρ0Ψ_b (κ_i/ρ_i) ∇W_ib] with κ = scale·kappa; then kappa = κ.
/// Returns the walls' share Σ_i Δv_i of the velocity change (correctPass).
Vec2d Dfsph::warmStart(StepContext& c, std::vector<Real>& kappa, Real scale) {
  ParticleStore& P = c.P;
  const std::size_t n = P.size();
  const Real* IR = P.invRho.data();
  Real* K = kappa.data();
  c.pool.parallelFor(n, 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      dk_[i] = scale * K[i];
      q_[i] = dk_[i] * IR[i];
      K[i] = 0;  // correctPass adds dk_ back
    }
    if (moving_) std::fill(qAcc_.begin() + std::ptrdiff_t(b), qAcc_.begin() + std::ptrdiff_t(e), 0.0);
  });
  return correctPass(c, kappa);
}

/// The mean residual of pass A; in a closed domain (closed_) the source's
/// mean is first found by a pass with no shift, then removed.
double Dfsph::sourceMean(StepContext& c, const std::vector<Real>& kappa, bool divergence) {
  const double n = double(std::max<std::size_t>(c.P.size(), 1));
  Real shift = 0;
  if (closed_) shift = Real(sourcePass(c, kappa, divergence, 0).src / n);
  const Sums s = sourcePass(c, kappa, divergence, shift);
  bodyErr_ = s.bodyN > 0 ? s.bodyErr / s.bodyN : 0;
  return s.err / n;
}

Dfsph::Sums Dfsph::sourcePass(StepContext& c, const std::vector<Real>& kappa, bool divergence, Real shift) {
  ParticleStore& P = c.P;
  const NeighbourLists& L = c.nbr;
  const Vec2* V = P.v.data();
  const Real* K = kappa.data();
  const Real dt = c.dt, invDt = Real(1) / dt, rho0 = c.rho0;
  const Real wInvDt = omega_ * invDt, wInvDt2 = wInvDt * invDt;
  const bool unilateral = unilateral_;
  const Real kMin = kMin_;
  const Real kneeRho = kKneeDensity * rho0;
  const Real pushout = rho0 * Real(2) * kPushoutSpeed * dt / c.dx;  // [kg/m³] per substep
  const Real* movSrc = moving_ ? movSrc_.data() : nullptr;
  return c.pool.reduce(
      P.size(), kBlock, Sums{},
      [&](std::size_t b, std::size_t e) {
        const std::vector<Pair>& G = pairs_[b / kBlock];
        double errSum = 0, srcSum = 0, bodyErr = 0, bodyN = 0;
        for (std::size_t i = b; i < e; ++i) {
          const std::uint32_t cnt = L.count[i];
          const Pair* Gi = G.data() + L.start[i];
          // Σ_j m∇W_ij·(v_i − v_j) + Σ_b ρ0Ψ_b∇W_ib·v_i (walls at rest) = v_i·gradSum − Σ_j m∇W_ij·v_j.
          Real sx = 0, sy = 0;
          for (std::uint32_t k = 0; k < cnt; ++k) {
            const Vec2& vj = V[Gi[k].j];
            sx += Gi[k].gx * vj.x();
            sy += Gi[k].gy * vj.y();
          }
          Real div = (gradSum_[i].x() * V[i].x() + gradSum_[i].y() * V[i].y()) - (sx + sy);
          if (movSrc) {  // the moving samples' velocities: Σ_b ρ0Ψ_b∇W_ib·(v_i − v_b)
            Real ms = movSrc[i];
            const std::vector<MovTerm>& T = movTerms_[b / kBlock];
            for (std::uint32_t k = movStart_[i], ke = k + movCount_[i]; k < ke; ++k)  // the bodies' response so far
              ms += Real(double(T[k].gx) * dv_[T[k].body].x() + double(T[k].gy) * dv_[T[k].body].y() +
                         double(T[k].t) * dw_[T[k].body]);
            div -= ms;
          }
          Real src, dk;
          if (divergence) {
            src = div - shift;
            dk = src * alpha_[i] * wInvDt;
          } else {
            src = P.rho[i] + dt * div - rho0 - shift;
            // Compression already there is removed at most at the pushout rate.
            const Real excess = P.rho[i] - rho0 - pushout;
            if (excess > 0) src -= excess;
            dk = src * alpha_[i] * wInvDt2;
          }
          // Beyond the knee density the Jacobi step shrinks as ρ_knee/ρ_i (the header's A).
          if (P.rho[i] > kneeRho) dk *= kneeRho * P.invRho[i];
          // Complementarity residual: where κ_i > 0 the constraint is active and
          // any deviation counts; where κ_i = 0 only compression does.
          const double err = double(K[i] > 0 || !unilateral ? std::fabs(src) : std::max(src, Real(0)));
          errSum += err;
          if (movSrc && movCount_[i] > 0) bodyErr += err, bodyN += 1;
          dk = std::max(dk, kMin - K[i]);  // κ stays ≥ 0: no tension at the free surface
          dk_[i] = dk;
          q_[i] = dk * P.invRho[i];
          srcSum += double(src);
        }
        return Sums{errSum, srcSum, bodyErr, bodyN};
      },
      [](Sums a, Sums b) {
        return Sums{a.err + b.err, a.src + b.src, a.bodyErr + b.bodyErr, a.bodyN + b.bodyN};
      });
}

/// Pass B: v_i −= dt [Σ_j (q_i + q_j) m∇W_ij + q_i Σ_b ρ0Ψ_b∇W_ib]; κ_i += dk_i
/// (w ≠ 1: the Chebyshev step from the previous iterate). Returns the walls' share of the
/// Jacobi step, Σ_i −dt q_i Σ_b ρ0Ψ_b∇W_ib, summed per block and the blocks in order.
Vec2d Dfsph::correctPass(StepContext& c, std::vector<Real>& kappa, Real w) {
  ParticleStore& P = c.P;
  const NeighbourLists& L = c.nbr;
  Vec2* V = P.v.data();
  const Real* Q = q_.data();
  const Real dt = c.dt;
  const Real kMin = kMin_;
  const std::size_t blocks = (P.size() + kBlock - 1) / kBlock;
  wallBlock_.assign(blocks, Vec2d(0, 0));
  double* QA = moving_ ? qAcc_.data() : nullptr;  // Σ of the q_i applied (the moving bodies' reaction)
  c.pool.parallelFor(P.size(), kBlock, [&](std::size_t b, std::size_t e) {
    const std::vector<Pair>& G = pairs_[b / kBlock];
    Vec2d wallSum(0, 0);
    for (std::size_t i = b; i < e; ++i) {
      const Real qi = Q[i];
      wallSum -= wallGrad_[i].cast<double>() * (double(dt) * double(qi));
      const std::uint32_t cnt = L.count[i];
      const Pair* Gi = G.data() + L.start[i];
      // Σ_j (q_i + q_j) m∇W_ij + q_i Σ_b ρ0Ψ_b∇W_ib = q_i gradSum + Σ_j q_j m∇W_ij.
      Real ax = 0, ay = 0;
      for (std::uint32_t k = 0; k < cnt; ++k) {
        const Real qj = Q[Gi[k].j];
        ax += Gi[k].gx * qj;
        ay += Gi[k].gy * qj;
      }
      ax += gradSum_[i].x() * qi;
      ay += gradSum_[i].y() * qi;
      const Vec2 vJ(V[i].x() - dt * ax, V[i].y() - dt * ay);
      const Real kJ = std::max(kappa[i] + dk_[i], kMin);
      if (cheb_ > 0) {  // x_{k+1} = w (x_Jacobi − x_{k−1}) + x_{k−1}; κ clamped again
        const Vec2 vOld = V[i];
        const Real kOld = kappa[i];
        V[i] = w == 1 ? vJ : Vec2((vJ - vPrev_[i]) * w + vPrev_[i]);
        kappa[i] = w == 1 ? kJ : std::max((kJ - kPrev_[i]) * w + kPrev_[i], kMin);
        vPrev_[i] = vOld;
        kPrev_[i] = kOld;
        if (QA) {  // the same recurrence as the velocity's
          const double qJ = QA[i] + double(qi), qOld = QA[i];
          QA[i] = w == 1 ? qJ : (qJ - qAccPrev_[i]) * double(w) + qAccPrev_[i];
          qAccPrev_[i] = qOld;
        }
      } else {
        V[i] = vJ;
        kappa[i] = kJ;
        if (QA) QA[i] += double(qi);
      }
    }
    wallBlock_[b / kBlock] = wallSum;
    if (QA) {  // Σ_i Q_i G_ik and Σ_i Q_i T_ik of this block, per body
      const std::size_t K = dv_.size();
      Vec2d* bg = blockG_.data() + (b / kBlock) * K;
      double* bt = blockT_.data() + (b / kBlock) * K;
      std::fill(bg, bg + K, Vec2d(0, 0));
      std::fill(bt, bt + K, 0.0);
      const std::vector<MovTerm>& T = movTerms_[b / kBlock];
      for (std::size_t i = b; i < e; ++i)
        for (std::uint32_t k = movStart_[i], ke = k + movCount_[i]; k < ke; ++k) {
          bg[T[k].body] += Vec2d(double(T[k].gx), double(T[k].gy)) * QA[i];
          bt[T[k].body] += double(T[k].t) * QA[i];
        }
    }
  });
  if (QA) bodyResponse(c, blocks);
  return sumInOrder(wallBlock_, blocks);
}

/// The dynamic bodies' velocity change so far in the substep (strong coupling: the solve's
/// next source sees the samples move with it): ΔV_k = Δ_prev + m dt Σ_i Q_i G_ik / M_k,
/// Δω_k = Δω_prev + m dt Σ_i Q_i T_ik / I_k, the blocks' sums in block order.
void Dfsph::bodyResponse(const StepContext& c, std::size_t blocks) {
  const std::size_t K = dv_.size();
  const double mdt = double(c.momentumMass) * double(c.dt);
  for (std::size_t k = 0; k < K; ++k) {
    Vec2d g(0, 0);
    double t = 0;
    for (std::size_t bl = 0; bl < blocks; ++bl) {
      g += blockG_[bl * K + k];
      t += blockT_[bl * K + k];
    }
    dv_[k] = dvBase_[k] + g * (mdt * invMass_[k]);
    dw_[k] = dwBase_[k] + t * (mdt * invInertia_[k]);
  }
}

}  // namespace sph2d
