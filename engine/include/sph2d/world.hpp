// sph2d/world.hpp — the fluid world a game or the app steps frame by frame.
//
//   SceneDef ──> World(scene) ──> stepFrame() ──> particles(), stateHash()
//
// A World owns its particles, its job system and (unless a game attaches its
// own) a b2World of static bodies. One stepFrame() advances 1/fps seconds in
// substeps as long as the solver's and the effects' limits allow; each
// substep runs one list of stages built with the World (stages(); the list of
// a scene is in docs/ARCHITECTURE.md and printed by `sph2d info`).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "sph2d/boundary.hpp"
#include "sph2d/foam.hpp"
#include "sph2d/groups.hpp"
#include "sph2d/id_range.hpp"
#include "sph2d/particle_events.hpp"
#include "sph2d/particles.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/surface.hpp"
#include "sph2d/world_stats.hpp"

class b2World;
class b2Shape;
class b2Fixture;
struct b2Vec2;
struct b2Transform;

namespace sph2d {

/// A run that went wrong: which stage, which particle and its values.
class SimulationError : public std::runtime_error {
 public:
  /// Builds the error with a full diagnosis in what().
  SimulationError(const std::string& what, std::string stage, std::uint32_t particleId, std::uint64_t step,
                  double time);
  std::string stage;         ///< stage that produced the bad value
  std::uint32_t particleId;  ///< id of the first bad particle
  std::uint64_t step;        ///< substep counter
  double time;               ///< simulated time [s]
};

/// The World was asked to stop (its stop flag, WorldOptions::stop or World::setStopFlag, was
/// set) and stopped its work: `stage` names where (a stage of the substep, "construction: ..."
/// or the call that was adding particles). Thrown by the constructor (nothing is built), by
/// step()/stepFrame()/bench::stepSubstep() (the step is abandoned: see World::interrupted()) and by
/// the calls that add particles (nothing is added: the World is as before the call).
class Interrupted : public std::runtime_error {
 public:
  /// Builds the error; what() says where the World stopped.
  Interrupted(const std::string& what, std::string stage);
  std::string stage;  ///< where the work stopped ("neighbours", "construction: fluid[0]", "addBlock", ...)
};

/// Options of a World that are not part of the scene.
struct WorldOptions {
  int threads = 0;  ///< job-system threads; 0 = all hardware threads
  /// A flag the caller may set from any thread or a signal handler (an atomic<bool> is
  /// lock-free here) to make the World stop what it is doing within milliseconds: it is read
  /// between the stages of a substep, before each block of the job system's work and every
  /// few thousand lattice points when fluid is added or the World is built, then the work
  /// ends with sph2d::Interrupted. Never written by the World; reading it changes no result
  /// (the same bits with or without it). Null: the World never stops on its own. It must
  /// outlive the World (or be replaced with setStopFlag).
  const std::atomic<bool>* stop = nullptr;
};

/// A push/pull at a point, set at run time (the mouse of a game).
struct UserForce {
  Vec2d point{0, 0};    ///< world coordinates [m]
  double radius = 0.5;  ///< reach [m]
  double strength = 0;  ///< acceleration at the centre [m/s²]; > 0 pulls towards the point, < 0 pushes away
};

/// A saved state that World::load refuses: not a save, another scene's, or damaged.
struct SaveError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// What World::save() could not put in the save: state of the b2World the fluid meets (a game's,
/// or the scene's own) that Box2D 2.4 keeps to itself and a rebuilt b2World starts without, so
/// a World loaded from the save, on a b2World rebuilt with the same bodies, steps on close to
/// the saved one but not bit for bit. All zero (complete()) when none of it is live. What each
/// is and the remedy: docs/EMBEDDING.md, "Saving and loading".
struct SaveReport {
  /// Touching contacts (sensors left out) that involve a dynamic body while the b2World
  /// warm-starts (b2World::GetWarmStarting()): Box2D starts each contact's solve from its
  /// impulses of the last step, which it does not expose (nor lets be set); 0 when warm
  /// starting is off.
  std::size_t warmStartedContacts = 0;
  /// Joints that involve a dynamic body while the b2World warm-starts: their impulses likewise.
  std::size_t warmStartedJoints = 0;
  /// Awake moving bodies slower than Box2D's sleep tolerances (b2_linearSleepTolerance,
  /// b2_angularSleepTolerance) while the b2World lets bodies sleep: each has a sleep timer
  /// running, which no call reads or sets (a rebuilt body's starts at 0, so it falls asleep
  /// later); 0 when sleeping is off (b2World::GetAllowSleeping()).
  std::size_t sleepTimers = 0;
  /// What is lost and the remedy, in a sentence ("" when complete()). save() also gives it to
  /// takeWarnings(), the first time only (a game that saves every frame is told once).
  std::string warning;
  /// True when none of the above is live: with the same bodies rebuilt, a load steps on bit for bit.
  bool complete() const { return warmStartedContacts == 0 && warmStartedJoints == 0 && sleepTimers == 0; }
};

class World;
namespace bench {
/// Advances one CFL-limited substep: a hook for benchmarks and tests that time or inspect a
/// single substep, not part of a game's loop (which steps frames). Throws as World::step.
void stepSubstep(World& world);
}  // namespace bench

/// The fluid simulation.
class World {
 public:
  /// Builds the world of a scene: its own b2World, the fluid blocks, the solver.
  explicit World(const SceneDef& scene, const WorldOptions& options = {});
  /// Builds the fluid of `scene` in a b2World the game owns: every static
  /// fixture of `gameWorld` is solid to the fluid. The World never steps or destroys
  /// `gameWorld` (it must outlive the World) and changes it only by the fluid's impulse on
  /// its dynamic bodies (ApplyLinearImpulse / ApplyAngularImpulse after each step); the scene's
  /// own `boundaries` are ignored, with a warning. Static bodies the game adds,
  /// moves or removes later are picked up at the next frame.
  World(const SceneDef& scene, b2World& gameWorld, const WorldOptions& options = {});
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  /// Advances one frame (1/fps seconds) in CFL substeps. Throws SimulationError, and
  /// Interrupted when the stop flag is set (setStopFlag).
  void stepFrame();
  /// Advances `dt` seconds in CFL substeps. The scene's own b2World (not a game's) steps once by
  /// `dt` after them, or with every substep when a dynamic body meets a solver that samples the
  /// moving bodies (wcsph, muller2003, dfsph). Throws SimulationError, and Interrupted when
  /// the stop flag is set: before the step starts (nothing changed), or within it (the step
  /// is abandoned: interrupted()).
  void step(double dt);

