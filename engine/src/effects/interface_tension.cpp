// Interface tension between immiscible materials (docs/SCENES.md, materials: tension_with): the
// surface stress of Hu & Adams 2006 ("A multi-phase SPH method for macroscopic and mesoscopic
// flows", J. Comput. Phys. 213), per pair of materials (a, b) with a tension σ_ab > 0. At a
// particle i of material a, the gradient of b's indicator and the stress it carries:
//   ∇C_i^b = Σ_{j of b} V ∇W_ij,      Π_i = Σ_b σ_ab (½|∇C_i^b|² I − ∇C_i^b ⊗ ∇C_i^b) / |∇C_i^b|,
// (2D: the isotropic part is 1/d = ½ of |∇C|²), and the force as a pressure's, with the stress
// in place of −p:
//   m_i a_i = Σ_j V² (Π_i + Π_j) ∇W_ij,
// pairwise antisymmetric (momentum is conserved, to rounding). Across a flat interface it adds
// nothing net; a curved one carries the Laplace jump σ/r (2D) and is pulled round. V = m/ρ0, the
// lattice volume every particle has (the number density's; materials of different density take
// their own mass m_i = r_i m). W is Wendland C2 at the solver's support. Particles away from an
// interface carry no stress and cost one test per pair. Time-step limit (Brackbill et al. 1992):
// dt ≤ sqrt(ρ_min h³ / (2π σ_max)), h = R/2.
#include <algorithm>
#include <cmath>

#include "effects/effect.hpp"
#include "particles/material_fields.hpp"

namespace sph2d {
namespace {

/// A symmetric 2×2 stress.
struct Stress {
  Real xx = 0, xy = 0, yy = 0;
  bool zero() const { return xx == 0 && xy == 0 && yy == 0; }
};

class InterfaceTension final : public Effect {
 public:
  explicit InterfaceTension(const std::vector<MaterialDef>& materials) : K_(materials.size()) {
    sigma_.assign(K_ * K_, 0);
    minDensity_ = materials.front().density;
    for (std::size_t a = 0; a < K_; ++a) {
      minDensity_ = std::min(minDensity_, materials[a].density);
      for (std::size_t b = 0; b < K_; ++b) {
        sigma_[a * K_ + b] = Real(tensionBetween(materials, a, b));
        maxSigma_ = std::max(maxSigma_, double(sigma_[a * K_ + b]));
      }
    }
  }

  const char* name() const override { return "interface_tension"; }
  const char* limitKey() const override { return "materials[].tension_with"; }
  Real maxTimeStep(const StepContext& c) const override {
    const double h = 0.5 * double(c.R);
    return Real(std::sqrt(minDensity_ * h * h * h / (2 * 3.14159265358979323846 * maxSigma_)));
  }

  std::size_t apply(StepContext& c) override {
    ParticleStore& P = c.P;
    const std::vector<std::uint32_t>* mat = P.findU32(ParticleStore::kMaterial);
    if (!mat) return kNone;
    const std::uint32_t* M = mat->data();
    const std::size_t n = P.size();
    const WendlandC2<Real> W(c.R);
    const Real V = c.mass / c.rho0;
    stress_.resize(n);
    // Each particle's stress, from the indicator gradients of the materials it has a tension with.
    c.pool.parallelFor(n, kBlock, [&](std::size_t lo, std::size_t hi) {
      std::vector<Vec2> g(K_, Vec2::Zero());
      for (std::size_t i = lo; i < hi; ++i) {
        stress_[i] = Stress{};
        if (M[i] >= K_) continue;  // a material added at run time has no tension
        const Real* sig = sigma_.data() + std::size_t(M[i]) * K_;
        const std::uint32_t* nb = c.nbr.of(i);
        bool any = false;
        for (std::uint32_t q = 0; q < c.nbr.count[i]; ++q) {
          const std::uint32_t j = nb[q];
          if (M[j] >= K_ || !(sig[M[j]] > 0)) continue;
          Real dx, dy, r2;
          pairDelta(c, i, j, dx, dy, r2);
          g[M[j]] += W.gradient(Vec2(dx, dy), std::sqrt(r2)) * V;
          any = true;
        }
        Stress s;
        if (any)
          for (std::size_t b = 0; b < K_; ++b) {
            const Real gn = g[b].norm();
            if (gn > 0) {
              const Real k = sig[b] / gn, gx = g[b].x(), gy = g[b].y();
              s.xx += k * Real(0.5) * (gy * gy - gx * gx);
              s.yy += k * Real(0.5) * (gx * gx - gy * gy);
              s.xy -= k * gx * gy;
            }
            g[b] = Vec2::Zero();
          }
        stress_[i] = s;
      }
    });
    // m_i a_i = Σ_j V² (Π_i + Π_j) ∇W_ij, over the pairs where either carries a stress.
    const std::vector<Real>* ratioField = P.find(ParticleStore::kRestRatio);
    const Real* ratio = ratioField ? ratioField->data() : nullptr;
    return firstBad(c.pool, n, [&](std::size_t lo, std::size_t hi) {
      std::size_t bad = kNone;
      for (std::size_t i = lo; i < hi; ++i) {
        const Stress si = stress_[i];
        const std::uint32_t* nb = c.nbr.of(i);
        Vec2 f = Vec2::Zero();
        for (std::uint32_t q = 0; q < c.nbr.count[i]; ++q) {
          const std::uint32_t j = nb[q];
          const Stress& sj = stress_[j];
          if (si.zero() && sj.zero()) continue;
          Real dx, dy, r2;
          pairDelta(c, i, j, dx, dy, r2);
          const Vec2 gw = W.gradient(Vec2(dx, dy), std::sqrt(r2));
          const Real xx = si.xx + sj.xx, xy = si.xy + sj.xy, yy = si.yy + sj.yy;
          f += Vec2(xx * gw.x() + xy * gw.y(), xy * gw.x() + yy * gw.y());
        }
        if (f.x() == 0 && f.y() == 0) continue;
        const Vec2 a = f * (V * V / (c.mass * (ratio ? ratio[i] : Real(1))));
        P.a[i] += a;
        if (!allFinite(a) && bad == kNone) bad = i;
      }
      return bad;
    });
  }

 private:
  std::size_t K_;
  std::vector<Real> sigma_;  ///< K × K: σ of each pair with an interface tension, else 0
  double maxSigma_ = 0, minDensity_ = 1000;
  std::vector<Stress> stress_;  ///< per particle, this substep
};

}  // namespace

/// The interface tension when two materials of the scene's table have one.
std::unique_ptr<Effect> interfaceTensionEffect(const SceneDef& scene) {
  const std::vector<MaterialDef> m = sceneMaterials(scene);
  for (std::size_t a = 0; a < m.size(); ++a)
    for (std::size_t b = 0; b < a; ++b)
      if (tensionBetween(m, a, b) > 0) return std::make_unique<InterfaceTension>(m);
  return nullptr;
}

}  // namespace sph2d
