// The stages every solver shares: grid, neighbour lists (fluid and boundary),
// integration, collision, the periodic wrap, and the deterministic reductions.
#include "step/stages.hpp"

#include "bodies/body_samples.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "core/simd.hpp"
#ifdef SPH2D_SIMD_SSE2
#define SPH2D_SSE2_NEIGHBOURS 1
#endif
#ifdef SPH2D_SIMD_X86_DISPATCH
#define SPH2D_AVX512_NEIGHBOURS 1
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
/// order), four candidates at a time unless not `vector` (setScalarPairLoops); writes up to 3
/// entries past the list's end.
#if defined(__GNUC__)
__attribute__((always_inline))  // called per row of cells with a few candidates: the call cost more than the row
#endif
inline std::size_t
nearInOrder(const Vec2* X, std::size_t n, std::uint32_t kb, std::uint32_t ke, std::size_t i, const Vec2& xi, Real R2,
            std::uint32_t* dst, std::size_t used, bool vector) {
  std::uint32_t k = kb;
#ifdef SPH2D_SSE2_NEIGHBOURS
  const std::uint32_t kv = vector ? ke : kb;  // without `vector`, the scalar loop takes every candidate
  static_assert(sizeof(Vec2) == 2 * sizeof(float), "positions are pairs of floats");
  const float* xy = reinterpret_cast<const float*>(X);
  const __m128 xi4 = _mm_set1_ps(xi.x()), yi4 = _mm_set1_ps(xi.y()), r24 = _mm_set1_ps(R2);
  for (; k < kv && std::size_t(k) + 4 <= n; k += 4) {  // lanes past ke read real particles, masked off
    const __m128 a = _mm_loadu_ps(xy + 2 * std::size_t(k)), b = _mm_loadu_ps(xy + 2 * std::size_t(k) + 4);
    const __m128 dx = _mm_sub_ps(xi4, _mm_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0)));
    const __m128 dy = _mm_sub_ps(yi4, _mm_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1)));
    const __m128 r2 = _mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy));
    unsigned mask = unsigned(_mm_movemask_ps(_mm_cmplt_ps(r2, r24)));
    mask &= (1u << std::min<std::uint32_t>(ke - k, 4)) - 1;  // no branches on the row's length
    const std::size_t self = i - k;                          // wraps around when i < k
    mask &= ~(unsigned(self < 4) << (self & 3));
    const __m128i lanes = _mm_load_si128(reinterpret_cast<const __m128i*>(kCompactLanes[mask]));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(dst + used), _mm_add_epi32(_mm_set1_epi32(int(k)), lanes));
    used += kBitCount[mask];
  }
#else
  (void)n;
  (void)vector;
#endif
  for (; k < ke; ++k) {
    const Real dx = xi.x() - X[k].x(), dy = xi.y() - X[k].y();
    const Real r2 = dx * dx + dy * dy;
    dst[used] = k;
    used += std::size_t((r2 < R2) & (k != i));
  }
  return used;
}

std::atomic<bool> gBaselineSimd{false};
std::atomic<bool> gScalarPairs{false};

#ifdef SPH2D_AVX512_NEIGHBOURS
/// True when this CPU runs the AVX-512 candidate filter (checked once).
bool haveAvx512() {
  static const bool yes = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("popcnt");
  return yes;
}

/// The cell of a position without a periodic axis, as Grid::forCandidateRanges finds it.
inline void cellOfPoint(const Grid& g, const Vec2& x, int& cx, int& cy) {
  cx = Grid::coord(x.x(), g.lo.x(), g.invCell, g.nx);
  cy = Grid::coord(x.y(), g.lo.y(), g.invCellY, g.ny);
}

/// Entries of nearInOrder16's staging buffer: a query's candidates, plus one vector's overrun.
constexpr std::size_t kStageEntries = 512;
/// Slots are searched together (up to kGroupSlots of them) when each lies in the first's row of
/// cells at most this many cells right of it: their rows then share all but this many columns.
constexpr int kPairShift = 3;
/// The most slots searched together.
constexpr int kGroupSlots = 4;

