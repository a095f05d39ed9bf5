// The game solver's grid pressure solve on its own (engine/src/solvers/game/grid_pcg.cpp): the
// 5-point system of a grid's fluid cells, with air cells as κ = 0 (Dirichlet) and solid cells
// as closed walls (Neumann), solved by MIC(0)-preconditioned conjugate gradients. Against the
// exact solutions of the discrete problem: a Dirichlet box's sine mode and a sealed box's
// cosine modes in closed form, a mixed domain's direct (sparse Cholesky, double) solve; the
// sealed pockets' union-find grounding; the same bits when two solves run at once.
//
// The bounds: the solver stops when the largest |r| of the residual it carries is below tol
// (float vectors, double sums); the residual of its answer, recomputed here in double, is
// within 2 tol (measured ≤ 0.8 tol). The tolerances sit where float vectors can reach them:
// 1e-3 of the largest |b| for the slow modes (the float rounding of p alone leaves a residual
// of ~8·2⁻²⁴·max|p|, 1e-4 of |b| for the sine mode; at 1e-5 its answer recomputed to 7.7 tol).
// An error e = p − p* with A e = −r is bounded by ‖A⁻¹‖∞ |r|∞ with Dirichlet walls (A an
// M-matrix: ‖A⁻¹‖∞ = max of A⁻¹·1, L²/8 for a box L cells between its air walls), and by
// ‖r‖₂ / λ₁ off the constants of a sealed pocket (λ₁ its smallest non-zero eigenvalue).
//
// Each check was seen failing with the solver broken on purpose: air cells taken as walls (the
// sine and mixed cases: a sealed pocket found, the residual and error checks fail), no
// grounding (the grounded cell at 1.76, not 0), the union-find linking a cell instead of its
// root (3 pockets, not 2), no balance (the grounded cells at 98 and 145), neither (|p| 1.5e8),
// one scratch shared by the solves (the concurrent bits differ).
#include <doctest/doctest.h>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/thread_pool.hpp"
#include "solvers/game/grid_pcg.hpp"

using namespace sph2d;

namespace {

/// The four neighbours' offsets: left, right, down, up.
constexpr std::pair<int, int> kSteps[4] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};

/// Cells of an nx × ny grid, row by row.
struct Cells {
  int nx, ny;
  std::vector<std::uint8_t> type;
  Cells(int w, int h, std::uint8_t fill) : nx(w), ny(h), type(std::size_t(w) * std::size_t(h), fill) {}
  std::size_t at(int i, int j) const { return std::size_t(j) * std::size_t(nx) + std::size_t(i); }
  void fill(int i0, int j0, int i1, int j1, std::uint8_t t) {  // [i0, i1) × [j0, j1)
    for (int j = j0; j < j1; ++j)
      for (int i = i0; i < i1; ++i) type[at(i, j)] = t;
  }
  bool fluid(int i, int j) const { return type[at(i, j)] == GridPcg::kFluid; }
};

/// The test's own matrix: (A p)_k = Σ over the four neighbours of fluid cell k that are fluid
/// or air of (p_k − p_nb), air holding 0; solid neighbours add nothing. No grounding.
std::vector<double> applyA(const Cells& c, const std::vector<double>& p) {
  std::vector<double> out(c.type.size(), 0.0);
  for (int j = 0; j < c.ny; ++j)
    for (int i = 0; i < c.nx; ++i) {
      if (!c.fluid(i, j)) continue;
      double s = 0;
      for (const auto& [di, dj] : kSteps) {
        const std::uint8_t t = c.type[c.at(i + di, j + dj)];
        if (t == GridPcg::kFluid)
          s += p[c.at(i, j)] - p[c.at(i + di, j + dj)];
        else if (t == GridPcg::kAir)
          s += p[c.at(i, j)];
      }
      out[c.at(i, j)] = s;
    }
  return out;
}

std::vector<double> toDouble(const std::vector<Real>& v) { return std::vector<double>(v.begin(), v.end()); }

/// b − A·p over the fluid cells (0 elsewhere), in double.
std::vector<double> residual(const Cells& c, const std::vector<double>& b, const std::vector<Real>& p) {
  std::vector<double> r = applyA(c, toDouble(p));
  for (std::size_t k = 0; k < r.size(); ++k) r[k] = c.type[k] == GridPcg::kFluid ? b[k] - r[k] : 0.0;
  return r;
}

