// Particle shifting (Lind, Xu, Stansby & Rogers 2012, "Incompressible
// smoothed particle hydrodynamics for free-surface flows: a generalised
// diffusion-based algorithm for stability and validations for impulsive
// flows and propagating waves", J. Comput. Phys. 231): Lagrangian particles
// that follow a flow with stagnation points bunch up along its stretching
// directions and open gaps across them; then the kernel sums are wrong and
// the flow turns noisy (a Taylor–Green vortex loses its mode by t ≈ 0.15 s
// at Re = 100 without it). Each substep moves every particle down the
// gradient of the particle concentration C_i = Σ_j V_j W_ij (Fick's law):
//   δx_i = −D ∇C_i,  ∇C_i = Σ_j V_j ∇W_ij + Σ_b Ψ_b ∇W_ib,  D = A h v_max dt,
// with h = R/2, A = effects.shifting.strength (Lind: 1 to 6), the largest
// speed v_max, Wendland C2 gradients, V_j = m/ρ_j, and δx capped at 0.1 dx
// per pass.
// One pass of explicit diffusion is stable for D below about 0.1 R²
// (measured: at dfsph's long substeps D = 0.4 A R² in one pass blew up within
// 6 substeps). A larger D is applied as k = ⌈D / 0.1 R²⌉ passes of D/k, each
// with ∇C of the positions the previous pass left (at most kMaxPasses; the
// neighbour lists of the substep are kept). Capping D at 0.1 R² instead made
// the shifting per second of simulated time proportional to 1/dt: at dfsph's
// substeps (3 a frame) the Taylor–Green vortex got a fifth of wcsph's
// shifting, its particles paired in the vortex cores and it blew up at
// t ≈ 0.6 s; with the passes its decay rate is within 2 % of the analytic one.
// Walls count in ∇C, so particles are not shifted into them; so do a moving body's
// samples (body_samples.hpp, for the solvers that take them), where they are this substep. At a free
// surface ∇C points into the fluid; there (C_i below 0.95 of a full lattice's)
// only the component along the surface is kept (Lind's surface treatment).
// Velocities are not interpolated to the new positions (the shift is a small
// fraction of the spacing per pass; at most 8 passes a substep, 0.8 dx in
// all). Later passes keep the substep's neighbour lists: pairs that moved
// out of the support are skipped, pairs that moved into it are not seen
// (only near a pair that was already closer than R + 0.8 dx).
//
// The stage runs after the forces, before integration: it reads x, ρ and
// the neighbour lists, and writes x (through a scratch copy: a gather).
#include <algorithm>
#include <cmath>

#include "bodies/body_samples.hpp"
#include "effects/effect.hpp"

namespace sph2d {
namespace {

class ParticleShifting final : public Effect {
 public:
  explicit ParticleShifting(double strength) : strength_(Real(strength)) {}
  const char* name() const override { return "shifting"; }
  const char* limitKey() const override { return "effects.shifting.strength"; }

  /// Shifts every particle down ∇C in as many passes as D needs (see above).
  std::size_t apply(StepContext& c) override {
    ParticleStore& P = c.P;
    if (!(c.dt > 0) || P.size() == 0) return kNone;
    const Real vmax = maxSpeedOf(P, c.pool);
    const Real dPass = Real(0.1) * c.R * c.R;  // the largest stable D of one pass
    const Real dWant = strength_ * Real(0.5) * c.R * vmax * c.dt;
    const int passes = dWant > dPass ? int(std::min(Real(kMaxPasses), std::ceil(dWant / dPass))) : 1;
    const Real D = std::min(dWant / Real(passes), dPass);
    for (int pass = 0; pass < passes; ++pass) {
      const std::size_t bad = shiftOnce(c, D);
      if (bad != kNone) return bad;
    }
    return kNone;
  }

 private:
  static constexpr int kMaxPasses = 8;  ///< beyond this a substep gets less than A h v_max dt

