// step_context.hpp (internal) — what every stage of a substep works on.
//
// A StepContext bundles the particle arrays, the neighbour grid and lists,
// the boundary samples, the job system and the substep's constants. Stages
// run in parallel over fixed blocks of kBlock particles (block boundaries
// depend on the particle count only), each particle writes only its own
// slots (gathers) and reductions combine per-block results in block order,
// so every thread count gives the same bits.
//
// The neighbour lists hold, per particle, the fluid neighbours within the
// support R and the visible boundary samples within R, both found by the one
// neighbours stage (stages.hpp) and read by every later pass of the substep.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>

#include "boundary/boundary_set.hpp"
#include "core/constants.hpp"
#include "core/kernels.hpp"
#include "core/thread_pool.hpp"
#include "particles/neighbour_grid.hpp"
#include "particles/particle_store.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace sph2d {

struct MovingSolids;
struct BodySamples;

constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();  ///< "no bad particle"

/// Neighbour lists of one substep, stored per job block so that blocks fill
/// them in parallel without sharing; buffers keep their capacity, so after
/// warm-up a substep allocates nothing.
struct NeighbourLists {
  std::vector<std::vector<std::uint32_t>> perBlock;          ///< fluid neighbour slots, block by block
  std::vector<std::uint32_t> start;                          ///< offset of particle i's fluid list in its block
  std::vector<std::uint32_t> count;                          ///< number of fluid neighbours of particle i
  std::vector<std::vector<std::uint32_t>> boundaryPerBlock;  ///< boundary sample indices, block by block
  std::vector<std::uint32_t> boundaryStart;                  ///< offset of particle i's boundary list in its block
  std::vector<std::uint32_t> boundaryCount;                  ///< number of boundary samples near particle i
  std::vector<std::vector<std::uint32_t>> movingPerBlock;    ///< moving bodies' samples (BodySamples), block by block
  std::vector<std::uint32_t> movingStart;                    ///< offset of particle i's moving-sample list in its block
  std::vector<std::uint32_t> movingCount;                    ///< number of moving bodies' samples near particle i
  /// First fluid neighbour slot of particle i.
  const std::uint32_t* of(std::size_t i) const { return perBlock[i / kBlock].data() + start[i]; }
  /// First boundary sample index near particle i.
  const std::uint32_t* boundaryOf(std::size_t i) const {
    return boundaryPerBlock[i / kBlock].data() + boundaryStart[i];
  }
  /// First moving bodies' sample index near particle i (only while BodySamples::active()).
  const std::uint32_t* movingOf(std::size_t i) const { return movingPerBlock[i / kBlock].data() + movingStart[i]; }
  /// Total fluid pairs (each counted from both sides).
  std::size_t pairs() const {
    std::size_t n = 0;
    for (std::uint32_t c : count) n += c;
    return n;
  }
};

/// Reusable scratch buffers for reordering (one per element type).
struct Scratch {
  std::vector<Vec2> v;
  std::vector<Real> r;
  std::vector<std::uint32_t> u;
  std::vector<double> d;  ///< the double fields' (ParticleStore::extraD: the mixing's concentrations)
};

/// World::wallImpulse()'s accumulator. Stages that change particle velocities because of the
/// static solids add m·Δv to `sum` (each as per-block partials summed in block order, never
/// atomics); the explicit solvers add their wall force Σ m·a_wall to `force`, which the World
/// multiplies by the substep actually taken (force_limit may shorten it after the force stage).
struct WallAccount {
  WallImpulse sum;
  Vec2d force{0, 0};  ///< this substep's wall force on the fluid [N per metre of depth]
};

/// Sums per-block partials in block order (the fixed reduction order of every wall-impulse part).
inline Vec2d sumInOrder(const std::vector<Vec2d>& parts, std::size_t count) {
  Vec2d s(0, 0);
  for (std::size_t k = 0; k < count && k < parts.size(); ++k) s += parts[k];
  return s;
}