  /// Replaces the stop flag (WorldOptions::stop; null: none). While the flag is set, a step
  /// and the calls that add particles throw sph2d::Interrupted within milliseconds (between
  /// stages, and at block granularity inside them: the cost is one relaxed load a block).
  void setStopFlag(const std::atomic<bool>* stop);
  /// True after a step was interrupted by the stop flag: that step stopped inside a stage,
  /// so the particles are as that stage left them (readable, every array of one length, but
  /// not a state the solver produced) and the World will not step again: step(),
  /// stepFrame() and bench::stepSubstep() throw sph2d::Interrupted naming the stage. load() of a
  /// saved state clears it (the World is then that state). A game that may stop a World
  /// midway and go on saves a state to go back to, or builds a new World.
  bool interrupted() const;

  /// The particles as read-only arrays by slot (local frame; add origin() for world
  /// coordinates). No copy is made: the views show the World's own arrays, and the World keeps
  /// them current after every step and every change of its particles, so the reference stays
  /// valid for the World's life. (An element read before a step is the value before it.)
  const Particles& particles() const;
  /// Number of particles.
  std::size_t particleCount() const;
  /// Offset of the local frame in world coordinates [m].
  Vec2d origin() const;
  /// World position of particle slot i.
  Vec2d worldPosition(std::size_t i) const;
  /// The solids, in the local frame.
  const std::vector<Collider>& colliders() const;
  /// Boundary samples (layers of dummy particles inside the solids), in the local frame.
  const std::vector<Vec2>& boundarySamples() const;
  /// The Box2D world the fluid collides with.
  b2World& box2d();
  /// Const variant of box2d().
  const b2World& box2d() const;
  /// The scene this world was built from.
  const SceneDef& scene() const;

