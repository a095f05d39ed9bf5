// Surface tension, two models (effects.surface_tension.model):
//
// "csf" — continuum surface force (Brackbill, Kothe & Zemach 1992) on the
//   colour field of Müller, Charypar & Gross 2003 (SCA 2003): c = Σ V0 W_poly6
//   (V0 = m/ρ0), n = ∇c (pointing into the fluid), κ = −∇·n̂, and
//   a = σ κ n / (I ρ0) where |n| > threshold/R.
//   * Curvature. Müller's κ = −∇²c/|n| is wrong at a free surface: the colour
//     field is cut off there, so ∇²c does not vanish on a flat surface and the
//     force added a pressure of about 1.2σ/R_kernel whatever the drop's radius
//     (measured: 12× σ/r for a drop of 8 kernel supports, and the same 120–140 Pa
//     for r = 0.1 and 0.05 m). κ is now −∇·n̂ in SPH form, renormalised by the
//     tangential first moment of the neighbours that have a normal:
//     κ_i = −t̂ᵀ[Σ V_j (n̂_j − n̂_i) ⊗ ∇W_ij]t̂ / t̂ᵀ[Σ V_j (−W'/r) x_ij x_ijᵀ]t̂,
//     t̂ ⊥ n̂_i (n̂ varies only along the surface, so the tangential moment is
//     the one that matters and it is well sampled inside the surface band).
//     Exact for a circle; zero for a flat surface. Clamped to |κ| ≤ 2/R (radii
//     below R/2 are not resolved); 0 where the tangential moment is under 1/8
//     (a lone particle or a filament).
//   * One-sided delta. The colour exists on the fluid side only, so Σ|n| dx
//     across the surface is about 1/2, not 1: I is that sum on a flat half
//     lattice (flatSurfaceDeltaIntegral, ≈ 0.5), and dividing by it makes the
//     force across a surface integrate to σκ — the 2D Laplace jump σ/r
//     (tests/engine/effects/test_surface_tension.cpp: 1.00–1.08 σ/r).
//   Per-particle (not pairwise). Time-step limit (Brackbill et al.):
//   dt ≤ sqrt(ρ0 h³ / (2π σ)), h = R/2.
//
// "akinci" — cohesion + curvature of Akinci, Akinci & Teschner 2013,
//   "Versatile surface tension and adhesion for SPH fluids": normals
//   n_i = R Σ m/ρ_j ∇W_ij; pair forces K_ij (−γ m² C(r) x_ij/r − γ m (n_i − n_j))
//   with K_ij = 2ρ0/(ρ_i + ρ_j) and their spline C(r), here normalised in 2D
//   (∫C dA = 1 over the disc). Pairwise antisymmetric: momentum is conserved.
//   Its step limit is the World's force limit 0.25 sqrt(R/a_max).
//   γ is not σ (the paper's model is not dimensionally consistent): the cohesion
//   is a pair attraction, whose fluid carries an internal pressure
//   A = γρ0²∫C r dA/4 ≈ 0.157 γρ0²R that the solver's pressure balances, and a
//   surface tension σ ≈ γρ0²∫C r² dA/(6π) ≈ 0.021 γρ0²R² (pair-potential
//   theory, 2D). The curvature term is small beside the cohesion at these scales.
//
// Both create the particle fields "surface_tension.nx" and "surface_tension.ny"
// (the normals), only when the scene enables surface tension.
#include <cmath>

#include "effects/effect.hpp"

namespace sph2d {
namespace {

class SurfaceTension final : public Effect {
 public:
  /// The model and parameters of the scene's surface_tension.
  explicit SurfaceTension(const SurfaceTensionDef& d) : def_(d) {}
  /// Stage name.
  const char* name() const override { return "surface_tension"; }
  /// The key whose value sets the step limit.
  const char* limitKey() const override { return "effects.surface_tension.sigma"; }

  /// csf: Brackbill's capillary limit sqrt(ρ0 h³/(2πσ)), h = R/2; akinci: none of its own.
  Real maxTimeStep(const StepContext& c) const override {
    if (def_.model != "csf" || !(def_.sigma > 0)) return std::numeric_limits<Real>::infinity();
    const double h = 0.5 * double(c.R);
    return Real(std::sqrt(double(c.rho0) * h * h * h / (2 * 3.14159265358979323846 * def_.sigma)));
  }