double maxAbs(const std::vector<double>& v) {
  double m = 0;
  for (const double x : v) m = std::max(m, std::fabs(x));
  return m;
}

double norm2(const std::vector<double>& v) {
  double s = 0;
  for (const double x : v) s += x * x;
  return std::sqrt(s);
}

/// The exact solution of A p = b (test matrix, Dirichlet: no sealed pocket) by sparse Cholesky in double.
std::vector<double> directSolve(const Cells& c, const std::vector<double>& b) {
  std::vector<int> unknown(c.type.size(), -1);
  int m = 0;
  for (std::size_t k = 0; k < c.type.size(); ++k)
    if (c.type[k] == GridPcg::kFluid) unknown[k] = m++;
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < c.ny; ++j)
    for (int i = 0; i < c.nx; ++i) {
      const int a = unknown[c.at(i, j)];
      if (a < 0) continue;
      double d = 0;
      for (const auto& [di, dj] : kSteps) {
        const std::uint8_t tt = c.type[c.at(i + di, j + dj)];
        if (tt == GridPcg::kFluid) t.emplace_back(a, unknown[c.at(i + di, j + dj)], -1.0);
        if (tt == GridPcg::kFluid || tt == GridPcg::kAir) d += 1;
      }
      t.emplace_back(a, a, d);
    }
  Eigen::SparseMatrix<double> A(m, m);
  A.setFromTriplets(t.begin(), t.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> llt(A);
  REQUIRE(llt.info() == Eigen::Success);
  Eigen::VectorXd rhs(m);
  for (std::size_t k = 0; k < c.type.size(); ++k)
    if (unknown[k] >= 0) rhs[unknown[k]] = b[k];
  const Eigen::VectorXd x = llt.solve(rhs);
  std::vector<double> out(c.type.size(), 0.0);
  for (std::size_t k = 0; k < c.type.size(); ++k)
    if (unknown[k] >= 0) out[k] = x[unknown[k]];
  return out;
}

std::vector<Real> toReal(const std::vector<double>& v) { return std::vector<Real>(v.begin(), v.end()); }

}  // namespace

TEST_CASE("grid PCG: a Dirichlet box's discrete sine mode, to the tolerance and within the maximum-principle bound") {
  // N × N fluid cells inside a ring of air: p = sin(π i/L) sin(π j/L), L = N + 1, vanishes at
  // the air cells' centres and is an eigenvector of A: A p = 8 sin²(π/2L) p. So b = λ p has
  // the exact discrete solution p. ‖A⁻¹‖∞ = max of φ = i(L − i)/2 (A φ = 1) = L²/8.
  const int N = 40, L = N + 1;
  Cells c(N + 2, N + 2, GridPcg::kAir);
  c.fill(1, 1, N + 1, N + 1, GridPcg::kFluid);
  const double lambda = 8 * std::pow(std::sin(kPi<double> / (2 * L)), 2);
  std::vector<double> exact(c.type.size(), 0.0), b(c.type.size(), 0.0);
  for (int j = 1; j <= N; ++j)
    for (int i = 1; i <= N; ++i) {
      exact[c.at(i, j)] = std::sin(kPi<double> * i / L) * std::sin(kPi<double> * j / L);
      b[c.at(i, j)] = lambda * exact[c.at(i, j)];
    }
  const std::vector<Real> bf = toReal(b);
  const Real tol = Real(1e-3 * lambda);  // 1e-3 of the largest |b|
  const GridPoissonResult r = solveGridPoisson(c.nx, c.ny, c.type, bf, tol, 1000);
  const double res = maxAbs(residual(c, toDouble(bf), r.pressure));
  double err = 0;
  for (std::size_t k = 0; k < exact.size(); ++k) err = std::max(err, std::fabs(double(r.pressure[k]) - exact[k]));
  // The float right-hand side is b to 2⁻²⁴: its own exact solution is p within L²/8 · 2⁻²⁴ λ.
  const double bound = double(L) * L / 8 * (res + std::ldexp(lambda, -24));
  MESSAGE("sine mode, " << r.unknowns << " unknowns: " << r.iterations << " iterations, residual " << r.residual / tol
                        << " tol (recomputed " << res / tol << " tol), max error " << err << " (bound " << bound
                        << ")");
  CHECK(r.unknowns == N * N);
  CHECK(r.pockets == 0);
  CHECK(r.residual <= tol);
  CHECK(res <= 2 * tol);
  CHECK(err <= bound);
  CHECK(err <= 1e-4);  // of the mode's amplitude 1
  CHECK(r.iterations < 100);
}