  /// Simulated time [s].
  double time() const;
  /// Frames stepped.
  std::uint64_t frame() const;
  /// The substep length [s] the limits (CFL, force, effects) allow in the current state.
  double stableTimeStep() const;
  /// A particle's mass [kg per metre of depth] of the first material: its rest density times the
  /// spacing squared, the area it fills at rest (a particle of material k: × its density over the
  /// first's). Momentum, energy and the exchanges with bodies and walls count this mass.
  Real particleMass() const;
  /// Kernel support R [m].
  Real support() const;
  /// Particle spacing dx [m].
  Real spacing() const;
  /// Threads of the job system.
  int threads() const;

  /// XXH64 of (id, position, velocity, and material with more than one) in id order, plus the origin.
  std::uint64_t stateHash() const;
  /// Density error statistics of the current state.
  DensityStats densityStats() const;
  /// Kinetic energy ½ Σ m |v|² [J per metre of depth].
  double kineticEnergy() const;
  /// The impulse the static solids gave the fluid over every substep since construction, the
  /// last load() or the last resetWallImpulse() (whichever came last) [N·s per metre of depth].
  /// With the gravity impulse Σm·g·t it closes the fluid's momentum balance (docs/EMBEDDING.md)
  /// while nothing else acts on the fluid: no force fields, user forces, emitters, sinks,
  /// lifetimes or particle edits, and no moving bodies (their exchange is the bodies' own).
  /// A diagnostic: keeping it changes nothing in the simulation; not part of save().
  WallImpulse wallImpulse() const;
  /// Zeroes wallImpulse() (say, at the start of the interval a game wants to measure).
  void resetWallImpulse();
  /// The World's counts: frames, substeps, solver iterations, particles, neighbour pairs,
  /// removals and memory (WorldCounters).
  WorldCounters counters() const;
  /// Per-stage wall time and calls since construction or the last resetProfile().
  WorldProfile profile() const;
  /// Zeroes the stage timings of profile().
  void resetProfile();
  /// Messages the world wants the user to see (substep cap hits, dropped particles); cleared on read.
  std::vector<std::string> takeWarnings();

  /// Sets gravity [m/s²] from the next substep on (tilting the tank); the scene's own b2World
  /// takes it too (its dynamic bodies fall the same way). A game sets its own b2World's.
  void setGravity(const Vec2d& g);
  Vec2d gravity() const;  ///< the gravity of the next substep [m/s²] (setGravity or the scene's)
  /// Adds a block of fluid on the lattice of the scene's spacing (particles
  /// inside solids are skipped), row by row from the bottom, until the world holds
  /// its particle budget (max_particles, or effects.budget when set): the rest is
  /// refused with one warning (takeWarnings). Returns the ids of the particles added. The
  /// work grows with the lattice points of the block's rectangle, not only the particles
  /// added (points inside solids are visited too): a caller taking blocks from elsewhere
  /// bounds their area first. Throws Interrupted, adding nothing, when the stop flag is set.
  IdRange addBlock(const FluidBlockDef& block);
  /// Adds a drop of fluid: the lattice points of a block around `center` that lie
  /// within `radius` (world coordinates), moving at `velocity`; points inside
  /// solids are skipped; the particle budget holds as for addBlock. Returns the ids
  /// of the particles added, of `material`. Throws Interrupted, adding nothing, when the stop flag is set.
  IdRange addDrop(const Vec2d& center, double radius, const Vec2d& velocity = Vec2d(0, 0), std::uint32_t material = 0);
  /// Removes the particles inside the box [lo, hi] (world coordinates). Returns their ids,
  /// in increasing order.
  std::vector<std::uint32_t> removeParticlesInBox(const Vec2d& lo, const Vec2d& hi);

  /// The shapes of the moving (kinematic and dynamic) bodies at their current pose as the fluid
  /// meets them, in the local frame like colliders() (polygons with Box2D's skin, faces moved
  /// out by b2_polygonRadius and corners mitred; circles as they are; for drawing). They push
  /// the fluid, and the fluid pushes the dynamic ones.
  std::vector<Collider> movingColliders() const;
  /// Writes the World's whole changing state (particles with every field, time and
  /// counters, emitters with their random streams, gravity, user forces, switched
  /// effects, the solver's warm starts; the scene's own b2World's moving bodies with their
  /// awake state, and its warm-starting and sleeping switches) to `out`, in this machine's
  /// byte order. A World built from the same scene and load()ed from it steps on to the same
  /// state hashes, as far as the b2World allows: the report says what of its state no save
  /// can hold (Box2D's contact impulses, sleep timers), with a warning (takeWarnings) the
  /// first time. Throws SaveError when the stream refuses the bytes.
  SaveReport save(std::ostream& out) const;
  /// Replaces this World's state with one save() wrote for the same scene (on a machine
  /// with the same byte order). Throws SaveError, changing nothing, when the input is not
  /// a save, belongs to another scene or solver, is truncated, or holds a count beyond
  /// the particle budget or the scene's emitters.
  void load(std::istream& in);

