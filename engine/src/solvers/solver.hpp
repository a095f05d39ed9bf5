// solvers/solver.hpp (internal) — the pressure solver interface.
//
// A solver owns one substep from the neighbour grid to the integration:
// it computes density and pressure its own way, adds its pressure
// acceleration, calls the scene's effects where its scheme puts external
// forces, and integrates. The World then runs the shared collision stage.
// One file per solver in this folder; registry.cpp maps scene names to them.
#pragma once

#include <memory>

#include "effects/effect.hpp"
#include "stages.hpp"

namespace sph2d {

/// What an iterative solver did in its last substep (all zero for explicit solvers).
struct SolverStats {
  int pressureIterations = 0;     ///< constant-density (pressure) solve iterations
  int divergenceIterations = 0;   ///< divergence-free solve iterations (0 when disabled)
  double densityError = 0;        ///< mean predicted density error /ρ0 after the pressure solve (solver-defined residual)
  double divergenceError = 0;     ///< mean |Dρ/Dt|·dt/ρ0 after the divergence solve (solver-defined residual)
};

class Solver {
 public:
  virtual ~Solver() = default;
  /// The scene name of this solver.
  virtual const char* name() const = 0;
  /// f in ρ = ρ0(1 + f·g·z) [s²/m²]: how much the solver compresses a column
  /// at rest at depth z, used to start fluid blocks in hydrostatic
  /// equilibrium (0: start uncompressed).
  virtual double hydrostaticFactor() const = 0;
  /// The kernel the solver sums density with, W(r) for support R (double):
  /// the World sets the particle mass so a square lattice has density ρ0.
  virtual double densityKernel(double r, double R) const = 0;
  /// Density and pressure of the current positions (for a complete initial state).
  virtual void prepare(StepContext& c) = 0;
  /// Smallest substep the scheme can take [s] (0: any). A position-based solver
  /// turns its corrections into velocities by dividing by dt, so it cannot follow
  /// an effect's explicit limit below this; the World then refuses the scene.
  virtual double minTimeStep(const StepContext& c) const {
    (void)c;
    return 0;
  }
  /// Largest stable substep for the current state, given the largest speed and acceleration.
  virtual Real maxTimeStep(const StepContext& c, Real vmax, Real amax) const = 0;
  /// One substep (grid → … → integrate).
  virtual void substep(StepContext& c, StageRunner& run, const EffectList& effects) = 0;
  /// Iterations and residuals of the last substep (explicit solvers: all zero).
  virtual SolverStats stats() const { return {}; }
};

/// True when this substep reorders particle storage along the grid.
inline bool reorderThisStep(const StepContext& c) {
  const int every = c.def.reorderInterval;
  return every > 0 && c.step % std::uint64_t(every) == 0;
}

/// The substep of the equation-of-state solvers (muller2003, wcsph):
/// grid → neighbours → density → pressure → pressure_force → effects → integrate.
/// density(c) and pressureForce(c) return the first bad slot; pressure(c) returns nothing.
template <class Density, class Pressure, class Force>
void explicitSubstep(StepContext& c, StageRunner& run, const EffectList& effects, Density density, Pressure pressure,
                     Force pressureForce) {
  const bool reorder = reorderThisStep(c);
  run.run("grid", [&] { stageGrid(c, reorder); });
  run.run("neighbours", [&] { stageNeighbours(c); });
  run.checked("density", [&] { return density(c); });
  run.run("pressure", [&] { pressure(c); });
  run.checked("pressure_force", [&] { return pressureForce(c); });
  applyEffects(c, run, effects);
  run.checked("integrate", [&] { return stageIntegrate(c); });
}

/// The complete initial state of the equation-of-state solvers: grid,
/// neighbours, density and pressure of the current positions.
template <class Density, class Pressure>
void explicitPrepare(StepContext& c, Density density, Pressure pressure) {
  stageGrid(c, false);
  stageNeighbours(c);
  density(c);
  pressure(c);
}

/// One solver-specific scene key (under "solver").
struct SolverParam {
  std::string key;   ///< scene key
  double def;        ///< default
  double lo, hi;     ///< allowed range (inclusive)
  std::string doc;   ///< one line for docs/SCENES.md and errors
};

/// The solver a scene names. Throws std::invalid_argument for an unknown name.
std::unique_ptr<Solver> makeSolver(const SolverDef& def);

/// The names makeSolver knows, for error messages and docs.
const std::vector<std::string>& solverNames();

/// The extra keys solver `type` accepts (empty for an unknown type).
const std::vector<SolverParam>& solverParams(const std::string& type);

}  // namespace sph2d
