
// The SPH step of Müller, Charypar & Gross 2003, "Particle-based fluid
// simulation for interactive applications" (seed 002), in 2D: poly6 density,
// p = K(ρ − ρ0), the symmetric spiky pressure force, the viscosity-kernel
// Laplacian, gravity and symplectic Euler. Walls add Akinci et al. 2012
// boundary samples to density and pressure.
#include <algorithm>
#include <cmath>

#include "stages.hpp"

namespace sph2d {

namespace {

/// Lowest slot reported by the blocks (the blocks are in slot order).
std::size_t firstBad(ThreadPool& pool, std::size_t n, const std::function<std::size_t(std::size_t, std::size_t)>& fn) {
  return pool.reduce(n, kBlock, kNone, fn, [](std::size_t a, std::size_t b) { return std::min(a, b); });
}

template <class T>
void permute(std::vector<T>& field, const std::vector<std::uint32_t>& order, std::vector<T>& scratch, ThreadPool& pool) {
  scratch.resize(field.size());
  pool.parallelFor(field.size(), 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) scratch[k] = field[order[k]];
  });
  field.swap(scratch);
}

/// A fixed unit direction for two coincident particles, antisymmetric in (i, j).
inline Vec2 tieBreakDirection(std::uint32_t idi, std::uint32_t idj) {
  const std::uint32_t lo = std::min(idi, idj), hi = std::max(idi, idj);
  std::uint64_t h = (std::uint64_t(lo) << 32) | hi;
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdULL;
  h ^= h >> 33;
  const Real angle = Real(double(h % 3600) * (2 * 3.14159265358979323846 / 3600.0));
  const Vec2 d(std::cos(angle), std::sin(angle));
  return idi < idj ? d : Vec2(-d);
}

}  // namespace

void stageGrid(StepContext& c, bool reorder, std::vector<Vec2>& sv, std::vector<Real>& sr, std::vector<std::uint32_t>& su) {
  Particles& P = c.P;
  c.grid.build(P.x.data(), P.size(), c.poly6.R, c.pool);
  if (!reorder) return;
  const std::vector<std::uint32_t>& order = c.grid.sorted;
  permute(P.x, order, sv, c.pool);
  permute(P.v, order, sv, c.pool);
  permute(P.a, order, sv, c.pool);
  permute(P.xPrev, order, sv, c.pool);
  permute(P.rho, order, sr, c.pool);
  permute(P.p, order, sr, c.pool);
  permute(P.id, order, su, c.pool);
  // After the permutation slot k is the k-th particle in cell order.
  std::vector<std::uint32_t>& cellOf = c.grid.cellOf;
  permute(cellOf, order, su, c.pool);
  for (std::size_t k = 0; k < c.grid.sorted.size(); ++k) c.grid.sorted[k] = std::uint32_t(k);
}

std::size_t stageDensity(StepContext& c) {
  Particles& P = c.P;
  const Grid& g = c.grid;
  const BoundarySet& B = c.boundary;
  const bool hasBoundary = !B.samples.empty();
  return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
    std::size_t bad = kNone;
    for (std::size_t i = b; i < e; ++i) {
      const Vec2 xi = P.x[i];
      Real sum = 0;
      g.forCandidates(xi, [&](std::uint32_t j) { sum += c.poly6.valueR2((xi - P.x[j]).squaredNorm()); });
      Real rho = c.mass * sum;
      if (hasBoundary) {
        Real bs = 0;
        B.sampleGrid.forCandidates(xi, [&](std::uint32_t k) {
          if (B.visible(k, xi)) bs += B.volume[k] * c.poly6.valueR2((xi - B.samples[k]).squaredNorm());
        });
        rho += c.rho0 * bs;
      }
      P.rho[i] = rho;
      if (!std::isfinite(rho) && bad == kNone) bad = i;
    }
    return bad;
  });
}

void stagePressure(StepContext& c) {
  Particles& P = c.P;
  c.pool.parallelFor(P.size(), 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      Real p = c.stiffness * (P.rho[i] - c.rho0);
      if (c.clampNegative && p < 0) p = 0;
      P.p[i] = p;
    }
  });
}