  // Particles by id (particle_access.cpp). A slot changes when the grid reorders the
  // particles or some are removed; an id never does, so a game holds particles by id.

  /// The value slotOf() returns for an id no particle has.
  static constexpr std::size_t npos = static_cast<std::size_t>(-1);
  /// The storage slot of the particle with id `id` (P.id[slot] == id), or npos when no
  /// particle has it (removed, or never made). O(log n); the id index is rebuilt, O(n log n),
  /// only when a lookup finds it stale (after a step reordered or changed the particles).
  std::size_t slotOf(std::uint32_t id) const;
  /// Position (world coordinates) and velocity of particle `id`; false (outputs untouched)
  /// when no particle has the id.
  bool getParticle(std::uint32_t id, Vec2d& position, Vec2d& velocity) const;
  /// Moves particle `id` to `position` (world coordinates) with `velocity`, as a teleport:
  /// the next swept collision starts there. False, changing nothing, when no particle has
  /// the id or the position is inside a solid. Throws std::invalid_argument for a
  /// non-finite position or velocity.
  bool setParticle(std::uint32_t id, const Vec2d& position, const Vec2d& velocity);
  /// Sets the velocity of particle `id`; false when no particle has it. Throws
  /// std::invalid_argument for a non-finite velocity.
  bool setParticleVelocity(std::uint32_t id, const Vec2d& velocity);
  /// Bulk: the velocity of particle ids[k] becomes velocities[k]. Returns how many of the
  /// ids a particle has (the rest are skipped). Throws std::invalid_argument when the
  /// lengths differ or a velocity is not finite (then nothing is changed).
  std::size_t setVelocities(const std::vector<std::uint32_t>& ids, const std::vector<Vec2d>& velocities);
  /// Bulk read: positions[k] (world coordinates) and velocities[k] of particle ids[k]; both
  /// vectors are resized to ids.size(), and an id no particle has gets NaN in both. Returns
  /// how many of the ids a particle has. One id-index rebuild at most, then O(log n) an id.
  std::size_t getParticles(const std::vector<std::uint32_t>& ids, std::vector<Vec2d>& positions,
                           std::vector<Vec2d>& velocities) const;
  /// Bulk teleport: particle ids[k] moves to positions[k] (world coordinates), its velocity
  /// kept, as setParticle does (the next swept collision starts there). Ids no particle has,
  /// and positions inside a solid, are skipped. Returns how many particles moved. Throws
  /// std::invalid_argument when the lengths differ or a position is not finite (then nothing
  /// is changed).
  std::size_t setPositions(const std::vector<std::uint32_t>& ids, const std::vector<Vec2d>& positions);
  /// Adds one particle at each of `points` (world coordinates, any arrangement; the
  /// caller keeps them about a spacing apart) moving at velocities[k] (`velocities`
  /// empty: at rest). Points inside solids are skipped, and the particle budget holds as
  /// for addBlock (one warning for the refused rest). Returns the ids of the particles
  /// added, in the order of their points (a skipped point takes none). Throws
  /// std::invalid_argument when the lengths differ, a value is not finite or `material` does
  /// not exist (then nothing is added).
  IdRange addParticles(const std::vector<Vec2d>& points, const std::vector<Vec2d>& velocities = {},
                       std::uint32_t material = 0);
  /// Removes the particles with these ids (ids no particle has, and repeats, are ignored).
  /// Returns the ids removed, in increasing order.
  std::vector<std::uint32_t> removeParticles(const std::vector<std::uint32_t>& ids);
  /// Sets the destruction listener (particle_events.hpp; empty: none, the default). Only
  /// while one is set are the removed ids collected.
  void setDestructionListener(DestructionListener listener);
  /// Each particle of `ids` leaves the World `seconds` from now (within the substep that
  /// passes that time; 0: in the next substep; infinity: never, the default). Returns how
  /// many of the ids a particle has. The field and its stage exist from the first call on
  /// (kept through save/load). Throws std::invalid_argument for a negative or NaN `seconds`.
  std::size_t setLifetimes(const std::vector<std::uint32_t>& ids, double seconds);
  /// The seconds particle `id` has left (infinity: no lifetime of its own, or no such particle).
  double lifetimeLeft(std::uint32_t id) const;
  /// Calls f for each particle whose disc (radius half the spacing) the segment p1 → p2
  /// enters, nearest first (ties by id), until f returns false; a disc p1 lies in is not
  /// hit. Visits only the neighbour grid's cells along the segment.
  void rayCast(const Vec2d& p1, const Vec2d& p2, const std::function<bool(const RayHit&)>& f) const;
  /// The nearest hit of rayCast(p1, p2); false (and `hit` untouched) when there is none.
  bool rayCastFirst(const Vec2d& p1, const Vec2d& p2, RayHit& hit) const;
  /// The fluid's outlines now (surface.hpp: closed curves in world coordinates, holes
  /// clockwise), from the particles of options.material or of every material. Costs one pass
  /// over the particles and one over the nodes around them; nothing is kept.
  std::vector<SurfaceCurve> surfaceCurves(const SurfaceOptions& options = {}) const;
  /// The diffuse particles of `effects.foam` (sph2d/foam.hpp): spray, foam and bubbles, in the
  /// local frame (add origin()); empty without the effect. Valid until the next step.
  DiffuseParticles diffuse() const;
  /// Sets (or with an empty listener clears) the particle contact listener: after each step
  /// the pairs of particles touching that `filter` takes (particle_events.hpp). While none is
  /// set nothing is computed; with one, a search around each particle of either side.
  void setParticleContactListener(const ParticleContactFilter& filter, ParticleContactListener listener);
  /// Makes a group (groups.hpp) of new particles filling def.region; `ids` (when given) gets
  /// them. Returns the group's index: one past the highest a particle holds now (the index of
  /// a group whose particles are all gone may be given again). The fields and the `groups`
  /// stage exist from the first group on. Throws std::invalid_argument for a stiffness
  /// outside (0, 1] or a region that makes no particle (nothing added).
  std::uint32_t createGroup(const GroupDef& def, IdRange* ids = nullptr);
  /// The state of group `group` now; false when no particle is in it.
  bool groupState(std::uint32_t group, GroupState& state) const;
  /// Gives group `group` a linear impulse (N·s per metre of depth) at its centre and an
  /// angular one (N·m·s per metre): each particle's velocity changes as the rigid body's.
  /// False when no particle is in it.
  bool applyGroupImpulse(std::uint32_t group, const Vec2d& linear, double angular);
  /// Ends group `group`: its particles go free as fluid, or with `withParticles` are removed
  /// (to the destruction listener as a game call). False when no particle is in it.
  bool destroyGroup(std::uint32_t group, bool withParticles = false);
  /// Joins group `from` into `into`: one group, of `into`'s stiffness and strains, whose rest
  /// shape is the two as they are now. False when either has no particle or they are one.
  bool joinGroups(std::uint32_t into, std::uint32_t from);
  /// Splits group `group` into the parts of it connected now (neighbours at most 1.5
  /// spacings apart): the largest keeps the index, each other part of 3 or more particles
  /// gets a new one (returned, by its lowest slot), smaller parts go free as fluid.
  std::vector<std::uint32_t> splitGroup(std::uint32_t group);
  /// One past the highest group index a particle holds (0: no group).
  std::uint32_t groupCount() const;

