// dfsph.cpp — the dfsph solver's fields (density, the factor α, the bodies' lumped terms), its
// stages, time step, integration and registration. The method and every choice: dfsph.hpp.
#include "solvers/dfsph/dfsph.hpp"

namespace sph2d {

/// Creates the κ fields; density, α and gradients of the initial positions.
void Dfsph::prepare(StepContext& c) {
  std::vector<Real>& kappa = c.P.field("dfsph.kappa");
  c.P.field("dfsph.kappa_v");
  stageGrid(c, false);
  stageNeighbours(c);
  densityAndFactor(c, WendlandC2<Real>(c.R));
  hydrostaticWarmStart(c, kappa);
}

/// The first pressure solve's warm start: the hydrostatic κ = |g|·(depth
/// below the highest particle of the same column, strips of width R across
/// gravity) + |g| dx/2, and p = κρ for readers. A column starts at rest
/// and incompressible, so this is its pressure; without it the first
/// solves build ρ0 g H from zero, and a Jacobi iteration needs about
/// (H/dx)² iterations for that (measured: at dx = 5 mm the 2 m dam-break
/// column crushed its floor rows by 55 % and blew up at t = 0.06 s).
void Dfsph::hydrostaticWarmStart(StepContext& c, std::vector<Real>& kappa) const {
  ParticleStore& P = c.P;
  const Real g = hydrostaticGravity(c).norm();
  if (!(g > 0) || P.size() == 0) return;
  depths(c, [&](std::size_t i, Real depth) {
    kappa[i] = g * (depth + Real(0.5) * c.dx);
    P.p[i] = kappa[i] * P.rho[i];
  });
}

/// velocity_cfl·R/v_max, 0.1·sqrt(R/|g|), 0.25·sqrt(R/a_max) and 0.35·R/sqrt(|g| D), whichever is least
/// (docs/SOLVERS.md: the hydrostatic stiffness limit).
Real Dfsph::maxTimeStep(const StepContext& c, Real vmax, Real amax) const {
  Real dt = cfl_ * c.R / std::max(vmax, Real(1e-6) * c.R);
  const Real g = c.gravity.norm();
  if (g > 0) dt = std::min(dt, Real(0.1) * std::sqrt(c.R / g));
  if (amax > 0) dt = std::min(dt, kForceCfl * std::sqrt(c.R / amax));
  // The hydrostatic pressure's own stiffness: dt ≤ 0.35·R/sqrt(|g| D) (docs/SOLVERS.md).
  const Real gh = hydrostaticGravity(c).norm();
  if (gh > 0 && c.P.size() > 0) {
    Real dMax = 0;
    depths(c, [&](std::size_t, Real depth) { dMax = std::max(dMax, depth); });
    if (dMax > 0) dt = std::min(dt, kPressureCfl * c.R / std::sqrt(gh * dMax));
  }
  return dt;
}

/// grid → neighbours → density (and α) → divergence_solve → gravity → effects →
/// predict_velocity → pressure_solve → integrate.
std::vector<Stage> Dfsph::stages(bool) {
  std::vector<Stage> s;
  s.push_back(plainStage("grid", [](StepContext& c) { stageGrid(c, reorderThisStep(c)); }));
  s.push_back(plainStage("neighbours", [](StepContext& c) { stageNeighbours(c); }));
  s.push_back(Stage{"density", [this](StepContext& c) {
                      c.P.field("dfsph.kappa");
                      c.P.field("dfsph.kappa_v");
                      closed_ = !unilateral_ && c.periodic.x && c.periodic.y && c.boundary.samples.empty();
                      stats_ = SolverStats{};
                      return densityAndFactor(c, WendlandC2<Real>(c.R));
                    }});
  if (divSolve_) s.push_back(plainStage("divergence_solve", [this](StepContext& c) { solve(c, true); }));
  s.push_back(plainStage("gravity", [](StepContext& c) {
    c.pool.parallelFor(c.P.size(), kStreamBlock, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) c.P.a[i] = c.gravity;
    });
  }));
  s.push_back(Stage::effects());
  s.push_back(plainStage("predict_velocity", [](StepContext& c) {
    c.pool.parallelFor(c.P.size(), kStreamBlock, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) c.P.v[i] += c.P.a[i] * c.dt;
    });
  }));
  s.push_back(plainStage("pressure_solve", [this](StepContext& c) { solve(c, false); }));
  s.push_back(Stage{"integrate", [this](StepContext& c) { return integrate(c); }});
  return s;
}