  /// Adds the surface-tension acceleration to P.a; returns the first bad slot.
  std::size_t apply(StepContext& c) override { return def_.model == "csf" ? applyCsf(c) : applyAkinci(c); }

 private:
  /// CSF: colour gradients (pass 1), then curvature and force (pass 2).
  std::size_t applyCsf(StepContext& c) {
    ParticleStore& P = c.P;
    P.field("surface_tension.nx");
    P.field("surface_tension.ny");
    std::vector<Real>& nx = *P.find("surface_tension.nx");
    std::vector<Real>& ny = *P.find("surface_tension.ny");
    const Vec2* X = P.x.data();
    const Poly6<Real> W(c.R);
    const Real v0 = c.mass / c.rho0;  // rest volume: c is a number-density colour
    // Pass 1: n = ∇c = Σ V_j ∇W_ij (points into the fluid).
    c.pool.parallelFor(P.size(), kBlock, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        Real gx = 0, gy = 0;
        const std::uint32_t* nb = c.nbr.of(i);
        for (std::uint32_t q = 0; q < c.nbr.count[i]; ++q) {
          const std::uint32_t j = nb[q];
          Real dx = X[i].x() - X[j].x(), dy = X[i].y() - X[j].y();
          c.periodic.nearest(dx, dy);
          const Real a = W.R2 - (dx * dx + dy * dy);
          const Real g = Real(-6) * W.c * a * a;  // ∇W_ij = g·x_ij (a > 0 within R)
          gx += g * dx;
          gy += g * dy;
        }
        nx[i] = gx * v0;
        ny[i] = gy * v0;
      }
    });
    // Pass 2: κ = −∇·n̂ from the tangential moments over the neighbours that
    // have a normal, and a = σ κ n / (I ρ).
    const Real thresh = Real(def_.threshold) / c.R;
    const Real thresh2 = thresh * thresh;
    // A curvature radius below R/2 is not resolved by the kernel: κ is clamped there.
    const Real kappaMax = Real(2) / c.R;
    if (!(deltaR_ == c.R && deltaDx_ == c.dx && deltaV0_ == v0)) {
      deltaIntegral_ = Real(flatSurfaceDeltaIntegral(double(c.R), double(c.dx), double(v0), def_.threshold));
      deltaR_ = c.R;
      deltaDx_ = c.dx;
      deltaV0_ = v0;
    }
    const Real accScale = Real(def_.sigma) / (deltaIntegral_ * c.rho0);
    return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      std::size_t bad = kNone;
      for (std::size_t i = b; i < e; ++i) {
        const Real n2 = nx[i] * nx[i] + ny[i] * ny[i];
        if (!(n2 > thresh2)) continue;
        const Real inv = Real(1) / std::sqrt(n2);
        const Real hx = nx[i] * inv, hy = ny[i] * inv;  // n̂_i
        const Real tx = -hy, ty = hx;                   // t̂_i
        Real tgt = 0, tmt = 0;
        const std::uint32_t* nb = c.nbr.of(i);
        for (std::uint32_t q = 0; q < c.nbr.count[i]; ++q) {
          const std::uint32_t j = nb[q];
          const Real m2 = nx[j] * nx[j] + ny[j] * ny[j];
          if (!(m2 > thresh2)) continue;
          const Real invj = Real(1) / std::sqrt(m2);
          Real dx = X[i].x() - X[j].x(), dy = X[i].y() - X[j].y();
          c.periodic.nearest(dx, dy);
          const Real a = W.R2 - (dx * dx + dy * dy);
          const Real w = Real(6) * W.c * a * a;  // −W'(r)/r (the volume V0 cancels in κ)
          const Real tx_ij = tx * dx + ty * dy;  // t̂·x_ij
          const Real tdn = tx * (nx[j] * invj - hx) + ty * (ny[j] * invj - hy);
          tgt -= w * tdn * tx_ij;    // t̂ᵀ Σ V_j (n̂_j − n̂_i) ⊗ ∇W_ij t̂ (without m)
          tmt += w * tx_ij * tx_ij;  // t̂ᵀ Σ V_j (−W'/r) x_ij x_ijᵀ t̂ (without m)
        }
        // The tangential moment is about 1/2 for a particle on a flat surface
        // (half of a full lattice); below 1/8 of it the neighbourhood is too
        // sparse (a lone particle, a filament) to tell a curvature.
        Real kappa = tmt * v0 > Real(0.125) ? -tgt / tmt : Real(0);
        kappa = std::max(-kappaMax, std::min(kappaMax, kappa));
        const Vec2 acc = Vec2(nx[i], ny[i]) * (accScale * kappa);
        P.a[i] += acc;
        if (!allFinite(acc) && bad == kNone) bad = i;
      }
      return bad;
    });
  }

  /// Akinci et al. 2013: normals (pass 1), then pairwise cohesion and curvature forces (pass 2).
  std::size_t applyAkinci(StepContext& c) {
    ParticleStore& P = c.P;
    P.field("surface_tension.nx");
    P.field("surface_tension.ny");
    std::vector<Real>& nx = *P.find("surface_tension.nx");
    std::vector<Real>& ny = *P.find("surface_tension.ny");
    const Vec2* X = P.x.data();
    const WendlandC2<Real> WW(c.R);
    c.pool.parallelFor(P.size(), kBlock, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        Vec2 n = Vec2::Zero();
        const std::uint32_t* nb = c.nbr.of(i);
        for (std::uint32_t q = 0; q < c.nbr.count[i]; ++q) {
          const std::uint32_t j = nb[q];
          const Vec2 d = c.periodic.delta(X[i], X[j]);
          n += WW.gradient(d, d.norm()) * (c.mass / P.rho[j]);
        }
        n *= c.R;
        nx[i] = n.x();
        ny[i] = n.y();
      }
    });
    const Real gamma = Real(def_.gamma);
    const Real ck = cohesionNorm(c.R);
    return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      std::size_t bad = kNone;
      for (std::size_t i = b; i < e; ++i) {
        Vec2 acc = Vec2::Zero();
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
        P.a[i] += acc;
        if (!allFinite(acc) && bad == kNone) bad = i;
      }
      return bad;
    });
  }

  /// I = Σ_rows dx |n_row| over the rows of a half-lattice (spacing dx, volume v0,
  /// poly6 of support R) whose colour gradient exceeds threshold/R: the discrete
  /// integral of the surface delta |∇c| across a flat free surface. The colour
  /// field exists on the fluid side only, so I ≈ 1/2 (not 1 as across a
  /// two-fluid interface); dividing the CSF force by it makes the force across a
  /// surface of curvature κ integrate to σκ.
  static double flatSurfaceDeltaIntegral(double R, double dx, double v0, double threshold) {
    const Poly6<double> W(R);
    const int n = int(std::ceil(R / dx)) + 1;
    double I = 0;
    for (int k0 = 0; k0 <= 2 * n; ++k0) {  // particle rows at depth (k0 + 1/2) dx
      double g = 0;
      for (int k = 0; k <= k0 + n; ++k)
        for (int i = -n; i <= n; ++i) {
          const Vec2d d(-double(i) * dx, double(k - k0) * dx);  // x_0 − x_j (rows below have k > k0)
          g += v0 * W.gradient(d, d.norm()).y();
        }
      if (std::fabs(g) > threshold / R) I += dx * std::fabs(g);
    }
    return I;
  }

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
  Real deltaR_ = 0, deltaDx_ = 0, deltaV0_ = 0, deltaIntegral_ = 1;  ///< flatSurfaceDeltaIntegral for (R, dx, V0)
};

}  // namespace

/// The surface-tension effect (model csf or akinci) when the scene enables effects.surface_tension.
std::unique_ptr<Effect> surfaceTensionEffect(const SceneDef& scene) {
  if (!scene.effects.surfaceTension) return nullptr;
  return std::make_unique<SurfaceTension>(scene.effects.tension);
}

}  // namespace sph2d
