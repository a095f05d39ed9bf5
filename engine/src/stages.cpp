// The stages every solver shares: grid, neighbour lists (fluid and boundary),
// integration, collision, the periodic wrap, and the deterministic reductions.
#include "stages.hpp"

#include <algorithm>
#include <cmath>

#if defined(__SSE2__) && !defined(SPH2D_NO_SIMD)
#include <emmintrin.h>
#define SPH2D_SSE2_NEIGHBOURS 1
#endif

namespace sph2d {

namespace {

#ifdef SPH2D_SSE2_NEIGHBOURS
/// The lanes of the set bits of a 4-bit mask, in lane order (then 0): four candidates
/// compacted at once, without branches.
alignas(16) constexpr std::uint32_t kCompactLanes[16][4] = {
    {0, 0, 0, 0}, {0, 0, 0, 0}, {1, 0, 0, 0}, {0, 1, 0, 0}, {2, 0, 0, 0}, {0, 2, 0, 0}, {1, 2, 0, 0}, {0, 1, 2, 0},
    {3, 0, 0, 0}, {0, 3, 0, 0}, {1, 3, 0, 0}, {0, 1, 3, 0}, {2, 3, 0, 0}, {0, 2, 3, 0}, {1, 2, 3, 0}, {0, 1, 2, 3}};
constexpr std::uint8_t kBitCount[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};
#endif

/// Appends to dst[used..] the slots k of [kb, ke), k ≠ i, with |xi − X[k]|² < R2, in
/// order: candidates that are slots themselves (the grid's particles in order), no
/// periodic axis. The same r² as the scalar loop (one IEEE operation a lane, in the same
/// order), four candidates at a time; writes up to 3 entries past the list's end.
#if defined(__GNUC__)
__attribute__((always_inline))  // called per row of cells with a few candidates: the call cost more than the row
#endif
inline std::size_t nearInOrder(const Vec2* X, std::size_t n, std::uint32_t kb, std::uint32_t ke, std::size_t i, const Vec2& xi,
                               Real R2, std::uint32_t* dst, std::size_t used) {
  std::uint32_t k = kb;
#ifdef SPH2D_SSE2_NEIGHBOURS
  static_assert(sizeof(Vec2) == 2 * sizeof(float), "positions are pairs of floats");
  const float* xy = reinterpret_cast<const float*>(X);
  const __m128 xi4 = _mm_set1_ps(xi.x()), yi4 = _mm_set1_ps(xi.y()), r24 = _mm_set1_ps(R2);
  for (; k < ke && std::size_t(k) + 4 <= n; k += 4) {  // lanes past ke read real particles, masked off
    const __m128 a = _mm_loadu_ps(xy + 2 * std::size_t(k)), b = _mm_loadu_ps(xy + 2 * std::size_t(k) + 4);
    const __m128 dx = _mm_sub_ps(xi4, _mm_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0)));
    const __m128 dy = _mm_sub_ps(yi4, _mm_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1)));
    const __m128 r2 = _mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy));
    unsigned mask = unsigned(_mm_movemask_ps(_mm_cmplt_ps(r2, r24)));
    if (ke - k < 4) mask &= (1u << (ke - k)) - 1;
    if (i >= k && i - k < 4) mask &= ~(1u << (i - k));
    const __m128i lanes = _mm_load_si128(reinterpret_cast<const __m128i*>(kCompactLanes[mask]));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(dst + used), _mm_add_epi32(_mm_set1_epi32(int(k)), lanes));
    used += kBitCount[mask];
  }
#else
  (void)n;
#endif
  for (; k < ke; ++k) {
    const Real dx = xi.x() - X[k].x(), dy = xi.y() - X[k].y();
    const Real r2 = dx * dx + dy * dy;
    dst[used] = k;
    used += std::size_t((r2 < R2) & (k != i));
  }
  return used;
}

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
  c.grid.inOrder = true;
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
  // Candidates that are slots (just reordered) and no wrap: four at a time.
  const bool inOrder = g.inOrder && !per.any() && g.sorted.size() == n;
  c.pool.parallelFor(n, kBlock, [&](std::size_t b, std::size_t e) {
    std::vector<std::uint32_t>& out = L.perBlock[b / kBlock];
    std::vector<std::uint32_t>& bout = L.boundaryPerBlock[b / kBlock];
    bout.clear();
    std::size_t used = 0;
    for (std::size_t i = b; i < e; ++i) {
      const Vec2 xi = P.x[i];
      L.start[i] = std::uint32_t(used);
      g.forCandidateRanges(xi, [&](std::uint32_t kb, std::uint32_t ke) {
        // Room for every candidate (written before the test; and 3 more, nearInOrder's
        // last group); grown by an eighth, not doubled: the lists are most of the
        // engine's memory, and a block's need settles.
        const std::size_t need = used + (ke - kb) + 3;
        if (out.size() < need) {
          if (out.capacity() < need) out.reserve(need + need / 8);
          out.resize(need);
        }
        std::uint32_t* dst = out.data();
        const std::uint32_t* sorted = g.sorted.data();
        const Vec2* X = P.x.data();
        if (inOrder) {
          used = nearInOrder(X, n, kb, ke, i, xi, R2, dst, used);
          return;
        }
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
  // The velocity response is the static solids' impulse on the fluid: m·Δv of each contact,
  // summed per block and the blocks in order (WallImpulse::collision). Δv of two floats in double is exact.
  const Vec2d dv = c.pool.reduce(
      P.size(), kBlock, Vec2d(0, 0),
      [&](std::size_t b, std::size_t e) {
        Vec2d s(0, 0);
        for (std::size_t i = b; i < e; ++i) {
          const Vec2 v0 = P.v[i];
          if (c.boundary.resolve(P.x[i], P.v[i], P.xPrev[i], c.clearance))
            s += P.v[i].cast<double>() - v0.cast<double>();
        }
        return s;
      },
      [](const Vec2d& a, const Vec2d& b) { return Vec2d(a + b); });
  if (c.wall) c.wall->sum.collision += dv * double(c.mass);
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
