// muller2003 — the SPH step of Müller, Charypar & Gross 2003, "Particle-based
// fluid simulation for interactive applications" (SCA 2003), in 2D: poly6
// density, p = K(ρ − ρ0) with K = c², the symmetric spiky pressure force
// m (p_i + p_j)/(2ρ_j) ∇W, gravity, the scene's effects (viscosity: the
// viscosity-kernel Laplacian), symplectic Euler. Walls: the boundary samples
// act as frozen fluid in the density, and push with the particle's own
// pressure only (the single term; see pressureForce).
//
// Measured property (docs/SCENES.md): the density and gradient kernels differ,
// so the pressure force is not the gradient of an energy, and the symmetric
// average recovers ∇p/2. A resting column needs ν ≳ 0.005 m²/s to stay calm,
// and its pressure at rest grows by 2ρg per metre.
#include <algorithm>
#include <cmath>

#include "solvers/solver.hpp"

namespace sph2d {
namespace {

std::size_t density(StepContext& c, const Poly6<Real>& W) {
  ParticleStore& P = c.P;
  const NeighbourLists& L = c.nbr;
  const BoundarySet& B = c.boundary;
  const bool hasBoundary = !B.samples.empty();
  const Real self = W.valueR2(0);
  return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
    std::size_t bad = kNone;
    for (std::size_t i = b; i < e; ++i) {
      const Vec2 xi = P.x[i];
      const std::uint32_t* nb = L.of(i);
      const std::uint32_t cnt = L.count[i];
      Real sum = self;
      const Vec2* X = P.x.data();
      for (std::uint32_t k = 0; k < cnt; ++k) {
        const Vec2 xj = X[nb[k]];
        Real dx = xi.x() - xj.x(), dy = xi.y() - xj.y();
        c.periodic.nearest(dx, dy);
        sum += W.valueR2(dx * dx + dy * dy);
      }
      Real rho = c.mass * sum;
      if (hasBoundary) {
        Real bs = 0;
        const std::uint32_t* bl = L.boundaryOf(i);
        for (std::uint32_t k = 0; k < L.boundaryCount[i]; ++k)
          bs += B.volume[bl[k]] * W.valueR2((xi - B.samples[bl[k]]).squaredNorm());
        rho += c.rho0 * bs;
      }
      P.rho[i] = rho;
      if (!std::isfinite(rho) && bad == kNone) bad = i;
    }
    return bad;
  });
}

void pressure(StepContext& c) {
  const Real stiffness = Real(c.def.soundSpeed * c.def.soundSpeed);
  const bool clampNegative = c.def.clampNegativePressure;
  ParticleStore& P = c.P;
  c.pool.parallelFor(P.size(), 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      Real p = stiffness * (P.rho[i] - c.rho0);
      if (clampNegative && p < 0) p = 0;
      P.p[i] = p;
      P.invRho[i] = Real(1) / P.rho[i];
      P.pOverRho[i] = p * P.invRho[i];
    }
  });
}

