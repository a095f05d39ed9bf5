// world_impl.hpp (internal) — the World: its core (the scene, the particles, the neighbour
// grid, the static solids, the solver and effects, the stage list, the clock) and the
// subsystems it owns, each with its own data and header:
//   ParticleSources   particle_sources.hpp  emitters, the budget, removals
//   MovingBodies      moving_bodies.hpp     the kinematic and dynamic bodies, their samples
//   StaticBridge      box2d_bridge.hpp      the static bodies read from the b2World
//   ContactTracker    contacts.hpp          which particles touched which fixture
//   ParticleIndex     particle_index.hpp    lookups by id and by region
// The files that implement it, one job each:
//   world.cpp            construction and the public API
//   stepper.cpp          the stage list, the time-step policy, the guard
//   particle_sources.cpp  fluid blocks and drops, emitters, lifetimes, sinks, the budget
//   box2d_bridge.cpp     the scene's b2World and the colliders read from a b2World
//   moving_bodies.cpp, moving_collision.cpp  the moving bodies' stages
//   contacts.cpp         the contacts stage
//   queries.cpp          what readers ask of the state (hash, statistics, searches)
//   particle_index.cpp   the id index and the search grid
//   particle_access.cpp  particles by id: read, write, add at points, remove
//   save_load.cpp        the changing state to and from a byte stream
#pragma once

#include <box2d/box2d.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "effects/effect.hpp"
#include "solvers/solver.hpp"
#include "sph2d/world.hpp"
#include "step/stage_list.hpp"
#include "step/stages.hpp"
#include "world/box2d_bridge.hpp"
#include "world/contacts.hpp"
#include "world/foam.hpp"
#include "world/moving_bodies.hpp"
#include "world/particle_index.hpp"
#include "world/particle_sources.hpp"

namespace sph2d {

struct World::Impl {
  SceneDef scene;
  ThreadPool pool;
  std::unique_ptr<b2World> ownWorld;  ///< the scene's bodies (null when a game attached its own)
  b2World* b2 = nullptr;              ///< the b2World the fluid collides with
  Vec2d origin{0, 0};                 ///< local frame offset (world = local + origin)
  ParticleStore P;
  /// What World::particles() shows: views of P's public arrays, refreshed after every step and
  /// every change of the particles (refreshView), so a reference a game holds stays current.
  mutable Particles view;
  /// Points `view` at P's arrays as they are now (they move when they grow or are reordered).
  void refreshView() const;
  /// True when `view` shows P's arrays as they are now.
  bool viewCurrent() const;
  Grid grid;
  NeighbourLists nbr;
  BoundarySet boundary;
  Scratch scratch;
  std::unique_ptr<Solver> solver;
  EffectList effects;
  StageList stages;  ///< the substep, built by buildStages()
  StageList drift;   ///< a sliver of a step: drift and the particle system (buildStages())
  Real dx = 0, R = 0;
  Real mass = 0;          ///< the density sums' particle mass (StepContext::mass)
  Real momentumMass = 0;  ///< a particle's mass in momentum and energy (StepContext::momentumMass)
  PeriodicBox periodic;   ///< the scene's periodic box in the local frame
  double time = 0;
  std::uint64_t frames = 0, steps = 0;
  int lastSubsteps = 0;
  Real lastAccel = 0;  ///< largest acceleration of the last substep (the force limit)
  double lastDt = 0;   ///< the last full substep's length (0 before the first)
  std::uint32_t nextId = 0;
  std::uint64_t iterations = 0;  ///< solver iterations summed over the substeps
  WallAccount wall;              ///< World::wallImpulse(): the stages of each substep add to it (substep())
  std::vector<std::string> warnings;
  bool warnedSave = false;             ///< save() has warned of the b2World's state it cannot hold (once per World)
  std::vector<MaterialDef> materials;  ///< World::materials(): index 0 is the solver's fluid (materials.cpp)
  /// Fills `materials` from the scene (its table, checked as addMaterial checks, or the solver's
  /// one fluid); with more than one, creates the per-particle field. Throws SceneError by key.
  void initMaterials();
  /// Throws std::invalid_argument naming `call` and the materials unless material `m` exists.
  void checkMaterial(std::uint32_t m, const char* call) const;
  /// The same for a scene built in code: SceneError at `key`.
  void checkSceneMaterial(std::uint32_t m, const std::string& key) const;
  /// Gives the particles in slots [from, P.size()) material `m` (nothing to do with one material).
  void setMaterial(std::size_t from, std::uint32_t m);
  /// True when two materials differ in rest density (then P holds ParticleStore::kRestRatio).
  bool densityContrast() const;
  /// Writes each particle's ρ0 over the first material's into the rest-ratio field, from slot
  /// `from` on (nothing without the field).
  void fillRestRatio(std::size_t from);
  /// A new particle's fields that follow its material (slots ≥ `from`): the rest ratio, and with
  /// mixing all of its own material and that material's colour.
  void initMaterialFields(std::size_t from);

