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

class Solver {
 public:
  virtual ~Solver() = default;
  /// The scene name of this solver.
  virtual const char* name() const = 0;
  /// f in ρ = ρ0(1 + f g z / c²): how much the solver compresses a column at
  /// rest, used to start fluid blocks in hydrostatic equilibrium (0: none).
  virtual double hydrostaticFactor() const = 0;
  /// Density and pressure of the current positions (for a complete initial state).
  virtual void prepare(StepContext& c) = 0;
  /// Largest stable substep for the current state, given the largest speed and acceleration.
  virtual Real maxTimeStep(const StepContext& c, Real vmax, Real amax) const = 0;
  /// One substep (grid → … → integrate).
  virtual void substep(StepContext& c, StageRunner& run, const EffectList& effects) = 0;
};

/// The solver a scene names. Throws std::invalid_argument for an unknown name.
std::unique_ptr<Solver> makeSolver(const SolverDef& def);

/// The names makeSolver knows, for error messages and docs.
const std::vector<std::string>& solverNames();

}  // namespace sph2d