/// ρ, 1/ρ, α, the per-neighbour (slot, m∇W_ij) and per particle Σ_j m∇W_ij + Σ_b ρ0Ψ_b∇W_ib.
std::size_t Dfsph::densityAndFactor(StepContext& c, const WendlandC2<Real>& W) {
  ParticleStore& P = c.P;
  const std::size_t n = P.size();
  const BoundarySet& B = c.boundary;
  const bool walls = !B.samples.empty();
  const BodySamples* moving = c.bodySamples && c.bodySamples->active() ? c.bodySamples : nullptr;
  const NeighbourLists& L = c.nbr;
  pairs_.resize(L.perBlock.size());
  moving_ = moving != nullptr;
  if (moving_) {
    movSrc_.resize(n);
    movStart_.resize(n);
    movCount_.resize(n);
    movTerms_.resize(L.perBlock.size());
    qAcc_.resize(n);
    if (cheb_ > 0) qAccPrev_.resize(n);
    const std::size_t K = moving->placed.size();
    invMass_.assign(K, 0.0);
    invInertia_.assign(K, 0.0);
    for (std::size_t k = 0; k < K && c.solids && k < c.solids->bodies.size(); ++k)
      if (moving->placed[k].dynamic) {
        invMass_[k] = c.solids->bodies[k].invMass;
        invInertia_[k] = c.solids->bodies[k].invInertia;
      }
    dvBase_.assign(K, Vec2d(0, 0));
    dwBase_.assign(K, 0.0);
    dv_.assign(K, Vec2d(0, 0));
    dw_.assign(K, 0.0);
    const std::size_t blocks = L.perBlock.size();
    blockG_.assign(blocks * K, Vec2d(0, 0));
    blockT_.assign(blocks * K, 0.0);
  }
  gradSum_.resize(n);
  wallGrad_.resize(n);
  alpha_.resize(n);
  dk_.resize(n);
  q_.resize(n);
  const Real R = c.R;
  const Real gradK = W.gradientScale;  // ∇W = gradK (1 − q)³ d
  const Real mGradK = c.mass * gradK;
  const Real aFlat = Real(1) - kFlatGradientQ;
  const Real mGradFlat = mGradK * aFlat * aFlat * aFlat * (kFlatGradientQ * R);  // m|∇W| at q = 1/4, times r/|d|
  const Real self = W.value(0);
  // Below this the factor's denominator means no neighbours at all (a full
  // neighbourhood gives about 2 (ρ0/R)² at R = 2.5 dx).
  const Real eps = Real(1e-6) * (c.rho0 / R) * (c.rho0 / R);
  const Real factorFloor = kFactorFloor * (c.rho0 / R) * (c.rho0 / R);  // the header's (3)
  const Vec2* X = P.x.data();
  const std::size_t firstBadSlot = firstBad(c.pool, n, [&](std::size_t b, std::size_t e) {
    std::size_t bad = kNone;
    std::vector<Pair>& G = pairs_[b / kBlock];
    G.resize(L.perBlock[b / kBlock].size());
    for (std::size_t i = b; i < e; ++i) {
      const std::uint32_t* nb = L.of(i);
      const std::uint32_t cnt = L.count[i];
      Pair* Gi = G.data() + L.start[i];
      Real sum = self, gx = 0, gy = 0, sq = 0;
      for (std::uint32_t k = 0; k < cnt; ++k) {
        const std::uint32_t j = nb[k];
        Real dx, dy, r2;
        pairDelta(c, i, j, dx, dy, r2);  // coincident pairs: a fixed, antisymmetric direction
        const Real r = std::sqrt(r2);
        const Real q = r * W.invR;
        const Real a = Real(1) - q;
        sum += W.valueQ(q);
        // m∇W_ij = g·d; below q = 1/4, where |∇W| peaks, the solves' gradient keeps
        // its peak magnitude along d (the header's (2); docs/SOLVERS.md, issue 17).
        const Real g = q < kFlatGradientQ ? mGradFlat / r : mGradK * a * a * a;
        const Real gxk = g * dx, gyk = g * dy;
        Gi[k] = Pair{j, gxk, gyk};
        gx += gxk;
        gy += gyk;
        sq += gxk * gxk + gyk * gyk;
      }
      Real rho = c.mass * sum;
      Vec2 gb = Vec2::Zero();
      if (walls) {
        Real vol = 0;
        const Vec2 xi = X[i];
        const std::uint32_t* bl = L.boundaryOf(i);
        for (std::uint32_t k = 0; k < L.boundaryCount[i]; ++k) {
          const std::uint32_t s = bl[k];
          const Vec2 d = xi - B.samples[s];
          const Real q = std::sqrt(d.squaredNorm()) * W.invR;
          const Real a = Real(1) - q;
          vol += B.volume[s] * W.valueQ(q);
          gb += d * (gradK * a * a * a * B.volume[s]);
        }
        rho += c.rho0 * vol;
        gb *= c.rho0;
      }
      Vec2 gm = Vec2::Zero();  // the moving samples' Σ ρ0Ψ_b∇W_ib
      if (moving) {
        // Body by body (the list holds each body's samples together): ρ, the gradient, the
        // source's Σ ρ0Ψ_b∇W_ib·v_b, and per dynamic body G_ik and T_ik for the reaction.
        std::vector<MovTerm>& T = movTerms_[b / kBlock];
        if (i == b) T.clear();
        movStart_[i] = std::uint32_t(T.size());
        const Vec2 xi = X[i];
        const std::uint32_t* ml = L.movingOf(i);
        const std::uint32_t mc = L.movingCount[i];
        Real vol = 0, src = 0;
        moving->forEachBody(ml, mc, [&](std::uint32_t body, const std::uint32_t* run, const std::uint32_t* runEnd) {
          Vec2 gk = Vec2::Zero();
          Real tk = 0;
          for (const std::uint32_t* p = run; p != runEnd; ++p) {
            const std::uint32_t s = *p;
            const Vec2 d = xi - moving->x[s];
            const Real q = std::sqrt(d.squaredNorm()) * W.invR;
            const Real a = Real(1) - q;
            vol += moving->volume[s] * W.valueQ(q);
            const Vec2 g = d * (c.rho0 * gradK * a * a * a * moving->volume[s]);
            gk += g;
            src += g.x() * moving->v[s].x() + g.y() * moving->v[s].y();
            tk += BodySamples::torque(moving->arm[s], g);
          }
          gm += gk;
          if (moving->placed[body].dynamic) T.push_back(MovTerm{body, gk.x(), gk.y(), tk});
        });
        movCount_[i] = std::uint32_t(T.size() - movStart_[i]);
        movSrc_[i] = src;
        rho += c.rho0 * vol;
      }
      Real tx = gx + gb.x(), ty = gy + gb.y();
      if (moving) tx += gm.x(), ty += gm.y();
      const Real denom = tx * tx + ty * ty + sq;
      wallGrad_[i] = gb;
      P.rho[i] = rho;
      P.invRho[i] = Real(1) / rho;
      gradSum_[i] = Vec2(tx, ty);
      alpha_[i] = denom > eps ? rho / std::max(denom, factorFloor) : Real(0);
      if (!std::isfinite(rho) && bad == kNone) bad = i;
    }
    return bad;
  });
  if (moving_) lumpBodies(c);
  return firstBadSlot;
}

