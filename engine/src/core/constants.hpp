// constants.hpp (internal) — the engine's tuning constants in one place, each
// with the reason for its value (Box2D's constants.h). Solver-specific
// constants that a scene may change are solver parameters instead
// (solvers/<name>/: each solver declares its own).
#pragma once

#include <cstddef>

#include "sph2d/math.hpp"

namespace sph2d {

/// Particles per job block of a pass over neighbours: large enough that a
/// block's neighbour lists fill whole cache lines, small enough for 2–8
/// threads to share 10k particles evenly. Block boundaries never depend on
/// the thread count (the determinism of every reduction rests on that).
constexpr std::size_t kBlock = 256;

/// Particles per job block of a streaming pass (no neighbours: integrate,
/// gravity, reductions): a pass of a few ns per particle needs large blocks
/// or the job system's overhead dominates.
constexpr std::size_t kStreamBlock = 4096;

/// A pair closer than sqrt(kCoincident2)·R is coincident: its direction is
/// undefined (0/0), so it gets a fixed antisymmetric one (pairDelta).
constexpr Real kCoincident2 = Real(1e-12);

/// The length of that fixed direction, in R: short enough not to change a
/// kernel value, long enough to give a finite gradient direction.
constexpr Real kTieBreakLength = Real(1e-6);

/// Below q = r/R = kFlatGradientQ a pair's Wendland gradient keeps its peak
/// magnitude (|∇W| peaks at q = 1/4) along its direction, instead of falling to
/// 0 as r → 0 (Thomas & Couchman 1992's modified gradient): a stacked or
/// coincident pair then pushes apart. Pairs of fluid near its rest spacing are
/// farther apart and unaffected (dfsph's solves, wcsph's pressure force).
constexpr Real kFlatGradientQ = Real(0.25);

/// The force limit of explicit schemes, dt ≤ kForceCfl·sqrt(R/a_max)
/// (Monaghan 1992's force condition; 0.25 is the usual safety factor).
constexpr Real kForceCfl = Real(0.25);

/// Particles are kept kClearance·dx clear of solid surfaces: the layer of
/// boundary samples starts dx/2 inside, so a particle at the clearance still
/// sees a full neighbourhood, and a resting particle does not touch the surface.
constexpr Real kClearance = Real(0.25);

/// The fastest a static body that the game moves (SetTransform between frames) may go and
/// still be a sliding wall, a kinematic body for the step [m/s]: a door or a piston a game
/// slides is slower. A faster move is a teleport: the static solids take the body where it
/// is now, and the particles it lands on are dropped (pushing them out of a 0.6 m box set on
/// water threw particles at 50–100 m/s).
constexpr Real kStaticPushSpeed = Real(10);

/// Integration moves no particle more than kMaxMove·R in one substep: a force
/// that jumps within a substep (a new overlap) cannot fling a particle across
/// the neighbour search radius before the next step's limits see it.
constexpr Real kMaxMove = Real(0.5);

/// dt ≤ kPressureCfl·R/sqrt(|g| D), D the greatest depth below the top of a particle's
/// column: the hydrostatic pressure's own stiffness (a wave of speed ~sqrt(|g| D) crosses at
/// most this share of a support a substep) for the solvers whose iterations carry that pressure
/// (dfsph; pbf without the grid projection). docs/SOLVERS.md has the measurements.
constexpr Real kPressureCfl = Real(0.35);

/// The grid's ghost-fluid surface is never nearer a fluid cell's centre than this
/// fraction of a cell: nearer, the cell's 1/θ would dominate its row for no gain (its
/// pressure is ~0 either way) and slow the conjugate gradients.
constexpr Real kMinSurfaceFraction = Real(0.1);

/// The Laplacian viscosity's coupling of one pair over a substep, dt·μm·∇²W/(ρ_i ρ_j), is at
/// most this (ViscosityTerm::pairCap), so the pair's relative velocity loses at most a quarter
/// a substep: ∇²W grows as 1/r³, and two particles pressed together would otherwise overshoot
/// and run away. Lattice pairs at the viscous time-step limit take at most 0.061, so flows
/// the limit resolves never meet the cap.
constexpr Real kViscousPairShare = Real(0.125);

/// A step() shorter than this fraction of the last substep only drifts (no
/// solver stage): a solver that divides by dt (the density solves of pbf and
/// dfsph) would turn the compression the last substep left into a huge
/// velocity. (A fraction of the stable limit would not do: in zero gravity at
/// rest that limit is ~1e5 s, and every frame would be a sliver.)
constexpr double kMinStepOfLast = 1e-2;

/// What is left of a frame after its substeps, below this fraction of the
/// frame, is float rounding of the substep lengths and is dropped.
constexpr double kFrameLeftover = 1e-6;

}  // namespace sph2d