/// The fluid neighbours of slots i .. i + N − 1 among the grid's candidates that are slots
/// themselves (no periodic axis), appended to out from `usedOut`, slot after slot:
/// nearInOrder sixteen candidates at a time (AVX-512F, chosen at run time). The same r² per
/// lane as the scalar and SSE2 loops (one IEEE operation a lane, in the same order), so the
/// same lists. Masked loads: nothing is read past the positions; whole vectors are stored past
/// the kept entries into room reserved for them. Slot i lies in cell (cx, cy); slot i + s lies
/// in the same row of cells, shift[s] cells right of it (0: the same cell; shift[0] = 0,
/// nondecreasing), so their candidate rows overlap: each row's candidates are loaded once over
/// all the slots' columns, and each slot keeps only candidates of its own columns (so its list
/// is the one search's exactly). Slot i's kept slots go straight to out; the others' to
/// buffers on the stack, copied after it at the end. ends[s] is the end of slot i + s's list,
/// and `usedOut` becomes the last one. False, with nothing written, when N > 1 and the rows
/// hold more candidates than a buffer (a pile-up: the caller then searches slot by slot).
template <int N>
__attribute__((target("avx512f,popcnt"))) bool nearInOrder16(const Grid& g, const Vec2* X, std::size_t i, int cx,
                                                             int cy, const int* shift, Real R2,
                                                             std::vector<std::uint32_t>& out, std::size_t& usedOut,
                                                             std::size_t* ends) {
  std::size_t used = usedOut;  // a local: through the reference it would go through memory every chunk
  const float* xy = reinterpret_cast<const float*>(X);
  const __m512 r216 = _mm512_set1_ps(R2);
  __m512 px[N], py[N];
  int c0[N], c1[N];  // each slot's columns of cells
  for (int q = 0; q < N; ++q) {
    px[q] = _mm512_set1_ps(X[i + q].x());
    py[q] = _mm512_set1_ps(X[i + q].y());
    c0[q] = std::max(cx + shift[q] - g.reach, 0);
    c1[q] = std::min(cx + shift[q] + g.reach, g.nx - 1);
  }
  const __m512i evens = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
  const __m512i odds = _mm512_setr_epi32(1, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27, 29, 31);
  const __m512i iota = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  // Grid::forCandidateRanges without a periodic axis, written out (a lambda would not
  // carry this function's target).
  const int y0 = std::max(cy - g.reach, 0), y1 = std::min(cy + g.reach, g.ny - 1);
  if (N > 1) {
    std::size_t total = 0;
    for (int y = y0; y <= y1; ++y)
      total += g.cellStart[std::size_t(y) * g.nx + c1[N - 1] + 1] - g.cellStart[std::size_t(y) * g.nx + c0[0]];
    if (total + 16 > kStageEntries) return false;
  }
  // The first n lanes (n clamped to 0..16).
  const auto below = [](std::int64_t n) { return n <= 0 ? 0u : n >= 16 ? 0xFFFFu : (1u << n) - 1; };
  alignas(64) std::uint32_t buf[N > 1 ? N - 1 : 1][N > 1 ? kStageEntries : 1];
  std::size_t got[N > 1 ? N - 1 : 1] = {};
  for (int y = y0; y <= y1; ++y) {
    const std::size_t row = std::size_t(y) * g.nx;
    std::uint32_t lo[N], hi[N];  // each slot's candidates in this row
    for (int q = 0; q < N; ++q) {
      lo[q] = g.cellStart[row + c0[q]];
      hi[q] = g.cellStart[row + c1[q] + 1];
    }
    const std::uint32_t kb = lo[0], ke = hi[N - 1];
    if (!(kb < ke)) continue;
    const std::size_t need = used + (hi[0] - kb) + 16;  // room for a whole vector stored past the last kept entry
    if (out.size() < need) {
      if (out.capacity() < need) out.reserve(need + need / 16);
      out.resize(need);
    }
    std::uint32_t* dst = out.data();
    for (std::uint32_t k = kb; k < ke; k += 16) {
      // Masks without branches (the row lengths vary: a branch on them mispredicts).
      const std::uint32_t m = std::min<std::uint32_t>(16, ke - k);
      const __mmask16 lanes = __mmask16((1u << m) - 1);
      const std::uint64_t floats = (std::uint64_t(1) << (2 * m)) - 1;  // the 2m floats of the m candidates
      const __mmask16 flo = __mmask16(floats & 0xFFFF), fhi = __mmask16(floats >> 16);
      const __m512 a = _mm512_maskz_loadu_ps(flo, xy + 2 * std::size_t(k));
      const __m512 b = _mm512_maskz_loadu_ps(fhi, xy + 2 * std::size_t(k) + 16);
      const __m512 xs = _mm512_permutex2var_ps(a, evens, b), ys = _mm512_permutex2var_ps(a, odds, b);
      const __m512i ks = _mm512_add_epi32(_mm512_set1_epi32(int(k)), iota);
      for (int q = 0; q < N; ++q) {
        // Slot i + q's kept lanes: its own columns, within R, not itself.
        const __mmask16 mine = __mmask16(lanes & below(std::int64_t(hi[q]) - k) & ~below(std::int64_t(lo[q]) - k));
        const __m512 dx = _mm512_sub_ps(px[q], xs), dy = _mm512_sub_ps(py[q], ys);
        const __m512 r2 = _mm512_add_ps(_mm512_mul_ps(dx, dx), _mm512_mul_ps(dy, dy));
        const std::size_t self = i + q - k;  // wraps around when i + q < k
        const unsigned keep =
            unsigned(_mm512_mask_cmp_ps_mask(mine, r2, r216, _CMP_LT_OQ)) & ~(unsigned(self < 16) << (self & 15));
        const __m512i kept = _mm512_maskz_compress_epi32(__mmask16(keep), ks);
        if (q == 0) {
          _mm512_storeu_si512(dst + used, kept);
          used += unsigned(__builtin_popcount(keep));
        } else {
          _mm512_storeu_si512(buf[q - 1] + got[q - 1], kept);
          got[q - 1] += unsigned(__builtin_popcount(keep));
        }
      }
    }
  }
  ends[0] = used;
  for (int q = 1; q < N; ++q) {
    const std::size_t n = got[q - 1];
    const std::size_t need = used + n + 16;
    if (out.size() < need) {
      if (out.capacity() < need) out.reserve(need + need / 16);
      out.resize(need);
    }
    std::uint32_t* dst = out.data() + used;
    for (std::size_t k = 0; k < n; k += 16)  // whole vectors: the lanes past the list are room
      _mm512_storeu_si512(dst + k, _mm512_load_si512(buf[q - 1] + k));
    used += n;
    ends[q] = used;
  }
  usedOut = used;
  return true;
}
#endif