/// A dynamic body moves with what all its neighbours push it by at once, which a particle's
/// Jacobi step alone does not see: the factor of a particle beside body k takes a bound on the
/// body's row of the coupled system, m (|G_ik| Σ_j |G_jk| / M_k + |T_ik| Σ_j |T_jk| / I_k), into
/// its denominator (sums in block order).
void Dfsph::lumpBodies(StepContext& c) {
  const std::size_t K = invMass_.size();
  sumG_.assign(K, 0.0);
  sumT_.assign(K, 0.0);
  for (const std::vector<MovTerm>& T : movTerms_)
    for (const MovTerm& t : T) {
      sumG_[t.body] += std::hypot(double(t.gx), double(t.gy));
      sumT_[t.body] += std::fabs(double(t.t));
    }
  const double m = double(c.momentumMass);
  c.pool.parallelFor(c.P.size(), kBlock, [&](std::size_t b, std::size_t e) {
    const std::vector<MovTerm>& T = movTerms_[b / kBlock];
    for (std::size_t i = b; i < e; ++i) {
      double extra = 0;
      for (std::uint32_t k = movStart_[i], ke = k + movCount_[i]; k < ke; ++k) {
        const MovTerm& t = T[k];
        extra += m * (invMass_[t.body] * std::hypot(double(t.gx), double(t.gy)) * sumG_[t.body] +
                      invInertia_[t.body] * std::fabs(double(t.t)) * sumT_[t.body]);
      }
      if (extra > 0 && alpha_[i] > 0) {
        const double rho = double(c.P.rho[i]), a = double(alpha_[i]);
        alpha_[i] = Real(a * rho / (rho + a * extra));
      }
    }
  });
}

