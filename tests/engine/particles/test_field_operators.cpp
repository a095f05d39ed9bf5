// Field operators (sph2d/field_operators.hpp): the neighbour search against brute
// force, exactness on constant, linear and quadratic fields, conservation of the
// symmetric gradient, and the convergence orders that docs/KERNELS.md reports.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "core/kernels.hpp"
#include "particles/field_operators.hpp"
#include "support/field_study.hpp"

using namespace sph2d;
using study::Lattice;
using study::makeLattice;

namespace {

template <class T>
using Vec = Vector2<T>;

// Rounding tolerance of a sum of ~30 kernel-weighted terms, relative to its scale.
template <class T>
constexpr double roundTol() {
  return std::is_same<T, float>::value ? 2e-5 : 1e-12;
}

// Particles whose whole support lies inside the lattice (n×n sites of spacing dx at lo = 0).
template <class T>
bool interior(const Vec<T>& p, int n, double dx, double R) {
  const double lo = R + dx, hi = n * dx - R - dx;
  return p.x() > lo && p.x() < hi && p.y() > lo && p.y() < hi;
}

}  // namespace

TEST_CASE_TEMPLATE("NeighbourSearch returns exactly the points within the radius, in a fixed order", T, float, double) {
  std::mt19937 g(12345);
  for (const double offset : {0.0, 1000.0}) {  // 1000: float coordinates with large ulps
    std::vector<Vec<T>> x;
    for (int i = 0; i < 2000; ++i)
      x.emplace_back(T(offset + 3 * study::uniform01(g)), T(offset - 1 + 2 * study::uniform01(g)));
    const double R = 0.13;
    NeighbourSearch s;
    s.build(x.data(), x.size(), R);
    CHECK(s.size() == x.size());
    CHECK(s.cellSize() >= R);
    std::size_t pairs = 0;
    for (int q = 0; q < 300; ++q) {
      // Queries inside and up to 2R outside the particles' box.
      const Vec<T> p(T(offset - 2 * R + (3 + 4 * R) * study::uniform01(g)),
                     T(offset - 1 - 2 * R + (2 + 4 * R) * study::uniform01(g)));
      std::vector<char> seen(x.size(), 0);
      std::vector<std::size_t> order;
      s.forCandidates(p, [&](std::size_t j) {
        CHECK(seen[j] == 0);  // each candidate once
        seen[j] = 1;
        order.push_back(j);
      });
      for (std::size_t j = 0; j < x.size(); ++j) {
        const T r2 = (p - x[j]).squaredNorm();
        if (r2 < T(R * R)) {
          CHECK(seen[j] == 1);
          ++pairs;
        }
      }
      // The same query on a second build visits the same candidates in the same order.
      std::vector<std::size_t> again;
      NeighbourSearch s2;
      s2.build(x.data(), x.size(), R);
      s2.forCandidates(p, [&](std::size_t j) { again.push_back(j); });
      CHECK(again == order);
    }
    CHECK(pairs > 300 * 5);  // the queries did see neighbours
  }
}

TEST_CASE("FieldOperators::forNeighbours visits exactly the particles with r < R, with d = x - x_j") {
  const Lattice<double> lat = makeLattice<double>(25, 25, 0.04, -0.5, 0.25, 0.45, 3);
  const WendlandC2<double> k(0.1);
  NeighbourSearch s;
  s.build(lat.x.data(), lat.x.size(), k.R);
  const FieldOperators<WendlandC2<double>> ops(k, lat.view(), s);
  std::mt19937 g(77);
  for (int q = 0; q < 200; ++q) {
    const Vec2d p(-0.55 + 1.1 * study::uniform01(g), 0.2 + 1.1 * study::uniform01(g));
    std::vector<int> hit(lat.x.size(), 0);
    ops.forNeighbours(p, [&](std::size_t j, const Vec2d& d, double r) {
      ++hit[j];
      CHECK((d - (p - lat.x[j])).norm() == 0);
      CHECK(r == doctest::Approx(d.norm()).epsilon(1e-15));
    });
    for (std::size_t j = 0; j < lat.x.size(); ++j) CHECK(hit[j] == ((p - lat.x[j]).norm() < k.R ? 1 : 0));
  }
}

