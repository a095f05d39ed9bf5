// The neighbour grid (engine/src/particles/neighbour_grid.cpp, neighbour_grid.hpp): the candidates are exactly the
// brute-force neighbour sets, also through periodic seams; PeriodicBox wraps.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <set>
#include <vector>

#include "core/thread_pool.hpp"
#include "particles/neighbour_grid.hpp"

using namespace sph2d;

namespace {

/// Deterministic uniform in [0, 1) from a 64-bit engine (portable across standard libraries).
double unit(std::mt19937_64& rng) { return double(rng() >> 11) * (1.0 / 9007199254740992.0); }

void expectSameAsBruteForce(const std::vector<Vec2>& x, Real R, int cellsPerSupport, ThreadPool& pool) {
  Grid g;
  g.build(x.data(), x.size(), R, pool, cellsPerSupport);
  const Real R2 = R * R;
  std::size_t mismatches = 0, pairs = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    std::vector<std::uint32_t> fromGrid, brute;
    g.forCandidates(x[i], [&](std::uint32_t j) {
      if ((x[i] - x[j]).squaredNorm() < R2) fromGrid.push_back(j);
    });
    for (std::size_t j = 0; j < x.size(); ++j)
      if ((x[i] - x[j]).squaredNorm() < R2) brute.push_back(std::uint32_t(j));
    std::sort(fromGrid.begin(), fromGrid.end());  // unique values: no ties
    pairs += brute.size();
    if (fromGrid != brute) ++mismatches;
  }
  CHECK(mismatches == 0);
  CHECK(pairs >= x.size());  // every particle finds at least itself
}

}  // namespace

TEST_CASE("grid neighbours equal brute force: random, clustered and degenerate inputs") {
  ThreadPool pool(2);
  std::mt19937_64 rng(12345);
  const Real R = 0.05f;
  for (int cps : {1, 2}) {
    CAPTURE(cps);
    // Uniform random.
    std::vector<Vec2> x;
    for (int i = 0; i < 1500; ++i) x.emplace_back(Real(unit(rng)), Real(unit(rng)));
    expectSameAsBruteForce(x, R, cps, pool);
    // Clustered: tight Gaussian-ish blobs.
    x.clear();
    for (int c = 0; c < 5; ++c) {
      const double cx = unit(rng), cy = unit(rng);
      for (int i = 0; i < 300; ++i)
        x.emplace_back(Real(cx + 0.02 * (unit(rng) - 0.5)), Real(cy + 0.02 * (unit(rng) - 0.5)));
    }
    expectSameAsBruteForce(x, R, cps, pool);
    // All particles in one cell, many coincident.
    x.assign(400, Vec2(0.3f, 0.3f));
    for (int i = 0; i < 400; i += 2) x[i] += Vec2(Real(0.001 * unit(rng)), 0);
    expectSameAsBruteForce(x, R, cps, pool);
    // Exactly on cell borders (multiples of the cell size).
    x.clear();
    for (int j = 0; j < 30; ++j)
      for (int i = 0; i < 30; ++i) x.emplace_back(Real(i) * R / Real(cps), Real(j) * R / Real(cps));
    expectSameAsBruteForce(x, R, cps, pool);
    // Far outside the usual range: a cluster at the origin and stragglers 10 km away.
    x.clear();
    for (int i = 0; i < 500; ++i) x.emplace_back(Real(0.2 * unit(rng)), Real(0.2 * unit(rng)));
    for (int i = 0; i < 20; ++i) x.emplace_back(Real(1e4 + 0.03 * i), Real(-1e4));
    x.emplace_back(-3e4f, 2e4f);
    expectSameAsBruteForce(x, R, cps, pool);
  }
}

TEST_CASE(
    "grid counting sort: the one stable order by cell for 1 to 4 threads, sorted, shuffled and clustered inputs") {
  // The sort cuts the cells into one band per thread (at the cells of evenly spaced slots) and
  // each thread places only its band's particles: any cut must give the same order, and that
  // order is the stable sort by cell (cells ascending, slots ascending within a cell).
  std::mt19937_64 rng(777);
  std::vector<Vec2> sortedInput, shuffled, clustered;
  for (int j = 0; j < 120; ++j)
    for (int i = 0; i < 100; ++i)
      sortedInput.emplace_back(Real(0.01 * i + 0.001 * unit(rng)), Real(0.01 * j + 0.001 * unit(rng)));
  shuffled = sortedInput;
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  for (int i = 0; i < 12000; ++i)  // most particles in one corner: uneven bands
    clustered.emplace_back(Real(i < 10000 ? 0.05 * unit(rng) : unit(rng)),
                           Real(i < 10000 ? 0.05 * unit(rng) : unit(rng)));
  for (const std::vector<Vec2>* x : {&sortedInput, &shuffled, &clustered}) {
    std::vector<std::uint32_t> order, starts;
    for (int threads = 1; threads <= 4; ++threads) {
      CAPTURE(threads);
      ThreadPool pool(threads);
      Grid g;
      g.build(x->data(), x->size(), Real(0.04), pool, 2);
      if (threads == 1) {
        order = g.sorted;
        starts = g.cellStart;
        // The stable order by cell.
        for (std::size_t k = 0; k + 1 < g.sorted.size(); ++k) {
          const std::uint32_t a = g.sorted[k], b = g.sorted[k + 1];
          REQUIRE((g.cellOf[a] < g.cellOf[b] || (g.cellOf[a] == g.cellOf[b] && a < b)));
        }
        for (std::size_t c = 0; c + 1 < g.cellStart.size(); ++c)
          for (std::uint32_t k = g.cellStart[c]; k < g.cellStart[c + 1]; ++k) REQUIRE(g.cellOf[g.sorted[k]] == c);
        CHECK(g.cellStart.back() == x->size());
      }
      CHECK(g.sorted == order);
      CHECK(g.cellStart == starts);
    }
  }
}