TEST_CASE("grid PCG: a manufactured sin·cos pressure around a solid block matches the direct solve in double") {
  // A 48 × 36 box: fluid inside a ring of air (κ = 0) except a solid floor (closed), with a
  // solid block in the middle (closed faces) and an air gap over the fluid's top right. Any
  // p on the fluid cells is the exact discrete solution of A p = A p: p = sin(πx) cos(πy/2) +
  // 0.3 cos(3πx) sin(2πy) (x, y the cell's centre over the box). The float right-hand side's
  // own exact solution comes from sparse Cholesky in double, ‖A⁻¹‖∞ from A φ = 1 the same way.
  const int nx = 50, ny = 38;
  Cells c(nx, ny, GridPcg::kAir);
  c.fill(1, 1, nx - 1, ny - 1, GridPcg::kFluid);
  c.fill(0, 0, nx, 1, GridPcg::kSolid);               // the floor
  c.fill(20, 10, 30, 22, GridPcg::kSolid);            // the block
  c.fill(35, ny - 6, nx - 1, ny - 1, GridPcg::kAir);  // an air pocket open to the top
  c.fill(5, 5, 8, 8, GridPcg::kSolid);                // a pillar of 3 × 3 cells
  std::vector<double> want(c.type.size(), 0.0);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      if (c.fluid(i, j)) {
        const double x = (i + 0.5) / nx, y = (j + 0.5) / ny;
        want[c.at(i, j)] = std::sin(kPi<double> * x) * std::cos(kPi<double> * y / 2) +
                           0.3 * std::cos(3 * kPi<double> * x) * std::sin(2 * kPi<double> * y);
      }
  const std::vector<double> b = applyA(c, want);
  const std::vector<Real> bf = toReal(b);
  const std::vector<double> exact = directSolve(c, toDouble(bf));
  std::vector<double> ones(c.type.size(), 0.0);
  for (std::size_t k = 0; k < ones.size(); ++k) ones[k] = c.type[k] == GridPcg::kFluid ? 1.0 : 0.0;
  const double normInv = maxAbs(directSolve(c, ones));  // ‖A⁻¹‖∞ (A⁻¹ ≥ 0)
  const Real tol = Real(1e-5 * maxAbs(b));
  const GridPoissonResult r = solveGridPoisson(nx, ny, c.type, bf, tol, 1000);
  const double res = maxAbs(residual(c, toDouble(bf), r.pressure));
  double err = 0, errWant = 0;
  for (std::size_t k = 0; k < exact.size(); ++k) {
    err = std::max(err, std::fabs(double(r.pressure[k]) - exact[k]));
    errWant = std::max(errWant, std::fabs(double(r.pressure[k]) - want[k]));
  }
  const double bound = normInv * res;
  MESSAGE("mixed walls, " << r.unknowns << " unknowns: " << r.iterations << " iterations, residual " << r.residual / tol
                          << " tol (recomputed " << res / tol << " tol), ||A^-1|| " << normInv << ", max error " << err
                          << " (bound " << bound << "), against the manufactured p " << errWant);
  CHECK(r.pockets == 0);
  CHECK(r.residual <= tol);
  CHECK(res <= 2 * tol);
  CHECK(err <= bound);
  CHECK(errWant <= 1e-3);  // of an amplitude ~1.3
  for (std::size_t k = 0; k < c.type.size(); ++k)
    if (c.type[k] != GridPcg::kFluid) REQUIRE(r.pressure[k] == 0);  // air and solid cells hold 0
}