TEST_CASE("NeighbourSearch and FieldOperators reject bad input") {
  std::vector<Vec2d> x{Vec2d(0, 0), Vec2d(1, 0)};
  NeighbourSearch s;
  CHECK_THROWS_AS(s.build(x.data(), x.size(), 0.0), std::invalid_argument);
  CHECK_THROWS_AS(s.build(x.data(), x.size(), -1.0), std::invalid_argument);
  x[1].x() = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(s.build(x.data(), x.size(), 0.5), std::invalid_argument);
  x[1].x() = 1;
  s.build(x.data(), x.size(), 0.5);
  int count = 0;
  s.forCandidates(Vec2d(std::numeric_limits<double>::infinity(), 0), [&](std::size_t) { ++count; });
  CHECK(count == 0);
  NeighbourSearch empty;
  empty.build(x.data(), 0, 0.5);
  empty.forCandidates(Vec2d(0, 0), [&](std::size_t) { ++count; });
  CHECK(count == 0);

  const std::vector<double> vol{1, 1};
  const CubicSpline<double> k(1.0);
  CHECK_THROWS_AS(FieldOperators<CubicSpline<double>>(k, ParticleView<double>::withVolumes(x.data(), vol.data(), 2), s),
                  std::invalid_argument);  // search radius 0.5 < R = 1
  s.build(x.data(), x.size(), 1.0);
  CHECK_THROWS_AS(FieldOperators<CubicSpline<double>>(k, ParticleView<double>::withVolumes(x.data(), vol.data(), 1), s),
                  std::invalid_argument);  // different sizes
  CHECK_THROWS_AS(FieldOperators<CubicSpline<double>>(k, ParticleView<double>::withVolumes(x.data(), nullptr, 2), s),
                  std::invalid_argument);  // no volumes
  CHECK_NOTHROW(FieldOperators<CubicSpline<double>>(k, ParticleView<double>::withVolumes(x.data(), vol.data(), 2), s));
}

TEST_CASE_TEMPLATE("Shepard sampling reproduces a constant to rounding on a jittered lattice, the plain sum does not",
                   K, CubicSpline<float>, CubicSpline<double>, WendlandC2<float>, WendlandC2<double>, Poly6<double>,
                   Spiky<double>) {
  using T = typename K::V::Scalar;
  const int n = 30;
  const double dx = 0.1;
  const Lattice<T> lat = makeLattice<T>(n, n, dx, 0, 0, 0.3, 99);
  const K k(T(3 * dx));
  NeighbourSearch s;
  s.build(lat.x.data(), lat.x.size(), k.R);
  const FieldOperators<K> ops(k, lat.view(), s);
  const T c = T(2.5);
  const std::vector<T> A(lat.x.size(), c);
  const std::vector<Vec<T>> Av(lat.x.size(), Vec<T>(T(-1.5), T(0.25)));
  std::mt19937 g(4);
  double worstPlain = 0;
  for (int q = 0; q < 200; ++q) {
    // Anywhere in the lattice, edges included (truncated supports).
    const Vec<T> p(T(n * dx * study::uniform01(g)), T(n * dx * study::uniform01(g)));
    CHECK(std::fabs(ops.sampleShepard(p, A.data()) - c) <= roundTol<T>() * c);
    const Vec<T> sv = ops.sampleShepard(p, Av.data());
    CHECK(std::fabs(sv.x() + 1.5) <= roundTol<T>() * 1.5);
    CHECK(std::fabs(sv.y() - 0.25) <= roundTol<T>() * 1.5);
    worstPlain = std::max(worstPlain, std::fabs(double(ops.sample(p, A.data())) - c) / c);
    // The plain sum is the Shepard sum times the field.
    CHECK(ops.sample(p, A.data()) == doctest::Approx(double(c * ops.shepardSum(p))).epsilon(roundTol<T>()));
  }
  CHECK(worstPlain > 0.05);  // kernel-sum deficit (edges, jitter) that Shepard removes
}