  // The subsystems.
  ParticleSources sources;           ///< emitters, the budget, removals
  MovingBodies moving;               ///< the kinematic and dynamic bodies
  StaticBridge statics;              ///< the static bodies read from the b2World
  ContactTracker contacts;           ///< contact tracking (off until a game turns it on)
  std::unique_ptr<FoamSystem> foam;  ///< effects.foam's diffuse particles (null without it)
  /// 1 per granular material, by index (what sheds no foam).
  std::vector<std::uint8_t> granularMaterials() const;
  ParticleIndex index;                      ///< lookups by id and by region
  DestructionListener destructionListener;  ///< the game's (empty: none; then nothing is collected)
  ParticleContactListener contactListener;  ///< the game's particle contact listener (empty: none)
  ParticleContactFilter contactFilter;      ///< … and which pairs it hears of
  std::vector<std::pair<std::uint32_t, std::uint32_t>> lastContacts;  ///< the pairs it heard of last
  /// After a step: the pairs touching that the filter takes, to the listener.
  void deliverParticleContacts();
  std::vector<Removal> removals;  ///< removed since the last delivery (with a listener)

  // Stopping on request (World::setStopFlag, WorldOptions::stop).
  const std::atomic<bool>* stop = nullptr;  ///< the caller's stop flag (null: none)
  std::string abandonedIn;                  ///< the stage an interrupted step stopped in ("" : none)
  /// Refuses a step of an abandoned World, or one asked for while the flag is set
  /// (Interrupted; `call` names the API call).
  void beforeStep(const char* call);
  /// After an Interrupted inside a step: marks the World abandoned in its stage and throws
  /// the Interrupted the caller sees (the stage, substep, frame and time).
  [[noreturn]] void abandon(const Interrupted& e);
  /// fillBlock for the API (no hydrostatic start); an interruption names `call`.
  IdRange fillNamed(const FluidBlockDef& b, const char* call);
  /// True when the stop flag is set (one relaxed load).
  bool stopSet() const { return stop && stop->load(std::memory_order_relaxed); }
  /// While it lives, the job system skips the blocks it has not started once the stop flag is
  /// set, and the job then throws Interrupted (thread_pool.hpp). Scoped to the World's own
  /// work (construction, steps, adding fluid), so that reading a World never throws it.
  struct StopScope {
    ThreadPool& pool;
    StopScope(ThreadPool& p, const std::atomic<bool>* flag) : pool(p) { pool.setCancel(flag); }
    ~StopScope() { pool.setCancel(nullptr); }
    StopScope(const StopScope&) = delete;
    StopScope& operator=(const StopScope&) = delete;
  };

  // Inputs a game sets between steps.
  std::vector<UserForce> userForces;
  bool userForceEffect = false;
  /// Moves particle slot i to `position` (world coordinates) as a teleport (xPrev too);
  /// false, changing nothing, when the position is inside a solid (setParticle, setPositions).
  bool teleport(std::size_t i, const Vec2d& position);

