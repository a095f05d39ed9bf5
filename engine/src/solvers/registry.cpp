// The solvers a scene can name, and the extra scene keys each one accepts.
// A new solver: one file in this folder with a make function, one entry below.
#include <stdexcept>
#include <string>

#include "solvers/solver.hpp"

namespace sph2d {

std::unique_ptr<Solver> makeMuller2003(const SolverDef& def);
std::unique_ptr<Solver> makeWcsph(const SolverDef& def);
std::unique_ptr<Solver> makePbf(const SolverDef& def);
std::unique_ptr<Solver> makeDfsph(const SolverDef& def);

namespace {

struct Entry {
  const char* name;
  std::unique_ptr<Solver> (*make)(const SolverDef&);
  std::vector<SolverParam> params;
};

const std::vector<Entry>& entries() {
  static const std::vector<Entry> e = {
      {"muller2003", &makeMuller2003, {}},
      {"wcsph",
       &makeWcsph,
       {{"gamma", 7, 1, 10, "Tait exponent γ in p = B((ρ/ρ0)^γ − 1), B = ρ0c²/γ"},
        {"alpha", 0.05, 0, 2, "Monaghan artificial viscosity α (Π = −α c h μ/ρ̄ for approaching pairs)"},
        {"expected_speed", 0, 0, 1e4, "when > 0, the sound speed is 10 × this (m/s) instead of sound_speed"}}},
      {"pbf",
       &makePbf,
       {{"iterations", 4, 1, 1000, "Jacobi iterations of the density constraint per substep, at least (integer)"},
        {"max_iterations", 100, 1, 1000, "iterations per substep, at most (integer); unconverged: shorter substeps"},
        {"tolerance", 0.01, 0, 1, "stop once mean(max(ρ/ρ0 − 1, 0)) ≤ this … (0: exactly `iterations`)"},
        {"tolerance_max", 0.05, 0.001, 10, "… and the largest compression max(ρ/ρ0 − 1) ≤ this"},
        {"relaxation", 0.5, 0, 100, "ε of the constraint denominator, in units of its value on a full rest lattice"},
        {"chebyshev", 0.9, 0, 0.99, "Chebyshev acceleration: spectral radius estimate ρ (0: plain Jacobi)"},
        {"tensile_k", 0, 0, 1, "s_corr strength k, in multipliers of a unit density error (0: off)"},
        {"tensile_n", 4, 1, 8, "s_corr exponent n (integer)"},
        {"tensile_dq", 0.2, 0.01, 0.9, "s_corr reference distance Δq, in units of the support R"},
        {"xsph", 0.01, 0, 1, "XSPH velocity smoothing c"},
        {"max_dt", 1.0 / 60.0, 1e-5, 0.1, "largest substep (s)"},
        {"max_move", 1, 0.05, 10, "dt ≤ max_move · R / v_max: largest move per substep, in support radii"}}},
      {"dfsph",
       &makeDfsph,
       {{"tolerance", 0.001, 1e-6, 0.1,
         "largest mean predicted density error |ρ* − ρ0|/ρ0 the pressure solve accepts (compression only where κ = 0)"},
        {"divergence_tolerance", 1e-4, 1e-8, 1,
         "largest mean |Dρ/Dt|·dt/ρ0 (the density change one substep's divergence error makes) the divergence-free solve accepts (compression only where κ_v = 0)"},
        {"max_iterations", 100, 1, 10000, "iterations per solve at most (each solve separately)"},
        {"min_iterations", 2, 0, 10000, "iterations per solve at least"},
        {"relaxation", 0.5, 0.05, 1, "Jacobi relaxation ω of both solves (κ increments are ω times the diagonal estimate)"},
        {"chebyshev_rho", 0.98, 0, 0.999,
         "Chebyshev acceleration of both solves (Wang 2015) with this spectral radius estimate; 0: plain relaxed Jacobi"},
        {"velocity_cfl", 0.4, 0.01, 1, "dt ≤ velocity_cfl·R/v_max (dfsph does not read solver.cfl, the CFL number on c + v_max)"},
        {"divergence_solve", 1, 0, 1, "1: run the divergence-free solve each substep; 0: constant-density solve only"}}},
  };
  return e;
}

}  // namespace

const std::vector<std::string>& solverNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& e : entries()) n.push_back(e.name);
    return n;
  }();
  return names;
}

const std::vector<SolverParam>& solverParams(const std::string& type) {
  static const std::vector<SolverParam> none;
  for (const auto& e : entries())
    if (type == e.name) return e.params;
  return none;
}

std::unique_ptr<Solver> makeSolver(const SolverDef& def) {
  for (const auto& e : entries())
    if (def.type == e.name) return e.make(def);
  throw std::invalid_argument("unknown solver '" + def.type + "'");
}

}  // namespace sph2d
