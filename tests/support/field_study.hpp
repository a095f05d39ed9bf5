// tests/support/field_study.hpp — particle lattices and the convergence study
// shared by tests/engine/test_field_operators.cpp and app/tools/kernel_report.cpp
// (so the table in docs/KERNELS.md is what the tests assert).
//
// Jitter is portable: a fixed-seed std::mt19937 (its output sequence is fixed by
// the standard) mapped to [0, 1) by hand; std::uniform_real_distribution is not
// used because its mapping differs across standard libraries.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <type_traits>
#include <vector>

#include "particles/field_operators.hpp"

namespace sph2d::study {

/// A square lattice of particles with uniform volume dx², optionally jittered.
template <class T>
struct Lattice {
  using V = Vector2<T>;
  std::vector<V> x;
  std::vector<T> vol;
  double dx = 0;
  /// The particle view of this lattice (volumes).
  ParticleView<T> view() const { return ParticleView<T>::withVolumes(x.data(), vol.data(), x.size()); }
};

/// Uniform double in [0, 1) from 53 bits of two mt19937 draws.
inline double uniform01(std::mt19937& g) {
  const std::uint64_t a = g() >> 5, b = g() >> 6;  // 27 + 26 bits
  return (double(a) * 67108864.0 + double(b)) * (1.0 / 9007199254740992.0);
}

/// nx × ny particles at lo + (i + ½, j + ½)·dx, each moved by up to ±jitter·dx
/// per axis (uniform, seeded), with volume dx².
template <class T>
Lattice<T> makeLattice(int nx, int ny, double dx, double loX, double loY, double jitter, std::uint32_t seed) {
  Lattice<T> L;
  L.dx = dx;
  std::mt19937 g(seed);
  L.x.reserve(std::size_t(nx) * std::size_t(ny));
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double jx = jitter * (2 * uniform01(g) - 1), jy = jitter * (2 * uniform01(g) - 1);
      L.x.emplace_back(T(loX + (i + 0.5 + jx) * dx), T(loY + (j + 0.5 + jy) * dx));
    }
  L.vol.assign(L.x.size(), T(dx * dx));
  return L;
}

/// The smooth test field of the convergence study, A = sin(3x + 0.5) cos(2y − 0.3),
/// chosen off the lattice's symmetry axes so no error cancels by symmetry.
struct SmoothField {
  /// A(x, y).
  static double value(double x, double y) { return std::sin(3 * x + 0.5) * std::cos(2 * y - 0.3); }
  /// ∂A/∂x.
  static double dx(double x, double y) { return 3 * std::cos(3 * x + 0.5) * std::cos(2 * y - 0.3); }
  /// ∂A/∂y.
  static double dy(double x, double y) { return -2 * std::sin(3 * x + 0.5) * std::sin(2 * y - 0.3); }
  /// ∇²A = −13 A.
  static double laplacian(double x, double y) { return -13 * value(x, y); }
};

/// Max-norm errors of each operator at one resolution.
struct Errors {
  double dx = 0;
  double sample = 0;          ///< plain Σ V A W at off-lattice points
  double shepard = 0;         ///< Shepard-normalised, same points
  double gradient = 0;        ///< difference form (|error| of the vector)
  double gradientSym = 0;     ///< symmetric form (volume set: ρ = 1)
  double gradientCorr = 0;    ///< kernel-gradient corrected
  double laplacian = 0;       ///< kernel-Laplacian form (NaN for kernels without one)
  double laplacianBrook = 0;  ///< Brookshaw/Morris form
  double laplacianNorm = 0;   ///< renormalised Brookshaw form
};

/// K: a kernel of kernels.hpp in double. The domain [0, 2]² with n particles per side, support R = kappa·dx, jitter as
/// a fraction of dx; errors are taken at particles (and, for sampling, at the
/// midpoints between four lattice sites) inside the central square [0.5, 1.5]²,
/// which is farther than R from the edge for every resolution used.
template <class K>
Errors measure(int n, double kappa, double jitter, std::uint32_t seed = 7) {
  static_assert(std::is_same<typename K::V::Scalar, double>::value, "the study runs in double");
  using V = typename K::V;
  const double L = 2.0, dx = L / n;
  const Lattice<double> lat = makeLattice<double>(n, n, dx, 0.0, 0.0, jitter, seed);
  const K k(kappa * dx);
  NeighbourSearch search;
  search.build(lat.x.data(), lat.x.size(), k.R);
  const FieldOperators<K> ops(k, lat.view(), search);
  std::vector<double> A(lat.x.size());
  for (std::size_t i = 0; i < A.size(); ++i) A[i] = SmoothField::value(lat.x[i].x(), lat.x[i].y());

  Errors e;
  e.dx = dx;
  e.laplacian = K::hasLaplacian ? 0.0 : std::nan("");
  const auto inside = [](double x, double y) { return x >= 0.5 && x <= 1.5 && y >= 0.5 && y <= 1.5; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const V p((i + 1.0) * dx, (j + 1.0) * dx);  // between four sites
      if (!inside(p.x(), p.y())) continue;
      const double exact = SmoothField::value(p.x(), p.y());
      e.sample = std::max(e.sample, std::fabs(ops.sample(p, A.data()) - exact));
      e.shepard = std::max(e.shepard, std::fabs(ops.sampleShepard(p, A.data()) - exact));
    }
  for (std::size_t i = 0; i < lat.x.size(); ++i) {
    const double x = lat.x[i].x(), y = lat.x[i].y();
    if (!inside(x, y)) continue;
    const V g(SmoothField::dx(x, y), SmoothField::dy(x, y));
    e.gradient = std::max(e.gradient, (ops.gradient(i, A.data()) - g).norm());
    e.gradientSym = std::max(e.gradientSym, (ops.gradientSymmetric(i, A.data()) - g).norm());
    e.gradientCorr = std::max(e.gradientCorr, (ops.gradientCorrected(i, A.data()) - g).norm());
    const double lap = SmoothField::laplacian(x, y);
    if constexpr (K::hasLaplacian) e.laplacian = std::max(e.laplacian, std::fabs(ops.laplacian(i, A.data()) - lap));
    e.laplacianBrook = std::max(e.laplacianBrook, std::fabs(ops.laplacianBrookshaw(i, A.data()) - lap));
    e.laplacianNorm = std::max(e.laplacianNorm, std::fabs(ops.laplacianBrookshawNormalised(i, A.data()) - lap));
  }
  return e;
}

/// Observed order of accuracy between two resolutions: log(e1/e2) / log(dx1/dx2).
inline double order(double e1, double dx1, double e2, double dx2) { return std::log(e1 / e2) / std::log(dx1 / dx2); }

}  // namespace sph2d::study