TEST_CASE("grid PCG: a sealed box (Neumann walls) solves its cosine modes up to a constant, its last cell grounded") {
  // N × N fluid cells inside a ring of solid: the Neumann Laplacian, singular (the constants).
  // v_kl = cos(πk(i − ½)/N) cos(πl(j − ½)/N) are its eigenvectors, λ_kl = (2 − 2cos(πk/N)) +
  // (2 − 2cos(πl/N)); a sum of modes other than (0, 0) is balanced and its solution is Σ v/λ
  // plus any constant. The solver grounds the pocket's last cell (its κ is 0) and balances
  // the float right-hand side. Off the constants, ‖e‖∞ ≤ ‖e‖₂ ≤ ‖r‖₂/λ₁₀.
  const int N = 32;
  Cells c(N + 2, N + 2, GridPcg::kSolid);
  c.fill(1, 1, N + 1, N + 1, GridPcg::kFluid);
  auto lam = [&](int k) { return 2 - 2 * std::cos(kPi<double> * k / N); };
  struct Mode {
    int k, l;
    double amp;
  };
  const Mode modes[] = {{1, 1, 1.0}, {2, 0, 0.5}, {0, 3, -0.25}};
  std::vector<double> exact(c.type.size(), 0.0), b(c.type.size(), 0.0);
  for (int j = 1; j <= N; ++j)
    for (int i = 1; i <= N; ++i)
      for (const Mode& m : modes) {
        const double v = std::cos(kPi<double> * m.k * (i - 0.5) / N) * std::cos(kPi<double> * m.l * (j - 0.5) / N);
        exact[c.at(i, j)] += m.amp * v;
        b[c.at(i, j)] += m.amp * (lam(m.k) + lam(m.l)) * v;
      }
  const std::vector<Real> bf = toReal(b);
  // The float right-hand side balanced as the solver balances it (its mean out), in double.
  double mean = 0;
  for (int j = 1; j <= N; ++j)
    for (int i = 1; i <= N; ++i) mean += double(bf[c.at(i, j)]) / (N * N);
  std::vector<double> bb = toDouble(bf);
  for (std::size_t k = 0; k < bb.size(); ++k)
    if (c.type[k] == GridPcg::kFluid) bb[k] -= mean;
  const Real tol = Real(1e-3 * maxAbs(b));
  const GridPoissonResult r = solveGridPoisson(c.nx, c.ny, c.type, bf, tol, 1000);
  const double res = maxAbs(residual(c, bb, r.pressure)), res2 = norm2(residual(c, bb, r.pressure));
  // The error off the constants: p − exact, its mean over the pocket out.
  double shift = 0;
  for (int j = 1; j <= N; ++j)
    for (int i = 1; i <= N; ++i) shift += (double(r.pressure[c.at(i, j)]) - exact[c.at(i, j)]) / (N * N);
  double err = 0;
  for (int j = 1; j <= N; ++j)
    for (int i = 1; i <= N; ++i)
      err = std::max(err, std::fabs(double(r.pressure[c.at(i, j)]) - exact[c.at(i, j)] - shift));
  const double bound = res2 / lam(1);
  const Real grounded = r.pressure[c.at(N, N)];  // the last unknown in cell order
  MESSAGE("sealed box, " << r.unknowns << " unknowns: " << r.iterations << " iterations, residual " << r.residual / tol
                         << " tol (recomputed " << res / tol << " tol), max error off the constants " << err
                         << " (bound " << bound << "), last cell " << grounded << ", mean of b " << mean);
  CHECK(r.pockets == 1);
  CHECK(r.residual <= tol);
  CHECK(res <= 2 * tol);
  CHECK(err <= bound);
  CHECK(err <= 1e-3);                  // of amplitudes 1 + 0.5 + 0.25 over λ ≥ 0.0096
  CHECK(std::fabs(grounded) <= 1e-3);  // the grounded cell: κ = 0 up to the solve's error
}