  // Per-particle colour and user data: each field is allocated on the first set (every
  // other particle, and every particle added later, holds 0), kept through reordering,
  // removal and save/load, and not part of stateHash().

  /// Sets the colour of particle `id` (0xRRGGBB; the renderer's particles mode draws it with
  /// `color_by: color`; 0 means "none of its own"). False when no particle has the id.
  bool setParticleColor(std::uint32_t id, std::uint32_t rgb);
  /// Bulk: the colour of particle ids[k] becomes colors[k]. Returns how many of the ids a
  /// particle has. Throws std::invalid_argument when the lengths differ.
  std::size_t setParticleColors(const std::vector<std::uint32_t>& ids, const std::vector<std::uint32_t>& colors);
  /// The colour of particle `id` (0 when it has none, no particle has the id, or no colour
  /// was ever set).
  std::uint32_t particleColor(std::uint32_t id) const;
  /// Sets the game's value for particle `id` (an index into the game's own table, say).
  /// False when no particle has the id.
  bool setParticleUserData(std::uint32_t id, std::uint32_t value);
  /// The game's value of particle `id` (0 when none was set or no particle has the id).
  std::uint32_t particleUserData(std::uint32_t id) const;
  /// Turns on (or off) the emitter tag: from then on every particle an emitter makes carries
  /// that emitter's index (particleEmitter(); Particles::emitter holds 1 + it). Particles there
  /// when it is turned on, and those other calls add, carry none. Off by default: the field
  /// exists only while it is on (no memory, no work); turning it off frees it. Kept like the
  /// colour (a save holds it, and loading a save that has it turns it on); not in stateHash().
  void setEmitterTracking(bool on);
  /// True while the emitter tag is on (setEmitterTracking).
  bool emitterTracking() const;
  /// The index of the emitter that made particle `id`, as emitters are numbered now
  /// (removeEmitter moves the later ones' particles down one, and leaves the removed one's
  /// with none); npos when it has none (made by another call, or while tracking was off),
  /// tracking is off, or no particle has the id.
  std::size_t particleEmitter(std::uint32_t id) const;

