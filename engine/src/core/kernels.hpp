// sph2d/kernels.hpp — 2D SPH smoothing kernels.
//
// Every kernel is a small value type built from its support radius R (the
// distance beyond which W = 0). Each provides
//   value(r)        W(r)
//   derivative(r)   dW/dr
//   gradient(d, r)  ∇W at d = x_i - x_j, |d| = r   (zero vector at r = 0)
//   laplacian(r)    ∇²W = W'' + W'/r in 2D, where it is defined (hasLaplacian)
// and works for float and double. All are finite at r = 0 and at r = R.
//
// The 2D normalisation constants come from shared/reference/kernel_constants_2d.csv
// (checked there by integration over the disc); tests/engine/test_kernels.cpp
// checks ∫W = 1, symmetry and the derivatives against finite differences.
#pragma once

#include <algorithm>
#include <cmath>

#include "sph2d/math.hpp"

namespace sph2d {

/// Gradient helper: dW/dr times the unit vector d/r, zero at r = 0.
template <class T>
inline Vector2<T> radialGradient(const Vector2<T>& d, T r, T dWdr) {
  if (!(r > T(0))) return Vector2<T>::Zero();
  return (d / r) * dWdr;  // unit vector first: no overflow for tiny r
}

/// Poly6 (Müller, Charypar & Gross 2003): W = 4/(π R^8) (R² − r²)³ in 2D.
/// Smooth at r = 0; the density kernel of that paper's solver (muller2003).
template <class T = Real>
struct Poly6 {
  using V = Vector2<T>;
  static constexpr bool hasLaplacian = true;
  static constexpr const char* name = "poly6";
  T R, R2, c;
  /// Builds the kernel with support radius `support`.
  explicit Poly6(T support) : R(support), R2(support * support), c(T(4) / (kPi<T> * std::pow(support, T(8)))) {}
  /// W as a function of r² (no square root; the density loop uses this).
  T valueR2(T r2) const {
    if (r2 >= R2) return T(0);
    const T a = R2 - r2;
    return c * a * a * a;
  }
  /// W(r).
  T value(T r) const { return valueR2(r * r); }
  /// dW/dr = −6 c r (R² − r²)².
  T derivative(T r) const {
    if (r >= R) return T(0);
    const T a = R2 - r * r;
    return T(-6) * c * r * a * a;
  }
  /// ∇W at d = x_i − x_j with |d| = r. Equals −6c (R² − r²)² d (smooth at 0).
  V gradient(const V& d, T r) const {
    if (r >= R) return V::Zero();
    const T a = R2 - r * r;
    return d * (T(-6) * c * a * a);
  }
  /// ∇²W = 12 c (R² − r²)(3r² − R²).
  T laplacian(T r) const {
    if (r >= R) return T(0);
    const T r2 = r * r;
    return T(12) * c * (R2 - r2) * (T(3) * r2 - R2);
  }
};

/// Spiky (Müller et al. 2003): W = 10/(π R^5) (R − r)³ in 2D. Its gradient
/// does not vanish at r = 0, so pressure keeps close particles apart. The
/// 2D gradient constant is −30/(π R^5) (not the W constant, a common slip).
template <class T = Real>
struct Spiky {
  using V = Vector2<T>;
  static constexpr bool hasLaplacian = false;  // W'/r is singular at r = 0
  static constexpr const char* name = "spiky";
  T R, c;
  /// Builds the kernel with support radius `support`.
  explicit Spiky(T support) : R(support), c(T(10) / (kPi<T> * std::pow(support, T(5)))) {}
  /// W(r).
  T value(T r) const {
    if (r >= R) return T(0);
    const T a = R - r;
    return c * a * a * a;
  }
  /// dW/dr = −3c (R − r)².
  T derivative(T r) const {
    if (r >= R) return T(0);
    const T a = R - r;
    return T(-3) * c * a * a;
  }
  /// ∇W (zero vector at r = 0, where the direction is undefined).
  V gradient(const V& d, T r) const { return radialGradient<T>(d, r, derivative(r)); }
  /// Not defined at r = 0; returns W'' + W'/r with r clamped to 1e-3 R.
  T laplacian(T r) const {
    if (r >= R) return T(0);
    const T rr = std::max(r, T(1e-3) * R);
    const T a = R - rr;
    return T(6) * c * a - T(3) * c * a * a / rr;
  }
};

/// Viscosity kernel (Müller et al. 2003), 2D normalisation 10/(3π R²):
/// W = c (−r³/(2R³) + r²/R² + R/(2r) − 1). Its 2D Laplacian is
/// 5 (R − r)(R³ + R² r + R r² + 9 r³) / (3π R^5 r³) — not c·(R − r) as in 3D.
/// W, W' and ∇²W are singular at r = 0. W and W' clamp r to 1e-6 R (finite,
/// and the clamp changes ∫W by under 1e-5); ∇²W clamps r to rMin = 0.05 R, which
/// caps the viscous coupling of nearly coincident pairs (docs/KERNELS.md).
template <class T = Real>
struct ViscosityKernel {
  using V = Vector2<T>;
  static constexpr bool hasLaplacian = true;
  static constexpr const char* name = "viscosity";
  T R, c, rMin, rTiny;
  /// Builds the kernel with support radius `support`.
  explicit ViscosityKernel(T support)
      : R(support), c(T(10) / (T(3) * kPi<T> * support * support)), rMin(T(0.05) * support), rTiny(T(1e-6) * support) {}
  /// W(r), r clamped to 1e-6 R.
  T value(T r) const {
    if (r >= R) return T(0);
    const T q = std::max(r, rTiny);
    return c * (-q * q * q / (T(2) * R * R * R) + q * q / (R * R) + R / (T(2) * q) - T(1));
  }
  /// dW/dr, r clamped to 1e-6 R.
  T derivative(T r) const {
    if (r >= R) return T(0);
    const T q = std::max(r, rTiny);
    return c * (T(-3) * q * q / (T(2) * R * R * R) + T(2) * q / (R * R) - R / (T(2) * q * q));
  }
  /// ∇W (zero vector at r = 0).
  V gradient(const V& d, T r) const { return radialGradient<T>(d, r, derivative(r)); }
  /// The same Laplacian for r² (pair loops): one square root and one division,
  /// r clamped to rMin; equal to laplacian(√r²) to rounding.
  T laplacianR2(T r2) const {
    if (r2 >= R * R) return T(0);
    const T R2 = R * R, R3 = R2 * R;
    const T lapK = T(5) / (T(3) * kPi<T> * R2 * R3);
    const T q = r2 > rMin * rMin ? std::sqrt(r2) : rMin;
    const T iq = T(1) / q;
    return lapK * (R - q) * (R3 + R2 * q + R * q * q + T(9) * q * q * q) * iq * iq * iq;
  }
  /// The exact 2D Laplacian, r clamped to rMin.
  T laplacian(T r) const {
    if (r >= R) return T(0);
    const T q = std::max(r, rMin);
    return T(5) * (R - q) * (R * R * R + R * R * q + R * q * q + T(9) * q * q * q) /
           (T(3) * kPi<T> * R * R * R * R * R * q * q * q);
  }
};

/// Cubic spline (Monaghan's M4, the example kernel of the GAMES103 course
/// notes' SPH introduction), written with support radius R
/// (R = 2h in the h-convention): σ = 40/(7π R²), q = r/R,
/// W = σ(6q³ − 6q² + 1) for q ≤ ½, 2σ(1 − q)³ for q ≤ 1.
template <class T = Real>
struct CubicSpline {
  using V = Vector2<T>;
  static constexpr bool hasLaplacian = true;
  static constexpr const char* name = "cubic";
  T R, invR, s;
  /// Builds the kernel with support radius `support`.
  explicit CubicSpline(T support) : R(support), invR(T(1) / support), s(T(40) / (T(7) * kPi<T> * support * support)) {}
  /// W(r).
  T value(T r) const {
    const T q = r * invR;
    if (q >= T(1)) return T(0);
    if (q <= T(0.5)) return s * (T(6) * q * q * q - T(6) * q * q + T(1));
    const T a = T(1) - q;
    return T(2) * s * a * a * a;
  }
  /// dW/dr.
  T derivative(T r) const {
    const T q = r * invR;
    if (q >= T(1)) return T(0);
    if (q <= T(0.5)) return s * T(6) * q * (T(3) * q - T(2)) * invR;
    const T a = T(1) - q;
    return T(-6) * s * a * a * invR;
  }
  /// ∇W (zero vector at r = 0).
  V gradient(const V& d, T r) const { return radialGradient<T>(d, r, derivative(r)); }
  /// ∇²W: σ(54q − 24)/R² for q ≤ ½, σ(12(1−q) − 6(1−q)²/q)/R² beyond.
  T laplacian(T r) const {
    const T q = r * invR;
    if (q >= T(1)) return T(0);
    if (q <= T(0.5)) return s * (T(54) * q - T(24)) * invR * invR;
    const T a = T(1) - q;
    return s * (T(12) * a - T(6) * a * a / q) * invR * invR;
  }
};

/// Wendland C2 (Wendland 1995), support R: σ = 7/(π R²), W = σ(1 − q)⁴(4q + 1).
template <class T = Real>
struct WendlandC2 {
  using V = Vector2<T>;
  static constexpr bool hasLaplacian = true;
  static constexpr const char* name = "wendland_c2";
  T R, invR, s;
  /// −20σ/R²: ∇W = gradientScale·(1 − q)³·d (the pair loops multiply by (1 − q)³ themselves).
  T gradientScale;
  /// Builds the kernel with support radius `support`.
  explicit WendlandC2(T support)
      : R(support),
        invR(T(1) / support),
        s(T(7) / (kPi<T> * support * support)),
        gradientScale(T(-20) * s * invR * invR) {}
  /// W(r).
  T value(T r) const {
    const T q = r * invR;
    if (q >= T(1)) return T(0);
    return valueQ(q);
  }
  /// W at q = r/R < 1 (no range check; pair loops that know q < 1 call this).
  T valueQ(T q) const {
    const T a = T(1) - q;
    return s * a * a * a * a * (T(4) * q + T(1));
  }
  /// dW/dr = −20σ q (1 − q)³ / R.
  T derivative(T r) const {
    const T q = r * invR;
    if (q >= T(1)) return T(0);
    const T a = T(1) - q;
    return T(-20) * s * q * a * a * a * invR;
  }
  /// ∇W = −20σ (1 − q)³ d / R² (smooth at 0).
  V gradient(const V& d, T r) const {
    const T q = r * invR;
    if (q >= T(1)) return V::Zero();
    const T a = T(1) - q;
    return d * (T(-20) * s * a * a * a * invR * invR);
  }
  /// ∇²W = −20σ (1 − q)²(2 − 5q) / R².
  T laplacian(T r) const {
    const T q = r * invR;
    if (q >= T(1)) return T(0);
    const T a = T(1) - q;
    return T(-20) * s * a * a * (T(2) - T(5) * q) * invR * invR;
  }
};

/// The first moment M = −Σ_j V x_ij,x ∂W/∂x over a square lattice of spacing
/// dx (V = volume per particle): 1 for an exact gradient. A symmetric SPH
/// pressure gradient underestimates ∇p by this factor (Wendland C2 at
/// R = 2.5 dx: 0.953), so solvers divide their pressure term by it.
template <class Kernel>
double latticeGradientMoment(const Kernel& W, double dx, double volume) {
  const int n = int(std::ceil(double(W.R) / dx)) + 1;
  double m = 0;
  for (int j = -n; j <= n; ++j)
    for (int i = -n; i <= n; ++i) {
      const double x = i * dx, y = j * dx, r = std::sqrt(x * x + y * y);
      if (r > 0) m -= volume * x * x * double(W.derivative(decltype(W.R)(r))) / r;  // W' < 0
    }
  return m;
}

/// The second moment ¼ Σ_j V r² L(r) of a Laplacian kernel L over a square
/// lattice of spacing dx (V = dx²), the centre excluded: the factor by which
/// Σ_j V (A_j − A_i) L(r_ij) gives ∇²A for a smooth field (1 when exact). The
/// 2D Laplacian of Müller's viscosity kernel has an R³/r³ term whose continuous
/// moment diverges, so the discrete one depends on R/dx (0.834 at R = 2.5 dx):
/// the viscosity effect divides by it.
template <class Laplacian>
double latticeLaplacianMoment(const Laplacian& L, double R, double dx) {
  const int n = int(std::ceil(R / dx)) + 1;
  double m = 0;
  for (int j = -n; j <= n; ++j)
    for (int i = -n; i <= n; ++i) {
      const double r = std::sqrt(double(i * i + j * j)) * dx;
      if (r > 0 && r < R) m += 0.25 * dx * dx * r * r * L(r);
    }
  return m;
}

}  // namespace sph2d
