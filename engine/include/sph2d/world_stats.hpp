// sph2d/world_stats.hpp — what a World reports about its own work: the solver's last
// substep, the density's spread, the walls' impulse, the counters and the stages' timings
// (World::counters(), World::profile(), World::wallImpulse(), World::densityStats()).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sph2d/math.hpp"

namespace sph2d {

/// Time and call count of one stage.
struct StageTiming {
  std::string name;
  double seconds = 0;
  std::uint64_t calls = 0;
};

/// What an iterative pressure solver did in its last substep (all zero for explicit solvers).
struct SolverStats {
  int pressureIterations = 0;    ///< constant-density (pressure) solve iterations
  int divergenceIterations = 0;  ///< divergence-free solve iterations (0 when disabled)
  double densityError = 0;     ///< mean predicted density error /ρ0 after the pressure solve (solver-defined residual)
  double divergenceError = 0;  ///< mean |Dρ/Dt|·dt/ρ0 after the divergence solve (solver-defined residual)
};

/// Density error of the fluid, relative to ρ0.
struct DensityStats {
  double meanError = 0;  ///< mean of max(ρ − ρ0, 0)/ρ0 over particles (compression)
  double maxError = 0;   ///< max of max(ρ − ρ0, 0)/ρ0 over particles (the most compressed particle)
  double meanDensity = 0;
};

/// The impulse the static solids gave the fluid [N·s per metre of depth, i.e. kg·m/s in 2D],
/// split by the stage that applied it. A static solid is a fixture of a static body of the
/// b2World (World::colliders() and its boundary samples); kinematic and dynamic bodies are
/// not: what they exchange with the fluid stays inside fluid plus bodies and is not counted.
/// Each part is the m·Δv the solver gives the particles because of the solids, taken where it
/// applies it (not inferred from the fluid's momentum). docs/EMBEDDING.md: what each solver
/// counts, and how closely Δ(momentum) = gravity's impulse + this closes.
struct WallImpulse {
  /// The solver's boundary-sample terms: wcsph's wall pressure and wall viscosity (m·a·dt of the
  /// substep taken), dfsph's wall terms of both velocity solves, pbf's wall share of the density
  /// solve when its moves become velocity (correction_to_velocity > 0), muller2003's wall pressure,
  /// and with solver.no_slip the viscosity's wall term (every solver). 0 for the game solver
  /// unless no_slip.
  Vec2d samples{0, 0};
  /// The game solver's grid projection (pbf with grid_cell > 0): the pressure of the fluid cells
  /// on their faces closed by a static solid (ρ0 κ h dt), and the normal velocity those faces
  /// remove (the faces' particle mass times their change). Grid-level figures: the transfer to
  /// the particles does not conserve momentum exactly.
  Vec2d grid{0, 0};
  /// The swept collision with the static colliders (the collide stage, and pbf's own sweeps
  /// when its moves become velocity): m·Δv of the velocity response.
  Vec2d collision{0, 0};
  /// samples + grid + collision.
  Vec2d total() const { return samples + grid + collision; }
};

/// What a World has done, counted (World::counters()), as Box2D's b2Counters are for a b2World.
struct WorldCounters {
  std::uint64_t frames = 0;            ///< frames stepped (stepFrame, step)
  std::uint64_t substeps = 0;          ///< substeps taken
  int lastFrameSubsteps = 0;           ///< substeps of the last frame
  std::uint64_t solverIterations = 0;  ///< pressure and divergence solve iterations summed over every substep
  SolverStats lastSolve;               ///< the last substep's solve (explicit solvers: all zero)
  std::size_t particles = 0;           ///< particles now
  std::size_t neighbourPairs = 0;      ///< fluid pairs of the last substep, each counted from both sides
  std::uint64_t removed = 0;           ///< particles removed by lifetimes, sinks and the budget policy
  std::size_t memoryBytes = 0;  ///< bytes for the particles, grid, neighbour lists, boundary samples and lookup indexes
  std::size_t particleBytes = 0;  ///< bytes the particle arrays hold (the solver's working fields included)
};

/// Where a World's time went (World::profile()), as Box2D's b2Profile is for a b2World.
struct WorldProfile {
  std::vector<StageTiming> stages;  ///< wall time and calls per stage, in list order
  /// The seconds of every stage together.
  double totalSeconds() const {
    double t = 0;
    for (const StageTiming& s : stages) t += s.seconds;
    return t;
  }
};

}  // namespace sph2d
