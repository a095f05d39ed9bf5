// Viscosity, the Laplacian form of Müller, Charypar & Gross 2003 (seed 002,
// eq. 14): a_i += (μ/ρ_i) Σ_j m (v_j − v_i)/ρ_j ∇²W_visc(r_ij), with the 2D
// Laplacian of the viscosity kernel (kernels.hpp: 5(R−r)(R³+R²r+Rr²+9r³)/(3πR⁵r³),
// not the 3D c·(R − r)), r clamped to 0.05 R. μ = ν·ρ0.
// Time-step limit: dt ≤ 0.03 R²/ν (explicit diffusion).
#include <cmath>

#include "effects/effect.hpp"

namespace sph2d {
namespace {

class LaplacianViscosity final : public Effect {
 public:
  explicit LaplacianViscosity(double nu) : nu_(Real(nu)) {}
  const char* name() const override { return "viscosity"; }
  const char* limitKey() const override { return "solver.viscosity"; }

  Real maxTimeStep(const StepContext& c) const override { return Real(0.03) * c.R * c.R / nu_; }

  std::size_t apply(StepContext& c) override {
    Particles& P = c.P;
    const ViscosityKernel<Real> W(c.R);
    const Real R = c.R, R2 = R * R, R3 = R2 * R;
    const Real rMin = W.rMin, invRMin = Real(1) / W.rMin;
    const Real lapK = Real(5) / (Real(3) * kPi<Real> * R2 * R3);
    const Real muMass = nu_ * c.rho0 * c.mass;
    const Vec2* X = P.x.data();
    const Vec2* V = P.v.data();
    const Real* IR = P.invRho.data();
    return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      std::size_t bad = kNone;
      for (std::size_t i = b; i < e; ++i) {
        const Real xix = X[i].x(), xiy = X[i].y(), vix = V[i].x(), viy = V[i].y();
        Real fx = 0, fy = 0;
        const std::uint32_t* nb = c.nbr.of(i);
        const std::uint32_t cnt = c.nbr.count[i];
        for (std::uint32_t k = 0; k < cnt; ++k) {
          const std::uint32_t j = nb[k];
          const Real dx = xix - X[j].x(), dy = xiy - X[j].y();
          const Real r2 = dx * dx + dy * dy;
          // The same clamped Laplacian as ViscosityKernel::laplacian, one division per pair.
          const Real q = r2 > rMin * rMin ? std::sqrt(r2) : rMin;
          const Real iq = r2 > rMin * rMin ? Real(1) / q : invRMin;
          const Real w = lapK * (R - q) * (R3 + R2 * q + R * q * q + Real(9) * q * q * q) * iq * iq * iq * IR[j];
          fx += (V[j].x() - vix) * w;
          fy += (V[j].y() - viy) * w;
        }
        const Vec2 acc = Vec2(fx, fy) * (muMass * IR[i]);
        P.a[i] += acc;
        if (!allFinite(acc) && bad == kNone) bad = i;
      }
      return bad;
    });
  }

 private:
  Real nu_;
};

}  // namespace

std::unique_ptr<Effect> makeLaplacianViscosity(double nu) { return std::make_unique<LaplacianViscosity>(nu); }

}  // namespace sph2d