TEST_CASE_TEMPLATE(
    "Shepard sampling of a linear field: exact at symmetric lattice sites, off by at most |g|·jitter on a jittered lattice",
    K, CubicSpline<double>, WendlandC2<double>, Poly6<double>) {
  const int n = 30;
  const double dx = 0.1, jitter = 0.2;
  const Vec2d g0(0.7, -1.3);
  const auto linear = [&](const Vec2d& p) { return 0.4 + g0.dot(p); };
  for (const double jit : {0.0, jitter}) {
    const Lattice<double> lat = makeLattice<double>(n, n, dx, 0, 0, jit, 5);
    const K k(3 * dx);
    NeighbourSearch s;
    s.build(lat.x.data(), lat.x.size(), k.R);
    const FieldOperators<K> ops(k, lat.view(), s);
    std::vector<double> A(lat.x.size());
    for (std::size_t i = 0; i < A.size(); ++i) A[i] = linear(lat.x[i]);
    double worst = 0;
    for (int j = 6; j < n - 6; ++j)
      for (int i = 6; i < n - 6; ++i) {
        const Vec2d site((i + 0.5) * dx, (j + 0.5) * dx);  // the unjittered site: a centre of symmetry
        worst = std::max(worst, std::fabs(ops.sampleShepard(site, A.data()) - linear(site)));
      }
    if (jit == 0.0) {
      CHECK(worst <= 1e-13);
    } else {
      // Error = g · Σ V W (x_j − x) / Σ V W, and each x_j is within √2·jitter·dx of its site.
      CHECK(worst <= g0.norm() * std::sqrt(2.0) * jitter * dx);
      CHECK(worst >= 1e-3 * g0.norm() * dx);  // not exact: Shepard is only zeroth-order consistent
    }
  }
}

TEST_CASE_TEMPLATE(
    "corrected gradient, divergence and curl are exact for linear fields on a jittered lattice, edges included", K,
    CubicSpline<float>, CubicSpline<double>, WendlandC2<float>, WendlandC2<double>, Spiky<double>,
    ViscosityKernel<double>) {
  using T = typename K::V::Scalar;
  const int n = 24;
  const double dx = 0.05;
  const Lattice<T> lat = makeLattice<T>(n, n, dx, 0.2, -0.1, 0.25, 11);
  const K k(T(2.6 * dx));
  NeighbourSearch s;
  s.build(lat.x.data(), lat.x.size(), k.R);
  const FieldOperators<K> ops(k, lat.view(), s);
  const Vec<T> g(T(1.25), T(-0.5));
  Eigen::Matrix<T, 2, 2> B;  // A_v = B x + c: div = B00 + B11, curl = B10 − B01
  B << T(0.3), T(-1.1), T(0.8), T(0.45);
  std::vector<T> A(lat.x.size());
  std::vector<Vec<T>> Av(lat.x.size());
  for (std::size_t i = 0; i < A.size(); ++i) {
    A[i] = T(2) + g.dot(lat.x[i]);
    const Vec<T>& x = lat.x[i];
    Av[i] = Vec<T>(B(0, 0) * x.x() + B(0, 1) * x.y(), B(1, 0) * x.x() + B(1, 1) * x.y()) + Vec<T>(T(0.5), T(-2));
  }
  const double div = B(0, 0) + B(1, 1), curl = B(1, 0) - B(0, 1);
  double worstPlain = 0;
  for (std::size_t i = 0; i < A.size(); ++i) {
    typename FieldOperators<K>::M2 L;
    REQUIRE(ops.correctionMatrix(i, L));  // invertible everywhere, corners too
    const Vec<T> gc = ops.gradientCorrected(i, A.data());
    CHECK((gc - g).norm() <= 20 * roundTol<T>() * g.norm());
    CHECK(std::fabs(ops.divergenceCorrected(i, Av.data()) - div) <= 20 * roundTol<T>() * B.norm());
    CHECK(std::fabs(ops.curlCorrected(i, Av.data()) - curl) <= 20 * roundTol<T>() * B.norm());
    worstPlain = std::max(worstPlain, double((ops.gradient(i, A.data()) - g).norm()));
  }
  CHECK(worstPlain > 0.1 * g.norm());  // the uncorrected gradient is not exact (edges, jitter)
}

