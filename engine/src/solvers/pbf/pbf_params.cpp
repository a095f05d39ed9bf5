// pbf_params.cpp — the scene keys of the Position Based Fluids solver (Macklin &
// Müller 2013) and its two registrations in solvers.def: "pbf", the classic
// defaults, and "game", the same code with real-time defaults and the coarse-grid
// pressure projection on (Hybrid SPH, Raveendran, Wojtan & Turk 2011); the
// calibration of the constraint's scale D0 from the spacing. What each key does:
// pbf.hpp and docs/SCENES.md.
#include <cmath>

#include "solvers/pbf/pbf.hpp"

namespace sph2d {

/// The parameters of pbf and of game (the same method; game's defaults make it real-time).
std::vector<SolverParam> pbfParams(bool game) {
  auto g = [game](double classic, double realtime) { return game ? realtime : classic; };
  return {
      {"iterations", g(4, 1), 1, 1000, "Jacobi iterations of the density constraint per substep, at least (integer)"},
      {"max_iterations", g(100, 4), 1, 1000, "iterations over all particles per substep, at most (integer)"},
      {"tolerance", 0.01, 0, 1,
       "stop once mean(max(ρ/ρ0 − 1, 0)) ≤ this … (0: only when nothing is compressed, so usually `max_iterations`)"},
      {"tolerance_max", g(0.05, 0.08), 0.001, 10, "… and the largest compression max(ρ/ρ0 − 1) ≤ this"},
      {"local_iterations", g(0, 100), 0, 1000,
       "then at most this many iterations on the particles near a compression above tolerance_max (and their neighbours)"},
      {"relaxation", 0.5, 0, 100, "ε of the constraint denominator, in units of its value on a full rest lattice"},
      {"chebyshev", 0.9, 0, 0.99, "Chebyshev acceleration: spectral radius estimate ρ (0: plain Jacobi)"},
      {"chebyshev_plain_above", g(0.1, 0), 0, 100,
       "a substep whose first pass finds a compression above this runs plain Jacobi (an impact; 0: never; with "
       "pushout_speed, beyond what the substep may remove as velocity)"},
      {"tensile_k", 0, 0, 1, "s_corr strength k, in multipliers of a unit density error (0: off)"},
      {"tensile_n", 4, 1, 8, "s_corr exponent n (integer)"},
      {"tensile_dq", 0.2, 0.01, 0.9, "s_corr reference distance Δq, in units of the support R"},
      {"xsph", 0.01, 0, 1, "XSPH velocity smoothing c"},
      {"max_dt", 1.0 / 60.0, 1e-5, 0.1, "largest substep (s)"},
      {"max_move", g(1, 6), 0.05, 20, "dt ≤ max_move · R / v_speed: largest move per substep, in support radii"},
      {"speed_quantile", g(0, 0.002), 0, 0.1,
       "v_speed is the speed this share of the particles exceeds (0: the largest): spray does not set the substep"},
      {"move_cap", g(0, 1.5), 0, 100,
       "> 0: no particle moves more than move_cap · max_move · R in a substep (its speed is cut)"},
      {"adaptive_dt", g(1, 0), 0, 1, "1: shorter substeps while max_iterations end above the tolerances"},
      {"correction_to_velocity", g(1, 0), 0, 1, "share of the density correction's move that becomes velocity"},
      {"pushout_speed", g(0.3, 0), 0, 1000,
       "m/s: the compression a substep starts with becomes velocity at most at this speed (ρ0·2·v·dt/dx a substep); the "
       "rest is pushed out moving positions only (with correction_to_velocity > 0; 0: no limit)"},
      {"max_approach", g(0.5, 0), 0, 10,
       "dt ≤ max_approach · R / w, w the fastest approach of two neighbours (m/s) at the end of the last substep (0: off)"},
      {"resolve_each", 1, 0, 1,
       "1: every correction is swept out of the solids (0: the World's collision after the substep)"},
      {"grid_cell", g(0, 2), 0, 16, "coarse-grid projection (Hybrid SPH): cell size in spacings (0: none)"},
      {"grid_fluid_fraction", g(0.5, 0.15), 0.01, 1,
       "a grid cell is fluid above this fraction of a full cell's particle weight (low: the surface's cells count, and a pool comes to rest)"},
      {"grid_compression_rate", 0, 0, 1, "share of a grid cell's mean compression its velocity removes per substep"},
      {"grid_shift", g(0, 0.5), 0, 1,
       "share of a grid cell's compression (particle weight over a full cell's, − 1, above grid_shift_above) removed per substep by moving its particles (positions only; Kugelstadt et al. 2019)"},
      {"grid_shift_above", 0.005, 0, 1, "the compression a cell keeps from the shift (left to the density solve)"},
      {"grid_fill", g(0, 0.5), 0, 1,
       "share of an interior grid cell's deficit (1 − particle weight over a full cell's, above grid_shift_above) closed per substep by the shift's moves: air pockets rise out (interior: four fluid neighbours)"},
      {"grid_shift_tolerance", 0.01, 1e-7, 1,
       "the shift's solve: the density change its largest residual may stand for (a correction: looser than grid_tolerance)"},
      {"grid_surface", g(0, 1), 0, 1,
       "1: the grid's free surface lies half a spacing above the highest particle (ghost fluid, Gibou et al. 2002: a floating body's draught by Archimedes), 0: at the air cells' centres"},
      {"grid_tolerance", 1e-3, 1e-7, 1,
       "grid solve: the density change per substep its largest residual may stand for"},
      {"grid_max_iterations", 200, 1, 10000, "grid solve: conjugate-gradient iterations at most"},
      {"grid_pic", g(0, 0.05), 0, 1,
       "share of the projected grid velocity the particles take per grid cell their velocity carries them in the "
       "substep, at least once (PIC; the rest is the FLIP change)"},
      {"grid_conserve", 1, 0, 1,
       "1: a fluid region no wall, kinematic body or Box2D-held body holds, with an interior cell, keeps its momentum "
       "with the dynamic bodies it touches through the grid's transfer (its imbalance taken out as one velocity "
       "change)"},
      {"grid_flip_clamp", 0, 0, 1,
       "1: the transfer makes no particle faster than it was or than the projected velocities of the faces it samples "
       "reach (no new extreme of speed)"},
  };
}

namespace {
/// The compression shift moves positions only; a solver that turns its moves into velocity
/// (correction_to_velocity > 0) would turn the shift into velocity too.
std::pair<std::string, std::string> pbfCheck(const SolverDef& d) {
  if (d.param("grid_cell") > 0 && d.param("grid_shift") > 0 && d.param("correction_to_velocity") > 0)
    return {
        "solver.grid_shift",
        "the grid's compression shift needs correction_to_velocity 0 (it would become velocity): set one of them to 0"};
  if (d.param("grid_cell") > 0 && d.param("grid_fill") > 0 && d.param("correction_to_velocity") > 0)
    return {"solver.grid_fill",
            "the grid's fill shift needs correction_to_velocity 0 (it would become velocity): set one of them to 0"};
  return {};
}
}  // namespace

/// pbf's registration (solvers.def): classic Position Based Fluids.
SolverInfo pbfSolver() {
  return {"pbf", pbfParams(false),
          [](const SolverDef& d) -> std::unique_ptr<Solver> { return std::make_unique<Pbf>(d); }, nullptr, pbfCheck};
}

/// game's registration (solvers.def): pbf with the coarse-grid projection, local
/// iterations and a robust substep, the real-time end (docs/PERFORMANCE.md).
SolverInfo gameSolver() {
  return {"game", pbfParams(true),
          [](const SolverDef& d) -> std::unique_ptr<Solver> { return std::make_unique<Pbf>(d); },
          [](SolverDef& d) {
            d.viscosity = 0;     // XSPH smooths; an explicit viscosity would limit the substep
            d.supportRatio = 2;  // 8 neighbours at rest: measured as accurate as 2.5 here, at half the pairs
          },
          pbfCheck};
}

void Pbf::calibrate(const StepContext& c) {
  const double R = double(c.R), dx = double(c.dx);
  const double V = double(c.mass) / double(c.rho0);
  const Spiky<double> W(R);
  const int n = int(std::ceil(R / dx)) + 1;
  double s = 0;
  for (int j = -n; j <= n; ++j)
    for (int i = -n; i <= n; ++i) {
      if (i == 0 && j == 0) continue;
      const double g = W.derivative(std::sqrt(double(i * i + j * j)) * dx);
      s += g * g;
    }
  d0_ = Real(V * V * s);
  eps_ = relaxation_ * d0_;
  // s_corr = −k (W(r)/W(Δq))^n, in multipliers: 1/D0 corrects a density error of 1.
  invWdq_ = Real(1.0 / W.value(double(tensileDq_) * R));
  sCorrScale_ = Real(-double(tensileK_) / double(d0_));
}

}  // namespace sph2d