/// The moving bodies' share of this solve's velocity change, −dt Q_i G_ik per particle and
/// dynamic body, as the force −m Q_i G_ik (torque −m Q_i T_ik) its block felt from the body
/// (BodySamples::addReaction: particles in order within a block, blocks summed in order).
void Dfsph::react(StepContext& c) {
  BodySamples& S = *c.bodySamples;
  const double m = double(c.momentumMass);
  c.pool.parallelFor(c.P.size(), kBlock, [&](std::size_t b, std::size_t e) {
    const std::vector<MovTerm>& T = movTerms_[b / kBlock];
    for (std::size_t i = b; i < e; ++i) {
      const double f = -m * qAcc_[i];
      for (std::uint32_t k = movStart_[i], ke = k + movCount_[i]; k < ke; ++k)
        S.addReaction(b / kBlock, T[k].body, Vec2d(double(T[k].gx) * f, double(T[k].gy) * f), double(T[k].t) * f);
    }
  });
}

/// x += dt v (xPrev for the swept collision); p = κρ for readers. Returns the first bad slot.
std::size_t Dfsph::integrate(StepContext& c) {
  ParticleStore& P = c.P;
  const std::vector<Real>& kappa = *P.find("dfsph.kappa");
  const Real dt = c.dt;
  const Real vmax2 = c.maxSpeed * c.maxSpeed;
  return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
    std::size_t bad = kNone;
    for (std::size_t i = b; i < e; ++i) {
      const Vec2 v = P.v[i];
      P.xPrev[i] = P.x[i];
      P.x[i] = P.x[i] + v * dt;
      P.p[i] = kappa[i] * P.rho[i];
      P.pOverRho[i] = kappa[i];
      if (bad == kNone && (!allFinite(P.x[i]) || !allFinite(v) || v.squaredNorm() > vmax2)) bad = i;
    }
    return bad;
  });
}

/// dfsph's registration (solvers.def) and its parameters.
SolverInfo dfsphSolver() {
  return {
      "dfsph",
      {{"tolerance", 0.001, 1e-6, 0.1,
        "largest mean predicted density error |ρ* − ρ0|/ρ0 the pressure solve accepts (compression only where κ = 0)"},
       {"divergence_tolerance", 1e-4, 1e-8, 1,
        "largest mean |Dρ/Dt|·dt/ρ0 (the density change one substep's divergence error makes) the divergence-free solve accepts (compression only where κ_v = 0)"},
       {"max_iterations", 100, 1, 10000, "iterations per solve at most (each solve separately)"},
       {"min_iterations", 2, 0, 10000, "iterations per solve at least"},
       {"relaxation", 0.5, 0.05, 1,
        "Jacobi relaxation ω of both solves (κ increments are ω times the diagonal estimate)"},
       {"chebyshev_rho", 0.98, 0, 0.999,
        "Chebyshev acceleration of both solves (Wang 2015) with this spectral radius estimate; 0: plain relaxed Jacobi"},
       {"velocity_cfl", 0.4, 0.01, 1,
        "dt ≤ velocity_cfl·R/v_max (dfsph does not read solver.cfl, the CFL number on c + v_max)"},
       {"divergence_solve", 1, 0, 1, "1: run the divergence-free solve each substep; 0: constant-density solve only"}},
      [](const SolverDef& d) -> std::unique_ptr<Solver> { return std::make_unique<Dfsph>(d); }};
}

}  // namespace sph2d
