// stages.hpp (internal) — the stages every solver shares: the neighbour grid,
// the neighbour lists (fluid and boundary in one search), integration, the
// swept collision, the periodic wrap, and the deterministic reductions the
// time-step limits read. Each is a free function over a StepContext; what
// each reads and writes is in docs/ARCHITECTURE.md.
#pragma once

#include <algorithm>
#include <limits>
#include <vector>

#include "step/step_context.hpp"

namespace sph2d {

/// With `on`, the pair loops use only the baseline SIMD (SSE2) even where the CPU has
/// wider vectors (chosen at run time: the neighbour filters' AVX-512, muller2003's AVX2 pair
/// loop). Every path gives the same bits; tests
/// switch this to compare them on one machine. Process-wide; off by default.
void setBaselineSimdOnly(bool on);
/// Whether setBaselineSimdOnly(true) is in force.
bool baselineSimdOnly();
/// With `on`, the pair loops with a scalar reference (the neighbour filter, muller2003's
/// density and pressure force) run it instead of SIMD, as in a periodic scene. The same
/// bits again; tests switch this to compare. Process-wide; off by default.
void setScalarPairLoops(bool on);
/// Whether setScalarPairLoops(true) is in force.
bool scalarPairLoops();

/// True when this substep reorders particle storage along the grid (every solver.reorder_interval substeps).
bool reorderThisStep(const StepContext& c);
/// Particle fields a solver's substep writes for every particle, after the grid and before
/// any stage reads them: stageGrid's reordering need not carry their old values.
enum RewrittenFields : unsigned {
  kRewritesA = 1u << 0,         ///< a: the pressure force sets it (effects add to it after)
  kRewritesXPrev = 1u << 1,     ///< xPrev: integrate sets it to x before moving x
  kRewritesRho = 1u << 2,       ///< rho: the density stage sums it
  kRewritesInvRho = 1u << 3,    ///< invRho: the pressure stage
  kRewritesPOverRho = 1u << 4,  ///< pOverRho: the pressure stage
};
/// Neighbour grid (counting sort, cells of R/2) and, when `reorder`, every particle array permuted
/// into cell order but the fields in `rewritten` (RewrittenFields), which keep stale values at
/// their slots until the substep writes them. In a periodic scene it first wraps every position
/// into the box (stageWrap).
void stageGrid(StepContext& c, bool reorder, unsigned rewritten = 0);
/// Moves particles that left the periodic box to their image inside it (x and
/// xPrev shift together, so the swept collision sees the true move). Reads and writes x, xPrev.
void stageWrap(StepContext& c);
/// Neighbour lists: the grid's candidates within R (compacted without
/// branches) and the visible boundary samples within R, in the sample grid's
/// order. Reads x, grid, boundary samples; writes nbr.
void stageNeighbours(StepContext& c);
/// Symplectic Euler: v += dt a; x += dt v, the displacement capped at kMaxMove·R.
/// Reads a; writes v, x, xPrev. Returns the first bad slot.
std::size_t stageIntegrate(StepContext& c);
/// A sliver of a step: a = g; v += dt g; x += dt v (xPrev for the collision). Returns the first bad slot.
std::size_t stageDrift(StepContext& c);
/// Swept collision against the Box2D colliders. Reads xPrev; writes x, v.
void stageCollide(StepContext& c);
/// Largest speed (deterministic reduction).
Real maxSpeedOf(const ParticleStore& P, ThreadPool& pool);
/// Largest acceleration magnitude (deterministic reduction).
Real maxAccelOf(const ParticleStore& P, ThreadPool& pool);
/// The gravity that builds a hydrostatic pressure: its components along
/// periodic axes are dropped (a body force along a periodic channel drives
/// a flow; the pressure does not grow along it).
inline Vec2 hydrostaticGravity(const StepContext& c) {
  Vec2 g = c.gravity;
  if (c.periodic.x) g.x() = 0;
  if (c.periodic.y) g.y() = 0;
  return g;
}

/// Calls f(i, depth) for every particle with its depth below the highest
/// particle of the same column (strips of width R across the hydrostatic
/// gravity): the depth of a hydrostatic pressure guess. Serial, O(n); `top`
/// is scratch kept by the caller. Needs hydrostaticGravity(c) ≠ 0.
template <class F>
void columnDepths(const StepContext& c, std::vector<Real>& top, F f) {
  const ParticleStore& P = c.P;
  const Vec2 gh = hydrostaticGravity(c);
  const Vec2 up = -gh / gh.norm(), across(up.y(), -up.x());
  Real sMin = std::numeric_limits<Real>::infinity(), sMax = -sMin;
  for (std::size_t i = 0; i < P.size(); ++i) {
    const Real s = across.dot(P.x[i]);
    sMin = std::min(sMin, s);
    sMax = std::max(sMax, s);
  }
  const std::size_t strips = std::min<std::size_t>(std::size_t((sMax - sMin) / c.R) + 1, 1u << 20);
  top.assign(strips, -std::numeric_limits<Real>::infinity());
  auto strip = [&](const Vec2& x) {
    return std::min(strips - 1, std::size_t(std::max(Real(0), (across.dot(x) - sMin) / c.R)));
  };
  for (std::size_t i = 0; i < P.size(); ++i) {
    Real& t = top[strip(P.x[i])];
    t = std::max(t, up.dot(P.x[i]));
  }
  for (std::size_t i = 0; i < P.size(); ++i) f(i, top[strip(P.x[i])] - up.dot(P.x[i]));
}

/// Permutes every particle field into `order` (slot k takes old slot order[k]), but the
/// fields in `rewritten` (RewrittenFields), which are left as they are.
void permuteParticles(ParticleStore& P, const std::vector<std::uint32_t>& order, Scratch& s, ThreadPool& pool,
                      unsigned rewritten = 0);

}  // namespace sph2d