TEST_CASE("grid PCG: sealed pockets with unbalanced right-hand sides stay finite, each grounded and balanced apart") {
  // A vented region (open to the air ring at the top), and two pockets sealed by solid: an arch
  // (∩: its legs are found as two regions, bottom row first, and joined at its top by the
  // union-find) and a square. The right-hand side is 1 + sin/2 everywhere: a sealed pocket
  // cannot hold that (Σ b ≠ 0, no solution), so each pocket's mean is taken out; without the
  // grounding or the balance the system is singular or inconsistent.
  const int nx = 40, ny = 30;
  Cells c(nx, ny, GridPcg::kSolid);
  c.fill(0, ny - 1, nx, ny, GridPcg::kAir);        // air along the top
  c.fill(1, 20, nx - 1, ny - 1, GridPcg::kFluid);  // the vented region, rows 20..28
  c.fill(3, 3, 6, 15, GridPcg::kFluid);            // the arch's left leg
  c.fill(12, 3, 15, 15, GridPcg::kFluid);          // its right leg
  c.fill(3, 15, 15, 18, GridPcg::kFluid);          // its top, joining the legs
  c.fill(22, 4, 34, 16, GridPcg::kFluid);          // the square
  std::vector<Real> b(c.type.size(), Real(1));
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) b[c.at(i, j)] = Real(1 + 0.5 * std::sin(0.7 * i + 0.3 * j));
  const Real tol = Real(1e-3);
  const GridPoissonResult r = solveGridPoisson(nx, ny, c.type, b, tol, 2000);
  bool finite = true;
  for (const Real p : r.pressure) finite = finite && std::isfinite(p);
  // Each region's right-hand side as the solver balances it (the vented region's unchanged).
  auto region = [&](int i, int j) { return j >= 20 ? 0 : i < 20 ? 1 : 2; };
  double sum[3] = {0, 0, 0}, count[3] = {0, 0, 0};
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      if (c.fluid(i, j)) {
        sum[region(i, j)] += double(b[c.at(i, j)]);
        count[region(i, j)] += 1;
      }
  std::vector<double> bb(c.type.size(), 0.0);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      if (c.fluid(i, j))
        bb[c.at(i, j)] = double(b[c.at(i, j)]) - (region(i, j) == 0 ? 0.0 : sum[region(i, j)] / count[region(i, j)]);
  const double res = maxAbs(residual(c, bb, r.pressure));
  const Real archLast = r.pressure[c.at(14, 17)], squareLast = r.pressure[c.at(33, 15)];
  double largest = 0;
  for (const Real p : r.pressure) largest = std::max(largest, std::fabs(double(p)));
  MESSAGE("pockets: " << r.pockets << ", " << r.iterations << " iterations, residual " << r.residual / tol
                      << " tol (recomputed " << res / tol << " tol), largest |p| " << largest << ", grounded cells "
                      << archLast << ", " << squareLast);
  CHECK(r.pockets == 2);  // 3 if the arch's legs were not joined
  REQUIRE(finite);
  CHECK(r.residual <= tol);
  CHECK(res <= 2 * tol);
  CHECK(r.iterations < 2000);
  // A grounded cell's κ is 0 (up to the solve's error, ~ ‖A⁻¹‖ tol).
  CHECK(std::fabs(archLast) <= 1e-2);
  CHECK(std::fabs(squareLast) <= 1e-2);
  CHECK(largest < 1e3);  // the vented region's hydrostatic-like κ: ~ depth²/2 = 40
}