  // The moving bodies' stages (moving_bodies.cpp, moving_collision.cpp).
  /// Reads the non-static bodies of the b2World (rebuilding the stage list when their
  /// presence or kind changed) at the current time.
  void captureBodies();
  /// After a step of `dt`: the fluid's impulse goes to each dynamic body, and the scene's
  /// own b2World moves its bodies (a game steps its own).
  void moveOwnBodies(double dt);
  /// True when local point p lies inside a moving body at the current pose.
  bool insideMoving(const Vec2& p) const;
  /// The `body_gravity` stage: each dynamic body's velocity takes its gravity for the substep.
  void bodyGravity(StepContext& c);
  /// The `body_walls` stage: a dynamic body whose shapes would, by the substep's end, overlap a
  /// static fixture deeper than Box2D's contact distance loses the part of its velocity into it.
  void bodyWalls(StepContext& c);
  /// Sets whether Box2D holds dynamic body m at the step's start (MovingSolid::held): a joint, or
  /// a static fixture its shapes touch at their pose then (from the poses alone, as bodyWalls
  /// tests them, so a loaded World holds it as the saved one did).
  void holdBody(MovingSolid& m) const;
  /// Calls f(n, deepest) for each static fixture child dynamic body m's shapes touch at pose xa
  /// (n from the body into the fixture; deepest, the most negative separation of its points).
  template <class F>
  void forStaticContacts(const MovingSolid& m, const b2Transform& xa, F f) const;
  /// The `bodies` stage: particles that entered a moving body during the substep are put
  /// back on its surface, their velocity into it replaced by the body's (free slip); with a
  /// dynamic body they meet as an inelastic contact, and the body takes the impulse.
  /// atStart (the `body_jump` stage): the same for the particles, standing still, that a
  /// body's move from where the fluid last saw it to its pose at the substep's start swept
  /// over (Box2D's step moves a dynamic body off the path the fluid's substeps assumed);
  /// nothing when no body jumped.
  void collideMoving(StepContext& c, bool atStart = false);
  /// True when the substep places moving bodies' samples: some moving body, and a solver that takes them.
  bool bodySamplesOn() const { return !moving.solids.bodies.empty() && solver && solver->movingSamples(); }
  /// With moving bodies' samples (bodySamplesOn), true when local point p lies within 0.4
  /// spacing outside a moving body at the current pose: a particle there would overlap the
  /// samples' first layer (dx/2 deep), so a fluid block leaves it out (body_samples.cpp).
  bool nearMovingSamples(const Vec2& p) const;
  /// True when local point p lies outside every static solid but within 0.4 spacing of one's
  /// surface: a particle there would overlap its samples' first layer (dx/2 deep), so a fluid
  /// block leaves it out, as beside a moving body (a lattice row on a wall's face started at
  /// 1.6 ρ0 and threw a particle at 11 m/s; particle_sources.cpp).
  bool onStaticSurface(const Vec2& p) const;

  /// The slots `accept` takes among the particles that may lie in the world box [lo, hi]
  /// (the search grid's candidates), in slot order.
  template <class Accept>
  std::vector<std::size_t> slotsWhere(const Vec2d& lo, const Vec2d& hi, Accept&& accept) const {
    std::vector<std::size_t> out;
    index.forCandidates(P, steps, double(R), origin, lo, hi, [&](std::size_t i) {
      if (accept(i)) out.push_back(i);
    });
    std::sort(out.begin(), out.end());
    return out;
  }

  /// The state of the particles and the scene's constants for a substep of length dt.
  Impl(const SceneDef& s, const WorldOptions& o) : scene(s), pool(o.threads), stop(o.stop) {}
  StepContext context(Real dt);

  // stepper.cpp
  /// (Re)builds the substep's stage list from the solver, the enabled effects and the particle system.
  void buildStages();
  /// Appends collide, wrap, lifetimes and sinks (those the scene needs) to `list`.
  /// The particle system's stages after the solver's; `full`: the substep's list (false: the
  /// drift-only one, which has no neighbour lists of its own).
  void addParticleSystemStages(StageList& list, bool full);
  /// The substep length the solver's and the enabled effects' limits allow now.
  Real stableDt();
  /// The fastest speed an enabled emitter may give a particle within the next frame (0: none).
  Real sourceSpeed() const;
  /// One substep of length dt (or shorter, if a stage shortened it): the stage list
  /// (driftOnly: the drift list), then the clock. Returns the substep taken.
  Real substep(Real dt, bool driftOnly = false);
  /// Advances frameDt in equal substeps within the limits (the frame's split is the World's alone).
  void advance(double frameDt);
  /// True when the scene's own b2World steps with every substep instead of once a frame:
  /// it has a dynamic body and the solver samples the moving bodies (those solvers take
  /// many substeps a frame, and a body–body contact resolved once a frame moved a crate by
  /// up to 5 cm off the path the fluid's substeps had assumed).
  bool bodiesEverySubstep() const { return ownWorld && moving.solids.anyDynamic() && bodySamplesOn(); }
  /// After a substep of `taken` seconds: with bodiesEverySubstep(), steps the scene's b2World by
  /// it and reads the bodies again.
  void bodiesFollow(Real taken);
  /// Bytes held for the particles, grid, neighbour lists, boundary samples and indexes.
  std::size_t memoryBytes() const;
  /// Throws the SimulationError naming the stage, the particle and its values.
  [[noreturn]] void fail(const std::string& stage, std::size_t slot);

