// validation.hpp — the analytic validation cases shared by `sph2d bench
// accuracy` and the tests (header-only: the engine tests include it without
// linking the app).
//
// Taylor–Green vortex (periodic box, no gravity): u = −U e^{bt} cos kx sin ky,
// v = U e^{bt} sin kx cos ky with b = −2νk² (= −8π²/Re for U = L = 1), the
// solution tabulated in assets/reference/taylor_green_decay.csv (PySPH's
// taylor_green example). Measured: the amplitude of the vortex mode (the
// least-squares projection of the particle velocities on it: far less noisy
// than the largest speed) and the largest speed, every frame; the decay rate
// is the least-squares slope of ln(amplitude) against t.
//
// Start-up Poiseuille flow (periodic in x, plates at y = 0 and y = H, body
// force F along x from rest): u(y, t) from Morris, Fox & Zhu 1997's series,
// tabulated in assets/reference/channel_flow_transient.csv against τ = νt/H²
// and y/H, scaled by the steady centre speed F H²/(8ν). Measured: the mean
// x-velocity of the particles within one spacing of each tabulated y/H, at
// each tabulated τ (rows in τ order).
//
// Hydrostatic tank (a resting column): the pressure averaged in 5 cm slabs of
// height near x = xc against ρ0 g (H − ȳ), ȳ the slab's mean particle height and
// H the free surface (the mean height of the top particles plus half a spacing).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace sph2d::validation {

/// Rows of a reference CSV (lines starting with '#' and the header skipped), split at commas.
inline std::vector<std::vector<double>> readReferenceCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || !(std::isdigit(static_cast<unsigned char>(line[0])) || line[0] == '-'))
      continue;
    std::vector<double> row;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  if (rows.empty()) throw std::runtime_error("no rows in " + path);
  return rows;
}

/// What a Taylor–Green run measured.
struct TaylorGreenResult {
  double rate = 0;          ///< fitted decay rate b of the vortex amplitude [1/s] (negative)
  double analyticRate = 0;  ///< −2νk²
  double rateError = 0;     ///< |rate − analyticRate| / |analyticRate|
  double umaxRms = 0;       ///< RMS of (|u|max/U − exp(bt)) at the reference table's times
  double amplitudeRms = 0;  ///< RMS of (A/U − exp(bt)) at the same times
  double simSeconds = 0;
  std::uint64_t substeps = 0;
  double meanDensityError = 0, maxDensityError = 0;  ///< of DensityStats::meanError over the frames
  std::vector<double> t, amplitude, umax;            ///< per frame (t = 0 included)
};

/// The amplitude of the Taylor–Green mode (wavelength L from `field`) in the particles' velocities.
inline double taylorGreenAmplitude(const World& w, const VelocityFieldDef& field) {
  const double k = 2 * 3.14159265358979323846 / field.wavelength;
  double num = 0, den = 0;
  const Particles& P = w.particles();
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const Vec2d q = w.worldPosition(i) - field.origin;
    const double px = -std::cos(k * q.x()) * std::sin(k * q.y()), py = std::sin(k * q.x()) * std::cos(k * q.y());
    num += double(P.v[i].x()) * px + double(P.v[i].y()) * py;
    den += px * px + py * py;
  }
  return den > 0 ? num / den : 0;
}