/// Particles per block of the reordering's gathers: kStreamBlock's 4096 cut 20k particles
/// into 5 blocks (3 on one thread, 2 on the other). Gathers: any block size, the same bits.
constexpr std::size_t kPermuteBlock = 1024;

template <class T>
void permuteField(std::vector<T>& field, const std::vector<std::uint32_t>& order, std::vector<T>& scratch,
                  ThreadPool& pool) {
  scratch.resize(field.size());
  pool.parallelFor(field.size(), kPermuteBlock, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) scratch[k] = field[order[k]];
  });
  field.swap(scratch);
}

std::vector<Vec2>& scratchFor(Scratch& s, const std::vector<Vec2>&) { return s.v; }
std::vector<Real>& scratchFor(Scratch& s, const std::vector<Real>&) { return s.r; }
std::vector<std::uint32_t>& scratchFor(Scratch& s, const std::vector<std::uint32_t>&) { return s.u; }
std::vector<double>& scratchFor(Scratch& s, const std::vector<double>&) { return s.d; }

}  // namespace

void setBaselineSimdOnly(bool on) { gBaselineSimd.store(on); }
bool baselineSimdOnly() { return gBaselineSimd.load(std::memory_order_relaxed); }
void setScalarPairLoops(bool on) { gScalarPairs.store(on); }
bool scalarPairLoops() { return gScalarPairs.load(std::memory_order_relaxed); }

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

