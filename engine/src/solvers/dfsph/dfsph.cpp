// dfsph — Divergence-free SPH (Bender & Koschier 2015, "Divergence-free
// smoothed particle hydrodynamics", SCA; and 2017, "Divergence-free SPH for
// incompressible and viscous fluids", IEEE TVCG). An implicit pressure
// solver: two iterative solves on the velocities per substep make the velocity
// field divergence-free and the predicted density ρ0, instead of an equation of
// state with a stiffness (solver.sound_speed is not read). Why each choice, the
// variants tried and the measurements: docs/SOLVERS.md, section dfsph.
//
// Quantities (Wendland C2 kernel W of support R; boundary samples b are frozen
// fluid of mass ρ0Ψ_b at rest; q = r/R):
//   (1) ρ_i = Σ_j m W_ij + Σ_b ρ0Ψ_b W_ib
//   (2) g_ij = m∇W_ij, except that below q = 1/4 it keeps the peak |∇W| along
//       x_i − x_j (a stacked pair has a direction and a magnitude; coincident
//       pairs take pairDelta's direction); G_i = Σ_j g_ij + Σ_b ρ0Ψ_b∇W_ib
//   (3) α_i = ρ_i / (|G_i|² + Σ_j |g_ij|²), the paper's factor (0 without neighbours)
//   (4) Dρ_i/Dt = G_i·v_i − Σ_j g_ij·v_j
//
// Substep (stages()):
//   1. grid, neighbours; ρ, g, G, α by (1)–(3), kept for the whole substep.
//   2. Divergence-free solve on v: source s_i = Dρ_i/Dt (4), until the mean
//      residual ≤ divergence_tolerance·ρ0/dt.
//   3. a = gravity + the scene's effects; v* = v + dt a.
//   4. Constant-density solve on v*: source s_i = ρ_i + dt Dρ_i/Dt − ρ0, the
//      compression ρ_i − ρ0 already present counting at most
//      ρ0·2·(3 m/s)·dt/dx (a pushout speed), until the mean residual ≤ tolerance·ρ0.
//   5. x += dt v (the World's swept collision follows); p = κρ for readers.
// Each solve starts from its previous substep's κ (fields "dfsph.kappa" = p/ρ,
// "dfsph.kappa_v" = κ_v·dt, permuted with the particles), applied once by B,
// then iterates two gathers:
//   A. δκ_i = ω s_i α_i / dt² (divergence: / dt), times 1.1 ρ0/ρ_i beyond
//      1.1 ρ0; κ_i + δκ_i ≥ 0 (no tension at a free surface: projected Jacobi
//      with the complementarity residual |s_i| where κ_i > 0, max(s_i, 0) where
//      κ_i = 0); the residuals summed per block.
//   B. v_i −= dt [Σ_j (δκ_i/ρ_i + δκ_j/ρ_j) g_ij + (δκ_i/ρ_i) Σ_b ρ0Ψ_b∇W_ib];
//      κ_i += δκ_i. The wall term is the paper's single term, so B is the
//      adjoint of A's prediction and a converged solve only removes energy.
// ω = solver.relaxation (0.5: plain Jacobi diverges in 2D); after 5 plain
// iterations Chebyshev semi-iteration (Wang 2015) with ρ = chebyshev_rho,
// restarted when the residual grows; min_iterations to max_iterations. With
// clamp_negative_pressure = false κ takes either sign, and in a closed periodic
// box (both axes periodic, no walls) A first removes the source's mean.
//
// Time step: the least of velocity_cfl·R/v_max, 0.25·sqrt(R/a_max) (a without
// pressure), 0.1·sqrt(R/|g|) and 0.35·R/sqrt(|g| D), D the greatest depth
// below the highest particle of a column (strips of width R; gravity along a
// periodic axis counts for neither this nor the warm start). A substep shorter
// than 1 % of that limit and of the last solved substep (a frame's float
// remainder) runs without the solves.
//
// Every pass is a gather over fixed blocks and every mean a block reduction
// combined in block order: the same bits for any thread count.
//
// Moving bodies (Solver::movingSamples; body_samples.hpp; Akinci et al. 2012, "Versatile
// rigid-fluid coupling for incompressible SPH", as Bender & Koschier 2017 couple DFSPH to rigid
// bodies): a kinematic or dynamic body's samples b, placed at the body's pose at the substep's
// start with its velocity v_b = v + ω × r, enter the same sums as the static ones: ρ_i and α_i
// (frozen fluid of mass ρ0Ψ_b), G_i, the wall term of B, and the source (4) with the relative
// velocity Σ_b ρ0Ψ_b∇W_ib·(v_i − v_b). Body k's share of particle i's velocity change in one B
// is −dt q_i G_ik, G_ik = Σ_{b of k} ρ0Ψ_b∇W_ib (torque: T_ik = Σ_b arm_b × ρ0Ψ_b∇W_ib), so
// over a solve it is −dt Q_i G_ik, Q_i the q_i of every B (warm start included) combined by
// the velocities' Chebyshev recurrence (kept per particle in double: κ is clamped after the
// extrapolation, so Σ κ would not do). At the end of each solve every block adds −m Q_i G_ik
// (torque −m Q_i T_ik) per dynamic body to BodySamples::perBlock, particles in order; the
// body_forces stage gives the body the opposite impulse. These samples stay out of
// World::wallImpulse (wallGrad_ is the static walls' part only).
// Strong coupling: a dynamic body takes that impulse within the solves, not only after them
// (as Gissler et al. 2019, "Interlinked SPH pressure solvers for strong fluid-rigid coupling",
// solve the body with the fluid): after every B its velocity change so far in the substep,
// ΔV_k = m dt Σ_i Q_i G_ik / M_k and Δω_k = m dt Σ_i Q_i T_ik / I_k (both solves; blocks in
// order), moves its samples in A's source by G_ik·ΔV_k + T_ik Δω_k (∇W·(Δω × r) = Δω r × ∇W).
// Measured (crate 0.6 m × 0.2 m, density 500, spacing 0.01): taking the reaction only after
// the solve, the body light against the water it moves (added mass), each substep's impulse
// overshot and the crate floated at 0.078 m (Archimedes 0.1). Two more terms make the coupled
// Jacobi iteration converge: a particle beside body k adds a bound on the body's row of the
// coupled system, m (|G_ik| Σ_j |G_jk| / M_k + |T_ik| Σ_j |T_jk| / I_k), to α_i's denominator
// (lumpBodies: each particle's step allows for the body giving way to all of them at once; the
// absolute values keep the bound where particles push the body from opposite sides: with the
// signed row, G_ik·Σ_j G_jk, those pushes cancelled, and the divergence solve of a crate wedged
// against the tank's wall diverged, its residual doubling every two iterations);
// and each solve also iterates until the mean residual of the particles beside a dynamic
// body meets the tolerance (the body's mode is global, the mean over all particles hides
// it). Measured with these: draught 0.0959 m over the third second (0.0942 without the
// lumping, 0.0933 without either; 0.0976 with the Box2D skin alone and no samples); 0.0952 m
// with the bound and Box2D stepping with the substeps (docs/SCENES.md).
//
// Parameters (solver.*): tolerance, divergence_tolerance, max_iterations,
// min_iterations, relaxation, chebyshev_rho, velocity_cfl, divergence_solve. stats()
// reports the last solved substep's iterations and residuals.
#include <algorithm>
#include <cmath>
#include <limits>