TEST_CASE("the correction falls back to the uncorrected operators where M is singular (particles on a line)") {
  std::vector<Vec2d> x;
  for (int i = 0; i < 10; ++i) x.emplace_back(0.1 * i, 0.3);
  const std::vector<double> vol(x.size(), 0.01), A{0, 1, 4, 9, 16, 25, 36, 49, 64, 81};
  const CubicSpline<double> k(0.35);
  NeighbourSearch s;
  s.build(x.data(), x.size(), k.R);
  const FieldOperators<CubicSpline<double>> ops(k, ParticleView<double>::withVolumes(x.data(), vol.data(), x.size()),
                                                s);
  Eigen::Matrix2d L;
  CHECK_FALSE(ops.correctionMatrix(4, L));
  CHECK(L == Eigen::Matrix2d::Identity());
  const Vec2d gc = ops.gradientCorrected(4, A.data()), gp = ops.gradient(4, A.data());
  CHECK(gc.x() == gp.x());
  CHECK(gc.y() == gp.y());
  CHECK(gp.x() != 0.0);
}

TEST_CASE_TEMPLATE("difference operators vanish for uniform fields and the symmetric gradient conserves momentum", K,
                   CubicSpline<float>, CubicSpline<double>, Spiky<double>) {
  using T = typename K::V::Scalar;
  const int n = 20;
  const double dx = 0.1;
  const Lattice<T> lat = makeLattice<T>(n, n, dx, 0, 0, 0.3, 21);
  std::mt19937 gen(8);
  std::vector<T> m(lat.x.size()), rho(lat.x.size()), A(lat.x.size()), c(lat.x.size(), T(3));
  for (std::size_t i = 0; i < A.size(); ++i) {
    rho[i] = T(900 + 200 * study::uniform01(gen));
    m[i] = T(dx * dx * 1000);
    A[i] = T(1e5 * (1 + study::uniform01(gen)));  // a pressure-like field
  }
  const std::vector<Vec<T>> cv(lat.x.size(), Vec<T>(T(2), T(-1)));
  const K k(T(2.5 * dx));
  NeighbourSearch s;
  s.build(lat.x.data(), lat.x.size(), k.R);
  const auto view = ParticleView<T>::withMassDensity(lat.x.data(), m.data(), rho.data(), lat.x.size());
  const FieldOperators<K> ops(k, view, s);
  Vec2d sumSym = Vec2d::Zero(), sumDiff = Vec2d::Zero();
  double scale = 0;
  for (std::size_t i = 0; i < A.size(); ++i) {
    CHECK(ops.gradient(i, c.data()).norm() == 0);
    CHECK(ops.divergence(i, cv.data()) == 0);
    CHECK(ops.curl(i, cv.data()) == 0);
    CHECK(ops.laplacianBrookshaw(i, c.data()) == 0);
    const Vec<T> gs = ops.gradientSymmetric(i, A.data()) * view.volumeOf(i);
    const Vec<T> gd = ops.gradient(i, A.data()) * view.volumeOf(i);
    sumSym += gs.template cast<double>();
    sumDiff += gd.template cast<double>();
    scale += double(gs.norm());
  }
  // Pairwise antisymmetric: Σ_i V_i ρ_i Σ_j m_j(…)∇W_ij = Σ_ij m_i m_j(…)∇W_ij = 0.
  CHECK(sumSym.norm() <= 10 * roundTol<T>() * scale);
  CHECK(sumDiff.norm() >= 1e-3 * scale);  // the difference form is not conservative
}

