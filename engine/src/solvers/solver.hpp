// solvers/solver.hpp (internal) — the pressure solver interface.
//
// A solver contributes the part of the substep from the neighbour search to
// the integration as an ordered list of stages (stage_list.hpp), with a marker
// where the scene's effects run; an iterative solve is one stage. It reports
// the largest substep it can take; the World owns the split of a frame into
// substeps, runs the stages, and follows them with the collision and the
// particle system. Each solver lives in its own folder with its parameters
// (name, default, range, one line of doc); registry.cpp lists them.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "sph2d/world.hpp"
#include "step/stage_list.hpp"
#include "step/stages.hpp"

namespace sph2d {

class StateOut;
class StateIn;
class Effect;

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
  /// the World sets the density sums' mass (StepContext::mass) so a square lattice has density ρ0.
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
  /// Largest stable substep for the current state, given the largest speed and
  /// acceleration. Pure: asking does not change the solver.
  virtual Real maxTimeStep(const StepContext& c, Real vmax, Real amax) const = 0;
  /// The stages of one substep in order, with Stage::effects() where the
  /// scene's effects run. `effects`: whether any effect will run (a solver may
  /// then need neighbours of the current positions first). The stages may
  /// keep pointers to the solver; the World rebuilds the list when effects change.
  virtual std::vector<Stage> stages(bool effects) = 0;
  /// Offers the scene's Laplacian viscosity (Effect::foldable, the first enabled effect;
  /// null: none) to compute inside the solver's own pair loop. True: the next stages()
  /// computes it (its pressure-force stage is named "pressure_force+viscosity") and
  /// the effect runs no stage of its own. The default folds nothing.
  virtual bool foldViscosity(Effect* viscosity) {
    (void)viscosity;
    return false;
  }
  /// True when the solver takes the moving bodies' boundary samples (body_samples.hpp): it
  /// counts them in its density and wall terms (with their velocity) while
  /// StepContext::bodySamples is active, and adds the force they exert on each particle to
  /// BodySamples::perBlock; the World then places them each substep and gives each dynamic
  /// body the opposite. False (the default): the bodies meet the fluid by the `bodies`
  /// stage's contacts alone (and the game solver's grid).
  virtual bool movingSamples() const { return false; }
  /// True when the solver itself says which of an elastic group's particles' moves are their
  /// own position corrections (groupMoves()): the World's groups stage takes those into their
  /// velocity (world/groups.cpp). False (the default): the groups stage takes each such
  /// particle's whole move over the substep, less its velocity.
  virtual bool groupCorrections() const { return false; }
  /// With groupCorrections(): per slot, the move of the last substep's corrections that an
  /// elastic group's particle takes into its velocity (its own, not its pairs' with the
  /// others); null when no particle is in an elastic group.
  virtual const std::vector<Vec2>* groupMoves() const { return nullptr; }
  /// Iterations and residuals of the last substep (explicit solvers: all zero).
  virtual SolverStats stats() const { return {}; }
  /// Writes what the solver carries from one substep to the next outside the particle
  /// fields (warm starts, step limits), for World::save. Nothing by default.
  virtual void saveState(StateOut& out) const { (void)out; }
  /// Reads back what saveState() wrote (throws SaveError on malformed input).
  virtual void loadState(StateIn& in) { (void)in; }
};

/// The stages of the equation-of-state solvers (muller2003, wcsph): grid →
/// neighbours → density → pressure → pressure_force → effects → force_limit →
/// integrate (force_limit shortens the substep to its own forces' limit).
/// density and pressureForce return the first bad slot; pressure returns nothing.
std::vector<Stage> explicitStages(Stage::Fn density, std::function<void(StepContext&)> pressure,
                                  Stage::Fn pressureForce);

/// One solver-specific scene key (under "solver").
struct SolverParam {
  std::string key;  ///< scene key
  double def;       ///< default
  double lo, hi;    ///< allowed range (inclusive)
  std::string doc;  ///< one line for docs/SCENES.md and errors
};

/// A solver's registration: its scene name, its parameters and how to make it.
struct SolverInfo {
  const char* name;                                       ///< solver.type
  std::vector<SolverParam> params;                        ///< its solver.* keys
  std::unique_ptr<Solver> (*make)(const SolverDef& def);  ///< builds it (params filled)
  /// Sets the shared keys (viscosity, support ratio...) this solver wants
  /// different from SolverDef's defaults when the scene leaves them out (may be null).
  void (*tune)(SolverDef& def) = nullptr;
  /// A combination of its parameters the solver cannot run, as {key, why} (an empty key:
  /// none); the World refuses such a scene naming the key (may be null).
  std::pair<std::string, std::string> (*check)(const SolverDef& def) = nullptr;
};

/// Applies the tune of `def.type`'s solver (SolverInfo::tune), if it has one.
void tuneSolverDefaults(SolverDef& def);

/// A shared solver key's allowed range (the scene loader's and the World's): [lo, hi], or
/// (lo, hi] when loOpen; `get` reads it from a SolverDef.
struct SharedSolverKey {
  const char* key;
  double lo, hi;
  bool loOpen;
  double (*get)(const SolverDef& def);
};
/// The shared numeric keys of solver (spacing, support_ratio, ...) with their ranges.
const std::vector<SharedSolverKey>& sharedSolverKeys();

/// What is wrong with `def`, as {"solver.<key>", why}, or an empty key when nothing: a shared
/// key or a parameter outside its range (or not finite), a parameter the solver does not
/// declare, an unknown solver type, then what the solver's own check (SolverInfo::check)
/// says against a combination.
std::pair<std::string, std::string> solverParamProblem(const SolverDef& def);

/// The solver a scene names. Throws std::invalid_argument for an unknown name.
std::unique_ptr<Solver> makeSolver(const SolverDef& def);

/// The names makeSolver knows, for error messages and docs.
const std::vector<std::string>& solverNames();

/// The extra keys solver `type` accepts (empty for an unknown type).
const std::vector<SolverParam>& solverParams(const std::string& type);

/// Fills every parameter of `def`'s solver that `def` leaves out with its default
/// (a scene built in code need not name them).
void fillSolverDefaults(SolverDef& def);

}  // namespace sph2d