  /// Slots of the particles inside `shape` placed by `xf` (world coordinates; b2Shape::TestPoint:
  /// polygons and circles hold points, edges and chains none), in slot order.
  std::vector<std::size_t> slotsInShape(const b2Shape& shape, const b2Transform& xf) const;
  /// Removes the particles inside `shape` placed by `xf`. Returns their ids, in increasing order.
  std::vector<std::uint32_t> removeParticlesInShape(const b2Shape& shape, const b2Transform& xf);
  /// Fills `shape` placed by `xf` (a b2PolygonShape or b2CircleShape) with fluid on the lattice
  /// of the scene's spacing, moving at `velocity`, as addBlock does (solids skipped, the budget
  /// held). Returns the ids added. Throws std::invalid_argument for an edge or chain, and
  /// Interrupted (nothing added) when the stop flag is set.
  IdRange addShape(const b2Shape& shape, const b2Transform& xf, const Vec2d& velocity = Vec2d(0, 0),
                   std::uint32_t material = 0);
  // The searches below visit only the cells of a grid of the current particles, built on the
  // first search after a step or a change (O(n)), not every particle.
  /// Slots of the particles within `radius` of `center` (world coordinates), in slot order.
  std::vector<std::size_t> slotsInRadius(const Vec2d& center, double radius) const;
  /// Slots of the particles inside the box [lo, hi] (world coordinates), in slot order.
  std::vector<std::size_t> slotsInBox(const Vec2d& lo, const Vec2d& hi) const;
  /// Shepard-normalised SPH samples at a world point: density [kg/m³] and velocity [m/s]
  /// (Σ V_j A_j W / Σ V_j W over the fluid, Wendland C2 kernel of the world's support).
  /// Where no particle is within the support, density 0 and velocity 0.
  struct FieldSample {
    double density = 0;
    Vec2d velocity{0, 0};
    double weight = 0;  ///< Σ V_j W: near 1 inside the fluid, 0 far from it
  };
  /// Samples the fluid's fields at `point`.
  FieldSample sampleAt(const Vec2d& point) const;
  /// The ids of the particles touching `fixture` now (between frames: at the end of the last
  /// one): their centres within one spacing of its surface, or inside it; in slot order. Any
  /// fixture of the b2World the fluid sees, static or moving, at the body's current pose; the
  /// surface where the fluid meets it (a moving body's polygon with Box2D's skin, or its
  /// fixture for a solver that samples moving bodies: wcsph, muller2003). With contact
  /// tracking on (setContactTracking), also every particle still in the World that touched it
  /// at the end of a substep of the last step.
  std::vector<std::uint32_t> idsTouching(const b2Fixture& fixture) const;
  /// Calls f(fixture, ids) for every fixture of box2d() that particles touch now, with their
  /// ids as idsTouching() gives them; bodies and fixtures in Box2D's list order. The
  /// game's contact listener for the fluid (a button the water reaches, a fire it puts out).
  void forEachContact(const std::function<void(const b2Fixture&, const std::vector<std::uint32_t>&)>& f) const;
  /// Turns on (or off) the `contacts` stage: at the end of every substep it records which
  /// particles touch which fixture, so that idsTouching() and forEachContact() also
  /// report the particles that touched a fixture during the last step and left it before its
  /// end (a splash that hit a button and bounced off; a jet through a sensor), not only those
  /// touching it at the step's end. Off by default: the stage exists only while it is on.
  void setContactTracking(bool on);
  /// True while contact tracking is on (setContactTracking).
  bool contactTracking() const;
  /// Re-reads the static fixtures of the b2World now, every static body where it is (step
  /// and stepFrame do it when they changed, sliding a moved one instead: below). Particles
  /// a static solid now covers are removed, with a warning (takeWarnings).
  ///
  /// A static body the game moves with SetTransform between steps, at no more than 10 m/s
  /// at any point, is a sliding wall: through the next step it moves from its old pose to
  /// its new one as a kinematic body would, pushing the water ahead of it, and it is a
  /// static solid again from the first step it did not move. A faster move is a teleport.
  void refreshBoundaries();

