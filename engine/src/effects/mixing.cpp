// Mixing of miscible materials (docs/SCENES.md, materials: miscible_with, diffusion): every
// particle of a scene with a miscible pair carries a concentration of each material
// ("concentration.K", ParticleStore::concentration(K), in double; 1 of its own when it is made), which
// diffuses between particles that mix (the same material, or a miscible pair) by the SPH
// Laplacian:
//   dc_i/dt = Σ_j D_ij V ∇²W(r_ij) (c_j − c_i) / m₂,
// D_ij the mean of the two materials' `diffusion`, V = m/ρ0 the lattice volume (every particle
// has it: the number-density formulation), ∇²W the viscosity kernel's 2D Laplacian and m₂ its
// lattice moment (the viscosity effect's), so that a resolved profile diffuses at D. The pair
// weights are symmetric, so Σ_i c_i is conserved to rounding; the update is a Jacobi step
// (every particle from the old values), the same bits on any thread count. Then each
// particle's colour ("mixed_color", drawn by the renderer) is Σ_k c_k colour_k, and with a
// density contrast its rest ratio Σ_k c_k ρ0_k / ρ0: density follows concentration. Colour
// mixing (LiquidFun's colorMixing) is the case of materials of one density.
// Time-step limit: 0.03 R²/D (explicit diffusion, as the viscosity's), and each pair's share
// capped at 1/8 a substep (symmetric: the totals still hold).
#include <algorithm>
#include <cmath>

#include "effects/effect.hpp"
#include "particles/material_fields.hpp"

namespace sph2d {
namespace {

class Mixing final : public Effect {
 public:
  explicit Mixing(std::vector<MaterialDef> materials) : materials_(std::move(materials)) {
    const std::size_t K = materials_.size();
    pairD_.assign(K * K, 0);
    for (std::size_t a = 0; a < K; ++a)
      for (std::size_t b = 0; b < K; ++b)
        if (mixes(materials_, a, b)) {
          pairD_[a * K + b] = Real(0.5 * (materials_[a].diffusion + materials_[b].diffusion));
          maxD_ = std::max(maxD_, pairD_[a * K + b]);
        }
  }

  const char* name() const override { return "mixing"; }
  const char* limitKey() const override { return "materials[].diffusion"; }
  Real maxTimeStep(const StepContext& c) const override {
    return maxD_ > 0 ? Real(0.03) * c.R * c.R / maxD_ : std::numeric_limits<Real>::infinity();
  }

  std::size_t apply(StepContext& c) override {
    ParticleStore& P = c.P;
    const std::size_t K = materials_.size(), n = P.size();
    const std::vector<std::uint32_t>* mat = P.findU32(ParticleStore::kMaterial);
    if (!mat || !(c.dt > 0) || maxD_ <= 0) return kNone;
    if (c.R != momentR_ || c.dx != momentDx_) {
      const ViscosityKernel<double> Wd(double(c.R));
      scale_ = Real(1.0 / latticeLaplacianMoment([&](double r) { return Wd.laplacian(r); }, Wd.R, double(c.dx)));
      momentR_ = c.R;
      momentDx_ = c.dx;
    }
    std::vector<const double*> conc(K);
    for (std::size_t k = 0; k < K; ++k) conc[k] = P.findD(ParticleStore::concentration(k))->data();
    next_.resize(K * n);
    const ViscosityKernel<Real> W(c.R);
    const Real k0 = c.dt * scale_ * c.mass / c.rho0;  // dt V / m₂
    // Each pair moves at most an eighth of its difference per substep (the viscosity's
    // kViscousPairShare, for the same reason: ∇²W grows as 1/r³, and a pair pressed together
    // would overshoot). Lattice pairs at the time-step limit take at most 0.061: not reached.
    const double cap = kViscousPairShare / double(k0);
    const Vec2* X = P.x.data();
    const std::uint32_t* M = mat->data();
    const std::size_t bad = firstBad(c.pool, n, [&](std::size_t b, std::size_t e) {
      std::vector<double> sum(K);
      std::size_t first = kNone;
      for (std::size_t i = b; i < e; ++i) {
        std::fill(sum.begin(), sum.end(), 0.0);
        const Real* Di = pairD_.data() + std::size_t(M[i]) * K;
        const std::uint32_t* nb = c.nbr.of(i);
        for (std::uint32_t q = 0; q < c.nbr.count[i]; ++q) {
          const std::uint32_t j = nb[q];
          const Real D = Di[M[j]];
          if (D <= 0) continue;  // immiscible (or no diffusion)
          Real dx = X[i].x() - X[j].x(), dy = X[i].y() - X[j].y();
          c.periodic.nearest(dx, dy);
          const double w = std::min(double(D * W.laplacianR2(dx * dx + dy * dy)), cap);
          for (std::size_t k = 0; k < K; ++k) sum[k] += w * (conc[k][j] - conc[k][i]);
        }
        for (std::size_t k = 0; k < K; ++k) {
          const double v = conc[k][i] + double(k0) * sum[k];
          next_[k * n + i] = v;
          if (!std::isfinite(v) && first == kNone) first = i;
        }
      }
      return first;
    });
    for (std::size_t k = 0; k < K; ++k) {
      std::vector<double>& f = *P.findD(ParticleStore::concentration(k));
      std::copy(next_.begin() + std::ptrdiff_t(k * n), next_.begin() + std::ptrdiff_t((k + 1) * n), f.begin());
    }
    deriveFromConcentrations(P, materials_, 0);
    return bad;
  }

 private:
  std::vector<MaterialDef> materials_;
  std::vector<Real> pairD_;  ///< K × K: D of each pair that mixes, else 0
  Real maxD_ = 0;
  Real scale_ = 1, momentR_ = -1, momentDx_ = -1;
  std::vector<double> next_;  ///< the Jacobi step's new concentrations, K blocks of n
};

}  // namespace

/// Mixing when the scene's materials hold a miscible pair.
std::unique_ptr<Effect> mixingEffect(const SceneDef& scene) {
  const std::vector<MaterialDef> m = sceneMaterials(scene);
  if (!anyMiscible(m)) return nullptr;
  return std::make_unique<Mixing>(m);
}

}  // namespace sph2d
