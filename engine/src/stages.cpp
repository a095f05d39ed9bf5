// The stages every solver shares: grid, neighbour lists (fluid and boundary),
// integration, collision, the periodic wrap, and the deterministic reductions.
#include "stages.hpp"

#include <algorithm>
#include <cmath>

namespace sph2d {

namespace {

template <class T>
void permuteField(std::vector<T>& field, const std::vector<std::uint32_t>& order, std::vector<T>& scratch,
                  ThreadPool& pool) {
  scratch.resize(field.size());
  pool.parallelFor(field.size(), kStreamBlock, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) scratch[k] = field[order[k]];
  });
  field.swap(scratch);
}

std::vector<Vec2>& scratchFor(Scratch& s, const std::vector<Vec2>&) { return s.v; }
std::vector<Real>& scratchFor(Scratch& s, const std::vector<Real>&) { return s.r; }
std::vector<std::uint32_t>& scratchFor(Scratch& s, const std::vector<std::uint32_t>&) { return s.u; }

}  // namespace

std::size_t firstBad(ThreadPool& pool, std::size_t n, const std::function<std::size_t(std::size_t, std::size_t)>& fn) {
  return pool.reduce(n, kBlock, kNone, fn, [](std::size_t a, std::size_t b) { return std::min(a, b); });
}

Vec2 tieBreakDirection(std::uint32_t idi, std::uint32_t idj) {
  const std::uint32_t lo = std::min(idi, idj), hi = std::max(idi, idj);
  std::uint64_t h = (std::uint64_t(lo) << 32) | hi;
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdULL;
  h ^= h >> 33;
  const Real angle = Real(double(h % 3600) * (2 * 3.14159265358979323846 / 3600.0));
  const Vec2 d(std::cos(angle), std::sin(angle));
  return idi < idj ? d : Vec2(-d);
}

bool reorderThisStep(const StepContext& c) {
  const int every = c.def.reorderInterval;
  return every > 0 && c.step % std::uint64_t(every) == 0;
}

void permuteParticles(ParticleStore& P, const std::vector<std::uint32_t>& order, Scratch& s, ThreadPool& pool) {
  P.forEachField([&](const char*, auto& field) { permuteField(field, order, scratchFor(s, field), pool); });
}

void stageWrap(StepContext& c) {
  if (!c.periodic.any()) return;
  ParticleStore& P = c.P;
  const PeriodicBox& box = c.periodic;
  c.pool.parallelFor(P.size(), kStreamBlock, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const Vec2 s = box.wrap(P.x[i]);
      P.xPrev[i] += s;
    }
  });
}

void stageGrid(StepContext& c, bool reorder) {
  ParticleStore& P = c.P;
  if (c.periodic.any()) stageWrap(c);
  c.grid.build(P.x.data(), P.size(), c.R, c.pool, 2, c.periodic.any() ? &c.periodic : nullptr);
  if (!reorder) return;
  const std::vector<std::uint32_t>& order = c.grid.sorted;
  permuteParticles(P, order, c.scratch, c.pool);
  // After the permutation slot k is the k-th particle in cell order.
  permuteField(c.grid.cellOf, order, c.scratch.u, c.pool);
  for (std::size_t k = 0; k < c.grid.sorted.size(); ++k) c.grid.sorted[k] = std::uint32_t(k);
}