  // particle_sources.cpp
  /// Fills a block on the lattice of the spacing (hydrostaticStart: rows closer with
  /// depth, at the density the solver holds at rest), keeping the points of its circle
  /// (a drop, addDrop) or polygon. Stops at the particle budget (one warning for the rest).
  /// Returns the ids added (consecutive: each particle takes the next id).
  IdRange fillBlock(const FluidBlockDef& b, bool hydrostaticStart, const char* call = "addBlock");
  /// Warns once when a weakly compressible solver's sound speed is below 10 × the fastest
  /// speed the scene sets (blocks, emitters, timeline events).
  void warnLowSoundSpeed();
  /// One warning when a muller2003 scene has no viscosity (world.cpp).
  void warnInviscidMuller();
  /// A warning when the scene has moving bodies and a periodic axis (they do not wrap).
  void warnMovingBodiesInPeriodic();
  /// The scene key that sets the particle budget.
  const char* budgetKey() const;
  /// The emit stage: every enabled emitter's particles due by the end of the substep.
  void emit(Real dt);
  /// The lifetimes stage: ages particles and removes those older than max_age.
  void lifetimes(Real dt);
  /// The sinks stage: removes particles inside sink regions.
  void sinks();
  /// The particle_lifetimes stage: removes the particles whose own end (the double field
  /// ParticleStore::kLifeEnd, World::setLifetimes) is at or before `t1`, the substep's end.
  void particleLifetimes(double t1);
  /// Removes the particles flagged in `sources.dead` (stable order), counting them; `ids`, when
  /// given, receives their ids in increasing order. With a destruction listener, their ids and
  /// `reason` join the removals to deliver.
  void removeFlagged(RemovalReason reason, std::vector<std::uint32_t>* ids = nullptr);
  /// Hands the removals collected since the last delivery to the destruction listener.
  void deliverRemovals();
  /// deliverRemovals() in a step that is failing: an exception from the listener is dropped
  /// (the step's own error is the one to report).
  void deliverRemovalsAfterFailure() noexcept {
    try {
      deliverRemovals();
    } catch (...) {
    }
  }
  // groups.cpp
  /// The groups stage: each group's particles towards the best-fit rigid placement of its
  /// rest shape (all the way when rigid), their velocities with them; then out of the static
  /// solids (a rigid group as one). In a drift (`full` false: a sliver of a step, no solver
  /// stage) an elastic group is neither pulled nor yields: its stiffness is a share per
  /// substep, and the pull over a microsecond's dt became a velocity of hundreds of m/s.
  void matchGroups(StepContext& c, bool full);
  /// Before the collisions (with an elastic group): each elastic group particle's position and
  /// velocity, so that matchGroups can tell the solver's corrections from the collisions'.
  void groupsBeforeCollide(const StepContext& c);
  struct PositionVelocity {
    Vec2 x, v;
  };
  std::vector<PositionVelocity> groupBefore;  ///< groupsBeforeCollide's record (empty: none this substep)
  /// Each group's figures now (index g: group g), in slot order, in double.
  struct GroupSums {
    double m = 0, mx = 0, my = 0, mvx = 0, mvy = 0, mqx = 0, mqy = 0;  // Σ m, Σ m x, Σ m v, Σ m q
    double a00 = 0, a01 = 0, a10 = 0, a11 = 0, L = 0, I = 0;           // Σ m r q̃ᵀ, Σ m r × ṽ, Σ m |r|²
    std::size_t n = 0;
  };
  void groupSums(std::vector<GroupSums>& sums) const;
  /// After matching: splits each breakable group with a pair of rest neighbours stretched
  /// beyond its break strain into the parts still connected (splitParts).
  void breakGroups(const StepContext& c);
  /// Splits group g (its particles `slots`, in slot order) into the parts `linked` pairs
  /// connect: the largest keeps g, each other part of at least kMinGroup particles a new
  /// index (appended to `made`), smaller parts go free (group 0). Only pairs within `reach` of
  /// each other at `place` are asked (a linked pair must be): O(n log n) in the group's size.
  void splitParts(std::uint32_t g, const std::vector<std::size_t>& slots,
                  const std::function<Vec2d(std::size_t)>& place, double reach,
                  const std::function<bool(std::size_t, std::size_t)>& linked,
                  std::vector<std::uint32_t>* made = nullptr);
  /// The fewest particles a group keeps (fewer hold no shape).
  static constexpr std::size_t kMinGroup = 3;
  std::vector<GroupSums> groupScratch;  ///< matchGroups' sums
  std::vector<double> groupPush;        ///< matchGroups' pushes out of the solids, per group
  /// Removes the k oldest particles (smallest ids).
  void removeOldest(std::size_t k);

  // box2d_bridge.cpp
  /// Reads the static solids from the b2World into `boundary` (StaticBridge::read).
  void readBoundary();
  /// At a step of `dt`: finds the sliding static bodies, then re-reads the static solids when
  /// they changed (dropBuried), and records the static poses.
  void readStatics(double dt);
  /// After readBoundary: drops the particles now inside a static solid, with a warning.
  void dropBuried();
};

}  // namespace sph2d