/// Runs a Taylor–Green scene (one block with a taylor_green velocity field)
/// for `seconds`, frame by frame; `table` rows are (Re, t, umax_ratio, ke_ratio).
inline TaylorGreenResult runTaylorGreen(const SceneDef& s, double seconds,
                                        const std::vector<std::vector<double>>& table, int threads = 1) {
  if (s.blocks.empty() || s.blocks[0].field.type != VelocityFieldDef::Type::TaylorGreen)
    throw std::runtime_error("a Taylor-Green scene needs a block with a taylor_green velocity field");
  const VelocityFieldDef& f = s.blocks[0].field;
  const double k = 2 * 3.14159265358979323846 / f.wavelength, U = std::fabs(f.amplitude);
  TaylorGreenResult r;
  r.analyticRate = -2 * s.solver.viscosity * k * k;
  World w(s, WorldOptions{threads});
  const int frames = int(std::lround(seconds * s.fps));
  auto sample = [&] {
    r.t.push_back(w.time());
    r.amplitude.push_back(taylorGreenAmplitude(w, f) / f.amplitude);
    double m = 0;
    for (std::size_t i = 0; i < w.particleCount(); ++i) m = std::max(m, double(w.particles().v[i].norm()));
    r.umax.push_back(m / U);
  };
  sample();
  for (int fr = 0; fr < frames; ++fr) {
    w.stepFrame();
    sample();
    const DensityStats d = w.densityStats();
    r.meanDensityError += d.meanError / frames;
    r.maxDensityError = std::max(r.maxDensityError, d.meanError);
  }
  r.simSeconds = w.time();
  r.substeps = w.counters().substeps;
  // Least-squares slope of ln A(t).
  double st = 0, sy = 0, stt = 0, sty = 0, n = 0;
  for (std::size_t i = 0; i < r.t.size(); ++i) {
    if (!(r.amplitude[i] > 0)) continue;
    const double y = std::log(r.amplitude[i]);
    st += r.t[i];
    sy += y;
    stt += r.t[i] * r.t[i];
    sty += r.t[i] * y;
    n += 1;
  }
  r.rate = n > 1 ? (n * sty - st * sy) / (n * stt - st * st) : 0;
  r.rateError = std::fabs(r.rate - r.analyticRate) / std::fabs(r.analyticRate);
  // Against the table at its times (the scene's Re must match the table's).
  const double Re = U * f.wavelength / s.solver.viscosity;
  double su = 0, sa = 0;
  int m = 0;
  for (const auto& row : table) {
    if (row.size() < 3 || std::fabs(row[0] - Re) > 1e-6 * Re || row[1] > r.simSeconds + 1e-9) continue;
    // The frame nearest the table's time.
    std::size_t best = 0;
    for (std::size_t i = 1; i < r.t.size(); ++i)
      if (std::fabs(r.t[i] - row[1]) < std::fabs(r.t[best] - row[1])) best = i;
    const double ref = row[2];
    su += (r.umax[best] - ref) * (r.umax[best] - ref);
    sa += (r.amplitude[best] - ref) * (r.amplitude[best] - ref);
    ++m;
  }
  r.umaxRms = m ? std::sqrt(su / m) : NAN;
  r.amplitudeRms = m ? std::sqrt(sa / m) : NAN;
  return r;
}

/// What a start-up Poiseuille run measured.
struct PoiseuilleResult {
  double worstError = 0;   ///< largest |u − u_ref| over the table's points, as a share of the steady centre speed
  double steadyError = 0;  ///< the same over the last τ of the table (τ = 0.5: within 1 % of steady)
  double rmsError = 0;     ///< RMS over all the table's points
  double simSeconds = 0;
  std::uint64_t substeps = 0;
  double meanDensityError = 0, maxDensityError = 0;  ///< of DensityStats::meanError at the table's times
  /// (τ, y/H, measured u/u_c, reference u/u_c) for each interior point of the table.
  std::vector<std::array<double, 4>> points;
};

