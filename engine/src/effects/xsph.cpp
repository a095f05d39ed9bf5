// XSPH velocity smoothing (Monaghan 1989, "On the problem of penetration in
// particle methods"; as used by Macklin & Müller 2013): each particle's
// velocity moves towards its neighbours' average,
//   v_i += c Σ_j (2m/(ρ_i + ρ_j)) (v_j − v_i) W_ij,
// applied as the acceleration that does so over one substep. The symmetric
// weight 2m/(ρ_i + ρ_j) makes the pair terms antisymmetric: linear momentum is
// conserved to rounding.
#include "effects/effect.hpp"

namespace sph2d {
namespace {

class Xsph final : public Effect {
 public:
  explicit Xsph(double c) : c_(Real(c)) {}
  const char* name() const override { return "xsph"; }
  std::size_t apply(StepContext& c) override {
    ParticleStore& P = c.P;
    if (!(c.dt > 0)) return kNone;
    const WendlandC2<Real> W(c.R);
    const Real k = c_ / c.dt * Real(2) * c.mass;
    const Vec2* X = P.x.data();
    const Vec2* V = P.v.data();
    return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      std::size_t bad = kNone;
      for (std::size_t i = b; i < e; ++i) {
        Real sx = 0, sy = 0;
        const std::uint32_t* nb = c.nbr.of(i);
        for (std::uint32_t q = 0; q < c.nbr.count[i]; ++q) {
          const std::uint32_t j = nb[q];
          const Real w = W.value(c.periodic.delta(X[i], X[j]).norm()) / (P.rho[i] + P.rho[j]);
          sx += (V[j].x() - V[i].x()) * w;
          sy += (V[j].y() - V[i].y()) * w;
        }
        const Vec2 acc(sx * k, sy * k);
        P.a[i] += acc;
        if (!allFinite(acc) && bad == kNone) bad = i;
      }
      return bad;
    });
  }

 private:
  Real c_;
};

}  // namespace

/// XSPH when the scene enables effects.xsph.
std::unique_ptr<Effect> xsphEffect(const SceneDef& scene) {
  if (!scene.effects.xsph) return nullptr;
  return std::make_unique<Xsph>(scene.effects.xsphC);
}

}  // namespace sph2d