TEST_CASE_TEMPLATE("Laplacian of x^2 + y^2 at interior points of a regular lattice", K, Poly6<double>, Spiky<double>,
                   ViscosityKernel<double>, CubicSpline<double>, WendlandC2<double>, CubicSpline<float>) {
  using T = typename K::V::Scalar;
  const int n = 30;
  const double dx = 0.1;
  const Lattice<T> lat = makeLattice<T>(n, n, dx, -1.5, -1.5, 0.0, 1);
  const K k(T(3 * dx));
  NeighbourSearch s;
  s.build(lat.x.data(), lat.x.size(), k.R);
  const FieldOperators<K> ops(k, lat.view(), s);
  std::vector<T> A(lat.x.size());
  for (std::size_t i = 0; i < A.size(); ++i) A[i] = lat.x[i].squaredNorm();
  // Measured |Brookshaw − 4| at R = 3 dx, the same at every interior site (the
  // lattice's error in the kernel's second moment plus the 0.01 h² term):
  // poly6 0.0299, spiky 0.196, viscosity 1.414, cubic 0.0192, Wendland 0.0605.
  // The check keeps it within ±10 % of that: bounded, and not accidentally exact.
  const std::string name = K::name;
  const double brookErr = name == "poly6"       ? 0.0299
                          : name == "spiky"     ? 0.196
                          : name == "viscosity" ? 1.414
                          : name == "cubic"     ? 0.0192
                                                : 0.0605;
  double worstBrook = 0, worstNorm = 0, worstKernelLap = 0;
  int count = 0;
  for (std::size_t i = 0; i < A.size(); ++i) {
    const Vec<T> pos = lat.x[i] - Vec<T>(T(-1.5), T(-1.5));
    if (!interior<T>(pos, n, dx, k.R)) continue;
    ++count;
    worstBrook = std::max(worstBrook, std::fabs(double(ops.laplacianBrookshaw(i, A.data())) - 4));
    // The renormalised form is exact for quadratics on a lattice (to rounding;
    // the float field x² + y² itself carries a few ulps of error).
    worstNorm = std::max(worstNorm, std::fabs(double(ops.laplacianBrookshawNormalised(i, A.data())) - 4));
    if constexpr (K::hasLaplacian)
      worstKernelLap = std::max(worstKernelLap, std::fabs(double(ops.laplacian(i, A.data())) - 4));
  }
  MESSAGE(name, ": |kernel-Laplacian form - 4| = ", worstKernelLap);
  if constexpr (K::hasLaplacian) {
    // The seed's kernel-Laplacian form is much further off on the same lattice
    // (measured poly6 0.926, viscosity 0.782, cubic 0.445, Wendland 0.0375), ±10 %.
    const double kernelLapErr = name == "poly6"       ? 0.926
                                : name == "viscosity" ? 0.782
                                : name == "cubic"     ? 0.445
                                                      : 0.0375;
    CHECK(worstKernelLap <= 1.1 * kernelLapErr);
    CHECK(worstKernelLap >= 0.9 * kernelLapErr);
  }
  CHECK(count > 100);
  MESSAGE(name, ": |Brookshaw - 4| = ", worstBrook, ", |normalised - 4| = ", worstNorm);
  CHECK(worstBrook <= 1.1 * brookErr);
  CHECK(worstBrook >= 0.9 * brookErr);
  CHECK(worstNorm <= (std::is_same<T, float>::value ? 1e-4 : 1e-11));  // measured 2.9e-5 (float), 2e-13 (double)
}

