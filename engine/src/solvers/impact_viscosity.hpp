// solvers/impact_viscosity.hpp (internal) — the explicit solvers' (muller2003,
// wcsph) damping of collisions at impact speeds.
//
// A weakly compressible fluid meets an impact by compressing: a pair that closes
// at speed w stores ½ w² a unit mass in its compression (the water hammer,
// Δρ/ρ0 ≈ w/c, whatever the sound speed), and without dissipation gives it back
// as the rebound. An incompressible fluid does not bounce: the stopped motion is
// lost (a real liquid radiates it as sound, which the scene's artificial sound
// speed cannot carry away). Monaghan's artificial viscosity Π = −α c μ / ρ̄ damps
// a colliding pair, with the damping ratio of its contact about 0.44 α (h = R/2
// at r ≈ dx): wcsph's α = 0.05–0.1 and muller2003's Laplacian ν leave it a
// spring. Measured on a 50 m/s jet into a funnel of zigzag chains (c = 80 m/s):
// the front row stopped at a tooth tip and the jet piled up behind it at 1.44 ρ0
// (2.8 MPa, about twice the incompressible stagnation pressure ½ρV²); the
// pressure then threw the front particle along the wall at sqrt(2p/ρ) = 74 m/s,
// and a particle resting in a valley was pushed ahead of the arriving jet like a
// ball off a moving piston, to 86 m/s (up to 2.9 times the jet's specific
// energy). At c = 500 m/s the compression is 12 % and the rebound the same. With
// α = 2 for every pair those runs stayed at or below 1.12.
//
// So the impact viscosity adds up to `impact_alpha` to α for a pair whose
// approach speed w = −v_ij·x_ij/r exceeds `impact_speed`·c: nothing below w0 =
// impact_speed·c, the full amount from 2 w0 on, linear between (a pair's term is
// continuous in its velocity). w0 = 0.1 c, the fastest flow the solvers are meant for
// (c ≥ 10 v): a pair closing faster is an impact. At 0.2 c a 25 m/s jet into 40° and
// 15° chain teeth at c = 80 m/s (pairs closing at under 25 m/s, barely damped) piled
// up at 1.09 ρ0 and squirted a muller2003 particle out at 41 m/s, 2.64 times the jet's
// specific energy (1.86 at 0.1 c), and wcsph's worst of the five stress funnels fell
// from 1.70 to 1.19. The small dam break (c = 25 m/s, a surge of about 3.5 m/s into the
// far wall) takes a little of it there. A block falling 1.4 m onto water at c = 25
// (tests/every_stage.json) is an impact and takes it.
#pragma once

#include <algorithm>

#include "solvers/solver.hpp"

namespace sph2d {

/// The extra α of a pair that closes fast (the header).
struct ImpactViscosity {
  Real alpha0 = 0;  ///< impact_alpha: the extra α at full strength (0: off)
  Real w0 = 0;      ///< the approach speed where it starts [m/s] (impact_speed · c)

  ImpactViscosity() = default;
  ImpactViscosity(Real alpha, Real start) : alpha0(alpha), w0(start), invW0(start > 0 ? Real(1) / start : Real(0)) {}

  /// True when some pair can take an extra α.
  bool on() const { return alpha0 > 0 && w0 > 0; }

  /// The extra α of a pair with v_ij·x_ij = vdotx (< 0: approaching) at distance r > 0.
  Real alpha(Real vdotx, Real r) const {
    if (!on()) return 0;
    const Real w = -vdotx / r;  // approach speed
    if (!(w > w0)) return 0;
    return alpha0 * std::min(Real(1), (w - w0) * invW0);
  }

 private:
  Real invW0 = 0;
};

/// The scene keys (solver.*) of the impact viscosity, shared by muller2003 and wcsph.
inline const SolverParam kImpactAlphaParam{
    "impact_alpha", 2, 0, 10,
    "artificial viscosity α added for a pair approaching faster than impact_speed·c (full from twice that; 0: off)"};
inline const SolverParam kImpactSpeedParam{
    "impact_speed", 0.1, 0.001, 1, "the approach speed, as a share of the sound speed, where impact_alpha starts"};

}  // namespace sph2d
