// stages.hpp (internal) — the step context and the stages every solver shares.
//
// A substep is a fixed list of stages, each a free function over the
// structure-of-arrays particles with a StepContext (Box2D v3's layout). Each
// particle writes only its own slots (gathers), so any thread count gives the
// same bits. What each stage reads and writes is in docs/ARCHITECTURE.md.
// A stage that finds a non-finite or runaway value returns the slot of the
// first bad particle (lowest slot), or kNone; the World turns that into a
// SimulationError.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>

#include "boundary_set.hpp"
#include "grid.hpp"
#include "sph2d/kernels.hpp"
#include "sph2d/particles.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/thread_pool.hpp"

namespace sph2d {

constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
constexpr std::size_t kBlock = 256;  ///< particles per job block (fixed: results never depend on threads)

/// Each particle's neighbours within the support (itself excluded), built
/// once per substep and read by every later pass. Stored per job block so that
/// blocks fill them in parallel without sharing; buffers keep their capacity,
/// so after warm-up a step allocates nothing.
struct NeighbourLists {
  std::vector<std::vector<std::uint32_t>> perBlock;  ///< neighbour slots, block by block
  std::vector<std::uint32_t> start;                  ///< offset of particle i's list in its block
  std::vector<std::uint32_t> count;                  ///< number of neighbours of particle i
  /// First neighbour slot of particle i.
  const std::uint32_t* of(std::size_t i) const { return perBlock[i / kBlock].data() + start[i]; }
  /// Total pairs (each counted from both sides).
  std::size_t pairs() const {
    std::size_t n = 0;
    for (std::uint32_t c : count) n += c;
    return n;
  }
};

/// Reusable scratch buffers for reordering.
struct Scratch {
  std::vector<Vec2> v;
  std::vector<Real> r;
  std::vector<std::uint32_t> u;
};

/// Everything a stage needs for one substep.
struct StepContext {
  Particles& P;
  Grid& grid;
  NeighbourLists& nbr;
  const BoundarySet& boundary;
  ThreadPool& pool;
  Scratch& scratch;
  const SolverDef& def;
  Real R = 0;                   ///< kernel support
  Real dx = 0;                  ///< particle spacing
  Real dt = 0;                  ///< this substep
  Real mass = 0;                ///< particle mass
  Real rho0 = 1000;             ///< rest density
  Vec2 gravity = Vec2::Zero();
  Real clearance = 0;           ///< distance kept from solid surfaces
  Real maxSpeed = 0;            ///< the guard's runaway limit
  std::uint64_t step = 0;       ///< substep counter
  double time = 0;              ///< simulated time at the start of the substep
  Vec2d origin{0, 0};           ///< local frame offset (world = local + origin)
  PeriodicBox periodic{};       ///< periodic axes: every pair difference takes the nearest image
};

/// Runs named stages: times them and turns a bad slot into a SimulationError.
struct StageRunner {
  virtual ~StageRunner() = default;
  /// Runs and times stage `name`.
  virtual void run(const char* name, const std::function<void()>& f) = 0;
  /// Runs and times stage `name`; f returns the first bad slot or kNone.
  virtual void checked(const char* name, const std::function<std::size_t()>& f) = 0;
};

/// Lowest slot reported by the blocks (the blocks are in slot order).
std::size_t firstBad(ThreadPool& pool, std::size_t n, const std::function<std::size_t(std::size_t, std::size_t)>& fn);

/// A fixed unit direction for two coincident particles, antisymmetric in (i, j).
Vec2 tieBreakDirection(std::uint32_t idi, std::uint32_t idj);

/// Neighbour grid (counting sort, cells of R/2) and, when `reorder`, every particle array permuted into cell order.
/// In a periodic scene it first wraps every position into the box (stageWrap).
void stageGrid(StepContext& c, bool reorder);
/// Moves particles that left the periodic box to their image inside it (x and
/// xPrev shift together, so the swept collision sees the true move). Reads and writes x, xPrev.
void stageWrap(StepContext& c);
/// Neighbour lists: the grid's candidates within R, compacted without branches. Reads x, grid; writes nbr.
void stageNeighbours(StepContext& c);
/// Σ_b Ψ_b W(x − x_b) over the boundary samples visible from x (a volume fraction; times ρ0 for density).
template <class Kernel>
Real boundaryVolumeSum(const BoundarySet& B, const Kernel& W, const Vec2& x) {
  Real s = 0;
  B.sampleGrid.forCandidates(x, [&](std::uint32_t k) {
    const Vec2 d = x - B.samples[k];
    const Real r2 = d.squaredNorm();
    if (r2 < W.R * W.R && B.visible(k, x)) s += B.volume[k] * W.value(std::sqrt(r2));
  });
  return s;
}
/// The first moment M = −Σ_j V x_ij,x ∂W/∂x over a square lattice of spacing
/// dx (V = volume per particle): 1 for an exact gradient. A symmetric SPH
/// pressure gradient underestimates ∇p by this factor (Wendland C2 at
/// R = 2.5 dx: 0.953), so solvers divide their pressure term by it.
template <class Kernel>
double latticeGradientMoment(const Kernel& W, double dx, double volume) {
  const int n = int(std::ceil(double(W.R) / dx)) + 1;
  double m = 0;
  for (int j = -n; j <= n; ++j)
    for (int i = -n; i <= n; ++i) {
      const double x = i * dx, y = j * dx, r = std::sqrt(x * x + y * y);
      if (r > 0) m -= volume * x * x * double(W.derivative(decltype(W.R)(r))) / r;  // W' < 0
    }
  return m;
}

/// The second moment ¼ Σ_j V r² L(r) of a Laplacian kernel L over a square
/// lattice of spacing dx (V = dx²), the centre excluded: the factor by which
/// Σ_j V (A_j − A_i) L(r_ij) gives ∇²A for a smooth field (1 when exact). The
/// 2D Laplacian of Müller's viscosity kernel has an R³/r³ term whose continuous
/// moment diverges, so the discrete one depends on R/dx (0.834 at R = 2.5 dx):
/// the viscosity effect divides by it.
template <class Laplacian>
double latticeLaplacianMoment(const Laplacian& L, double R, double dx) {
  const int n = int(std::ceil(R / dx)) + 1;
  double m = 0;
  for (int j = -n; j <= n; ++j)
    for (int i = -n; i <= n; ++i) {
      const double r = std::sqrt(double(i * i + j * j)) * dx;
      if (r > 0 && r < R) m += 0.25 * dx * dx * r * r * L(r);
    }
  return m;
}

/// Symplectic Euler: v += dt a; x += dt v. Reads a; writes v, x, xPrev. Returns the first bad slot.
std::size_t stageIntegrate(StepContext& c);
/// Swept collision against the Box2D colliders. Reads xPrev; writes x, v.
void stageCollide(StepContext& c);
/// Largest speed (deterministic reduction).
Real maxSpeedOf(const Particles& P, ThreadPool& pool);
/// Largest acceleration magnitude (deterministic reduction).
Real maxAccelOf(const Particles& P, ThreadPool& pool);

}  // namespace sph2d