  /// Replaces the user forces (push/pull at points). The user_force stage
  /// exists only once a force has been set.
  void setUserForces(const std::vector<UserForce>& forces);
  const std::vector<UserForce>& userForces() const;  ///< the forces setUserForces set (none at first)
  /// Enables or disables emitter `index` (scene order). Throws std::out_of_range.
  void setEmitterEnabled(std::size_t index, bool enabled);
  bool emitterEnabled(std::size_t index) const;  ///< emitter `index` emits (std::out_of_range)
  /// Moves emitter `index` to `position` shooting along `direction` (normalised here)
  /// from the next substep on; its timing, seed and count continue. Throws
  /// std::out_of_range for a bad index, std::invalid_argument for a zero direction.
  void moveEmitter(std::size_t index, const Vec2d& position, const Vec2d& direction);
  /// The current settings of emitter `index` (position, direction, enabled...). Throws std::out_of_range.
  const EmitterDef& emitter(std::size_t index) const;
  /// Adds an emitter (a faucet the player places) after the others; returns its index. Its
  /// `start` and `stop` are simulated times: a start already past means now (nothing is owed
  /// for the time before). Its seed gives its own random stream, as in a scene. Throws
  /// std::invalid_argument naming the field when a value is outside the scene format's range
  /// (docs/SCENES.md, `effects.emitters`) or the direction is zero.
  std::size_t addEmitter(const EmitterDef& def);
  // Materials (docs/SCENES.md, "materials"): the scene's, then those added here, by index; a
  // block, drop, shape, emitter or addParticles names one (default 0, the solver's fluid).
  /// Adds material `m`; returns its index. Throws std::invalid_argument naming the problem
  /// (materialProblem(): a name taken, a value out of range, a contrast the solver cannot take).
  std::uint32_t addMaterial(const MaterialDef& m);
  const std::vector<MaterialDef>& materials() const;           ///< every material, by index
  static constexpr std::uint32_t kNoMaterial = 0xFFFFFFFFu;    ///< materialIndex/materialOf: none
  std::uint32_t materialIndex(const std::string& name) const;  ///< the index of `name`, or kNoMaterial
  /// The material of particle `id` (kNoMaterial when no particle has it); bulk: particles().material.
  std::uint32_t materialOf(std::uint32_t id) const;
  /// Particle `id`'s concentration of `material` (with mixing; else 1 for its own, 0 for others;
  /// NaN when no particle has the id). Its colour from them: particles().mixedColor.
  double concentrationOf(std::uint32_t id, std::uint32_t material) const;
  /// Σ over the particles of their concentration of `material` (in double, in slot order).
  double totalConcentration(std::uint32_t material) const;
  /// Removes emitter `index` (its particles stay); the emitters after it move down one index.
  /// Throws std::out_of_range.
  void removeEmitter(std::size_t index);
  /// Number of emitters: the scene's and those added since, less those removed.
  std::size_t emitterCount() const;
  /// Switches an effect the scene enables ("viscosity", "xsph", "force_fields",
  /// "surface_tension", "interface_tension", "shifting", "mixing", "user_force") on or off. Throws
  /// std::invalid_argument naming the scene's effects when it has no such effect.
  void setEffectEnabled(const std::string& name, bool enabled);
  bool effectEnabled(const std::string& name) const;  ///< the effect runs (refused as setEffectEnabled)
  /// Names of the effects this world can run (enabled or not), in stage order.
  std::vector<std::string> effects() const;
  /// Particles emitted so far by emitter `index`.
  std::uint64_t emittedCount(std::size_t index) const;
  /// Names of the per-particle fields this world allocates (the fixed ones
  /// and the optional ones its solver and effects created).
  std::vector<std::string> particleFields() const;
  /// Names of the stages a substep runs, in order: the list built with the World
  /// (the solver's stages with the enabled effects where the solver puts them,
  /// then collision and the particle system), rebuilt when a user force is first
  /// set or an effect is switched.
  std::vector<std::string> stages() const;