TEST_CASE("grid PCG: two solves on one system at once give the bits of one after the other, on 1, 2 and 3 threads") {
  // The projection solves the pressure and the compression shift on one GridPcg side by side
  // (grid_solve.cpp). The solve itself uses no thread; what it shares must be read only.
  // Large enough (22,680 unknowns, 75 and 73 iterations) that the two solves overlap.
  const int nx = 200, ny = 140;
  Cells c(nx, ny, GridPcg::kAir);
  c.fill(0, 0, nx, 1, GridPcg::kSolid);
  c.fill(1, 1, nx - 1, 120, GridPcg::kFluid);
  c.fill(25, 5, 35, 12, GridPcg::kSolid);
  c.fill(100, 40, 140, 60, GridPcg::kSolid);
  c.fill(10, 3, 14, 7, GridPcg::kSolid);  // a sealed pocket: cells 11..12 × 4..5 fluid inside a ring
  c.fill(11, 4, 13, 6, GridPcg::kFluid);
  const std::vector<std::uint8_t> uOpen(std::size_t(nx + 1) * ny, 1), vOpen(std::size_t(nx) * (ny + 1), 1);
  GridPcg pcg;
  pcg.assemble(nx, ny, c.type, uOpen, vOpen, nullptr);
  pcg.factor();
  REQUIRE(pcg.pockets() == 1);
  const std::size_t m = pcg.size();
  std::vector<Real> b0(m), b1(m);
  for (std::size_t a = 0; a < m; ++a) {
    b0[a] = Real(std::sin(0.37 * double(a)));
    b1[a] = Real(std::cos(0.11 * double(a)) * 0.5);
  }
  pcg.balance(b0);
  pcg.balance(b1);
  Real res[2];
  auto solveBoth = [&](ThreadPool* pool, std::vector<Real> x[2], int it[2]) {
    GridPcg::Work w[2];
    const std::vector<Real>* rhs[2] = {&b0, &b1};
    auto one = [&](std::size_t k) {
      x[k].assign(m, 0);
      it[k] = pcg.solve(x[k], *rhs[k], Real(1e-6), 500, res[k], w[k]);
    };
    if (pool)
      pool->parallelFor(2, 1, [&](std::size_t s, std::size_t e) {
        for (std::size_t k = s; k < e; ++k) one(k);
      });
    else
      for (std::size_t k = 0; k < 2; ++k) one(k);
  };
  std::vector<Real> ref[2];
  int refIt[2];
  solveBoth(nullptr, ref, refIt);
  MESSAGE(m << " unknowns: " << refIt[0] << " and " << refIt[1] << " iterations");
  for (int k = 0; k < 2; ++k) {
    CHECK(res[k] <= Real(1e-6));
    CHECK(refIt[k] > 10);
  }
  for (int threads = 1; threads <= 3; ++threads) {
    ThreadPool pool(threads);
    for (int round = 0; round < 5; ++round) {
      std::vector<Real> x[2];
      int it[2];
      solveBoth(&pool, x, it);
      CAPTURE(threads);
      CAPTURE(round);
      for (int k = 0; k < 2; ++k) {
        CHECK(it[k] == refIt[k]);
        REQUIRE(x[k].size() == ref[k].size());
        CHECK(std::memcmp(x[k].data(), ref[k].data(), m * sizeof(Real)) == 0);
      }
    }
  }
}

TEST_CASE("grid PCG: the cells-only solve refuses a fluid cell on the grid's border") {
  Cells c(6, 6, GridPcg::kAir);
  c.fill(1, 1, 5, 5, GridPcg::kFluid);
  const std::vector<Real> b(c.type.size(), Real(1));
  CHECK_NOTHROW(solveGridPoisson(6, 6, c.type, b, Real(1e-6), 100));
  c.type[c.at(5, 2)] = GridPcg::kFluid;
  CHECK_THROWS_AS(solveGridPoisson(6, 6, c.type, b, Real(1e-6), 100), std::invalid_argument);
  CHECK_THROWS_AS(solveGridPoisson(6, 5, c.type, b, Real(1e-6), 100), std::invalid_argument);
}