std::size_t pressureForce(StepContext& c, const Spiky<Real>& spiky) {
  ParticleStore& P = c.P;
  const BoundarySet& B = c.boundary;
  const bool hasBoundary = !B.samples.empty();
  const Real R = spiky.R;
  const Real spikyK = Real(-3) * spiky.c;  // dW/dr = −3c(R − r)²
  const Real halfMass = Real(0.5) * c.mass;
  const Real* IR = P.invRho.data();
  const Real* POR = P.pOverRho.data();
  return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
    std::size_t bad = kNone;
    for (std::size_t i = b; i < e; ++i) {
      const Vec2 xi = P.x[i];
      const Real pi = P.p[i];
      // Σ m (p_i + p_j)/(2 ρ_j) ∇W (force density, Müller eq. 10), accumulated
      // in scalars from raw arrays so the loop keeps everything in registers.
      Real fpx = 0, fpy = 0;
      const std::uint32_t* nb = c.nbr.of(i);
      const std::uint32_t cnt = c.nbr.count[i];
      for (std::uint32_t k = 0; k < cnt; ++k) {
        const std::uint32_t j = nb[k];
        Real dx, dy, r2;
        pairDelta(c, i, j, dx, dy, r2);  // coincident pairs: a fixed, antisymmetric direction
        // One square root and one division per pair.
        const Real invr = Real(1) / std::sqrt(r2);
        const Real r = r2 * invr;
        const Real a = R - r;
        const Real irj = IR[j];
        // Spiky gradient dW/dr · d/r, dW/dr = −3c(R − r)², times m (p_i + p_j)/(2 ρ_j).
        const Real wp = spikyK * a * a * invr * (halfMass * (pi * irj + POR[j]));
        fpx += dx * wp;
        fpy += dy * wp;
      }
      const Vec2 fp(fpx, fpy);
      const Real invRhoi = P.invRho[i];
      Vec2 acc = -fp * invRhoi;
      if (hasBoundary) {
        // Boundary samples as frozen fluid of mass ρ0·Ψ_b that carries no
        // pressure of its own: m (p_i + 0)/(2ρ_b) ∇W with ρ_b = ρ0 (the single
        // term p_i/ρ_i² of Akinci et al. 2012, in Müller's symmetric form). A pressure
        // mirrored onto the sample (p_b = p_i extrapolated hydrostatically,
        // Adami, Hu & Adams 2012) makes the wall force depend on where the
        // particle sits relative to each sample, so it does net work on fluid
        // oscillating against the wall: with only ν to dissipate it, the long
        // rest of tests/stability (dx = 0.04, c = 25, ν = 0.01) heated up to
        // ~200 J/m (mean speed ~1 m/s) within 6 s; with the single term it stays
        // below 0.6 J/m. The single term pushes half as hard as the mirrored
        // pressure, so the wall row sits more compressed (the resting column's
        // most compressed particle: about 4 % instead of 2–3.5 %).
        Vec2 gb = Vec2::Zero();
        const std::uint32_t* bl = c.nbr.boundaryOf(i);
        for (std::uint32_t k = 0; k < c.nbr.boundaryCount[i]; ++k) {
          const Vec2 d = xi - B.samples[bl[k]];
          gb += spiky.gradient(d, std::sqrt(d.squaredNorm())) * B.volume[bl[k]];
        }
        acc -= gb * (Real(0.5) * pi * invRhoi);
      }
      acc += c.gravity;
      P.a[i] = acc;
      if (!allFinite(acc) && bad == kNone) bad = i;
    }
    return bad;
  });
}

class Muller2003 final : public Solver {
 public:
  explicit Muller2003(const SolverDef& d) : c_(d.soundSpeed) {}
  const char* name() const override { return "muller2003"; }
  // p = c²(ρ − ρ0) and the symmetric force recovers ∇p/2: ρ = ρ0(1 + 2 g z / c²).
  double hydrostaticFactor() const override { return 2.0 / (c_ * c_); }

  double densityKernel(double r, double R) const override { return Poly6<double>(R).value(r); }

  void prepare(StepContext& c) override {
    stageGrid(c, false);
    stageNeighbours(c);
    density(c, Poly6<Real>(c.R));
    pressure(c);
  }

  /// The CFL limit cfl·R/(c + v_max) and the force limit.
  Real maxTimeStep(const StepContext& c, Real vmax, Real amax) const override {
    Real dt = Real(c.def.cfl) * c.R / (Real(c.def.soundSpeed) + vmax);
    if (amax > 0) dt = std::min(dt, kForceCfl * std::sqrt(c.R / amax));
    return dt;
  }

  /// grid → neighbours → density (poly6) → pressure → pressure_force (spiky) → effects → force_limit → integrate.
  std::vector<Stage> stages(bool) override {
    return explicitStages([](StepContext& c) { return density(c, Poly6<Real>(c.R)); }, pressure,
                          [](StepContext& c) { return pressureForce(c, Spiky<Real>(c.R)); });
  }

 private:
  double c_;
};

}  // namespace

/// muller2003's registration (solvers.def): no parameters of its own (solver.sound_speed is its stiffness).
SolverInfo muller2003Solver() {
  return {"muller2003", {}, [](const SolverDef& d) -> std::unique_ptr<Solver> { return std::make_unique<Muller2003>(d); }};
}

}  // namespace sph2d
