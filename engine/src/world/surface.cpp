// surface.cpp — the fluid's outline (sph2d/surface.hpp): the covered fraction splatted onto a
// node grid and smoothed, marching squares on it, and the crossings linked into closed curves.
#include "sph2d/surface.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/thread_pool.hpp"
#include "world/world_impl.hpp"

namespace sph2d {
namespace {

/// The covered fraction on a grid of nodes (x0 + i h, y0 + j h), i < nx, j < ny.
struct NodeField {
  double x0 = 0, y0 = 0, h = 1;
  int nx = 0, ny = 0;
  std::vector<double> phi;
  double at(int i, int j) const { return phi[std::size_t(j) * std::size_t(nx) + std::size_t(i)]; }
  Vec2d node(int i, int j) const { return Vec2d(x0 + i * h, y0 + j * h); }
};

/// Calls fn(j) for j < n, on the pool's threads when given (rows in blocks of 8).
template <class Fn>
void forRows(ThreadPool* pool, int n, const Fn& fn) {
  if (!pool) {
    for (int j = 0; j < n; ++j) fn(j);
    return;
  }
  pool->parallelFor(std::size_t(n), 8, [&](std::size_t b, std::size_t e) {
    for (std::size_t j = b; j < e; ++j) fn(int(j));
  });
}

NodeField sampleField(const std::vector<Vec2d>& points, double dx, const SurfaceOptions& o, ThreadPool* pool) {
  NodeField f;
  if (points.empty()) return f;
  double lo[2] = {points[0].x(), points[0].y()}, hi[2] = {lo[0], lo[1]};
  for (const Vec2d& p : points) {
    lo[0] = std::min(lo[0], p.x()), lo[1] = std::min(lo[1], p.y());
    hi[0] = std::max(hi[0], p.x()), hi[1] = std::max(hi[1], p.y());
  }
  // A margin of the smoothing's reach and two cells: the border nodes read 0, so every curve
  // closes. A region too large for the budget (a long jet in one piece) gets larger cells.
  const double budget = std::max(64.0 * double(points.size()), 65536.0);
  f.h = o.cell * dx;
  for (;;) {
    const double margin = double(o.smoothing + 3) * f.h;
    f.x0 = std::floor((lo[0] - margin) / f.h) * f.h;
    f.y0 = std::floor((lo[1] - margin) / f.h) * f.h;
    const double nx = std::ceil((hi[0] + margin - f.x0) / f.h) + 1, ny = std::ceil((hi[1] + margin - f.y0) / f.h) + 1;
    if (nx * ny <= budget) {
      f.nx = int(nx);
      f.ny = int(ny);
      break;
    }
    f.h *= std::sqrt(nx * ny / budget) * 1.01;
  }
  const std::size_t nx = std::size_t(f.nx), ny = std::size_t(f.ny);
  f.phi.assign(nx * ny, 0.0);
  // Each particle's share (its area over a cell's) to the four nodes around it, bilinear, in
  // the order of `points`: a full lattice gives every node 1, a half plane 1/2 on the nodes of
  // its edge.
  const double invH = 1 / f.h, share = dx * dx / (f.h * f.h);
  for (const Vec2d& p : points) {
    const double px = (p.x() - f.x0) * invH, py = (p.y() - f.y0) * invH;
    const std::size_t i = std::min(std::size_t(px), nx - 2), j = std::min(std::size_t(py), ny - 2);
    const double tx = px - double(i), ty = py - double(j);
    double* n = &f.phi[j * nx + i];
    n[0] += share * (1 - tx) * (1 - ty);
    n[1] += share * tx * (1 - ty);
    n[nx] += share * (1 - tx) * ty;
    n[nx + 1] += share * tx * ty;
  }
  // Each smoothing pass: (1 2 1)/4 along x, then along y (into a second buffer and back). The
  // border rows and columns stay 0.
  std::vector<double> tmp(f.phi.size(), 0.0);
  for (int pass = 0; pass < o.smoothing; ++pass) {
    forRows(pool, f.ny, [&](int j) {
      const double* in = &f.phi[std::size_t(j) * nx];
      double* out = &tmp[std::size_t(j) * nx];
      for (std::size_t i = 1; i + 1 < nx; ++i) out[i] = 0.25 * (in[i - 1] + 2 * in[i] + in[i + 1]);
    });
    forRows(pool, f.ny, [&](int j) {
      if (j == 0 || j + 1 == f.ny) return;
      const double* in = &tmp[std::size_t(j) * nx];
      const double *below = in - nx, *above = in + nx;
      double* out = &f.phi[std::size_t(j) * nx];
      for (std::size_t i = 0; i < nx; ++i) out[i] = 0.25 * (below[i] + 2 * in[i] + above[i]);
    });
  }
  return f;
}

/// Marching squares on `f` at `level`: next[e] is the crossing that follows crossing e along
/// its curve (edge e: 2 (j nx + i) from node (i, j) to (i + 1, j), + 1 to (i, j + 1); −1: none).
std::vector<std::int64_t> linkCrossings(const NodeField& f, double level, ThreadPool* pool) {
  const std::size_t nx = std::size_t(f.nx);
  std::vector<std::int64_t> next(2 * nx * std::size_t(f.ny), -1);
  auto hEdge = [&](int i, int j) { return std::int64_t(2 * (std::size_t(j) * nx + std::size_t(i))); };
  auto vEdge = [&](int i, int j) { return std::int64_t(2 * (std::size_t(j) * nx + std::size_t(i)) + 1); };
  // Each crossing is an exit of exactly one cell, which alone writes its successor: rows of
  // cells may run side by side.
  forRows(pool, f.ny - 1, [&](int j) {
    for (int i = 0; i + 1 < f.nx; ++i) {
      // Corners counter-clockwise from the lower left, and the edge from each to the next.
      const double v[4] = {f.at(i, j), f.at(i + 1, j), f.at(i + 1, j + 1), f.at(i, j + 1)};
      const bool in[4] = {v[0] > level, v[1] > level, v[2] > level, v[3] > level};
      const std::int64_t edge[4] = {hEdge(i, j), vEdge(i + 1, j), hEdge(i, j + 1), vEdge(i, j)};
      int exits[2], entries[2], ne = 0, nn = 0;
      for (int k = 0; k < 4; ++k) {
        const int k1 = (k + 1) & 3;
        if (in[k] && !in[k1]) exits[ne++] = k;
        if (!in[k] && in[k1]) entries[nn++] = k;
      }
      if (ne == 1) {
        next[std::size_t(edge[exits[0]])] = edge[entries[0]];
      } else if (ne == 2) {  // a saddle: the centre's value joins the two fluid corners or parts them
        const bool joined = (v[0] + v[1] + v[2] + v[3]) / 4 > level;
        for (int q = 0; q < 2; ++q) {
          const int k = exits[q], to = joined ? (k + 1) & 3 : (k + 3) & 3;
          next[std::size_t(edge[k])] = edge[to];
        }
      }
    }
  });
  return next;
}

/// The curves of one region of points (coordinates relative to the caller's reference).
void regionCurves(const std::vector<Vec2d>& points, double spacing, const SurfaceOptions& o, ThreadPool* pool,
                  std::vector<SurfaceCurve>& curves) {
  const NodeField f = sampleField(points, spacing, o, pool);
  if (f.phi.empty()) return;
  std::vector<std::int64_t> next = linkCrossings(f, o.level, pool);
  const std::size_t nx = std::size_t(f.nx);
  auto crossing = [&](std::int64_t e) {  // where φ crosses the level along edge e
    const std::size_t k = std::size_t(e) / 2;
    const int i = int(k % nx), j = int(k / nx);
    const int i1 = (e & 1) ? i : i + 1, j1 = (e & 1) ? j + 1 : j;
    const double a = f.at(i, j), b = f.at(i1, j1), t = (o.level - a) / (b - a);
    return f.node(i, j) + (f.node(i1, j1) - f.node(i, j)) * t;
  };
  for (std::size_t start = 0; start < next.size(); ++start) {
    if (next[start] < 0) continue;
    SurfaceCurve c;
    std::int64_t e = std::int64_t(start);
    do {  // every crossing has one successor; taking it marks it used
      const Vec2d p = crossing(e);
      // A node exactly at the level puts the same point on two edges: kept once.
      if (c.points.empty() || !(p == c.points.back())) c.points.push_back(p);
      const std::int64_t n = next[std::size_t(e)];
      next[std::size_t(e)] = -1;
      e = n;
    } while (e >= 0 && e != std::int64_t(start));
    if (c.points.size() > 1 && c.points.front() == c.points.back()) c.points.pop_back();
    double a = 0;
    for (std::size_t k = 0; k < c.points.size(); ++k) {
      const Vec2d& p = c.points[k];
      const Vec2d& q = c.points[(k + 1) % c.points.size()];
      a += p.x() * q.y() - q.x() * p.y();
    }
    c.area = a / 2;
    curves.push_back(std::move(c));
  }
}

/// surfaceCurves() with its rows on `pool`'s threads (nullptr: the caller's alone).
std::vector<SurfaceCurve> extractCurves(const std::vector<Vec2d>& points, double spacing, const SurfaceOptions& o,
                                        ThreadPool* pool) {
  if (!(spacing > 0) || !std::isfinite(spacing))
    throw std::invalid_argument("surfaceCurves: the spacing must be a positive length, got " + std::to_string(spacing));
  if (!(o.cell >= 1 && o.cell <= 4)) throw std::invalid_argument("surfaceCurves: cell must be 1 to 4 spacings");
  if (!(o.smoothing >= 1 && o.smoothing <= 4))
    throw std::invalid_argument("surfaceCurves: smoothing must be 1 to 4 passes");
  if (!(o.level > 0 && o.level < 1)) throw std::invalid_argument("surfaceCurves: level must lie strictly in (0, 1)");
  std::vector<SurfaceCurve> curves;
  if (points.empty()) return curves;
  // Coordinates relative to the node nearest below the first point (far from the origin a level
  // keeps its precision; the nodes stay at whole cells of the world, so the curves do not move
  // with whichever particle comes first), spanning at most 2^30 spacings (the node indices).
  const double h = o.cell * spacing, limit = double(1 << 30) * spacing;
  if (!std::isfinite(points[0].x()) || !std::isfinite(points[0].y()))
    throw std::invalid_argument("surfaceCurves: particle 0's position is not finite");
  const Vec2d ref(std::floor(points[0].x() / h) * h, std::floor(points[0].y() / h) * h);
  std::vector<Vec2d> rel(points.size());
  double lo[2] = {points[0].x() - ref.x(), points[0].y() - ref.y()}, hi[2] = {lo[0], lo[1]};
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Vec2d& p = points[k];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()))
      throw std::invalid_argument("surfaceCurves: particle " + std::to_string(k) + "'s position is not finite");
    rel[k] = p - ref;
    lo[0] = std::min(lo[0], rel[k].x()), lo[1] = std::min(lo[1], rel[k].y());
    hi[0] = std::max(hi[0], rel[k].x()), hi[1] = std::max(hi[1], rel[k].y());
  }
  if (!(hi[0] - lo[0] <= limit && hi[1] - lo[1] <= limit))
    throw std::invalid_argument("surfaceCurves: the particles span more than 2^30 spacings");
  const double nodes = ((hi[0] - lo[0]) / h + 2 * (o.smoothing + 4)) * ((hi[1] - lo[1]) / h + 2 * (o.smoothing + 4));
  if (nodes <= std::max(64.0 * double(points.size()), 65536.0)) {
    regionCurves(rel, spacing, o, pool, curves);
  } else {
    // Far-flung particles (spray across a level): each region of coarse cells (64 nodes wide,
    // touching ones joined) gets a grid of its own, so that one stray particle neither makes
    // the grid huge nor its cells coarse. Regions apart by a coarse cell cannot share a curve
    // (the field reaches a few nodes). Regions in the order of their lowest, then leftmost cell.
    const double C = 64 * h;
    auto key = [&](const Vec2d& p) {
      return std::pair<std::int64_t, std::int64_t>{std::int64_t(std::floor((p.y() - lo[1]) / C)),
                                                   std::int64_t(std::floor((p.x() - lo[0]) / C))};
    };
    std::vector<std::pair<std::int64_t, std::int64_t>> cells(rel.size());
    for (std::size_t k = 0; k < rel.size(); ++k) cells[k] = key(rel[k]);
    std::vector<std::pair<std::int64_t, std::int64_t>> keys = cells;
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    std::vector<std::size_t> parent(keys.size());
    for (std::size_t k = 0; k < keys.size(); ++k) parent[k] = k;
    auto root = [&](std::size_t k) {
      while (parent[k] != k) k = parent[k] = parent[parent[k]];
      return k;
    };
    for (std::size_t k = 0; k < keys.size(); ++k)
      for (std::int64_t dy = 0; dy <= 1; ++dy)
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
          if (dy == 0 && dx <= 0) continue;
          const auto it = std::lower_bound(
              keys.begin(), keys.end(), std::pair<std::int64_t, std::int64_t>{keys[k].first + dy, keys[k].second + dx});
          if (it == keys.end() || *it != std::pair<std::int64_t, std::int64_t>{keys[k].first + dy, keys[k].second + dx})
            continue;
          const std::size_t a = root(k), b = root(std::size_t(it - keys.begin()));
          if (a != b) parent[std::max(a, b)] = std::min(a, b);  // the root: the region's first cell
        }
    std::vector<std::vector<Vec2d>> regions(keys.size());
    for (std::size_t k = 0; k < rel.size(); ++k) {
      const std::size_t c = std::size_t(std::lower_bound(keys.begin(), keys.end(), cells[k]) - keys.begin());
      regions[root(c)].push_back(rel[k]);
    }
    for (const std::vector<Vec2d>& r : regions)
      if (!r.empty()) regionCurves(r, spacing, o, pool, curves);
  }
  for (SurfaceCurve& c : curves)
    for (Vec2d& p : c.points) p += ref;
  return curves;
}

}  // namespace

std::vector<SurfaceCurve> surfaceCurves(const std::vector<Vec2d>& points, double spacing, const SurfaceOptions& o) {
  return extractCurves(points, spacing, o, nullptr);
}

std::vector<SurfaceCurve> World::surfaceCurves(const SurfaceOptions& options) const {
  const ParticleStore& P = impl_->P;
  const std::vector<std::uint32_t>* material = P.findU32(ParticleStore::kMaterial);
  const bool all = options.material == SurfaceOptions::kAllMaterials;
  if (!all) impl_->checkMaterial(options.material, "surfaceCurves");
  std::vector<Vec2d> points;
  points.reserve(P.size());
  const Vec2d o = origin();
  for (std::size_t i = 0; i < P.size(); ++i) {
    const std::uint32_t m = material ? (*material)[i] : 0;
    if (all || m == options.material) points.push_back(o + P.x[i].cast<double>());
  }
  return extractCurves(points, double(spacing()), options, &impl_->pool);
}

}  // namespace sph2d