namespace {

// Orders between the three resolutions n = 40, 80, 160 (R = 3 dx, fixed).
struct Orders {
  study::Errors e[3];
  double sample[2], shepard[2], gradient[2], gradientCorr[2], laplacianBrook[2], laplacianNorm[2];
};

template <class K>
Orders measureOrders(double jitter) {
  Orders o;
  const int ns[3] = {40, 80, 160};
  for (int r = 0; r < 3; ++r) o.e[r] = study::measure<K>(ns[r], 3.0, jitter);
  for (int r = 0; r < 2; ++r) {
    const study::Errors &a = o.e[r], &b = o.e[r + 1];
    o.sample[r] = study::order(a.sample, a.dx, b.sample, b.dx);
    o.shepard[r] = study::order(a.shepard, a.dx, b.shepard, b.dx);
    o.gradient[r] = study::order(a.gradient, a.dx, b.gradient, b.dx);
    o.gradientCorr[r] = study::order(a.gradientCorr, a.dx, b.gradientCorr, b.dx);
    o.laplacianBrook[r] = study::order(a.laplacianBrook, a.dx, b.laplacianBrook, b.dx);
    o.laplacianNorm[r] = study::order(a.laplacianNorm, a.dx, b.laplacianNorm, b.dx);
  }
  return o;
}

}  // namespace

TEST_CASE_TEMPLATE(
    "convergence on a regular lattice at fixed R/dx = 3: Shepard sample, corrected gradient and renormalised Laplacian are second order",
    K, Poly6<double>, Spiky<double>, ViscosityKernel<double>, CubicSpline<double>, WendlandC2<double>) {
  const Orders o = measureOrders<K>(0.0);
  // Measured (docs/KERNELS.md): 1.97–2.00 for all three, every kernel, both steps.
  for (int r = 0; r < 2; ++r) {
    CHECK(o.shepard[r] >= 1.9);
    CHECK(o.shepard[r] <= 2.1);
    CHECK(o.gradientCorr[r] >= 1.9);
    CHECK(o.gradientCorr[r] <= 2.1);
    CHECK(o.laplacianNorm[r] >= 1.9);
    CHECK(o.laplacianNorm[r] <= 2.1);
  }
  // The errors themselves are small at the finest resolution (|A| ≤ 1, |∇A| ≤ 3.6, |∇²A| ≤ 13).
  CHECK(o.e[2].shepard < 1e-3);
  CHECK(o.e[2].gradientCorr < 3e-3);
  CHECK(o.e[2].laplacianNorm < 6e-3);
  // The plain Brookshaw Laplacian stalls at fixed R/dx (the lattice's error in
  // the kernel's second moment does not shrink): measured order −0.01 to 0.26
  // on the last step.
  CHECK(o.laplacianBrook[1] < 0.5);
}

TEST_CASE_TEMPLATE("convergence on a jittered lattice (±0.1 dx): Shepard sample and corrected gradient are first order",
                   K, CubicSpline<double>, WendlandC2<double>) {
  const Orders o = measureOrders<K>(0.1);
  // Overall order from n = 40 to 160; measured 1.19–1.33 (docs/KERNELS.md).
  const double shep = study::order(o.e[0].shepard, o.e[0].dx, o.e[2].shepard, o.e[2].dx);
  const double gc = study::order(o.e[0].gradientCorr, o.e[0].dx, o.e[2].gradientCorr, o.e[2].dx);
  MESSAGE(std::string(K::name), ": jittered orders shepard ", shep, ", corrected gradient ", gc);
  CHECK(shep >= 1.0);
  CHECK(gc >= 1.0);
  // The Brookshaw Laplacian diverges like 1/dx on a disordered set (measured −1.0 to −1.3 per step).
  CHECK(o.laplacianBrook[1] < -0.5);
}
