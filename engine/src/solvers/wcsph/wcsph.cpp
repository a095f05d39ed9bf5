// wcsph — weakly compressible SPH with the Tait equation of state (Becker &
// Teschner 2007, "Weakly compressible SPH for free surface flows"):
// p = B((ρ/ρ0)^γ − 1), B = ρ0 c²/γ, c = 10·expected_speed when that is set,
// else solver.sound_speed. Density by summation; the pressure acceleration is
// the momentum- and energy-consistent form −Σ m (p_i/ρ_i² + p_j/ρ_j²) ∇W
// (Monaghan 1992) with the same kernel as the density (Wendland C2, immune to
// pairing: Dehnen & Aly 2012), plus Monaghan's artificial viscosity
// Π_ij = −α c h μ_ij / ρ̄_ij for approaching pairs (h = R/2). Walls: boundary
// samples are frozen fluid of mass ρ0Ψ_b with the particle's pressure
// extrapolated hydrostatically (Adami, Hu & Adams 2012), and the same artificial
// viscosity as a fluid neighbour at rest. That mirrored pressure is not the
// adjoint of the samples' share of the density, so the wall force does net work
// on fluid oscillating against it; the wall's viscosity takes that work out
// where it is done. Without it a column dropped into a 10° wedge (the
// stability suite) gained up to 14 % of the potential energy it had released
// (38 % at c0 = 160 m/s); with it, nothing. The single term of Akinci et al.
// 2012 (p_b = 0) is energy-stable too, but lets the floor row sink onto the
// collision clearance (the hydrostatic tank's pressure error 5.5 %; mirrored
// without the wall viscosity 2.0 %, with it 2.9 %). The pressure term is
// divided by the kernel's lattice gradient moment (0.953 for Wendland C2 at
// R = 2.5 dx), a constant: without it a resting column's pressure is 5 % high.
//
// Beyond ρ = 1.1 ρ0 the equation of state continues along its tangent (stacked
// or overlapping particles separate instead of exploding).
//
// Impacts (impact_alpha, impact_speed; solvers/impact_viscosity.hpp): a pair
// approaching faster than impact_speed·c0 takes up to impact_alpha more of the same
// artificial viscosity, so that a collision at impact speeds is damped near critically
// instead of bouncing off the compression it stores.
//
// Materials of different rest density (docs/SCENES.md, materials) in one pressure solve: the
// number-density formulation of Solenthaler & Pajarola 2008 ("Density contrast SPH
// interfaces", SCA). Every particle has the lattice's volume and the mass of its material,
// m_i = r_i m (r_i = ρ0_i/ρ0, the field "rest_ratio"); the density is the particle's mass
// times the number density, ρ_i = m_i Σ_j W_ij (walls as rest-density neighbours), so a
// particle beside a lighter one is not counted lighter (standard summation Σ m_j W_ij smears
// the interface and pushes it apart); p_i = r_i B((ρ_i/ρ0_i)^γ − 1); the pressure acceleration
// a_i = −(1/m_i) Σ_j (p_i/δ_i² + p_j/δ_j²) ∇W_ij, δ = ρ/m the number density. With one
// density (no field) every r_i is 1 and these are the formulas above, bit for bit.
//
// Parameters (solver.*): gamma, alpha, expected_speed, impact_alpha, impact_speed.
#include <algorithm>
#include <cmath>

#include "bodies/body_samples.hpp"
#include "solvers/impact_viscosity.hpp"
#include "solvers/solver.hpp"

namespace sph2d {
namespace {

class Wcsph final : public Solver {
 public:
  explicit Wcsph(const SolverDef& d)
      : gamma_(Real(d.param("gamma"))),
        alpha_(Real(d.param("alpha"))),
        c0_(Real(d.param("expected_speed") > 0 ? 10 * d.param("expected_speed") : d.soundSpeed)),
        impact_(Real(d.param("impact_alpha")), Real(d.param("impact_speed")) * c0_) {}

  const char* name() const override { return "wcsph"; }
  // Tait linearised at rest: ρ ≈ ρ0(1 + g z / c0²).
  double hydrostaticFactor() const override { return 1.0 / (double(c0_) * double(c0_)); }

