// scene_checks.hpp (internal) — what a scene must satisfy beyond types and
// ranges: what Box2D 2.4.1 would assert on, what would exhaust memory and what
// can only be a mistake. The scene loader calls each check right after reading
// the values it looks at, so the first error in a file is the one reported;
// every check fails through the Reader, at a key.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "scene/scene_reader.hpp"
#include "sph2d/scene.hpp"

namespace sph2d {

// Limits the loader enforces (documented in docs/SCENES.md).
constexpr double kLinearSlop = 0.005;              ///< Box2D 2.4.1's b2_linearSlop [m]
constexpr double kMaxFrames = 1e6;                 ///< duration × fps
constexpr double kMinCameraSize = 1e-3;            ///< camera width and height [m]
constexpr std::size_t kMinSampleBudget = 4000000;  ///< boundary samples allowed even when max_particles is lower

/// Fails at `path`.max unless max > min in x and in y (a block, a camera, a region).
void checkMaxAboveMin(const Reader& r, const Vec2d& min, const Vec2d& max, const std::string& path);

/// The scene's name becomes the output directory out/<name>: one plain path component.
void checkName(const Reader& r, const std::string& name);

/// duration × fps is at most kMaxFrames; `key` ("duration" or "fps") is where to report it.
void checkFrameCount(const Reader& r, double duration, double fps, const std::string& key);

/// A box's half sizes (at `path`.half_size): > 0, and at least half of Box2D's linear slop.
void checkBoxHalfSize(const Reader& r, const Vec2d& halfSize, const std::string& path);

/// A circle's radius (at `path`.radius): at least half of Box2D's linear slop.
void checkCircleRadius(const Reader& r, double radius, const std::string& path);

/// A polygon's vertices (at `path`, the vertices' key path): 3 to 8, none closer
/// than the linear slop, convex, with an area, and acceptable to b2PolygonShape::Set
/// as Box2D computes it in float.
void checkPolygon(const Reader& r, const std::vector<Vec2d>& vertices, const std::string& path);

/// An edge's vertices (at `path`, the vertices' key path): exactly 2, at least the linear slop apart.
void checkEdge(const Reader& r, const std::vector<Vec2d>& vertices, const std::string& path);

/// A chain's vertices (at `path`, the vertices' key path): enough of them (3 for a loop,
/// 2 open), neighbours at least the linear slop apart, a loop not repeating its first vertex.
void checkChain(const Reader& r, const std::vector<Vec2d>& vertices, bool loop, const std::string& path);

/// A fluid block (at `path`) that could hold a particle at `s`'s spacing: at least one
/// spacing wide and high, and not entirely inside one solid fixture of `s`'s bodies.
void checkBlock(const Reader& r, const SceneDef& s, const FluidBlockDef& block, const std::string& path);
/// A fluid polygon: 3..256 finite vertices enclosing a non-zero area (any simple or
/// self-crossing outline; the fill follows the even-odd rule).
void checkFluidPolygon(const Reader& r, const std::vector<Vec2d>& vertices, const std::string& path);
/// The lattice points of a region at spacing dx: its bounding box's, and for a circle or
/// polygon those inside it, counted row by row up to 10^7 rows for a circle and 2·10^5 for a
/// polygon (beyond: the box's count, an upper bound). The rows as a block without the
/// hydrostatic start places them.
double regionLatticeCount(const FluidBlockDef& b, double dx);

/// A periodic range (at `path`) spans at least three support radii `R` (min < max).
void checkPeriod(const Reader& r, const Vec2d& range, double R, const std::string& path);

/// A camera (at `path`) with max > min and at least kMinCameraSize wide and high.
void checkCamera(const Reader& r, const CameraDef& camera, const std::string& path);

/// Bytes of the estimate of a run's peak (estimateWorldBytes): the process (code, libraries,
/// thread stacks), each particle at the peak (its arrays, neighbour lists, the solvers' pair
/// caches, the grids, allocator slack) and each boundary sample. Measured as the peak
/// resident set of `sph2d run --no-images`: 55–61 MB with a few thousand particles; 149–151 MB
/// at 163k (game, dfsph): 580 B a particle above the process.
constexpr double kProcessBytes = 60e6;
constexpr double kBytesPerParticle = 600;
constexpr double kBytesPerSample = 64;

/// The particles of the blocks and the boundary samples of the solids of the whole
/// scene fit its budget (max_particles; samples: max(max_particles, kMinSampleBudget)).
/// Reported at solver.spacing.
void checkParticleBudget(const Reader& r, const SceneDef& s);

}  // namespace sph2d