/// Runs a channel scene — plates at y = y0 and y0 + H, periodic in x, body
/// force F = gravity.x, fluid at rest at t = 0 — and compares the mean
/// x-velocity of the particles within one spacing of each tabulated y/H with
/// `table` rows (τ, y/H, u_pois, ...) at each tabulated τ = νt/H², scaled by
/// u_c = F H²/(8ν).
inline PoiseuilleResult runPoiseuille(const SceneDef& s, double y0, double height,
                                      const std::vector<std::vector<double>>& table, int threads = 1) {
  const double nu = s.solver.viscosity, F = s.gravity.x();
  const double uc = F * height * height / (8 * nu);
  PoiseuilleResult r;
  World w(s, WorldOptions{threads});
  const double band = s.solver.spacing / height;
  double sq = 0;
  double lastTau = 0;
  for (const auto& row : table)
    if (row.size() >= 3) lastTau = std::max(lastTau, row[0]);
  for (const auto& row : table) {
    if (row.size() < 3 || !(row[1] > 0 && row[1] < 1)) continue;  // the walls' own points
    const double tau = row[0], eta = row[1], ref = row[2];
    const double t = tau * height * height / nu;
    while (w.time() < t - 1e-9) w.step(std::min(1.0 / s.fps, t - w.time()));
    double sum = 0, n = 0;
    for (std::size_t i = 0; i < w.particleCount(); ++i) {
      const double e = (w.worldPosition(i).y() - y0) / height;
      if (std::fabs(e - eta) <= band) {
        sum += double(w.particles().v[i].x());
        n += 1;
      }
    }
    const double u = n > 0 ? sum / n / uc : 0;
    const DensityStats d = w.densityStats();
    r.meanDensityError += d.meanError;
    r.maxDensityError = std::max(r.maxDensityError, d.meanError);
    r.points.push_back({tau, eta, u, ref});
    const double err = std::fabs(u - ref);
    r.worstError = std::max(r.worstError, err);
    if (tau == lastTau) r.steadyError = std::max(r.steadyError, err);
    sq += err * err;
  }
  r.rmsError = r.points.empty() ? 0 : std::sqrt(sq / double(r.points.size()));
  if (!r.points.empty()) r.meanDensityError /= double(r.points.size());
  r.simSeconds = w.time();
  r.substeps = w.counters().substeps;
  return r;
}

/// The pressure profile of a resting column, accumulated over frames in 5 cm slabs of height
/// (|x − xc| < 0.2 m). p is linear in y, so a slab's mean pressure is compared with the
/// pressure at its particles' mean height (a slab need not be filled evenly: at dx = 5 cm a
/// lattice row sits on a slab's edge).
struct PressureProfile {
  static constexpr double kSlab = 0.05;  ///< slab height [m]
  std::vector<double> sum = std::vector<double>(40, 0.0);
  std::vector<double> sumY = std::vector<double>(40, 0.0);
  std::vector<int> count = std::vector<int>(40, 0);
  double xc = 1.0;  ///< the column's middle [m]

  /// Adds every particle's pressure to its slab.
  void add(const World& w) {
    for (std::size_t i = 0; i < w.particleCount(); ++i) {
      const Vec2d q = w.worldPosition(i);
      const int band = int(std::lround(q.y() / kSlab));
      if (std::fabs(q.x() - xc) < 0.2 && band >= 0 && band < int(sum.size())) {
        sum[std::size_t(band)] += w.particles().p[i];
        sumY[std::size_t(band)] += q.y();
        ++count[std::size_t(band)];
      }
    }
  }

  /// The free surface near xc: the mean height of the particles within dx of the highest
  /// (|x − xc| < 0.5 m), plus dx/2.
  static double surface(const World& w, double xc, double dx) {
    double top = 0, H = 0;
    int n = 0;
    for (std::size_t i = 0; i < w.particleCount(); ++i) top = std::max(top, w.worldPosition(i).y());
    for (std::size_t i = 0; i < w.particleCount(); ++i)
      if (w.worldPosition(i).y() > top - dx && std::fabs(w.worldPosition(i).x() - xc) < 0.5) {
        H += w.worldPosition(i).y();
        ++n;
      }
    return n ? H / n + 0.5 * dx : 0;
  }

  /// The largest |p̄ − scale ρ0 g (H − ȳ)| over the slabs below the top three spacings, as a
  /// fraction of scale ρ0 g H; `measured` gets the number of slabs that held particles, `empty`
  /// the number that did not.
  double worstError(double H, double rho0, double g, double dx, double scale, int& measured, int& empty) const {
    double worst = 0;
    measured = empty = 0;
    for (int band = 1; kSlab * band < H - 3 * dx && band < int(sum.size()); ++band) {
      if (count[std::size_t(band)] == 0) {
        ++empty;
        continue;
      }
      ++measured;
      const double p = sum[std::size_t(band)] / count[std::size_t(band)];
      const double y = sumY[std::size_t(band)] / count[std::size_t(band)];
      worst = std::max(worst, std::fabs(p - scale * rho0 * g * (H - y)) / (scale * rho0 * g * H));
    }
    return worst;
  }
};

}  // namespace sph2d::validation
