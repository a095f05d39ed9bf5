// Kernels: normalisation, symmetry, derivatives, safety at r = 0 and r = R.
#include <doctest/doctest.h>

#include <cmath>

#include "core/kernels.hpp"

using namespace sph2d;

namespace {

template <class K>
double latticeIntegral(const K& k, int cellsPerR) {
  // Midpoint rule on a square lattice covering the support disc.
  const double R = k.R, d = R / cellsPerR;
  double s = 0;
  for (int j = -cellsPerR; j < cellsPerR; ++j)
    for (int i = -cellsPerR; i < cellsPerR; ++i) {
      const double x = (i + 0.5) * d, y = (j + 0.5) * d;
      s += k.value(std::sqrt(x * x + y * y));
    }
  return s * d * d;
}

using V2d = Vector2<double>;

}  // namespace

TEST_CASE_TEMPLATE("kernel integrates to 1 over its support (fine lattice, double)", K, Poly6<double>, Spiky<double>,
                   ViscosityKernel<double>, CubicSpline<double>, WendlandC2<double>) {
  for (double R : {0.05, 1.0, 3.0}) {
    const K k(R);
    CHECK(latticeIntegral(k, 1500) == doctest::Approx(1.0).epsilon(1e-3));
  }
}

TEST_CASE_TEMPLATE("kernel is non-negative, radially decreasing, zero at and beyond the support", K, Poly6<double>,
                   Spiky<double>, ViscosityKernel<double>, CubicSpline<double>, WendlandC2<double>) {
  const K k(0.7);
  double prev = k.value(1e-3 * k.R);
  for (int i = 1; i <= 1000; ++i) {
    const double r = k.R * i / 1000.0;
    const double w = k.value(r);
    CHECK(w >= 0);
    CHECK(w <= prev + 1e-12 * prev);
    prev = w;
  }
  CHECK(k.value(k.R) == 0);
  CHECK(k.value(1.5 * k.R) == 0);
  CHECK(k.derivative(k.R) == doctest::Approx(0).epsilon(1e-12));
}

TEST_CASE_TEMPLATE("kernel derivative and Laplacian agree with finite differences of W", K, Poly6<double>,
                   Spiky<double>, ViscosityKernel<double>, CubicSpline<double>, WendlandC2<double>) {
  const K k(0.9);
  const double e = 1e-5 * k.R;
  for (int i = 1; i < 19; ++i) {
    const double r = k.R * (0.06 + 0.05 * i);  // beyond the viscosity kernel's Laplacian clamp
    const double fd1 = (k.value(r + e) - k.value(r - e)) / (2 * e);
    CHECK(k.derivative(r) == doctest::Approx(fd1).epsilon(1e-5).scale(1e-3 * std::fabs(k.derivative(0.5 * k.R))));
    // ∇W = W'(r) d/r in any direction.
    const V2d d(r * std::cos(0.3 * i), r * std::sin(0.3 * i));
    const V2d g = k.gradient(d, r);
    CHECK(g.x() == doctest::Approx(k.derivative(r) * d.x() / r).epsilon(1e-9).scale(1e-9));
    CHECK(g.y() == doctest::Approx(k.derivative(r) * d.y() / r).epsilon(1e-9).scale(1e-9));
    if (K::hasLaplacian) {
      const double e2 = 1e-4 * k.R;
      const double fd2 = (k.value(r + e2) - 2 * k.value(r) + k.value(r - e2)) / (e2 * e2);
      const double lapFd = fd2 + k.derivative(r) / r;
      CHECK(k.laplacian(r) == doctest::Approx(lapFd).epsilon(1e-4).scale(1e-4 * std::fabs(k.laplacian(0.5 * k.R))));
    }
  }
}

TEST_CASE_TEMPLATE("kernel gradient is antisymmetric and sums to zero at an interior lattice point", K, Poly6<double>,
                   Spiky<double>, ViscosityKernel<double>, CubicSpline<double>, WendlandC2<double>) {
  const double dx = 0.1;
  const K k(2.5 * dx);
  V2d sum = V2d::Zero();
  double scale = 0;
  for (int j = -4; j <= 4; ++j)
    for (int i = -4; i <= 4; ++i) {
      const V2d d(-i * dx, -j * dx);  // x_0 − x_j
      const double r = d.norm();
      const V2d g = k.gradient(d, r);
      const V2d gBack = k.gradient(V2d(-d), r);
      CHECK((g + gBack).norm() <= 1e-12 * (1 + g.norm()));
      sum += g;
      scale += g.norm();
    }
  CHECK(sum.norm() <= 1e-12 * scale);
}

TEST_CASE_TEMPLATE("kernel is finite at r = 0 and r = R in float", K, Poly6<float>, Spiky<float>,
                   ViscosityKernel<float>, CubicSpline<float>, WendlandC2<float>) {
  const K k(0.035f);
  using V = typename K::V;
  for (float r : {0.0f, k.R, 1e-30f}) {
    CHECK(std::isfinite(k.value(r)));
    CHECK(std::isfinite(k.derivative(r)));
    CHECK(std::isfinite(k.laplacian(r)));
    const V g = k.gradient(V(r, 0.0f), r);
    CHECK(std::isfinite(g.x()));
    CHECK(std::isfinite(g.y()));
  }
  const V g0 = k.gradient(V(0.0f, 0.0f), 0.0f);
  CHECK(g0.norm() == 0.0f);
}

TEST_CASE("spiky gradient uses the 2D gradient constant -30/(pi R^5), not the W constant") {
  const Spiky<double> k(1.0);
  // At r = 0 (limit), dW/dr = -3 c R^2 with c = 10/(pi R^5): -30/pi.
  CHECK(k.derivative(0.0) == doctest::Approx(-30.0 / kPi<double>));
}

TEST_CASE("viscosity kernel Laplacian is the 2D form, not c(R - r)") {
  const ViscosityKernel<double> k(1.0);
  const double r = 0.5;
  const double expected = 5 * (1 - r) * (1 + r + r * r + 9 * r * r * r) / (3 * kPi<double> * r * r * r);
  CHECK(k.laplacian(r) == doctest::Approx(expected));
  CHECK(k.laplacian(r) != doctest::Approx(40 / kPi<double> * (1 - r)));
}

TEST_CASE("the pair-loop forms equal the kernels: Wendland's valueQ and gradientScale, the viscosity Laplacian of r²") {
  const WendlandC2<float> w(0.025f);
  const ViscosityKernel<float> v(0.025f);
  for (float r = 0.0f; r < 0.025f; r += 0.0005f) {
    CAPTURE(r);
    const float q = r * w.invR;
    CHECK(w.valueQ(q) == w.value(r));  // the same expression: the same bits
    const WendlandC2<float>::V d(0.6f * r, -0.8f * r);
    const float a = 1.0f - q;
    const WendlandC2<float>::V g = d * (w.gradientScale * a * a * a);
    const WendlandC2<float>::V ref = w.gradient(d, r);
    CHECK(g.x() == doctest::Approx(ref.x()).epsilon(1e-5));
    CHECK(g.y() == doctest::Approx(ref.y()).epsilon(1e-5));
    CHECK(v.laplacianR2(r * r) == doctest::Approx(v.laplacian(r)).epsilon(1e-5));
  }
  CHECK(v.laplacianR2(0.025f * 0.025f) == 0.0f);
  CHECK(std::isfinite(v.laplacianR2(0.0f)));  // clamped at rMin
}