  double densityKernel(double r, double R) const override { return WendlandC2<double>(R).value(r); }

  // The moving bodies' samples are walls like the static ones, moving with their body (its
  // velocity in the wall viscosity); their force on the fluid goes back to the body.
  bool movingSamples() const override { return true; }

  void prepare(StepContext& c) override {
    stageGrid(c, false);
    stageNeighbours(c);
    density(c, WendlandC2<Real>(c.R));
    pressure(c);
  }

  Real maxTimeStep(const StepContext& c, Real vmax, Real amax) const override {
    // The Tait sound speed grows with compression: c² = dp/dρ = c0² (ρ/ρ0)^(γ−1).
    // Using the largest density keeps the step stable when an impact compresses
    // the fluid far beyond what c0 was chosen for.
    const ParticleStore& P = c.P;
    const Real rhoMax = c.pool.reduce(
        P.size(), 4096, c.rho0,
        [&](std::size_t b, std::size_t e) {
          Real m = c.rho0;
          const Real* rr = restRatio(P);  // the compression ρ_i/ρ0_i counts, not the density
          for (std::size_t i = b; i < e; ++i) m = std::max(m, rr ? P.rho[i] / rr[i] : P.rho[i]);
          return m;
        },
        [](Real a, Real b2) { return std::max(a, b2); });
    const Real cEff = c0_ * std::pow(std::min(rhoMax / c.rho0, Real(1.1)), Real(0.5) * (gamma_ - Real(1)));
    Real dt = Real(c.def.cfl) * c.R / (cEff + vmax);
    if (amax > 0) dt = std::min(dt, kForceCfl * std::sqrt(c.R / amax));
    return dt;
  }

  /// grid → neighbours → density → pressure (Tait) → pressure_force (+ artificial viscosity) → effects → integrate.
  std::vector<Stage> stages(bool) override {
    return explicitStages([this](StepContext& c) { return density(c, WendlandC2<Real>(c.R)); },
                          [this](StepContext& c) { pressure(c); },
                          [this](StepContext& c) { return pressureForce(c, WendlandC2<Real>(c.R)); });
  }

 private:
  std::size_t density(StepContext& c, const WendlandC2<Real>& W) const {
    ParticleStore& P = c.P;
    const Real* ratio = restRatio(P);  // null with one rest density
    const Vec2* X = P.x.data();
    const Real self = W.value(0);
    const bool walls = !c.boundary.samples.empty();
    const BodySamples* moving = c.bodySamples && c.bodySamples->active() ? c.bodySamples : nullptr;
    return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      std::size_t bad = kNone;
      for (std::size_t i = b; i < e; ++i) {
        const Vec2 xi = X[i];
        const std::uint32_t* nb = c.nbr.of(i);
        const std::uint32_t cnt = c.nbr.count[i];
        Real sum = self;
        for (std::uint32_t k = 0; k < cnt; ++k) {
          Real dx = xi.x() - X[nb[k]].x(), dy = xi.y() - X[nb[k]].y();
          c.periodic.nearest(dx, dy);
          sum += W.value(std::sqrt(dx * dx + dy * dy));
        }
        Real rho = c.mass * sum;
        if (walls) {
          Real s = 0;
          const std::uint32_t* bl = c.nbr.boundaryOf(i);
          for (std::uint32_t k = 0; k < c.nbr.boundaryCount[i]; ++k)
            s += c.boundary.volume[bl[k]] * W.value(std::sqrt((xi - c.boundary.samples[bl[k]]).squaredNorm()));
          rho += c.rho0 * s;
        }
        if (moving) {
          Real s = 0;
          const std::uint32_t* ml = c.nbr.movingOf(i);
          for (std::uint32_t k = 0; k < c.nbr.movingCount[i]; ++k)
            s += moving->volume[ml[k]] * W.value(std::sqrt((xi - moving->x[ml[k]]).squaredNorm()));
          rho += c.rho0 * s;
        }
        if (ratio) rho *= ratio[i];  // m_i δ_i
        P.rho[i] = rho;
        if (!std::isfinite(rho) && bad == kNone) bad = i;
      }
      return bad;
    });
  }