std::size_t stageForces(StepContext& c) {
  Particles& P = c.P;
  const Grid& g = c.grid;
  const BoundarySet& B = c.boundary;
  const bool hasBoundary = !B.samples.empty();
  const Real R2 = c.poly6.R2;
  const Real tiny2 = Real(1e-12) * R2;
  return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
    std::size_t bad = kNone;
    for (std::size_t i = b; i < e; ++i) {
      const Vec2 xi = P.x[i], vi = P.v[i];
      const Real rhoi = P.rho[i], pi = P.p[i];
      const std::uint32_t idi = P.id[i];
      Vec2 fp = Vec2::Zero();  // Σ m (p_i + p_j)/(2 ρ_j) ∇W   (force density, Müller eq. 10)
      Vec2 fv = Vec2::Zero();  // Σ m (v_j − v_i)/ρ_j ∇²W       (Müller eq. 14, 2D Laplacian)
      g.forCandidates(xi, [&](std::uint32_t j) {
        if (j == i) return;
        Vec2 d = xi - P.x[j];
        Real r2 = d.squaredNorm();
        if (r2 >= R2) return;
        if (r2 < tiny2) {  // coincident pair: a fixed, antisymmetric direction
          d = tieBreakDirection(idi, P.id[j]) * (Real(1e-6) * c.poly6.R);
          r2 = d.squaredNorm();
        }
        const Real r = std::sqrt(r2);
        const Real rhoj = P.rho[j];
        fp += c.spiky.gradient(d, r) * (c.mass * (pi + P.p[j]) / (Real(2) * rhoj));
        fv += (P.v[j] - vi) * (c.mass * c.visc.laplacian(r) / rhoj);
      });
      Vec2 acc = (-fp + fv * c.mu) / rhoi;
      if (hasBoundary) {
        // Boundary samples as frozen fluid of mass ρ0·Ψ_b whose pressure is the
        // particle's own, extrapolated hydrostatically to the sample (Adami,
        // Hu & Adams 2012). Müller's symmetric force recovers ∇p/2, so at rest
        // this solver's pressure grows by 2ρg per metre: p_b = p_i + 2ρ_i g·(x_b − x_i).
        Vec2 gb = Vec2::Zero();
        B.sampleGrid.forCandidates(xi, [&](std::uint32_t k) {
          const Vec2 d = xi - B.samples[k];
          const Real r2 = d.squaredNorm();
          if (r2 >= R2 || !B.visible(k, xi)) return;
          const Real pb = std::max(Real(0), pi - Real(2) * rhoi * c.gravity.dot(d));
          gb += c.spiky.gradient(d, std::sqrt(r2)) * (B.volume[k] * (pi + pb));
        });
        acc -= gb * (c.rho0 / (Real(2) * rhoi * c.rho0));
      }
      acc += c.gravity;
      P.a[i] = acc;
      if (!allFinite(acc) && bad == kNone) bad = i;
    }
    return bad;
  });
}

std::size_t stageIntegrate(StepContext& c) {
  Particles& P = c.P;
  const Real dt = c.dt;
  const Real vmax2 = c.maxSpeed * c.maxSpeed;
  return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
    std::size_t bad = kNone;
    for (std::size_t i = b; i < e; ++i) {
      const Vec2 v = P.v[i] + P.a[i] * dt;
      P.xPrev[i] = P.x[i];
      P.v[i] = v;
      P.x[i] = P.x[i] + v * dt;
      if (bad == kNone && (!allFinite(P.x[i]) || !allFinite(v) || v.squaredNorm() > vmax2)) bad = i;
    }
    return bad;
  });
}

void stageCollide(StepContext& c) {
  Particles& P = c.P;
  if (c.boundary.colliders.empty()) return;
  c.pool.parallelFor(P.size(), kBlock, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) c.boundary.resolve(P.x[i], P.v[i], P.xPrev[i], c.clearance);
  });
}

Real maxSpeedOf(const Particles& P, ThreadPool& pool) {
  const Real m2 = pool.reduce(
      P.size(), 4096, Real(0),
      [&](std::size_t b, std::size_t e) {
        Real m = 0;
        for (std::size_t i = b; i < e; ++i) m = std::max(m, P.v[i].squaredNorm());
        return m;
      },
      [](Real a, Real b) { return std::max(a, b); });
  return std::sqrt(m2);
}

Real maxAccelOf(const Particles& P, ThreadPool& pool) {
  const Real m2 = pool.reduce(
      P.size(), 4096, Real(0),
      [&](std::size_t b, std::size_t e) {
        Real m = 0;
        for (std::size_t i = b; i < e; ++i) m = std::max(m, P.a[i].squaredNorm());
        return m;
      },
      [](Real a, Real b) { return std::max(a, b); });
  return std::sqrt(m2);
}

}  // namespace sph2d
