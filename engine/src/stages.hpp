// stages.hpp (internal) — the substep as a fixed list of free functions.
//
// Each stage is a pass over the structure-of-arrays particles with a
// StepContext; each particle writes only its own slots (gathers), so any
// thread count gives the same bits. What each stage reads and writes is in
// docs/ARCHITECTURE.md. A stage that finds a non-finite or runaway value
// returns the slot of the first bad particle (lowest slot), or kNone.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

#include "boundary_set.hpp"
#include "grid.hpp"
#include "sph2d/kernels.hpp"
#include "sph2d/particles.hpp"
#include "sph2d/thread_pool.hpp"

namespace sph2d {

constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
constexpr std::size_t kBlock = 256;  ///< particles per job block (fixed: results never depend on threads)
static_assert(kBlock == 256, "NeighbourLists::kBlockSize must equal kBlock");

/// Each particle's neighbours within the support (itself excluded), built
/// once per substep and read by every later pass. Stored per job block so that
/// blocks fill them in parallel without sharing; buffers keep their capacity,
/// so after warm-up a step allocates nothing.
struct NeighbourLists {
  std::vector<std::vector<std::uint32_t>> perBlock;  ///< neighbour slots, block by block
  std::vector<std::uint32_t> start;                  ///< offset of particle i's list in its block
  std::vector<std::uint32_t> count;                  ///< number of neighbours of particle i
  /// First neighbour slot of particle i.
  const std::uint32_t* of(std::size_t i) const { return perBlock[i / kBlockSize].data() + start[i]; }
  /// Total pairs (each counted from both sides).
  std::size_t pairs() const {
    std::size_t n = 0;
    for (std::uint32_t c : count) n += c;
    return n;
  }
  static constexpr std::size_t kBlockSize = 256;
};

/// Everything a stage needs for one substep.
struct StepContext {
  Particles& P;
  Grid& grid;
  NeighbourLists& nbr;
  const BoundarySet& boundary;
  ThreadPool& pool;
  Poly6<Real> poly6;            ///< density kernel
  Spiky<Real> spiky;            ///< pressure-gradient kernel
  ViscosityKernel<Real> visc;   ///< viscosity Laplacian kernel
  Real dt = 0;
  Real mass = 0;                ///< particle mass
  Real rho0 = 1000;             ///< rest density
  Real stiffness = 0;           ///< K in p = K(ρ − ρ0)
  Real mu = 0;                  ///< dynamic viscosity ν·ρ0
  Vec2 gravity = Vec2::Zero();
  bool clampNegative = true;
  Real clearance = 0;           ///< distance kept from solid surfaces
  Real maxSpeed = 0;            ///< the guard's runaway limit
};

/// Neighbour grid (counting sort) and, when `reorder`, the particle arrays permuted into cell order.
void stageGrid(StepContext& c, bool reorder, std::vector<Vec2>& scratchV, std::vector<Real>& scratchR,
               std::vector<std::uint32_t>& scratchU);
/// Neighbour lists: the grid's candidates within R, compacted without branches. Reads x, grid; writes nbr.
void stageNeighbours(StepContext& c);
/// ρ_i = m W(0) + Σ_j m W_poly6(x_i − x_j) + Σ_b ρ0 Ψ_b W_poly6(x_i − x_b). Reads x, nbr; writes rho.
std::size_t stageDensity(StepContext& c);
/// p_i = K(ρ_i − ρ0), clamped at 0 when asked. Reads rho; writes p.
void stagePressure(StepContext& c);
/// a_i = gravity + symmetric spiky pressure + Laplacian viscosity + boundary pressure.
/// Reads x, v, rho, p; writes a. Returns the first bad slot.
std::size_t stageForces(StepContext& c);
/// Symplectic Euler: v += dt a; x += dt v. Reads a; writes v, x, xPrev. Returns the first bad slot.
std::size_t stageIntegrate(StepContext& c);
/// Swept collision against the Box2D colliders. Reads xPrev; writes x, v.
void stageCollide(StepContext& c);
/// Largest speed (deterministic reduction).
Real maxSpeedOf(const Particles& P, ThreadPool& pool);
/// Largest acceleration magnitude (deterministic reduction).
Real maxAccelOf(const Particles& P, ThreadPool& pool);

}  // namespace sph2d