  void pressure(StepContext& c) {
    ParticleStore& P = c.P;
    pOverRho2_.resize(P.size());
    const Real B = c.rho0 * c0_ * c0_ / gamma_;
    const bool clamp = c.def.clampNegativePressure;
    // Beyond ρ = 1.1 ρ0 (never reached by a weakly compressible flow with a
    // proper c0, but reached by stacked or overlapping particles) the Tait
    // curve continues along its tangent, so such states separate at tens of
    // m/s instead of exploding at thousands.
    const Real kneeRatio = Real(1.1);
    const Real kneeP = B * (std::pow(kneeRatio, gamma_) - Real(1));
    const Real kneeSlope = B * gamma_ * std::pow(kneeRatio, gamma_ - Real(1)) / c.rho0;
    const Real* rr = restRatio(P);
    c.pool.parallelFor(P.size(), 4096, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        // ρ̃ = m δ: the density the particle would have as the first material (ρ_i/r_i).
        const Real rhoN = rr ? P.rho[i] / rr[i] : P.rho[i];
        const Real ratio = rhoN / c.rho0;
        Real p = ratio <= kneeRatio ? B * (std::pow(ratio, gamma_) - Real(1))
                                    : kneeP + kneeSlope * (rhoN - kneeRatio * c.rho0);
        if (clamp && p < 0) p = 0;
        if (rr) p *= rr[i];  // B_i = r_i B
        P.p[i] = p;
        P.invRho[i] = Real(1) / P.rho[i];
        P.pOverRho[i] = p * P.invRho[i];
        const Real invN = Real(1) / rhoN;
        pOverRho2_[i] = p * invN * invN;  // p/ρ̃² = p/(m δ)² for the symmetric pressure form
      }
    });
  }

  std::size_t pressureForce(StepContext& c, const WendlandC2<Real>& W) {
    ParticleStore& P = c.P;
    const BoundarySet& B = c.boundary;
    const bool walls = !B.samples.empty();
    BodySamples* moving = c.bodySamples && c.bodySamples->active() ? c.bodySamples : nullptr;
    const Real R = c.R, h = Real(0.5) * R;
    // ∇W = gradK (1 − q)³ d, with the pressure term renormalised by the lattice
    // gradient moment (kernels.hpp) so a hydrostatic column gets ρ g per metre.
    const Real gradK = W.gradientScale;
    const Real aFlat = Real(1) - kFlatGradientQ;
    const Real gradFlat = gradK * aFlat * aFlat * aFlat * (kFlatGradientQ * R);  // |∇W| at its peak, times r/|d|
    const Real pScale =
        Real(1.0 / latticeGradientMoment(WendlandC2<double>(double(c.R)), double(c.dx), double(c.mass / c.rho0)));
    const Real avK = alpha_ * c0_;         // Π = −α c μ / ρ̄ with μ = h v·x / (r² + 0.01h²)
    const ImpactViscosity& imp = impact_;  // + the impact share for fast approaches
    const Real eta2 = Real(0.01) * h * h;
    const Vec2* X = P.x.data();
    const Vec2* V = P.v.data();
    const Real* IR = P.invRho.data();
    const Real* POR2 = pOverRho2_.data();
    const Real* ratio = restRatio(P);  // m_i = r_i m (null: every r_i is 1)
    const std::size_t blocks = (P.size() + kBlock - 1) / kBlock;
    wallBlock_.assign(blocks, Vec2d(0, 0));
    const std::size_t first = firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      std::size_t bad = kNone;
      Vec2d wallAcc(0, 0);  // Σ a_wall over the block's particles
      for (std::size_t i = b; i < e; ++i) {
        const Real vix = V[i].x(), viy = V[i].y();
        const Real pri = POR2[i], iri = IR[i];
        const Real invRi = ratio ? Real(1) / ratio[i] : Real(1);  // m / m_i
        Real ax = 0, ay = 0;
        const std::uint32_t* nb = c.nbr.of(i);
        const std::uint32_t cnt = c.nbr.count[i];
        for (std::uint32_t k = 0; k < cnt; ++k) {
          const std::uint32_t j = nb[k];
          Real dx, dy, r2;
          pairDelta(c, i, j, dx, dy, r2);
          const Real r = std::sqrt(r2);
          const Real q = r * W.invR;
          const Real a = Real(1) - q;
          // ∇W = g·d; closer than R/4 it keeps its peak magnitude along d, so a stacked or
          // coincident pair pushes apart (constants.hpp, kFlatGradientQ).
          const Real g = q < kFlatGradientQ ? gradFlat / r : gradK * a * a * a;
          // Pressure: −(m²/m_i) (p_i/ρ̃_i² + p_j/ρ̃_j²) ∇W (one density: −m (p_i/ρ_i² + p_j/ρ_j²) ∇W).
          Real coef = -c.mass * invRi * pScale * (pri + POR2[j]);
          // Artificial viscosity for approaching pairs (−m_j Π_ij ∇W).
          const Real vdotx = (vix - V[j].x()) * dx + (viy - V[j].y()) * dy;
          if (vdotx < 0) {
            const Real mj = ratio ? c.mass * ratio[j] : c.mass;
            const Real mu = h * vdotx / (r2 + eta2);
            coef += mj * avK * mu * Real(2) / (Real(1) / iri + Real(1) / IR[j]);
            const Real ai = imp.alpha(vdotx, r);
            if (ai > 0) coef += mj * (c0_ * ai) * mu * Real(2) / (Real(1) / iri + Real(1) / IR[j]);
          }
          ax += coef * g * dx;
          ay += coef * g * dy;
        }
        Vec2 acc(ax, ay);
        if (walls) {
          const Real pi = P.p[i], rhoi = P.rho[i];
          Vec2 gb = Vec2::Zero(), gv = Vec2::Zero(), gi = Vec2::Zero();  // gi: the impact share of gv, by α
          bool impactWall = false;
          const std::uint32_t* bl = c.nbr.boundaryOf(i);
          for (std::uint32_t k = 0; k < c.nbr.boundaryCount[i]; ++k) {
            const std::uint32_t s = bl[k];
            const Vec2 d = X[i] - B.samples[s];
            const Real rr = d.squaredNorm();
            const Real q = std::sqrt(rr) * W.invR;
            const Real a = Real(1) - q;
            const Real gw = gradK * a * a * a * B.volume[s];
            // p_b: the particle's pressure extrapolated hydrostatically to the sample.
            const Real pb = std::max(Real(0), pi - rhoi * c.gravity.dot(d));
            gb += d * (gw * (pri + pb / (c.rho0 * c.rho0)));
            // Artificial viscosity against the sample (frozen fluid at rest) when approaching it.
            const Real vdotx = vix * d.x() + viy * d.y();
            if (vdotx < 0) {
              const Vec2 t = d * (gw * (h * vdotx / (rr + eta2)));
              gv += t;
              const Real ai = imp.alpha(vdotx, std::sqrt(rr));
              if (ai > 0) gi += t * ai, impactWall = true;
            }
          }
          Vec2 aViscous = gv * (c.rho0 * avK * Real(2) / (rhoi + c.rho0));
          if (impactWall) aViscous += gi * (c.rho0 * c0_ * Real(2) / (rhoi + c.rho0));
          const Vec2 aPressure = gb * (c.rho0 * pScale * invRi);
          acc -= aPressure;
          acc += aViscous;
          // This particle's wall force over m (the mass the sum is multiplied by below).
          wallAcc += (aViscous.cast<double>() - aPressure.cast<double>()) / double(invRi);
        }
        if (moving && c.nbr.movingCount[i] > 0) {
          // The moving bodies' samples: the same terms, the viscosity with the sample's
          // velocity; body by body (the list holds each body's samples together), each body's
          // share of the acceleration is also its reaction (body_samples.hpp).
          const Real pi = P.p[i], rhoi = P.rho[i];
          const Real pressK = c.rho0 * pScale * invRi, viscK = c.rho0 * avK * Real(2) / (rhoi + c.rho0);
          const Real impactK = c.rho0 * c0_ * Real(2) / (rhoi + c.rho0);
          const std::uint32_t* ml = c.nbr.movingOf(i);
          const std::uint32_t mc = c.nbr.movingCount[i];
          moving->forEachBody(ml, mc, [&](std::uint32_t body, const std::uint32_t* run, const std::uint32_t* runEnd) {
            Vec2 gb = Vec2::Zero(), gv = Vec2::Zero(), gi = Vec2::Zero();  // gi: the impact share of gv, by α
            Real tb = 0, tv = 0, ti = 0;  // Σ arm × (the pair's term), for the torque
            bool impact = false;
            for (const std::uint32_t* p = run; p != runEnd; ++p) {
              const std::uint32_t s = *p;
              const Vec2 d = X[i] - moving->x[s];
              const Real rr = d.squaredNorm();
              const Real q = std::sqrt(rr) * W.invR;
              const Real a = Real(1) - q;
              const Real gw = gradK * a * a * a * moving->volume[s];
              const Real pb = std::max(Real(0), pi - rhoi * c.gravity.dot(d));
              const Vec2 fp = d * (gw * (pri + pb / (c.rho0 * c.rho0)));
              gb += fp;
              tb += BodySamples::torque(moving->arm[s], fp);
              const Vec2 vr = V[i] - moving->v[s];
              const Real vdotx = vr.x() * d.x() + vr.y() * d.y();
              if (vdotx < 0) {
                const Vec2 fv = d * (gw * (h * vdotx / (rr + eta2)));
                gv += fv;
                tv += BodySamples::torque(moving->arm[s], fv);
                const Real ai = imp.alpha(vdotx, std::sqrt(rr));
                if (ai > 0) {
                  gi += fv * ai;
                  ti += BodySamples::torque(moving->arm[s], fv * ai);
                  impact = true;
                }
              }
            }
            Vec2 aBody = gv * viscK - gb * pressK;
            double torque = double(tv) * double(viscK) - double(tb) * double(pressK);
            if (impact) {
              aBody += gi * impactK;
              torque += double(ti) * double(impactK);
            }
            acc += aBody;
            if (moving->placed[body].dynamic)
              moving->addReaction(b / kBlock, body, aBody.cast<double>() * (double(c.momentumMass) / double(invRi)),
                                  torque * (double(c.momentumMass) / double(invRi)));
          });
        }
        acc += c.gravity;
        P.a[i] = acc;
        if (!allFinite(acc) && bad == kNone) bad = i;
      }
      wallBlock_[b / kBlock] = wallAcc;
      return bad;
    });
    // The walls' force on the fluid, Σ m a_wall in block order; the World multiplies it by the
    // substep integrate takes (force_limit may still shorten it).
    if (c.wall) c.wall->force += sumInOrder(wallBlock_, blocks) * double(c.momentumMass);
    return first;
  }

  /// r_i = ρ0_i/ρ0 per particle, or null when every material has the first's rest density.
  static const Real* restRatio(const ParticleStore& P) {
    const std::vector<Real>* f = P.find(ParticleStore::kRestRatio);
    return f ? f->data() : nullptr;
  }

  Real gamma_, alpha_, c0_;
  ImpactViscosity impact_;
  /// p/ρ² per particle, written by the pressure stage for the pressure force of the
  /// same substep (no reordering between them).
  std::vector<Real> pOverRho2_;
  /// Per block of kBlock particles, Σ of the wall acceleration (the walls' force, summed in block order).
  std::vector<Vec2d> wallBlock_;
};

}  // namespace

/// wcsph's registration (solvers.def) and its parameters.
SolverInfo wcsphSolver() {
  return {"wcsph",
          {{"gamma", 7, 1, 10, "Tait exponent γ in p = B((ρ/ρ0)^γ − 1), B = ρ0c²/γ"},
           {"alpha", 0.05, 0, 2, "Monaghan artificial viscosity α (Π = −α c h μ/ρ̄ for approaching pairs)"},
           {"expected_speed", 0, 0, 1e4, "when > 0, the sound speed is 10 × this (m/s) instead of sound_speed"},
           kImpactAlphaParam,
           kImpactSpeedParam},
          [](const SolverDef& d) -> std::unique_ptr<Solver> { return std::make_unique<Wcsph>(d); }};
}

}  // namespace sph2d