void permuteParticles(ParticleStore& P, const std::vector<std::uint32_t>& order, Scratch& s, ThreadPool& pool,
                      unsigned rewritten) {
  const void* skip[] = {rewritten & kRewritesA ? &P.a : nullptr, rewritten & kRewritesXPrev ? &P.xPrev : nullptr,
                        rewritten & kRewritesRho ? &P.rho : nullptr, rewritten & kRewritesInvRho ? &P.invRho : nullptr,
                        rewritten & kRewritesPOverRho ? &P.pOverRho : nullptr};
  P.forEachField([&](const char*, auto& field) {
    if (std::find(std::begin(skip), std::end(skip), static_cast<const void*>(&field)) == std::end(skip))
      permuteField(field, order, scratchFor(s, field), pool);
  });
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

void stageGrid(StepContext& c, bool reorder, unsigned rewritten) {
  ParticleStore& P = c.P;
  if (c.periodic.any()) stageWrap(c);
  c.grid.build(P.x.data(), P.size(), c.R, c.pool, 2, c.periodic.any() ? &c.periodic : nullptr);
  if (!reorder) return;
  const std::vector<std::uint32_t>& order = c.grid.sorted;
  permuteParticles(P, order, c.scratch, c.pool, rewritten);
  // After the permutation slot k is the k-th particle in cell order.
  // grid.cellOf is not permuted: only the next build reads it, and it writes it first.
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
  const BodySamples* moving = c.bodySamples && c.bodySamples->active() ? c.bodySamples : nullptr;
  if (moving) {
    L.movingPerBlock.resize(blocks);
    L.movingStart.resize(n);
    L.movingCount.resize(n);
  }
  // Candidates that are slots (just reordered) and no wrap: four at a time.
  const bool inOrder = g.inOrder && !per.any() && g.sorted.size() == n;
#ifdef SPH2D_AVX512_NEIGHBOURS
  const bool wide = !baselineSimdOnly() && !scalarPairLoops() && haveAvx512();
#endif
  const bool vector = !scalarPairLoops();
  c.pool.parallelFor(n, kBlock, [&](std::size_t b, std::size_t e) {
    std::vector<std::uint32_t>& out = L.perBlock[b / kBlock];
    std::vector<std::uint32_t>& bout = L.boundaryPerBlock[b / kBlock];
    bout.clear();
    std::size_t used = 0;
    std::size_t listed = b;  // slots below this have their fluid lists (those searched with an earlier slot)
    for (std::size_t i = b; i < e; ++i) {
      const Vec2 xi = P.x[i];
      if (i >= listed) {
        L.start[i] = std::uint32_t(used);
        listed = i + 1;
#ifdef SPH2D_AVX512_NEIGHBOURS
        if (inOrder && wide) {
          // Slots i + 1 .. in the same row of cells, at most kPairShift cells right of i's: searched with it.
          int cx, cy;
          cellOfPoint(g, xi, cx, cy);
          int shift[kGroupSlots] = {0, 0, 0, 0};
          int slots = 1;
          for (; slots < kGroupSlots && i + std::size_t(slots) < e; ++slots) {
            int nx, ny;
            cellOfPoint(g, P.x[i + std::size_t(slots)], nx, ny);
            if (ny != cy || nx < cx || nx - cx > kPairShift) break;
            shift[slots] = nx - cx;
          }
          std::size_t ends[kGroupSlots];
          const Vec2* X = P.x.data();
          bool done = false;
          switch (slots) {
            case 4:
              done = nearInOrder16<4>(g, X, i, cx, cy, shift, R2, out, used, ends);
              break;
            case 3:
              done = nearInOrder16<3>(g, X, i, cx, cy, shift, R2, out, used, ends);
              break;
            case 2:
              done = nearInOrder16<2>(g, X, i, cx, cy, shift, R2, out, used, ends);
              break;
            default:
              break;
          }
          if (!done) {
            slots = 1;  // alone, or a pile-up: one slot (always true)
            nearInOrder16<1>(g, X, i, cx, cy, shift, R2, out, used, ends);
          }
          for (int q = 0; q < slots; ++q) {
            L.start[i + std::size_t(q)] = q == 0 ? L.start[i] : std::uint32_t(ends[q - 1]);
            L.count[i + std::size_t(q)] = std::uint32_t(ends[q] - L.start[i + std::size_t(q)]);
          }
          listed = i + std::size_t(slots);
        } else
#endif
        {
          g.forCandidateRanges(xi, [&](std::uint32_t kb, std::uint32_t ke) {
            // Room for every candidate (written before the test; and 3 more, nearInOrder's
            // last group); grown by a sixteenth, not doubled: the lists are most of the
            // engine's memory, and a block's need settles.
            const std::size_t need = used + (ke - kb) + 3;
            if (out.size() < need) {
              if (out.capacity() < need) out.reserve(need + need / 16);
              out.resize(need);
            }
            std::uint32_t* dst = out.data();
            const std::uint32_t* sorted = g.sorted.data();
            const Vec2* X = P.x.data();
            if (inOrder) {
              used = nearInOrder(X, n, kb, ke, i, xi, R2, dst, used, vector);
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
        }
      }
      L.boundaryStart[i] = std::uint32_t(bout.size());
      if (walls && !B.noSamplesNear(xi))  // most particles are far from every wall
        B.sampleGrid.forCandidates(xi, [&](std::uint32_t s) {
          if ((xi - B.samples[s]).squaredNorm() < R2 && B.visible(s, xi)) bout.push_back(s);
        });
      L.boundaryCount[i] = std::uint32_t(bout.size() - L.boundaryStart[i]);
      if (moving) {
        // The moving bodies' samples within R: body by body, each searched in its own
        // frame's grid, the distance tested in the local frame.
        std::vector<std::uint32_t>& mout = L.movingPerBlock[b / kBlock];
        if (i == b) mout.clear();
        L.movingStart[i] = std::uint32_t(mout.size());
        for (const BodySamples::Placed& q : moving->placed) {
          const Real ex = xi.x() - q.com.x(), ey = xi.y() - q.com.y();
          if (!(ex * ex + ey * ey < q.reach2)) continue;
          const double px = double(xi.x()) - q.origin.x(), py = double(xi.y()) - q.origin.y();
          const Vec2 pb(Real(q.c * px + q.s * py), Real(-q.s * px + q.c * py));
          const Vec2* xs = moving->x.data() + q.first;
          q.sampled->grid.forCandidates(pb, [&](std::uint32_t s) {
            if ((xi - xs[s]).squaredNorm() < R2) mout.push_back(q.first + s);
          });
        }
        L.movingCount[i] = std::uint32_t(mout.size() - L.movingStart[i]);
      }
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
  const std::vector<Real>* ratioField = P.find(ParticleStore::kRestRatio);  // m_i = r_i m with a density contrast
  const Real* ratio = ratioField ? ratioField->data() : nullptr;
  const Vec2d dv = c.pool.reduce(
      P.size(), kBlock, Vec2d(0, 0),
      [&](std::size_t b, std::size_t e) {
        Vec2d s(0, 0);
        for (std::size_t i = b; i < e; ++i) {
          // Most particles are far from every solid: resolve would find no candidate there.
          if (c.boundary.clearOf(P.x[i], P.xPrev[i], c.clearance)) continue;
          const Vec2 v0 = P.v[i];
          if (c.boundary.resolve(P.x[i], P.v[i], P.xPrev[i], c.clearance)) {
            const Vec2d d = P.v[i].cast<double>() - v0.cast<double>();
            s += ratio ? Vec2d(d * double(ratio[i])) : d;
          }
        }
        return s;
      },
      [](const Vec2d& a, const Vec2d& b) { return Vec2d(a + b); });
  if (c.wall) c.wall->sum.collision += dv * double(c.momentumMass);
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
