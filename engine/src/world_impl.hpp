// world_impl.hpp (internal) — the World's state, shared by the files that
// implement it, one job each:
//   world.cpp            construction and the public API
//   stepper.cpp          the stage list, the time-step policy, the guard
//   particle_system.cpp  fluid blocks and drops, emitters, lifetimes, sinks, the budget
//   box2d_bridge.cpp     the scene's b2World and the colliders read from a b2World
//   queries.cpp          what readers ask of the state (hash, statistics, searches)
//   particle_access.cpp  particles by id: read, write, add at points, remove
#pragma once

#include <box2d/box2d.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "effects/effect.hpp"
#include "solvers/solver.hpp"
#include "sph2d/world.hpp"
#include "stage_list.hpp"
#include "stages.hpp"

namespace sph2d {

struct World::Impl {
  SceneDef scene;
  ThreadPool pool;
  std::unique_ptr<b2World> ownWorld;  ///< the scene's bodies (null when a game attached its own)
  b2World* b2 = nullptr;              ///< the b2World the fluid collides with
  Vec2d origin{0, 0};                 ///< local frame offset (world = local + origin)
  Particles P;
  Grid grid;
  NeighbourLists nbr;
  BoundarySet boundary;
  Scratch scratch;
  std::unique_ptr<Solver> solver;
  EffectList effects;
  StageList stages;                   ///< the substep, built by buildStages()
  StageList drift;                    ///< a sliver of a step: drift and the particle system (buildStages())
  Real dx = 0, R = 0, mass = 0;
  PeriodicBox periodic;               ///< the scene's periodic box in the local frame
  double time = 0;
  std::uint64_t frames = 0, steps = 0;
  int lastSubsteps = 0;
  Real lastAccel = 0;                 ///< largest acceleration of the last substep (the force limit)
  double lastDt = 0;                  ///< the last full substep's length (0 before the first)
  std::uint32_t nextId = 0;
  std::uint64_t iterations = 0;       ///< solver iterations summed over the substeps
  std::vector<std::string> warnings;
  std::uint64_t boundarySignature = 0;  ///< staticSignature() when the colliders were last read
  std::uint64_t boundaryVersion = 0;    ///< how many times the colliders were read (StepContext::boundaryVersion)

  // The particle system (particle_system.cpp): emitters, lifetimes, sinks, budget.
  struct EmitterState {
    EmitterDef def;
    std::uint64_t rng = 0;  ///< SplitMix64 state, seeded per emitter
    std::uint64_t emitted = 0;
    bool warnedBudget = false;
  };
  std::vector<EmitterState> emitters;
  std::size_t budget = 0;
  std::uint64_t removed = 0;
  std::vector<UserForce> userForces;
  bool userForceEffect = false;
  std::vector<unsigned char> dead;  ///< scratch: removal flags
  /// (id, slot) of every particle sorted by id: World::slotOf's index, rebuilt when a lookup
  /// finds it stale (particle_access.cpp). Mutable: a lookup on a const World refreshes it.
  mutable std::vector<std::pair<std::uint32_t, std::uint32_t>> idIndex;

  /// The state of the particles and the scene's constants for a substep of length dt.
  Impl(const SceneDef& s, const WorldOptions& o) : scene(s), pool(o.threads) {}
  StepContext context(Real dt);

  // stepper.cpp
  /// (Re)builds the substep's stage list from the solver, the enabled effects and the particle system.
  void buildStages();
  /// Appends collide, wrap, lifetimes and sinks (those the scene needs) to `list`.
  void addParticleSystemStages(StageList& list);
  /// The substep length the solver's and the enabled effects' limits allow now.
  Real stableDt();
  /// One substep of length dt (or shorter, if a stage shortened it): the stage list
  /// (driftOnly: the drift list), then the clock. Returns the substep taken.
  Real substep(Real dt, bool driftOnly = false);
  /// Advances frameDt in equal substeps within the limits (the frame's split is the World's alone).
  void advance(double frameDt);
  /// Throws the SimulationError naming the stage, the particle and its values.
  [[noreturn]] void fail(const std::string& stage, std::size_t slot);

  // particle_system.cpp
  /// Lattice points within `radius` of `center` (world coordinates): a drop.
  struct Disc {
    Vec2d center;
    double radius;
  };
  /// Fills a block on the lattice of the spacing (hydrostaticStart: rows closer with
  /// depth, at the density the solver holds at rest), keeping the points of its circle
  /// or polygon; `disc` keeps the points of a drop. Stops at the particle budget (one warning for the rest).
  std::size_t fillBlock(const FluidBlockDef& b, bool hydrostaticStart, const Disc* disc = nullptr);
  /// Warns once when a weakly compressible solver's sound speed is below 10 × the fastest
  /// speed the scene sets (blocks, emitters, timeline events).
  void warnLowSoundSpeed();
  /// The scene key that sets the particle budget.
  const char* budgetKey() const;
  /// The emit stage: every enabled emitter's particles due by the end of the substep.
  void emit(Real dt);
  /// The lifetimes stage: ages particles and removes those older than max_age.
  void lifetimes(Real dt);
  /// The sinks stage: removes particles inside sink regions.
  void sinks();
  /// Removes the particles flagged in `dead` (stable order), counting them.
  void removeFlagged();
  /// Removes the k oldest particles (smallest ids).
  void removeOldest(std::size_t k);

  // box2d_bridge.cpp
  /// XXH64 of the static fixtures' identities and transforms: changes when the game edits its level.
  std::uint64_t staticSignature() const;
  /// Reads the colliders and boundary samples from the b2World again.
  void rebuildBoundary();
};

/// A b2World with the scene's gravity and static bodies (box2d_bridge.cpp).
std::unique_ptr<b2World> makeSceneWorld(const SceneDef& scene);

}  // namespace sph2d