  /// One pass: x_i −= D ∇C_i (gathered into shift_, then applied). Returns the first bad slot.
  std::size_t shiftOnce(StepContext& c, Real D) {
    ParticleStore& P = c.P;
    const WendlandC2<Real> W(c.R);
    const Real R2 = c.R * c.R;
    const Real gradK = W.gradientScale;  // ∇W = gradK (1 − q)³ d
    const Real cap = Real(0.1) * c.dx, cap2 = cap * cap;
    // C of a full lattice (the mass makes Σ m W = ρ0 there, so Σ V W = 1).
    const Real surfaceC = Real(0.95);
    const BoundarySet& B = c.boundary;
    const bool walls = !B.samples.empty();
    const BodySamples* moving = c.bodySamples && c.bodySamples->active() ? c.bodySamples : nullptr;
    const PeriodicBox per = c.periodic;
    const Vec2* X = P.x.data();
    const Real* IR = P.invRho.data();
    shift_.resize(P.size());
    c.pool.parallelFor(P.size(), kBlock, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        const Vec2 xi = X[i];
        Real gx = 0, gy = 0, C = c.mass * IR[i] * W.value(0);
        const std::uint32_t* nb = c.nbr.of(i);
        const std::uint32_t cnt = c.nbr.count[i];
        for (std::uint32_t k = 0; k < cnt; ++k) {
          const std::uint32_t j = nb[k];
          Real dx = xi.x() - X[j].x(), dy = xi.y() - X[j].y();
          per.nearest(dx, dy);
          const Real r = std::sqrt(dx * dx + dy * dy);
          if (r >= c.R) continue;  // a later pass: the pair has left the support since the lists were built
          const Real q = r * W.invR, a = Real(1) - q;
          const Real V = c.mass * IR[j];
          const Real g = V * gradK * a * a * a;
          gx += g * dx;
          gy += g * dy;
          C += V * W.value(r);
        }
        if (walls) {
          const std::uint32_t* bl = c.nbr.boundaryOf(i);
          for (std::uint32_t k = 0; k < c.nbr.boundaryCount[i]; ++k) {
            const std::uint32_t s = bl[k];
            const Vec2 d = xi - B.samples[s];
            const Real r2 = d.squaredNorm();
            if (r2 >= R2) continue;  // a later pass: the sample has left the support since the lists were built
            const Real r = std::sqrt(r2), a = Real(1) - r * W.invR;
            const Real g = B.volume[s] * gradK * a * a * a;
            gx += g * d.x();
            gy += g * d.y();
            C += B.volume[s] * W.value(r);
          }
        }
        if (moving) {
          const std::uint32_t* ml = c.nbr.movingOf(i);
          for (std::uint32_t k = 0; k < c.nbr.movingCount[i]; ++k) {
            const std::uint32_t s = ml[k];
            const Vec2 d = xi - moving->x[s];
            const Real r2 = d.squaredNorm();
            if (r2 >= R2) continue;  // a later pass: the sample has left the support since the lists were built
            const Real r = std::sqrt(r2), a = Real(1) - r * W.invR;
            const Real g = moving->volume[s] * gradK * a * a * a;
            gx += g * d.x();
            gy += g * d.y();
            C += moving->volume[s] * W.value(r);
          }
        }
        Vec2 s(-D * gx, -D * gy);
        if (C < surfaceC) {  // near a free surface: keep only the tangential part
          const Real n2 = gx * gx + gy * gy;
          if (n2 > 0) s -= Vec2(gx, gy) * (s.x() * gx + s.y() * gy) / n2;
        }
        const Real s2 = s.squaredNorm();
        if (s2 > cap2) s *= cap / std::sqrt(s2);
        shift_[i] = s;
      }
    });
    return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      std::size_t bad = kNone;
      for (std::size_t i = b; i < e; ++i) {
        P.x[i] += shift_[i];
        if (!allFinite(P.x[i]) && bad == kNone) bad = i;
      }
      return bad;
    });
  }

  Real strength_;
  std::vector<Vec2> shift_;  ///< scratch: this substep's shifts
};

}  // namespace

/// Particle shifting when the scene enables effects.shifting.
std::unique_ptr<Effect> shiftingEffect(const SceneDef& scene) {
  if (!scene.effects.shifting) return nullptr;
  return std::make_unique<ParticleShifting>(scene.effects.shiftingStrength);
}

}  // namespace sph2d