TEST_CASE("grid PCG: a coefficient per face (materials of different density) solves -div(beta grad p) exactly") {
  // The mixed domain of the case above, each face with β from 0.3 to 2.5 (the projection's
  // 1/r_face for densities from 400 to 3300 kg/m³): any p on the fluid cells is the exact
  // discrete solution of A_β p = A_β p, A_β built here from the faces. And with every β = 1
  // the weighted loops give the bits of the plain ones.
  const int nx = 50, ny = 38;
  Cells c(nx, ny, GridPcg::kAir);
  c.fill(1, 1, nx - 1, ny - 1, GridPcg::kFluid);
  c.fill(0, 0, nx, 1, GridPcg::kSolid);
  c.fill(20, 10, 30, 22, GridPcg::kSolid);
  c.fill(35, ny - 6, nx - 1, ny - 1, GridPcg::kAir);
  const std::vector<std::uint8_t> uOpen(std::size_t(nx + 1) * ny, 1), vOpen(std::size_t(nx) * (ny + 1), 1);
  std::vector<Real> uBeta(uOpen.size()), vBeta(vOpen.size());
  std::uint32_t seed = 12345;
  auto next = [&] {
    seed = seed * 1664525u + 1013904223u;
    return Real(0.3) + Real(2.2) * Real(seed >> 8) / Real(1u << 24);
  };
  for (Real& b : uBeta) b = next();
  for (Real& b : vBeta) b = next();
  // The face between cell (i, j) and its neighbour along step q, and its β.
  auto beta = [&](int i, int j, int q) -> double {
    if (q == 0) return uBeta[std::size_t(j) * (nx + 1) + std::size_t(i)];
    if (q == 1) return uBeta[std::size_t(j) * (nx + 1) + std::size_t(i + 1)];
    if (q == 2) return vBeta[std::size_t(j) * nx + std::size_t(i)];
    return vBeta[std::size_t(j + 1) * nx + std::size_t(i)];
  };
  std::vector<double> want(c.type.size(), 0.0), b(c.type.size(), 0.0);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      if (c.fluid(i, j)) {
        const double x = (i + 0.5) / nx, y = (j + 0.5) / ny;
        want[c.at(i, j)] = std::sin(kPi<double> * x) * std::cos(kPi<double> * y / 2) + 0.5 * y;
      }
  auto applyBeta = [&](const std::vector<double>& p) {
    std::vector<double> out(c.type.size(), 0.0);
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        if (!c.fluid(i, j)) continue;
        double s = 0;
        for (int q = 0; q < 4; ++q) {
          const auto [di, dj] = kSteps[q];
          const std::uint8_t t = c.type[c.at(i + di, j + dj)];
          if (t == GridPcg::kFluid) s += beta(i, j, q) * (p[c.at(i, j)] - p[c.at(i + di, j + dj)]);
          if (t == GridPcg::kAir) s += beta(i, j, q) * p[c.at(i, j)];
        }
        out[c.at(i, j)] = s;
      }
    return out;
  };
  b = applyBeta(want);
  GridPcg pcg;
  pcg.assemble(nx, ny, c.type, uOpen, vOpen, nullptr, &uBeta, &vBeta);
  pcg.factor();
  const std::size_t m = pcg.size();
  std::vector<Real> rhs(m), x(m, 0);
  for (std::size_t a = 0; a < m; ++a) rhs[a] = Real(b[std::size_t(pcg.cells()[a])]);
  const Real tol = Real(1e-5 * maxAbs(b));
  Real res = 0;
  GridPcg::Work w;
  const int it = pcg.solve(x, rhs, tol, 1000, res, w);
  std::vector<double> p(c.type.size(), 0.0);
  for (std::size_t a = 0; a < m; ++a) p[std::size_t(pcg.cells()[a])] = double(x[a]);
  std::vector<double> r = applyBeta(p);
  double resDouble = 0, err = 0;
  for (std::size_t a = 0; a < m; ++a) {
    const std::size_t k = std::size_t(pcg.cells()[a]);
    resDouble = std::max(resDouble, std::fabs(double(rhs[a]) - r[k]));
    err = std::max(err, std::fabs(p[k] - want[k]));
  }
  MESSAGE("β from 0.3 to 2.5, " << m << " unknowns: " << it << " iterations, residual " << resDouble / double(tol)
                                << " tol, max error against the manufactured p " << err);
  CHECK(res <= tol);
  CHECK(resDouble <= 2 * double(tol));
  CHECK(err <= 2e-3);  // of an amplitude ~1.5
  CHECK(it < 200);

  // Every β = 1: the bits of the plain system.
  std::fill(uBeta.begin(), uBeta.end(), Real(1));
  std::fill(vBeta.begin(), vBeta.end(), Real(1));
  GridPcg plain, ones;
  plain.assemble(nx, ny, c.type, uOpen, vOpen, nullptr);
  ones.assemble(nx, ny, c.type, uOpen, vOpen, nullptr, &uBeta, &vBeta);
  plain.factor();
  ones.factor();
  std::vector<Real> x1(m, 0), x2(m, 0);
  Real r1 = 0, r2 = 0;
  GridPcg::Work w1, w2;
  const int it1 = plain.solve(x1, rhs, tol, 1000, r1, w1), it2 = ones.solve(x2, rhs, tol, 1000, r2, w2);
  CHECK(it1 == it2);
  CHECK(std::memcmp(x1.data(), x2.data(), m * sizeof(Real)) == 0);
}
