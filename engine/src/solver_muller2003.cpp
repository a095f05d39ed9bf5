
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
  c.grid.build(P.x.data(), P.size(), c.poly6.R, c.pool, 2);
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

void stageNeighbours(StepContext& c) {
  Particles& P = c.P;
  const Grid& g = c.grid;
  NeighbourLists& L = c.nbr;
  const std::size_t n = P.size();
  L.perBlock.resize((n + kBlock - 1) / kBlock);
  L.start.resize(n);
  L.count.resize(n);
  const Real R2 = c.poly6.R2;
  c.pool.parallelFor(n, kBlock, [&](std::size_t b, std::size_t e) {
    std::vector<std::uint32_t>& out = L.perBlock[b / kBlock];
    std::size_t used = 0;
    for (std::size_t i = b; i < e; ++i) {
      const Vec2 xi = P.x[i];
      L.start[i] = std::uint32_t(used);
      g.forCandidateRanges(xi, [&](std::uint32_t kb, std::uint32_t ke) {
        if (out.size() < used + (ke - kb)) out.resize(std::max(out.size() * 2, used + (ke - kb)));
        std::uint32_t* dst = out.data();
        const std::uint32_t* sorted = g.sorted.data();
        const Vec2* X = P.x.data();
        for (std::uint32_t k = kb; k < ke; ++k) {
          const std::uint32_t j = sorted[k];
          const Real dx = xi.x() - X[j].x(), dy = xi.y() - X[j].y();
          const Real r2 = dx * dx + dy * dy;
          dst[used] = j;  // written always, kept only when inside: no branch
          used += std::size_t((r2 < R2) & (j != i));
        }
      });
      L.count[i] = std::uint32_t(used - L.start[i]);
    }
  });
}

std::size_t stageDensity(StepContext& c) {
  Particles& P = c.P;
  const NeighbourLists& L = c.nbr;
  const BoundarySet& B = c.boundary;
  const bool hasBoundary = !B.samples.empty();
  const Real self = c.poly6.valueR2(0);
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
        const Real dx = xi.x() - xj.x(), dy = xi.y() - xj.y();
        sum += c.poly6.valueR2(dx * dx + dy * dy);
      }
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
      P.invRho[i] = Real(1) / P.rho[i];
      P.pOverRho[i] = p * P.invRho[i];
    }
  });
}

std::size_t stageForces(StepContext& c) {
  Particles& P = c.P;
  const BoundarySet& B = c.boundary;
  const bool hasBoundary = !B.samples.empty();
  const Real R2 = c.poly6.R2;
  const Real tiny2 = Real(1e-12) * R2;
  // Constants of the spiky gradient and the viscosity Laplacian (kernels.hpp), hoisted.
  const Real R = c.spiky.R, R3 = R * R * R;
  const Real spikyK = Real(-3) * c.spiky.c;
  const Real halfMass = Real(0.5) * c.mass;
  const Real rMin = c.visc.rMin, invRMin = Real(1) / c.visc.rMin;
  const Real lapK = Real(5) / (Real(3) * kPi<Real> * R * R * R * R * R);
  const Vec2* X = P.x.data();
  const Vec2* V = P.v.data();
  const Real* IR = P.invRho.data();
  const Real* POR = P.pOverRho.data();
  const std::uint32_t* ID = P.id.data();
  return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
    std::size_t bad = kNone;
    for (std::size_t i = b; i < e; ++i) {
      const Vec2 xi = P.x[i], vi = P.v[i];
      const Real rhoi = P.rho[i], pi = P.p[i];
      const std::uint32_t idi = P.id[i];
      // Σ m (p_i + p_j)/(2 ρ_j) ∇W (force density, Müller eq. 10) and
      // Σ m (v_j − v_i)/ρ_j ∇²W (eq. 14 with the 2D Laplacian), accumulated in
      // scalars from raw arrays so the loop keeps everything in registers.
      Real fpx = 0, fpy = 0, fvx = 0, fvy = 0;
      const Real xix = xi.x(), xiy = xi.y(), vix = vi.x(), viy = vi.y();
      const std::uint32_t* nb = c.nbr.of(i);
      const std::uint32_t cnt = c.nbr.count[i];
      for (std::uint32_t k = 0; k < cnt; ++k) {
        const std::uint32_t j = nb[k];
        Real dx = xix - X[j].x(), dy = xiy - X[j].y();
        Real r2 = dx * dx + dy * dy;
        if (r2 < tiny2) {  // coincident pair: a fixed, antisymmetric direction
          const Vec2 t = tieBreakDirection(idi, ID[j]) * (Real(1e-6) * R);
          dx = t.x();
          dy = t.y();
          r2 = dx * dx + dy * dy;
        }
        // One square root and one division per pair.
        const Real invr = Real(1) / std::sqrt(r2);
        const Real r = r2 * invr;
        const Real a = R - r;
        const Real irj = IR[j];
        // Spiky gradient dW/dr · d/r, dW/dr = −3c(R − r)², times m (p_i + p_j)/(2 ρ_j).
        const Real wp = spikyK * a * a * invr * (halfMass * (pi * irj + POR[j]));
        fpx += dx * wp;
        fpy += dy * wp;
        // Viscosity-kernel Laplacian (2D), r clamped to rMin as in ViscosityKernel::laplacian.
        const Real q = r > rMin ? r : rMin;
        const Real iq = r > rMin ? invr : invRMin;
        const Real wv = lapK * (R - q) * (R3 + R2 * q + R * q * q + Real(9) * q * q * q) * iq * iq * iq * (c.mass * irj);
        fvx += (V[j].x() - vix) * wv;
        fvy += (V[j].y() - viy) * wv;
      }
      const Vec2 fp(fpx, fpy), fv(fvx, fvy);
      const Real invRhoi = P.invRho[i];
      Vec2 acc = (-fp + fv * c.mu) * invRhoi;
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
        acc -= gb * (Real(0.5) * invRhoi);
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