#include "bodies/body_samples.hpp"
#include "solvers/solver.hpp"

namespace sph2d {
namespace {

class Dfsph final : public Solver {
 public:
  /// Reads the solver.* keys listed above (the registry fills their defaults).
  explicit Dfsph(const SolverDef& d)
      : tol_(d.param("tolerance")),
        divTol_(d.param("divergence_tolerance")),
        maxIt_(int(std::lround(d.param("max_iterations")))),
        minIt_(int(std::lround(d.param("min_iterations")))),
        divSolve_(d.param("divergence_solve") != 0),
        omega_(Real(d.param("relaxation"))),
        cheb_(Real(d.param("chebyshev_rho"))),
        cfl_(Real(d.param("velocity_cfl"))),
        unilateral_(d.clampNegativePressure),
        kMin_(d.clampNegativePressure ? Real(0) : -std::numeric_limits<Real>::infinity()) {}

  /// "dfsph".
  const char* name() const override { return "dfsph"; }
  /// 0: incompressible, a column at rest has ρ0 at every depth.
  double hydrostaticFactor() const override { return 0; }
  /// Wendland C2.
  double densityKernel(double r, double R) const override { return WendlandC2<double>(R).value(r); }
  /// The moving bodies' samples are walls like the static ones, moving with their body (the header).
  bool movingSamples() const override { return true; }

