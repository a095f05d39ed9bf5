// stages.hpp (internal) — the stages every solver shares: the neighbour grid,
// the neighbour lists (fluid and boundary in one search), integration, the
// swept collision, the periodic wrap, and the deterministic reductions the
// time-step limits read. Each is a free function over a StepContext; what
// each reads and writes is in docs/ARCHITECTURE.md.
#pragma once

#include "step_context.hpp"

namespace sph2d {

/// True when this substep reorders particle storage along the grid (every solver.reorder_interval substeps).
bool reorderThisStep(const StepContext& c);
/// Neighbour grid (counting sort, cells of R/2) and, when `reorder`, every particle array permuted into cell order.
/// In a periodic scene it first wraps every position into the box (stageWrap).
void stageGrid(StepContext& c, bool reorder);
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
Real maxSpeedOf(const Particles& P, ThreadPool& pool);
/// Largest acceleration magnitude (deterministic reduction).
Real maxAccelOf(const Particles& P, ThreadPool& pool);
/// Permutes every particle field into `order` (slot k takes old slot order[k]).
void permuteParticles(Particles& P, const std::vector<std::uint32_t>& order, Scratch& s, ThreadPool& pool);

}  // namespace sph2d
