// sph2d/scene.hpp — scene definitions (Def structs with defaults) and the
// JSON scene loader. Every key is documented in docs/SCENES.md. The fluid
// block and the input events a scene holds are declared in
// sph2d/fluid_block.hpp and sph2d/events.hpp, included here.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "sph2d/events.hpp"
#include "sph2d/fluid_block.hpp"
#include "sph2d/groups.hpp"
#include "sph2d/math.hpp"

namespace sph2d {

struct SceneDef;

/// A bad scene file: says which file, where, which key and what is allowed.
class SceneError : public std::runtime_error {
 public:
  /// Builds the error; `what()` is "file:line:col: key: message".
  SceneError(std::string file, int line, int column, std::string key, std::string message);
  std::string file;     ///< the scene file
  int line = 0;         ///< 1-based line (0 when unknown)
  int column = 0;       ///< 1-based column (0 when unknown)
  std::string key;      ///< key path, e.g. "boundaries[0].fixtures[2].radius"
  std::string message;  ///< what is wrong and what is allowed
};

/// One fixture of a static body (Box2D 2.4.1 shapes).
struct ShapeDef {
  /// Box2D shape kinds that scenes may use.
  enum class Type { Box, Polygon, Circle, Edge, Chain };
  Type type = Type::Box;
  Vec2d center{0, 0};           ///< box / circle centre in body coordinates
  double angle = 0;             ///< box rotation in the body [rad]
  Vec2d halfSize{0.5, 0.5};     ///< box half extents
  std::vector<Vec2d> vertices;  ///< polygon / edge (2) / chain vertices in body coordinates
  double radius = 0.5;          ///< circle radius
  bool loop = false;            ///< chain closes on itself
  double friction = 0.2;        ///< fixture friction (Box2D and fluid)
  double restitution = 0.0;     ///< fixture restitution (Box2D and fluid)
  double density = 1000.0;  ///< dynamic bodies: mass per area [kg/m²] (the fluid's rest density floats at the surface)
};

/// A Box2D body with its fixtures: static (a wall), kinematic (moved at a set velocity
/// by Box2D; it pushes the fluid, the fluid does not push it) or dynamic (moved by Box2D
/// under gravity, its contacts and the fluid's pressure; it pushes the fluid too).
struct BodyDef {
  /// How the body moves.
  enum class Type { Static, Kinematic, Dynamic };
  Type type = Type::Static;
  Vec2d position{0, 0};        ///< body origin in world coordinates [m]
  double angle = 0;            ///< body rotation [rad]
  Vec2d velocity{0, 0};        ///< kinematic: velocity; dynamic: initial velocity of its centre of mass [m/s]
  double angularVelocity = 0;  ///< kinematic: [rad/s], about `position` (Box2D turns a kinematic body about its
                               ///< origin); dynamic: initial, about its centre of mass
  std::vector<ShapeDef> fixtures;
};

/// Periodic boundaries: an axis with `x` (or `y`) set wraps at [min, max) —
/// a particle leaving one side enters at the other, and pairs interact
/// across the seam by the nearest image. Solids crossing a periodic seam
/// must extend at least one support radius beyond it (docs/SCENES.md).
struct PeriodicDef {
  bool x = false, y = false;
  Vec2d min{0, 0};  ///< lower corner of the periodic box (used per periodic axis)
  Vec2d max{0, 0};  ///< upper corner
  /// True when some axis wraps.
  bool any() const { return x || y; }
};

/// Pressure solver and its numerical parameters.
struct SolverDef {
  std::string type = "muller2003";    ///< pressure solver
  double spacing = 0.02;              ///< particle spacing dx [m]
  double supportRatio = 2.5;          ///< kernel support R = supportRatio · dx
  double restDensity = 1000;          ///< ρ0 [kg/m³]
  double soundSpeed = 25;             ///< c: p = c²(ρ − ρ0) (stiffness K = c²) [m/s]
  double viscosity = 0.01;            ///< kinematic viscosity ν [m²/s] (muller2003 heats up below ~0.005)
  bool noSlip = false;                ///< viscosity also acts between the fluid and the walls (no-slip walls)
  double cfl = 0.25;                  ///< dt ≤ cfl · R / (c + v_max)
  int maxSubsteps = 400;              ///< cap per frame; beyond it the frame advances less time
  bool clampNegativePressure = true;  ///< p = max(p, 0): no tension at the free surface
  int reorderInterval = 1;            ///< reorder particles along the grid every N substeps (0: never)
  double maxSpeed = 500;              ///< the guard stops a run above this speed [m/s]
  /// Solver-specific parameters (each solver declares its keys, defaults and
  /// ranges; the loader fills every declared key, with its default when absent).
  std::map<std::string, double> params;
  /// The value of solver parameter `key` (throws std::out_of_range if the solver has none).
  double param(const std::string& key) const { return params.at(key); }
};

/// The quality presets a scene (`solver.quality`) or a program can ask for.
/// "game": real time (the game solver), "balanced": wcsph, "accurate": dfsph.
const std::vector<std::string>& qualityPresets();

/// The solver definition of a quality preset: its solver type, the shared keys
/// that solver tunes by default (e.g. the game solver's viscosity and support)
/// and every parameter at its default. Throws std::invalid_argument naming the
/// presets for an unknown name.
SolverDef qualityPreset(const std::string& quality);

/// The solver definition of solver `type` with its defaults (shared keys it
/// tunes and its own parameters). Throws std::invalid_argument for an unknown type.
SolverDef solverDefaults(const std::string& type);

/// What is wrong with `def` as "solver.<key>: why" (a shared key or a parameter outside its
/// range or not finite, a parameter its solver does not declare, an unknown type, a
/// combination its solver cannot run), or "" when nothing. Parameters left out count at
/// their defaults. The World refuses such a solver with a SceneError naming the key.
std::string solverDefProblem(const SolverDef& def);

/// The world rectangle the image shows (aspect preserved by widening).
struct CameraDef {
  Vec2d min{0, 0};
  Vec2d max{0, 0};
  bool automatic = true;  ///< fit the boundaries when no camera is given
};

/// Renderer settings (used by sph2d::render; the engine ignores them).
struct RenderDef {
  int width = 960;
  int height = 540;
  std::string mode = "liquid";  ///< "liquid" or "particles"
  std::array<double, 3> background{0.06, 0.07, 0.09};
  std::array<double, 3> water{0.10, 0.45, 0.85};
  std::array<double, 3> solid{0.55, 0.52, 0.48};
  double splatRadius = 2.0;  ///< splat radius in particle spacings
  /// Liquid mode: the share of each colour channel of what is behind the water (background,
  /// solids) that a full layer of water lets through; thinner water (edges, spray) lets through
  /// transmission^fill (Beer–Lambert, its thickness following the field's fill). 0 0 0: opaque.
  std::array<double, 3> transmission{0.25, 0.4, 0.5};
  /// Liquid mode: how far what is seen through the water is shifted where the water's thickness
  /// changes (its front face tilts: refraction), in particle spacings at the steepest. 0: none.
  double refraction = 1.0;
  static constexpr double kMaxRefraction = 4;
  /// Side [m] of square tiles drawn into the background, world-aligned (something to see the
  /// water's refraction against); 0: a plain background.
  double tiles = 0;
  CameraDef camera;
};

/// A material: what a fluid region, an emitter, a drop or a game's particles are made of
/// (docs/SCENES.md, "materials"). A scene without a `materials` table has one, named
/// "fluid", with the solver's rest density and viscosity and the render's water colour.
/// Each particle of a World holding more than one material carries its material's index
/// (World::materialOf); a World of one material holds no such field.
struct MaterialDef {
  std::string name = "fluid";
  double density = 1000;                          ///< rest density ρ0 [kg/m³]
  double viscosity = -1;                          ///< kinematic ν [m²/s]; < 0: the solver's (solver.viscosity)
  std::array<double, 3> color{0.10, 0.45, 0.85};  ///< drawn colour, linear RGB in 0..1
  /// Liquid mode: the share of each channel of what is behind it that a full layer lets through
  /// (RenderDef::transmission, per material). A scene's materials default to its render's; one
  /// made in code (World::addMaterial) has this unless the game sets it.
  std::array<double, 3> transmission{0.25, 0.4, 0.5};
  std::vector<std::string> miscibleWith;  ///< the materials it mixes with, by name
  double diffusion = 1e-3;  ///< D [m²/s] of dc/dt = D∇²c with a material it mixes with (the pair's mean)
  /// Interface tension σ [N/m] with materials before it, by name (a pair that does not mix).
  std::vector<std::pair<std::string, double>> tensionWith;
  /// A liquid, or a granular material (sand, powder): a liquid whose shear stress is bounded by
  /// Coulomb friction, cohesion + tan(frictionAngle)·pressure (the granular effect; game solver).
  enum class Kind { fluid, granular };
  Kind kind = Kind::fluid;
  double frictionAngle = 30;  ///< granular: the angle of repose [degrees]; 0 flows as a liquid
  double cohesion = 0;        ///< granular: the shear stress it bears at no pressure [Pa]
  bool granular() const { return kind == Kind::granular; }
  // The ranges a scene's `materials[]` and World::addMaterial accept.
  static constexpr double kMinDensity = 1, kMaxDensity = 1e5, kMaxViscosity = 1e3, kMaxDiffusion = 1;
  static constexpr double kMaxTension = 1e3;
  static constexpr double kMaxFrictionAngle = 60, kMaxCohesion = 1e5;
  static constexpr std::size_t kMaxMaterials = 256, kMaxName = 64;
};

/// The kinematic viscosity material `m` has in a World of `solver` (its own, or solver.viscosity).
double viscosityOf(const MaterialDef& m, const SolverDef& solver);

/// True when solver `type` takes materials of different rest density in one pressure solve.
bool takesDensityContrast(const std::string& type);

/// Why `scene`'s effects cannot run beside materials of different density ("" when they can):
/// the effects that weigh neighbours by one particle mass.
std::string densityContrastProblem(const SceneDef& scene);

/// The materials of `scene`: its `materials` table, or when it has none the one material
/// made from its solver (rest density, viscosity) and its render's water colour.
std::vector<MaterialDef> sceneMaterials(const SceneDef& scene);

/// Why `m` cannot join `materials` in a World of `solver` ("" when it can): a name that is
/// empty, too long or already taken, a density or viscosity out of range, a miscible_with
/// naming no material, or a density the solver cannot take beside the first material's
/// (wcsph, pbf and game take a density contrast: docs/SCENES.md).
std::string materialProblem(const std::vector<MaterialDef>& materials, const MaterialDef& m, const SolverDef& solver);

/// An axis-aligned box region.
struct RegionDef {
  Vec2d min{0, 0};
  Vec2d max{0, 0};
  /// True when p lies inside (boundary included).
  bool contains(const Vec2d& p) const {
    return p.x() >= min.x() && p.y() >= min.y() && p.x() <= max.x() && p.y() <= max.y();
  }
};

/// A constant acceleration, everywhere or in a region (wind, currents).
struct ForceFieldDef {
  Vec2d acceleration{0, 0};  ///< m/s²
  bool everywhere = true;    ///< false: only inside `region`
  RegionDef region;
};

/// Surface tension. "csf": Müller et al. 2003's colour-field model;
/// "akinci": cohesion + curvature of Akinci, Akinci & Teschner 2013.
struct SurfaceTensionDef {
  std::string model = "akinci";
  double sigma = 0.0728;   ///< csf: surface tension coefficient [N/m]
  double gamma = 1.0;      ///< akinci: cohesion/curvature strength (dimensionless scale of σ)
  double threshold = 0.1;  ///< csf: |∇c| below threshold·(1/R) is not surface
};

/// An emitter of the particle system (emitters, lifetimes, forces, as in the
/// RWTH Aachen SPH tutorial's simple particle system): a nozzle at `position`
/// of `width`, shooting along `direction`.
struct EmitterDef {
  Vec2d position{0, 0};
  Vec2d direction{0, -1};      ///< normalised by the loader
  double width = 0;            ///< nozzle width across the direction [m] (0: a point)
  double rate = 100;           ///< particles per second
  double speed = 2;            ///< m/s along the direction
  double spread = 0;           ///< full cone angle of random directions [rad]
  double jitter = 0;           ///< random speed variation, fraction of speed
  double start = 0;            ///< s
  double stop = 1e30;          ///< s
  std::uint64_t seed = 1;      ///< per-emitter random seed: same seed, same particles
  bool enabled = true;         ///< input events may switch it
  std::uint32_t material = 0;  ///< what it emits: an index in the World's materials (scene: by name)
  // The ranges a scene's `effects.emitters[]` and World::addEmitter accept (0 up to these).
  static constexpr double kMaxWidth = 1e4, kMaxRate = 1e8, kMaxSpeed = 1e4, kMaxSpread = 6.2832, kMaxJitter = 1;
  static constexpr double kMaxStart = 1e9, kMaxStop = 1e30;
  static constexpr std::uint64_t kMaxSeed = 9007199254740992ULL;  ///< 2^53: exact in a JSON number
};

/// What happens when the particle budget is reached.
enum class BudgetPolicy {
  StopEmitting,   ///< emitters emit nothing until particles leave (default)
  RecycleOldest,  ///< the oldest particles (smallest ids) are removed to make room
};

/// Foam, spray and bubbles (`effects.foam`, sph2d/foam.hpp): the thresholds [lo, hi] between
/// which each potential rises from 0 to 1, how many diffuse particles a liquid particle sheds
/// per second at full potentials, their lifetimes and motion, and their largest number.
struct FoamDef {
  Vec2d trappedAir{2, 10};  ///< Σ |v_ij| (1 − v̂_ij·x̂_ij) W̃ [m/s]
  Vec2d waveCrest{0.5, 3};  ///< κ̃ where the surface moves outward
  Vec2d energy{1, 10};      ///< ½|v|² [J/kg]
  double rate = 100;        ///< diffuse particles per second at full potentials [1/s]
  Vec2d lifetime{1, 3};     ///< each lives a time drawn uniformly between these [s]
  double buoyancy = 2;      ///< bubbles: the upward push, in multiples of |g|
  double drag = 20;         ///< bubbles: the rate they take the liquid's velocity [1/s]
  std::size_t maxParticles = 50000;
  static constexpr double kMaxThreshold = 1e6, kMaxRate = 1e5, kMaxLifetime = 1e4;
  static constexpr double kMaxBuoyancy = 100, kMaxDrag = 1e4;
  static constexpr std::size_t kMaxParticles = 4000000;
};

/// The effects a scene calls for. Absent effects cost nothing.
struct EffectsDef {
  bool xsph = false;
  double xsphC = 0.05;          ///< XSPH velocity smoothing factor
  bool shifting = false;        ///< particle shifting (Lind et al. 2012)
  double shiftingStrength = 2;  ///< A in D = A h v_max dt
  std::vector<ForceFieldDef> forceFields;
  bool surfaceTension = false;
  SurfaceTensionDef tension;
  bool lifetime = false;
  double maxAge = 10;  ///< s: older particles are removed
  std::vector<RegionDef> sinks;
  std::vector<EmitterDef> emitters;
  std::size_t budget = 0;  ///< particle budget (0: max_particles)
  BudgetPolicy budgetPolicy = BudgetPolicy::StopEmitting;
  bool foam = false;  ///< foam, spray and bubbles (sph2d/foam.hpp)
  FoamDef foamDef;
};

/// A whole scene: the solids, the fluid, the solver, the clock and the camera.
struct SceneDef {
  std::string name = "scene";
  /// The materials (`materials`); empty: one, made from the solver (sceneMaterials()).
  std::vector<MaterialDef> materials;
  std::string path;  ///< file it came from ("" when built in code)
  Vec2d gravity{0, -9.81};
  /// Real time unless the program names another: the game preset (qualityPreset("game")). To
  /// name a solver, start from its own defaults (`solver = solverDefaults("wcsph")` or
  /// `qualityPreset("accurate")`), not by changing `solver.type` alone: the game's viscosity,
  /// support and parameters would stay.
  SolverDef solver = qualityPreset("game");
  std::vector<BodyDef> bodies;
  std::vector<FluidBlockDef> blocks;
  std::vector<GroupDef> groups;        ///< particle groups made with the World (`groups`), after the blocks
  PeriodicDef periodic;                ///< periodic axes (none by default)
  double fps = 60;                     ///< frames per simulated second
  double duration = 4;                 ///< simulated seconds the app renders
  std::size_t maxParticles = 4000000;  ///< refuse scenes with more particles than this
  EffectsDef effects;
  RenderDef render;
  std::vector<EventDef> events;  ///< the timeline (`events`), in file order, each stamped
};

/// Loads and validates a scene file. Throws SceneError.
SceneDef loadScene(const std::string& path);

/// Parses scene JSON text; `file` names it in errors. Throws SceneError.
SceneDef parseScene(const std::string& text, const std::string& file);

/// Number of particles the blocks and groups of `scene` will create.
std::size_t countBlockParticles(const SceneDef& scene);

/// An upper estimate of the boundary samples the World will lay in the solids of `scene`
/// (layers of ceil(R/dx) rows under every face, both sides of segments).
double estimateBoundarySamples(const SceneDef& scene);

/// The most particles a run of `scene` can hold: its blocks, what its emitters emit over
/// its duration and its timeline's blocks and drops, capped by the particle budget
/// (effects.budget, else max_particles). Events from elsewhere are capped by the budget too.
std::size_t peakParticles(const SceneDef& scene);

/// The peak memory a process simulating `scene` will hold [bytes], estimated from the
/// scene alone (nothing is allocated): the process itself, the particles at
/// peakParticles() and the boundary samples; within a factor of 2 of the measured peak
/// resident set (tested). A renderer adds its images (sph2d::Renderer's estimate).
double estimateWorldBytes(const SceneDef& scene);

}  // namespace sph2d
