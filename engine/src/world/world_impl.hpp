// world_impl.hpp (internal) — the World's state, shared by the files that
// implement it, one job each:
//   world.cpp            construction and the public API
//   stepper.cpp          the stage list, the time-step policy, the guard
//   particle_sources.cpp  fluid blocks and drops, emitters, lifetimes, sinks, the budget
//   box2d_bridge.cpp     the scene's b2World and the colliders read from a b2World
//   queries.cpp          what readers ask of the state (hash, statistics, searches)
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

#include "bodies/body_samples.hpp"
#include "bodies/moving_solid.hpp"
#include "effects/effect.hpp"
#include "solvers/solver.hpp"
#include "sph2d/world.hpp"
#include "step/stage_list.hpp"
#include "step/stages.hpp"

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
  Real dx = 0, R = 0, mass = 0;
  PeriodicBox periodic;  ///< the scene's periodic box in the local frame
  double time = 0;
  std::uint64_t frames = 0, steps = 0;
  int lastSubsteps = 0;
  Real lastAccel = 0;  ///< largest acceleration of the last substep (the force limit)
  double lastDt = 0;   ///< the last full substep's length (0 before the first)
  std::uint32_t nextId = 0;
  std::uint64_t iterations = 0;  ///< solver iterations summed over the substeps
  WallAccount wall;              ///< World::wallImpulse(): the stages of each substep add to it (substep())
  std::vector<std::string> warnings;
  bool warnedSave = false;              ///< save() has warned of the b2World's state it cannot hold (once per World)
  std::uint64_t boundarySignature = 0;  ///< staticSignature() when the colliders were last read
  std::uint64_t boundaryVersion = 0;    ///< how many times the colliders were read (StepContext::boundaryVersion)

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

  // The particle system (particle_sources.cpp): emitters, lifetimes, sinks, budget.
  struct EmitterState {
    EmitterDef def;
    std::uint64_t rng = 0;  ///< SplitMix64 state, seeded per emitter
    std::uint64_t emitted = 0;
    bool warnedBudget = false;
  };
  std::vector<EmitterState> emitters;
  /// What is wrong with an emitter built in code or read from a save, naming the field and
  /// its range (the scene format's), or "" when nothing is (particle_sources.cpp).
  static std::string emitterProblem(const EmitterDef& d);
  static constexpr std::size_t kMaxEmitters = 4096;  ///< addEmitter's and a save's limit
  std::size_t budget = 0;
  std::uint64_t removed = 0;
  std::vector<UserForce> userForces;
  bool userForceEffect = false;
  std::vector<unsigned char> dead;  ///< scratch: removal flags
  /// (id, slot) of every particle sorted by id: World::slotOf's index, rebuilt when a lookup
  /// finds it stale (particle_access.cpp). Mutable: a lookup on a const World refreshes it.
  mutable std::vector<std::pair<std::uint32_t, std::uint32_t>> idIndex;
  /// Moves particle slot i to `position` (world coordinates) as a teleport (xPrev too);
  /// false, changing nothing, when the position is inside a solid (setParticle, setPositions).
  bool teleport(std::size_t i, const Vec2d& position);
  // Moving bodies (moving_bodies.cpp, moving_solid.hpp): the kinematic and dynamic bodies
  // of the b2World, captured at the start of each step with their pose and velocity; the
  // `bodies` stage pushes the fluid out of them and, for a dynamic body, takes the
  // contacts' impulse; the grid projection of the game solver sees them as moving solids.
  MovingSolids moving;
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
  /// The `bodies` stage: particles that entered a moving body during the substep are put
  /// back on its surface, their velocity into it replaced by the body's (free slip); with a
  /// dynamic body they meet as an inelastic contact, and the body takes the impulse.
  /// atStart (the `body_jump` stage): the same for the particles, standing still, that a
  /// body's move from where the fluid last saw it to its pose at the substep's start swept
  /// over (Box2D's step moves a dynamic body off the path the fluid's substeps assumed);
  /// nothing when no body jumped.
  void collideMoving(StepContext& c, bool atStart = false);
  std::vector<std::int32_t> hitBody;  ///< the bodies stage's scratch: the dynamic body particle i met (−1: none)
  std::vector<Vec2d> hitNormal;       ///< … and the body's outward normal there
  /// The bodies stage's scratch per body: its pose at the substep's start and end.
  struct BodyPose {
    double theta0, theta1, c0, s0, c1, s1;  ///< the rotations at the substep's start and end
    Vec2d o0, o1, com1;
    double reach2;  ///< beyond this from com1, a particle's whole path misses the body (squared)
  };
  std::vector<BodyPose> bodyPoses;
  std::vector<int> contactCount;      ///< … its approaching contacts
  std::vector<Vec2d> contactImpulse;  ///< … the contacts' impulse on it
  std::vector<double> contactTorque;  ///< … and their angular impulse

  /// The moving bodies' boundary samples (body_samples.hpp), when the solver takes them.
  BodySamples bodySamples;
  /// True when the substep places moving bodies' samples: some moving body, and a solver that takes them.
  bool bodySamplesOn() const { return !moving.bodies.empty() && solver && solver->movingSamples(); }
  /// With moving bodies' samples (bodySamplesOn), true when local point p lies within 0.4
  /// spacing outside a moving body at the current pose: a particle there would overlap the
  /// samples' first layer (dx/2 deep), so a fluid block leaves it out (body_samples.cpp).
  bool nearMovingSamples(const Vec2& p) const;
  /// True when local point p lies outside every static solid but within 0.4 spacing of one's
  /// surface: a particle there would overlap its samples' first layer (dx/2 deep), so a fluid
  /// block leaves it out, as beside a moving body (a lattice row on a wall's face started at
  /// 1.6 ρ0 and threw a particle at 11 m/s; particle_sources.cpp).
  bool onStaticSurface(const Vec2& p) const;

  /// Changes of the particles made between steps (the API's adds, removals and moves):
  /// with `steps` and the count, what the query grid is valid for.
  std::uint64_t edits = 0;
  /// A uniform grid of the current particles for World's queries (queries.cpp): cells of
  /// side `h` from (x0, y0) over the particles' bounds, slots counting-sorted by cell.
  /// Built on the first query after a change, then each query visits only its cells.
  struct QueryGrid {
    std::uint64_t steps = ~std::uint64_t(0), edits = 0;
    std::size_t count = 0;
    double x0 = 0, y0 = 0, h = 1;
    long nx = 0, ny = 0;
    std::vector<std::uint32_t> start, items;  ///< cell k holds items[start[k] .. start[k + 1])
  };
  mutable QueryGrid queryGrid;
  /// The query grid of the current particles (rebuilt when stale).
  const QueryGrid& currentQueryGrid() const;
  /// Calls f(slot) for every particle whose world position may lie in [lo, hi] (the
  /// cells the box touches), in no particular order.
  template <class F>
  void forCandidates(const Vec2d& lo, const Vec2d& hi, F&& f) const {
    const QueryGrid& g = currentQueryGrid();
    if (g.nx == 0) return;
    // Local = world − origin, up to rounding: the box grows by a micrometre so that a particle
    // on a cell's edge is never missed (callers test each candidate exactly).
    const double ox = origin.x(), oy = origin.y();
    const Vec2d lo2 = lo - Vec2d(1e-6, 1e-6), hi2 = hi + Vec2d(1e-6, 1e-6);
    auto cell = [&](double v, double v0, long n) { return std::clamp(long(std::floor((v - v0) / g.h)), 0L, n - 1); };
    if (!(hi2.x() - ox >= g.x0 && hi2.y() - oy >= g.y0 && lo2.x() - ox <= g.x0 + double(g.nx) * g.h &&
          lo2.y() - oy <= g.y0 + double(g.ny) * g.h))
      return;  // outside the particles' bounds (or NaN)
    const long i0 = cell(lo2.x() - ox, g.x0, g.nx), i1 = cell(hi2.x() - ox, g.x0, g.nx);
    const long j0 = cell(lo2.y() - oy, g.y0, g.ny), j1 = cell(hi2.y() - oy, g.y0, g.ny);
    for (long j = j0; j <= j1; ++j)
      for (long i = i0; i <= i1; ++i) {
        const std::size_t k = std::size_t(j * g.nx + i);
        for (std::uint32_t q = g.start[k]; q < g.start[k + 1]; ++q) f(std::size_t(g.items[q]));
      }
  }

  /// The state of the particles and the scene's constants for a substep of length dt.
  Impl(const SceneDef& s, const WorldOptions& o) : scene(s), pool(o.threads), stop(o.stop) {}
  StepContext context(Real dt);

  // stepper.cpp
  /// (Re)builds the substep's stage list from the solver, the enabled effects and the particle system.
  void buildStages();
  /// Appends collide, wrap, lifetimes and sinks (those the scene needs) to `list`.
  void addParticleSystemStages(StageList& list);
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
  bool bodiesEverySubstep() const { return ownWorld && moving.anyDynamic() && bodySamplesOn(); }
  /// After a substep of `taken` seconds: with bodiesEverySubstep(), steps the scene's b2World by
  /// it and reads the bodies again.
  void bodiesFollow(Real taken);
  /// Throws the SimulationError naming the stage, the particle and its values.
  [[noreturn]] void fail(const std::string& stage, std::size_t slot);

  // particle_sources.cpp
  /// Fills a block on the lattice of the spacing (hydrostaticStart: rows closer with
  /// depth, at the density the solver holds at rest), keeping the points of its circle
  /// (a drop, addDrop) or polygon. Stops at the particle budget (one warning for the rest).
  /// Returns the ids added (consecutive: each particle takes the next id).
  IdRange fillBlock(const FluidBlockDef& b, bool hydrostaticStart);
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
  /// Removes the particles flagged in `dead` (stable order), counting them; `ids`, when
  /// given, receives their ids in increasing order.
  void removeFlagged(std::vector<std::uint32_t>* ids = nullptr);
  /// Removes the k oldest particles (smallest ids).
  void removeOldest(std::size_t k);

  // box2d_bridge.cpp
  /// A static body the game moved (SetTransform) since the last step, no faster than
  /// kStaticPushSpeed: through this step it moves as a kinematic body from its old pose to
  /// its new one (the water sees a moving wall), and it rejoins the static solids when it stops.
  struct SlidingStatic {
    b2Body* body = nullptr;
    Vec2d p0{0, 0};     ///< its origin at time t0 (world)
    double angle0 = 0;  ///< its angle at t0 [rad]
    Vec2d v{0, 0};      ///< its velocity over the step [m/s]
    double omega = 0;   ///< its angular velocity over the step [rad/s]
    double t0 = 0;      ///< the step's start
  };
  std::vector<SlidingStatic> sliding;
  /// The static bodies' poses at the last step's start (or the last re-read), by body.
  std::vector<std::pair<const void*, b2Transform>> staticPoses;
  /// XXH64 of the static fixtures' identities and transforms, the sliding ones left out:
  /// changes when the game edits its level.
  std::uint64_t staticSignature() const;
  /// Reads the colliders and boundary samples from the b2World's static bodies again, the
  /// sliding ones left out.
  void rebuildBoundary();
  /// At a step of `dt`: finds the sliding static bodies, then re-reads the static solids when
  /// they changed (dropBuried), and records the static poses.
  void readStatics(double dt);
  /// After rebuildBoundary: drops the particles now inside a static solid, with a warning.
  void dropBuried();
  /// Records every static body's pose (staticPoses).
  void recordStaticPoses();

  // contacts.cpp (World::setContactTracking)
  bool contactsOn = false;  ///< the `contacts` stage runs
  /// (fixture, particle id) of every contact at the end of a substep of the current (or last)
  /// step, sorted by fixture then id after the step (finishContacts).
  std::vector<std::pair<std::uintptr_t, std::uint32_t>> frameContacts;               ///< the fixture by its address
  std::vector<std::vector<std::pair<std::uintptr_t, std::uint32_t>>> contactBlocks;  ///< the stage's per-block scratch
  /// A moving body as the contacts stage sees it: its pose and centre at the substep's end.
  struct ContactPose {
    double theta = 0;
    Vec2d o{0, 0}, centre{0, 0};
  };
  std::vector<ContactPose> contactPoses;  ///< the stage's scratch, one per moving body
  /// The `contacts` stage: the particles within one spacing of each fixture now, into frameContacts.
  void recordContacts(StepContext& c);
  /// Sorts frameContacts and removes repeats (after a step).
  void finishContacts();
};

/// A b2World with the scene's gravity and static bodies (box2d_bridge.cpp).
std::unique_ptr<b2World> makeSceneWorld(const SceneDef& scene);

}  // namespace sph2d
