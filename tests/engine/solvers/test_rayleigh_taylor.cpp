// Rayleigh–Taylor instability: heavy fluid (ρ1) over light (ρ2), the interface perturbed by
// a0 cos(kx), released from rest, inviscid. Linear theory (Chandrasekhar 1961, ch. X; both
// layers deep, tanh kH ≈ 1): a(t) = a0 cosh(σt), σ = sqrt(A g k), A = (ρ1 − ρ2)/(ρ1 + ρ2).
// Free-slip walls at x = 0 and x = λ are planes of symmetry of cos(kx): the box holds one
// wavelength of the periodic problem. The heavy layer has a free surface on top.
//
// The game solver: its grid projection carries the pressure (its β = 1/r_face weighs the two
// fluids), and it grows within 5 % of σ as measured (the bound is 15 %) (0.95–1.00 at λ/dx from 50 to 100, layers 0.25 to 1 m
// deep, A from 1/3 to 0.6; 0.81 at λ/dx = 25). wcsph on the same set-up grows at 0.3–0.9 of σ,
// erratically (docs/notes/rayleigh-taylor.md): not tested here. With every β held at 1 (the
// grid blind to the contrast) the interface does not grow at all.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "support/fixture.hpp"
#include "test_util.hpp"

using namespace sph2d;

namespace {

struct Growth {
  double sigma = 0;   ///< fitted growth rate [1/s]
  double theory = 0;  ///< sqrt(A g k)
  double a0 = 0;      ///< the measured initial amplitude [m]
  int samples = 0;    ///< frames in the fit
};

/// The interface's cos(kx) amplitude: per column one spacing wide, halfway between the light
/// fluid's highest particle and the heavy fluid's lowest.
double amplitude(const World& w, double W, double dx, double k) {
  const int columns = int(std::lround(W / dx));
  std::vector<double> top(std::size_t(columns), -1e9), bottom(std::size_t(columns), 1e9);
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const Vec2d p = w.worldPosition(i);
    const int c = std::clamp(int(p.x() / dx), 0, columns - 1);
    if (w.particles().material[i] == 0)
      top[std::size_t(c)] = std::max(top[std::size_t(c)], p.y());
    else
      bottom[std::size_t(c)] = std::min(bottom[std::size_t(c)], p.y());
  }
  double a = 0;
  for (int c = 0; c < columns; ++c)
    a += 0.5 * (top[std::size_t(c)] + bottom[std::size_t(c)]) * std::cos(k * (c + 0.5) * dx);
  return 2 * a / columns;
}

Growth rayleighTaylor(const std::string& solver, double heavy, double dx, double a0, double depth, double W = 0.5) {
  const double light = 1000, g = 9.81, k = 2 * kPi<double> / W;
  SceneDef s = test::tank(solver, W, 2 * depth + 0.3, dx);
  s.solver.viscosity = 0;
  s.fps = 240;
  MaterialDef m0;
  m0.name = "light";
  m0.density = s.solver.restDensity;
  MaterialDef m1 = m0;
  m1.name = "heavy";
  m1.density = heavy;
  s.materials = {m0, m1};
  World w(s, WorldOptions{2});
  // A lattice, each point moved by the linear mode's displacement (incompressible: the
  // gradient of a harmonic potential on each side), ξ = a0 e^{−k|y − depth|} (±sin kx, cos kx),
  // its material by the side of the flat interface it started on: the interface is
  // depth + a0 cos(kx) for any a0, however small against the spacing.
  std::vector<Vec2d> lo, hi;
  const int nx = int(std::lround(W / dx)), ny = int(std::lround(2 * depth / dx));
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double x = (i + 0.5) * dx, y = (j + 0.5) * dx, below = y < depth ? 1 : -1;
      const double e = a0 * std::exp(-k * std::fabs(y - depth));
      (below > 0 ? lo : hi).push_back(Vec2d(x - below * e * std::sin(k * x), y + e * std::cos(k * x)));
    }
  w.addParticles(lo, {}, 0);
  w.addParticles(hi, {}, 1);
  Growth G;
  const double A = (heavy - light) / (heavy + light);
  G.theory = std::sqrt(A * g * k);
  G.a0 = amplitude(w, W, dx, k);
  // σ from a = a0 cosh(σt) by least squares on acosh(a/a0) = σt over the frames where the
  // amplitude lies between 1.3 a0 and k a = 0.2 (a below λ/30: the linear stage, before the
  // spikes and bubbles).
  double st = 0, tt = 0;
  for (int f = 1; f <= 240; ++f) {
    w.stepFrame();
    const double a = amplitude(w, W, dx, k), t = f / 240.0;
    if (k * a > 0.2) break;
    if (a < 1.3 * G.a0) continue;
    st += t * std::acosh(a / G.a0);
    tt += t * t;
    ++G.samples;
  }
  REQUIRE(test::allFiniteState(w));
  G.sigma = tt > 0 ? st / tt : 0;
  return G;
}

}  // namespace

TEST_CASE("rayleigh taylor: on the game solver the interface grows at sqrt(A g k) for A = 1/3 and 0.6") {
  struct Case {
    double heavy, dx, a0, depth, wavelength;
  };
  // λ = 0.5 m at 50 spacings, layers 0.5 m deep; λ = 1 m at 50 spacings, layers 1 m deep.
  for (const Case& c : {Case{2000, 0.01, 0.005, 0.5, 0.5}, Case{4000, 0.01, 0.005, 0.5, 0.5},
                        Case{2000, 0.02, 0.01, 1.0, 1.0}, Case{4000, 0.02, 0.01, 1.0, 1.0}}) {
    const Growth G = rayleighTaylor("game", c.heavy, c.dx, c.a0, c.depth, c.wavelength);
    const double A = (c.heavy - 1000) / (c.heavy + 1000);
    MESSAGE("A = " << A << ", lambda " << c.wavelength << " m, dx " << c.dx << " m: sigma " << G.sigma
                   << " 1/s against sqrt(A g k) = " << G.theory << " (ratio " << G.sigma / G.theory << ") over "
                   << G.samples << " frames, a0 " << G.a0 << " m");
    CHECK(G.samples >= 10);
    CHECK(G.sigma / G.theory == doctest::Approx(1).epsilon(0.15));
  }
}
