// Surface tension, two models (effects.surface_tension.model):
//
// "csf" — the colour-field model of Müller, Charypar & Gross 2003 (seed 002,
//   eqs. 15–19): c_s = Σ m/ρ_j W_poly6, n = ∇c_s, f = −σ ∇²c_s n/|n| where
//   |n| exceeds threshold/R. A per-particle force (not pairwise). Time-step
//   limit (Brackbill, Kothe & Zemach 1992): dt ≤ sqrt(ρ0 h³ / (2π σ)), h = R/2.
//
// "akinci" — cohesion + curvature of Akinci, Akinci & Teschner 2013,
//   "Versatile surface tension and adhesion for SPH fluids": normals
//   n_i = R Σ m/ρ_j ∇W_ij; pair forces K_ij (−γ m² C(r) x_ij/r − γ m (n_i − n_j))
//   with K_ij = 2ρ0/(ρ_i + ρ_j) and their spline C(r), here normalised in 2D
//   (∫C dA = 1 over the disc). Pairwise antisymmetric: momentum is conserved.
//   Its step limit is the World's force limit 0.25 sqrt(R/a_max).
//
// Both create the particle fields "surface_tension.nx" and "surface_tension.ny"
// (the normals), only when the scene enables surface tension.
#include <cmath>

#include "effects/effect.hpp"

namespace sph2d {
namespace {

class SurfaceTension final : public Effect {
 public:
  explicit SurfaceTension(const SurfaceTensionDef& d) : def_(d) {}
  const char* name() const override { return "surface_tension"; }
  const char* limitKey() const override { return "effects.surface_tension.sigma"; }

  Real maxTimeStep(const StepContext& c) const override {
    if (def_.model != "csf" || !(def_.sigma > 0)) return std::numeric_limits<Real>::infinity();
    const double h = 0.5 * double(c.R);
    return Real(std::sqrt(double(c.rho0) * h * h * h / (2 * 3.14159265358979323846 * def_.sigma)));
  }

  std::size_t apply(StepContext& c) override {
    Particles& P = c.P;
    const bool csf = def_.model == "csf";
    // Create every field before taking references: creating one may grow
    // P.extra and move the others (a dangling reference, found by ASan).
    P.field("surface_tension.nx");
    P.field("surface_tension.ny");
    if (csf) P.field("surface_tension.laplacian");
    std::vector<Real>& nx = *P.find("surface_tension.nx");
    std::vector<Real>& ny = *P.find("surface_tension.ny");
    const Vec2* X = P.x.data();
    // Pass 1: normals (and, for CSF, the colour-field Laplacian into a scratch field).
    std::vector<Real>* lap = csf ? P.find("surface_tension.laplacian") : nullptr;
    const Poly6<Real> W6(c.R);
    const WendlandC2<Real> WW(c.R);
    c.pool.parallelFor(P.size(), kBlock, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        Vec2 n = Vec2::Zero();
        Real l = csf ? c.mass / P.rho[i] * W6.laplacian(0) : Real(0);
        const std::uint32_t* nb = c.nbr.of(i);
        for (std::uint32_t q = 0; q < c.nbr.count[i]; ++q) {
          const std::uint32_t j = nb[q];
          const Vec2 d = c.periodic.delta(X[i], X[j]);
          const Real r = d.norm();
          const Real vj = c.mass / P.rho[j];
          if (csf) {
            n += W6.gradient(d, r) * vj;
            l += W6.laplacian(r) * vj;
          } else {
            n += WW.gradient(d, r) * vj;
          }
        }
        if (!csf) n *= c.R;
        nx[i] = n.x();
        ny[i] = n.y();
        if (csf) (*lap)[i] = l;
      }
    });
    // Pass 2: forces.
    const Real sigma = Real(def_.sigma), gamma = Real(def_.gamma);
    const Real thresh = Real(def_.threshold) / c.R;
    const Real ck = cohesionNorm(c.R);
    return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      std::size_t bad = kNone;
      for (std::size_t i = b; i < e; ++i) {
        Vec2 acc = Vec2::Zero();
        if (csf) {
          const Vec2 n(nx[i], ny[i]);
          const Real len = n.norm();
          if (len > thresh) acc = -(sigma * (*lap)[i] / (len * P.rho[i])) * n;
        } else {
          const std::uint32_t* nb = c.nbr.of(i);
          for (std::uint32_t q = 0; q < c.nbr.count[i]; ++q) {
            const std::uint32_t j = nb[q];
            const Vec2 d = c.periodic.delta(X[i], X[j]);
            const Real r = d.norm();
            const Real K = Real(2) * c.rho0 / (P.rho[i] + P.rho[j]);
            Vec2 f = Vec2(nx[j] - nx[i], ny[j] - ny[i]) * gamma;  // curvature: −γ (n_i − n_j)
            if (r > 0) f -= d * (gamma * c.mass * ck * cohesionShape(r, c.R) / r);
            acc += f * K;
          }
        }
        P.a[i] += acc;
        if (!allFinite(acc) && bad == kNone) bad = i;
      }
      return bad;
    });
  }

 private:
  /// Akinci's cohesion spline shape (without constant), support R.
  static Real cohesionShape(Real r, Real R) {
    if (r >= R) return 0;
    const Real a = (R - r) * (R - r) * (R - r) * r * r * r;
    if (2 * r > R) return a;
    return 2 * a - R * R * R * R * R * R / 64;
  }
  /// 1 / ∫ shape dA over the disc of radius R (2D normalisation).
  static Real cohesionNorm(Real R) {
    double s = 0;
    const int n = 2000;
    for (int k = 0; k < n; ++k) {
      const double r = (k + 0.5) / n * double(R);
      s += double(cohesionShape(Real(r), R)) * 2 * 3.14159265358979323846 * r * (double(R) / n);
    }
    return Real(1.0 / s);
  }

  SurfaceTensionDef def_;
};

}  // namespace

std::unique_ptr<Effect> makeSurfaceTension(const SurfaceTensionDef& def) { return std::make_unique<SurfaceTension>(def); }

}  // namespace sph2d