  /// Creates the κ fields; density, α and gradients of the initial positions.
  void prepare(StepContext& c) override {
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
  void hydrostaticWarmStart(StepContext& c, std::vector<Real>& kappa) const {
    ParticleStore& P = c.P;
    const Real g = hydrostaticGravity(c).norm();
    if (!(g > 0) || P.size() == 0) return;
    depths(c, [&](std::size_t i, Real depth) {
      kappa[i] = g * (depth + Real(0.5) * c.dx);
      P.p[i] = kappa[i] * P.rho[i];
    });
  }

  /// Calls f(i, depth) with every particle's depth below the top of its column (stages.hpp).
  template <class F>
  void depths(const StepContext& c, F f) const {
    columnDepths(c, topScratch_, f);
  }

  /// velocity_cfl·R/v_max, 0.1·sqrt(R/|g|), 0.25·sqrt(R/a_max) and 0.35·R/sqrt(|g| D), whichever is least
  /// (docs/SOLVERS.md: the hydrostatic stiffness limit).
  Real maxTimeStep(const StepContext& c, Real vmax, Real amax) const override {
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
  std::vector<Stage> stages(bool) override {
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

  /// Iterations and residuals of the last substep.
  SolverStats stats() const override { return stats_; }

 private:
  /// ρ, 1/ρ, α, the per-neighbour (slot, m∇W_ij) and per particle Σ_j m∇W_ij + Σ_b ρ0Ψ_b∇W_ib.
  std::size_t densityAndFactor(StepContext& c, const WendlandC2<Real>& W) {
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
    // neighbourhood gives about (ρ0/R)²).
    const Real eps = Real(1e-6) * (c.rho0 / R) * (c.rho0 / R);
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
        alpha_[i] = denom > eps ? rho / denom : Real(0);
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
  void lumpBodies(StepContext& c) {
    const std::size_t K = invMass_.size();
    sumG_.assign(K, 0.0);
    sumT_.assign(K, 0.0);
    for (const std::vector<MovTerm>& T : movTerms_)
      for (const MovTerm& t : T) {
        sumG_[t.body] += std::hypot(double(t.gx), double(t.gy));
        sumT_[t.body] += std::fabs(double(t.t));
      }
    const double m = double(c.mass);
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

  /// One solve: warm start, then iterations of (B, A) until the mean error is small.
  /// divergence: the divergence-free solve (source Dρ/Dt), else the constant-density solve.
  void solve(StepContext& c, bool divergence) {
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
    if (c.wall) c.wall->sum.samples += wall * double(c.mass);
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
  Vec2d warmStart(StepContext& c, std::vector<Real>& kappa, Real scale) {
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

  /// Pass A: the source of every particle, its κ increment (dk_, and dk_/ρ in q_)
  /// and the sum of the complementarity residuals, combined in block order.
  struct Sums {
    double err = 0, src = 0;
    double bodyErr = 0, bodyN = 0;  ///< the residuals of the particles beside a dynamic body, their count
  };
  /// The mean residual of pass A; in a closed domain (closed_) the source's
  /// mean is first found by a pass with no shift, then removed.
  double sourceMean(StepContext& c, const std::vector<Real>& kappa, bool divergence) {
    const double n = double(std::max<std::size_t>(c.P.size(), 1));
    Real shift = 0;
    if (closed_) shift = Real(sourcePass(c, kappa, divergence, 0).src / n);
    const Sums s = sourcePass(c, kappa, divergence, shift);
    bodyErr_ = s.bodyN > 0 ? s.bodyErr / s.bodyN : 0;
    return s.err / n;
  }

  Sums sourcePass(StepContext& c, const std::vector<Real>& kappa, bool divergence, Real shift) {
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
        [](Sums a, Sums b) { return Sums{a.err + b.err, a.src + b.src, a.bodyErr + b.bodyErr, a.bodyN + b.bodyN}; });
  }

  /// Pass B: v_i −= dt [Σ_j (q_i + q_j) m∇W_ij + q_i Σ_b ρ0Ψ_b∇W_ib]; κ_i += dk_i
  /// (w ≠ 1: the Chebyshev step from the previous iterate). Returns the walls' share of the
  /// Jacobi step, Σ_i −dt q_i Σ_b ρ0Ψ_b∇W_ib, summed per block and the blocks in order.
  Vec2d correctPass(StepContext& c, std::vector<Real>& kappa, Real w = 1) {
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
  void bodyResponse(const StepContext& c, std::size_t blocks) {
    const std::size_t K = dv_.size();
    const double mdt = double(c.mass) * double(c.dt);
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

  /// The moving bodies' share of this solve's velocity change, −dt Q_i G_ik per particle and
  /// dynamic body, as the force −m Q_i G_ik (torque −m Q_i T_ik) its block felt from the body
  /// (BodySamples::addReaction: particles in order within a block, blocks summed in order).
  void react(StepContext& c) {
    BodySamples& S = *c.bodySamples;
    const double m = double(c.mass);
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
  std::size_t integrate(StepContext& c) {
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

  double tol_, divTol_;
  int maxIt_, minIt_;
  bool divSolve_;
  Real omega_;
  Real cheb_;                            ///< Chebyshev ρ (0: plain relaxed Jacobi)
  Real cfl_;                             ///< dt ≤ cfl_·R/v_max
  static constexpr int kChebDelay = 5;   ///< plain iterations before the acceleration starts
  static constexpr Real kKneeDensity = Real(1.1);   ///< beyond ρ = 1.1 ρ0 the Jacobi step shrinks as 1.1 ρ0/ρ
  static constexpr Real kPushoutSpeed = Real(3);    ///< [m/s] existing compression is removed at most this fast
  std::vector<Vec2> vPrev_;              ///< velocity before the last iteration (Chebyshev)
  std::vector<Real> kPrev_;              ///< κ before the last iteration (Chebyshev)
  /// One neighbour entry of an iteration: the neighbour's slot and m∇W_ij.
  struct Pair {
    std::uint32_t j;
    Real gx, gy;
  };
  std::vector<std::vector<Pair>> pairs_;  ///< per neighbour entry, block by block (as NeighbourLists)
  std::vector<Vec2> gradSum_;             ///< Σ_j m∇W_ij + Σ_b ρ0Ψ_b∇W_ib per particle
  std::vector<Vec2> wallGrad_;            ///< its wall part Σ_b ρ0Ψ_b∇W_ib (World::wallImpulse)
  std::vector<Vec2d> wallBlock_;          ///< correctPass(): the walls' Σ Δv per block of kBlock
  /// One particle's term from one dynamic body's samples: G_ik = Σ_b ρ0Ψ_b∇W_ib, T_ik = Σ_b arm_b × ρ0Ψ_b∇W_ib.
  struct MovTerm {
    std::uint32_t body;
    Real gx, gy, t;
  };
  double bodyErr_ = 0;                    ///< sourceMean(): the mean residual beside the dynamic bodies (0: none)
  bool moving_ = false;                   ///< this substep has moving bodies' samples (BodySamples::active)
  std::vector<std::vector<MovTerm>> movTerms_;  ///< per block, particles in order
  std::vector<std::uint32_t> movStart_, movCount_;  ///< particle i's MovTerms in its block
  std::vector<Real> movSrc_;              ///< Σ_b ρ0Ψ_b∇W_ib·v_b over the moving samples
  std::vector<double> qAcc_, qAccPrev_;   ///< Q_i of this solve so far (and at the previous iterate)
  std::vector<double> invMass_, invInertia_;  ///< per placed body (0: kinematic)
  std::vector<Vec2d> dv_, dvBase_;        ///< per body: ΔV so far in the substep, and before this solve
  std::vector<double> dw_, dwBase_;       ///< … and Δω
  std::vector<double> sumG_;              ///< lumpBodies(): Σ_i |G_ik| per body
  std::vector<double> sumT_;              ///< … and Σ_i |T_ik|
  std::vector<Vec2d> blockG_;             ///< per block and body: Σ_i Q_i G_ik (block-major)
  std::vector<double> blockT_;            ///< … and Σ_i Q_i T_ik
  std::vector<Real> alpha_;              ///< the DFSPH factor α_i
  std::vector<Real> dk_;                 ///< this iteration's κ increment
  std::vector<Real> q_;                  ///< dk_/ρ
  SolverStats stats_;
  mutable std::vector<Real> topScratch_;  ///< depths(): the highest particle per strip (reused: maxTimeStep runs it every substep)
  bool closed_ = false;  ///< set per substep: no wall, no free surface (both axes periodic, κ of either sign)
  bool unilateral_;  ///< solver.clamp_negative_pressure: κ ≥ 0 (a free surface); false: κ of either sign
  Real kMin_;        ///< 0, or −∞ without the clamp
};

}  // namespace

/// dfsph's registration (solvers.def) and its parameters.
SolverInfo dfsphSolver() {
  return {"dfsph",
          {{"tolerance", 0.001, 1e-6, 0.1,
            "largest mean predicted density error |ρ* − ρ0|/ρ0 the pressure solve accepts (compression only where κ = 0)"},
           {"divergence_tolerance", 1e-4, 1e-8, 1,
            "largest mean |Dρ/Dt|·dt/ρ0 (the density change one substep's divergence error makes) the divergence-free solve accepts (compression only where κ_v = 0)"},
           {"max_iterations", 100, 1, 10000, "iterations per solve at most (each solve separately)"},
           {"min_iterations", 2, 0, 10000, "iterations per solve at least"},
           {"relaxation", 0.5, 0.05, 1, "Jacobi relaxation ω of both solves (κ increments are ω times the diagonal estimate)"},
           {"chebyshev_rho", 0.98, 0, 0.999,
            "Chebyshev acceleration of both solves (Wang 2015) with this spectral radius estimate; 0: plain relaxed Jacobi"},
           {"velocity_cfl", 0.4, 0.01, 1, "dt ≤ velocity_cfl·R/v_max (dfsph does not read solver.cfl, the CFL number on c + v_max)"},
           {"divergence_solve", 1, 0, 1, "1: run the divergence-free solve each substep; 0: constant-density solve only"}},
          [](const SolverDef& d) -> std::unique_ptr<Solver> { return std::make_unique<Dfsph>(d); }};
}

}  // namespace sph2d