  // b2Vec2 overloads (defined in sph2d/world_b2vec2.hpp): a game passes its Box2D vectors as
  // they are; each does exactly what the Vec2d call of the same name does. Templates on the type
  // (only b2Vec2 qualifies), so a braced pair {x, y} still picks the Vec2d call. The structs'
  // Vec2d fields take a b2Vec2 as it is: Vec2d converts from one (math.hpp).
  template <class T>
  using IfB2 = std::enable_if_t<std::is_same<T, b2Vec2>::value, int>;
  template <class B2, IfB2<B2> = 0>
  void setGravity(const B2& g);
  template <class B2, IfB2<B2> = 0>
  IdRange addDrop(const B2& center, double radius, const B2& velocity, std::uint32_t material = 0);
  template <class B2, IfB2<B2> = 0>
  IdRange addDrop(const B2& center, double radius);
  template <class B2, IfB2<B2> = 0>
  B2 worldPosition(std::size_t i) const;
  template <class B2, IfB2<B2> = 0>
  bool getParticle(std::uint32_t id, B2& position, B2& velocity) const;
  template <class B2, IfB2<B2> = 0>
  bool setParticle(std::uint32_t id, const B2& position, const B2& velocity);
  template <class B2, IfB2<B2> = 0>
  bool setParticleVelocity(std::uint32_t id, const B2& velocity);
  template <class B2, IfB2<B2> = 0>
  IdRange addParticles(const std::vector<B2>& points, const std::vector<B2>& velocities, std::uint32_t material = 0);
  template <class B2, IfB2<B2> = 0>
  IdRange addParticles(const std::vector<B2>& points);
  template <class B2, IfB2<B2> = 0>
  std::vector<std::size_t> slotsInRadius(const B2& center, double radius) const;
  template <class B2, IfB2<B2> = 0>
  std::vector<std::size_t> slotsInBox(const B2& lo, const B2& hi) const;
  template <class B2, IfB2<B2> = 0>
  FieldSample sampleAt(const B2& point) const;
  template <class B2, IfB2<B2> = 0>
  void moveEmitter(std::size_t index, const B2& position, const B2& direction);
  template <class B2, IfB2<B2> = 0>
  std::vector<std::uint32_t> removeParticlesInBox(const B2& lo, const B2& hi);
  template <class B2, IfB2<B2> = 0>
  IdRange addShape(const b2Shape& shape, const b2Transform& xf, const B2& velocity, std::uint32_t material = 0);
  template <class B2, IfB2<B2> = 0>
  std::size_t setVelocities(const std::vector<std::uint32_t>& ids, const std::vector<B2>& velocities);
  template <class B2, IfB2<B2> = 0>
  std::size_t setPositions(const std::vector<std::uint32_t>& ids, const std::vector<B2>& positions);
  template <class B2, IfB2<B2> = 0>
  std::size_t getParticles(const std::vector<std::uint32_t>& ids, std::vector<B2>& positions,
                           std::vector<B2>& velocities) const;

 private:
  friend void bench::stepSubstep(World& world);
  struct Impl;  ///< the World's state and its subsystems (engine/src/world/world_impl.hpp)
  template <class B2>
  static std::vector<Vec2d> toVec2d(const std::vector<B2>& in);
  void init();
  void initPhases(std::string& phase);
  std::unique_ptr<Impl> impl_;
};

}  // namespace sph2d

#include "sph2d/world_b2vec2.hpp"