TEST_CASE("grid build keeps its cell count bounded for a huge bounding box") {
  ThreadPool pool(1);
  std::vector<Vec2> x = {Vec2(0, 0), Vec2(1e6f, 1e6f), Vec2(0.01f, 0)};
  Grid g;
  g.build(x.data(), x.size(), 0.05f, pool, 2);
  CHECK(double(g.nx) * double(g.ny) <= 4096.0 * 1.05);
  CHECK(g.cell >= 0.025f);
  int found = 0;
  g.forCandidates(x[0], [&](std::uint32_t j) { found += (x[0] - x[j]).squaredNorm() < 0.0025f; });
  CHECK(found == 2);
}

TEST_CASE("periodic grid: the candidates within R are exactly the nearest-image neighbours, across both seams") {
  ThreadPool pool(2);
  PeriodicBox box;
  box.x = box.y = true;
  box.lo = Vec2(-0.3f, 0.2f);
  box.lx = 1.1f;
  box.ly = 0.7f;
  const Real R = 0.12f;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> ux(0, 1);
  std::vector<Vec2> x(3000);
  for (auto& p : x) p = box.lo + Vec2(ux(rng) * box.lx, ux(rng) * box.ly);
  for (int k = 0; k < 40; ++k) x[std::size_t(k)] = box.lo + Vec2(0.001f * k, box.ly * 0.999f);  // on the seams
  Grid g;
  g.build(x.data(), x.size(), R, pool, 2, &box);
  CHECK(g.wrapX);
  CHECK(g.wrapY);
  std::size_t pairs = 0, seamPairs = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    std::multiset<std::uint32_t> found;
    g.forCandidates(x[i], [&](std::uint32_t j) {
      if (j != i && box.delta(x[i], x[j]).squaredNorm() < R * R) found.insert(j);
    });
    std::multiset<std::uint32_t> brute;
    for (std::size_t j = 0; j < x.size(); ++j) {
      if (j == i) continue;
      const Vec2 d = box.delta(x[i], x[j]);
      if (d.squaredNorm() < R * R) {
        brute.insert(std::uint32_t(j));
        seamPairs += (x[i] - x[j]).squaredNorm() >= R * R;  // only a neighbour through a seam
      }
    }
    REQUIRE(found == brute);  // and no particle twice
    pairs += brute.size();
  }
  MESSAGE(pairs << " neighbour pairs, " << seamPairs << " of them through a seam");
  CHECK(seamPairs > 1000);
}

TEST_CASE("periodic grid: a period far longer than the fluid keeps the cell count bounded") {
  ThreadPool pool(1);
  PeriodicBox box;
  box.x = true;
  box.lo = Vec2(0, 0);
  box.lx = 1.0e5f;  // 100 km period, 10 particles
  std::vector<Vec2> x;
  for (int i = 0; i < 10; ++i) x.push_back(Vec2(0.01f * float(i), 0.5f));
  Grid g;
  g.build(x.data(), x.size(), 0.025f, pool, 2, &box);
  CHECK(double(g.nx) * double(g.ny) <= 4096.0 * 1.05);
  std::size_t found = 0;
  g.forCandidates(x[0], [&](std::uint32_t j) { found += box.delta(x[0], x[j]).squaredNorm() < 0.025f * 0.025f; });
  CHECK(found == 3);  // itself and the two within 0.025 m
  Grid empty;
  empty.build(x.data(), 0, 0.025f, pool, 2, &box);
  CHECK(empty.nx * empty.ny == 1);
}

TEST_CASE("periodic wrap: positions move into the box by whole periods, xPrev with them") {
  PeriodicBox box;
  box.x = true;
  box.lo = Vec2(1.0f, 0.0f);
  box.lx = 2.0f;
  Vec2 p(3.25f, 7.0f);
  const Vec2 s = box.wrap(p);
  CHECK(p.x() == doctest::Approx(1.25f));
  CHECK(p.y() == 7.0f);  // y is not periodic
  CHECK(s.x() == doctest::Approx(-2.0f));
  Vec2 q(0.5f, 0.0f);
  box.wrap(q);
  CHECK(q.x() == doctest::Approx(2.5f));
  Vec2 edge(3.0f, 0.0f);  // the upper edge belongs to the next period
  box.wrap(edge);
  CHECK(edge.x() >= 1.0f);
  CHECK(edge.x() < 3.0f);
}