/// Everything a stage needs for one substep.
struct StepContext {
  ParticleStore& P;
  Grid& grid;
  NeighbourLists& nbr;
  const BoundarySet& boundary;
  ThreadPool& pool;
  Scratch& scratch;
  const SolverDef& def;
  Real R = 0;   ///< kernel support
  Real dx = 0;  ///< particle spacing
  Real dt = 0;  ///< this substep
  /// The largest |a| of the particles, when a stage has just measured it and nothing has
  /// changed a since (force_limit; integrate reads a only), else −1: the `max_acceleration`
  /// stage then need not measure it again.
  Real accelMeasured = -1;
  /// The mass in the density sums (ρ = m Σ W): ρ0 over a square lattice's kernel sum, so that
  /// the lattice at spacing dx reads ρ0. A kernel of short support sums higher than its
  /// integral on a lattice (the game preset's, 2 spacings: 1.27×), so this is less than ρ0 dx².
  Real mass = 0;
  /// A particle's mass wherever momentum or energy leaves the particles (bodies, walls, groups,
  /// the World's queries): ρ0 dx², the rest density over the area a particle fills at rest. With
  /// `mass` there the water was lighter than its density to a body floating by the grid's
  /// pressure ρ0κ: a game solver's crate hit by water gained momentum (docs/notes/
  /// free-blob-momentum.md).
  Real momentumMass = 0;
  Real rho0 = 1000;  ///< rest density
  Vec2 gravity = Vec2::Zero();
  Real clearance = 0;  ///< distance kept from solid surfaces
  Real maxSpeed = 0;   ///< the guard's runaway limit
  /// The fastest particle an emitter may add in this frame (its speed × (1 + jitter)): the
  /// substep is set for it as for the particles already there (World::Impl::sourceSpeed).
  Real sourceSpeed = 0;
  std::uint64_t step = 0;  ///< substep counter
  double time = 0;         ///< simulated time at the start of the substep
  Vec2d origin{0, 0};      ///< local frame offset (world = local + origin)
  PeriodicBox periodic{};  ///< periodic axes: every pair difference takes the nearest image
  std::uint64_t boundaryVersion =
      0;                           ///< counts the times the colliders were read: changes whenever they are read again
  MovingSolids* solids = nullptr;  ///< the kinematic and dynamic bodies this step (moving_solid.hpp); null when none
  WallAccount* wall = nullptr;     ///< where stages add the static solids' impulse (null: not counted, e.g. prepare)
  /// The moving bodies' boundary samples (body_samples.hpp), for a solver that takes them
  /// (Solver::movingSamples) in a scene with moving bodies; else null. The neighbour lists
  /// hold them only while bodySamples->active().
  BodySamples* bodySamples = nullptr;
  /// The World's materials while it holds more than one (World::materials()); else null.
  const std::vector<MaterialDef>* materials = nullptr;
};

/// Lowest slot reported by the blocks (the blocks are in slot order).
std::size_t firstBad(ThreadPool& pool, std::size_t n, const std::function<std::size_t(std::size_t, std::size_t)>& fn);

/// A fixed unit direction for two coincident particles, antisymmetric in (i, j).
Vec2 tieBreakDirection(std::uint32_t idi, std::uint32_t idj);

/// The difference d = x_i − x_j of fluid pair (i, j) (nearest image on
/// periodic axes) and r² = |d|². Coincident particles (r² below
/// kCoincident2·R²) get a fixed direction of length kTieBreakLength·R that is
/// antisymmetric in (i, j), so pair forces that need a direction still push
/// the two apart and stay antisymmetric.
inline void pairDelta(const StepContext& c, std::size_t i, std::uint32_t j, Real& dx, Real& dy, Real& r2) {
  const Vec2* X = c.P.x.data();
  dx = X[i].x() - X[j].x();
  dy = X[i].y() - X[j].y();
  c.periodic.nearest(dx, dy);
  r2 = dx * dx + dy * dy;
  if (r2 < kCoincident2 * (c.R * c.R)) {
    const Vec2 t = tieBreakDirection(c.P.id[i], c.P.id[j]) * (kTieBreakLength * c.R);
    dx = t.x();
    dy = t.y();
    r2 = dx * dx + dy * dy;
  }
}

}  // namespace sph2d