void stageNeighbours(StepContext& c) {
  ParticleStore& P = c.P;
  const Grid& g = c.grid;
  const BoundarySet& B = c.boundary;
  NeighbourLists& L = c.nbr;
  const std::size_t n = P.size();
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  L.perBlock.resize(blocks);
  L.start.resize(n);
  L.count.resize(n);
  L.boundaryPerBlock.resize(blocks);
  L.boundaryStart.resize(n);
  L.boundaryCount.resize(n);
  const Real R2 = c.R * c.R;
  const PeriodicBox per = c.periodic;
  const bool walls = !B.samples.empty();
  c.pool.parallelFor(n, kBlock, [&](std::size_t b, std::size_t e) {
    std::vector<std::uint32_t>& out = L.perBlock[b / kBlock];
    std::vector<std::uint32_t>& bout = L.boundaryPerBlock[b / kBlock];
    bout.clear();
    std::size_t used = 0;
    for (std::size_t i = b; i < e; ++i) {
      const Vec2 xi = P.x[i];
      L.start[i] = std::uint32_t(used);
      g.forCandidateRanges(xi, [&](std::uint32_t kb, std::uint32_t ke) {
        // Room for every candidate (written before the test); grown by an eighth, not
        // doubled: the lists are most of the engine's memory, and a block's need settles.
        const std::size_t need = used + (ke - kb);
        if (out.size() < need) {
          if (out.capacity() < need) out.reserve(need + need / 8);
          out.resize(need);
        }
        std::uint32_t* dst = out.data();
        const std::uint32_t* sorted = g.sorted.data();
        const Vec2* X = P.x.data();
        for (std::uint32_t k = kb; k < ke; ++k) {
          const std::uint32_t j = sorted[k];
          Real dx = xi.x() - X[j].x(), dy = xi.y() - X[j].y();
          per.nearest(dx, dy);
          const Real r2 = dx * dx + dy * dy;
          dst[used] = j;  // written always, kept only when inside: no branch
          used += std::size_t((r2 < R2) & (j != i));
        }
      });
      L.count[i] = std::uint32_t(used - L.start[i]);
      L.boundaryStart[i] = std::uint32_t(bout.size());
      if (walls)
        B.sampleGrid.forCandidates(xi, [&](std::uint32_t s) {
          if ((xi - B.samples[s]).squaredNorm() < R2 && B.visible(s, xi)) bout.push_back(s);
        });
      L.boundaryCount[i] = std::uint32_t(bout.size() - L.boundaryStart[i]);
    }
  });
}

std::size_t stageIntegrate(StepContext& c) {
  ParticleStore& P = c.P;
  const Real dt = c.dt;
  const Real vmax2 = c.maxSpeed * c.maxSpeed;
  // The displacement clamp: no particle moves more than kMaxMove·R in one
  // substep (the CFL bound the next step's time step then honours). It
  // only acts when a force jumps within a substep (stacked particles, a new
  // overlap), before the force limit of the next step can see it.
  const Real vClamp = dt > 0 ? kMaxMove * c.R / dt : std::numeric_limits<Real>::infinity();
  const Real vClamp2 = vClamp * vClamp;
  return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
    std::size_t bad = kNone;
    for (std::size_t i = b; i < e; ++i) {
      Vec2 v = P.v[i] + P.a[i] * dt;
      const Real s2 = v.squaredNorm();
      if (s2 > vClamp2 && s2 <= vmax2) v *= vClamp / std::sqrt(s2);
      P.xPrev[i] = P.x[i];
      P.v[i] = v;
      P.x[i] = P.x[i] + v * dt;
      if (bad == kNone && (!allFinite(P.x[i]) || !allFinite(v) || v.squaredNorm() > vmax2)) bad = i;
    }
    return bad;
  });
}

std::size_t stageDrift(StepContext& c) {
  ParticleStore& P = c.P;
  const Real dt = c.dt, vmax2 = c.maxSpeed * c.maxSpeed;
  return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
    std::size_t bad = kNone;
    for (std::size_t i = b; i < e; ++i) {
      P.a[i] = c.gravity;
      P.xPrev[i] = P.x[i];
      P.v[i] += c.gravity * dt;
      P.x[i] += P.v[i] * dt;
      if (bad == kNone && (!allFinite(P.x[i]) || P.v[i].squaredNorm() > vmax2)) bad = i;
    }
    return bad;
  });
}

void stageCollide(StepContext& c) {
  ParticleStore& P = c.P;
  if (c.boundary.colliders.empty()) return;
  c.pool.parallelFor(P.size(), kBlock, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) c.boundary.resolve(P.x[i], P.v[i], P.xPrev[i], c.clearance);
  });
}

Real maxSpeedOf(const ParticleStore& P, ThreadPool& pool) {
  const Real m2 = pool.reduce(
      P.size(), kStreamBlock, Real(0),
      [&](std::size_t b, std::size_t e) {
        Real m = 0;
        for (std::size_t i = b; i < e; ++i) m = std::max(m, P.v[i].squaredNorm());
        return m;
      },
      [](Real a, Real b) { return std::max(a, b); });
  return std::sqrt(m2);
}

Real maxAccelOf(const ParticleStore& P, ThreadPool& pool) {
  const Real m2 = pool.reduce(
      P.size(), kStreamBlock, Real(0),
      [&](std::size_t b, std::size_t e) {
        Real m = 0;
        for (std::size_t i = b; i < e; ++i) m = std::max(m, P.a[i].squaredNorm());
        return m;
      },
      [](Real a, Real b) { return std::max(a, b); });
  return std::sqrt(m2);
}

}  // namespace sph2d
