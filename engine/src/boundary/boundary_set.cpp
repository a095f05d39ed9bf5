// boundary_set.cpp — the static solids as colliders: collected from the b2World, their bounds,
// the boundary samples, the collision bins and the early-out map (boundary_set.hpp). The swept
// collision itself is in swept_collision.cpp.
#include <box2d/box2d.h>

#include <algorithm>
#include <cmath>

#include "boundary/boundary_set.hpp"
#include "sph2d/world.hpp"  // sph2d::Interrupted

namespace sph2d {
namespace {

Vec2 toLocal(const b2Vec2& p, const Vec2d& origin) {
  return Vec2(Real(double(p.x) - origin.x()), Real(double(p.y) - origin.y()));
}

void finishBounds(Collider& c) {
  if (c.kind == Collider::Kind::Circle) {
    c.lo = c.center - Vec2(c.radius, c.radius);
    c.hi = c.center + Vec2(c.radius, c.radius);
    return;
  }
  c.lo = c.hi = c.vertices[0];
  for (const Vec2& v : c.vertices) {
    c.lo = c.lo.cwiseMin(v);
    c.hi = c.hi.cwiseMax(v);
  }
}

}  // namespace

void BoundarySet::collect(b2World& world, const Vec2d& origin, const std::vector<const void*>& skip) {
  colliders.clear();
  colliderFixture.clear();
  for (b2Body* body = world.GetBodyList(); body; body = body->GetNext()) {
    if (body->GetType() != b2_staticBody || std::find(skip.begin(), skip.end(), body) != skip.end()) continue;
    const b2Transform& xf = body->GetTransform();
    for (b2Fixture* fx = body->GetFixtureList(); fx; fx = fx->GetNext()) {
      Collider base;
      base.friction = fx->GetFriction();
      base.restitution = fx->GetRestitution();
      const b2Shape* shape = fx->GetShape();
      switch (shape->GetType()) {
        case b2Shape::e_polygon: {
          const auto* poly = static_cast<const b2PolygonShape*>(shape);
          Collider c = base;
          c.kind = Collider::Kind::Polygon;
          c.sourceShape = Collider::SourceShape::Polygon;
          for (int i = 0; i < poly->m_count; ++i) {
            c.vertices.push_back(toLocal(b2Mul(xf, poly->m_vertices[i]), origin));
            const b2Vec2 n = b2Mul(xf.q, poly->m_normals[i]);
            c.normals.push_back(Vec2(n.x, n.y).normalized());
          }
          finishBounds(c);
          colliders.push_back(c);
          break;
        }
        case b2Shape::e_circle: {
          const auto* circle = static_cast<const b2CircleShape*>(shape);
          Collider c = base;
          c.kind = Collider::Kind::Circle;
          c.sourceShape = Collider::SourceShape::Circle;
          c.center = toLocal(b2Mul(xf, circle->m_p), origin);
          c.radius = circle->m_radius;
          finishBounds(c);
          colliders.push_back(c);
          break;
        }
        case b2Shape::e_edge: {
          const auto* edge = static_cast<const b2EdgeShape*>(shape);
          Collider c = base;
          c.kind = Collider::Kind::Segment;
          c.sourceShape = Collider::SourceShape::Edge;
          c.vertices = {toLocal(b2Mul(xf, edge->m_vertex1), origin), toLocal(b2Mul(xf, edge->m_vertex2), origin)};
          finishBounds(c);
          colliders.push_back(c);
          break;
        }
        case b2Shape::e_chain: {
          const auto* chain = static_cast<const b2ChainShape*>(shape);
          for (int i = 0; i + 1 < chain->m_count; ++i) {
            Collider c = base;
            c.kind = Collider::Kind::Segment;
            c.sourceShape = Collider::SourceShape::Chain;
            c.vertices = {toLocal(b2Mul(xf, chain->m_vertices[i]), origin),
                          toLocal(b2Mul(xf, chain->m_vertices[i + 1]), origin)};
            finishBounds(c);
            colliders.push_back(c);
          }
          break;
        }
        default:
          break;
      }
      colliderFixture.resize(colliders.size(), fx);
    }
  }
}

Real colliderSeparation(const Collider& c, const Vec2& p) {
  switch (c.kind) {
    case Collider::Kind::Polygon: {
      Real s = -std::numeric_limits<Real>::infinity();
      for (std::size_t k = 0; k < c.vertices.size(); ++k) s = std::max(s, c.normals[k].dot(p - c.vertices[k]));
      return s;
    }
    case Collider::Kind::Circle:
      return (p - c.center).norm() - c.radius;
    case Collider::Kind::Segment: {
      const Vec2 a = c.vertices[0], e = c.vertices[1] - a;
      const Real len2 = e.squaredNorm();
      const Real t = len2 > 0 ? std::clamp((p - a).dot(e) / len2, Real(0), Real(1)) : Real(0);
      return (p - (a + e * t)).norm();
    }
  }
  return std::numeric_limits<Real>::infinity();
}

Real BoundarySet::insideDepth(const Vec2& p) const {
  Real depth = 0;
  for (const Collider& c : colliders) {
    if (p.x() < c.lo.x() || p.y() < c.lo.y() || p.x() > c.hi.x() || p.y() > c.hi.y()) continue;
    if (c.kind != Collider::Kind::Segment) depth = std::max(depth, -colliderSeparation(c, p));
  }
  return depth;
}

void colliderBounds(Collider& c) { finishBounds(c); }

void sampleColliders(const std::vector<Collider>& colliders, Real dx, Real depth, std::vector<Vec2>& samples,
                     std::vector<Real>& volume, std::vector<Vec2>& sideNormal, std::vector<Real>& sideOffset,
                     const std::atomic<bool>* stop) {
  auto checkStop = [stop] {
    if (stop && stop->load(std::memory_order_relaxed)) throw Interrupted("stopped by the stop flag", "");
  };
  samples.clear();
  volume.clear();
  sideNormal.clear();
  sideOffset.clear();
  const int layers = std::max(1, int(std::ceil(depth / dx)));
  auto add = [&](const Vec2& p, Real vol, const Vec2& n, Real off) {
    samples.push_back(p);
    volume.push_back(vol);
    sideNormal.push_back(n);
    sideOffset.push_back(off);
  };
  for (std::size_t ci = 0; ci < colliders.size(); ++ci) {
    checkStop();
    const Collider& c = colliders[ci];
    const std::size_t first = samples.size();
    if (c.kind == Collider::Kind::Polygon) {
      // Layers under each face, kept only in that face's part of the polygon
      // (where the face is the nearest): the faces' layers tile the rim.
      const std::size_t m = c.vertices.size();
      for (std::size_t f = 0; f < m; ++f) {
        const Vec2 a = c.vertices[f], b = c.vertices[(f + 1) % m];
        const Vec2 n = c.normals[f];
        const Real len = (b - a).norm();
        const int count = std::max(1, int(std::lround(len / dx)));
        const Real step = len / Real(count);
        for (int j = 0; j < layers; ++j)
          for (int i = 0; i < count; ++i) {
            const Vec2 p = a + (b - a) * ((Real(i) + Real(0.5)) / Real(count)) - n * (dx * (Real(j) + Real(0.5)));
            const Real sep = n.dot(p - a);
            bool inside = true, nearest = true;
            for (std::size_t k = 0; k < m && inside; ++k) {
              const Real s = c.normals[k].dot(p - c.vertices[k]);
              if (s > 0) inside = false;
              if (k != f && s > sep + Real(1e-6) * dx) nearest = false;
            }
            if (inside && nearest) add(p, step * dx, Vec2::Zero(), 0);
          }
      }
    } else if (c.kind == Collider::Kind::Circle) {
      for (int j = 0; j < layers; ++j) {
        const Real r = c.radius - dx * (Real(j) + Real(0.5));
        if (r <= 0) break;
        const int count = std::max(3, int(std::lround(2 * kPi<Real> * r / dx)));
        const Real vol = 2 * kPi<Real> * r / Real(count) * dx;
        for (int i = 0; i < count; ++i) {
          const Real t = 2 * kPi<Real> * (Real(i) + Real(0.5)) / Real(count);
          add(c.center + r * Vec2(std::cos(t), std::sin(t)), vol, Vec2::Zero(), 0);
        }
      }
    } else {
      const Vec2 a = c.vertices[0], b = c.vertices[1];
      const Real len = (b - a).norm();
      Vec2 n((a - b).y(), (b - a).x());
      n /= len;
      const int count = std::max(1, int(std::lround(len / dx)));
      const Real step = len / Real(count);
      for (int side = -1; side <= 1; side += 2)
        for (int j = 0; j < layers; ++j)
          for (int i = 0; i < count; ++i) {
            const Vec2 p =
                a + (b - a) * ((Real(i) + Real(0.5)) / Real(count)) + n * (Real(side) * dx * (Real(j) + Real(0.5)));
            // Visible only from the other side: normal pointing away from the sample.
            const Vec2 vn = n * Real(-side);
            add(p, step * dx, vn, vn.dot(a));
          }
    }
    // Samples inside an earlier solid collider are already represented there.
    std::size_t out = first;
    for (std::size_t k = first; k < samples.size(); ++k) {
      if ((k - first) % 4096 == 4095) checkStop();  // each sample is tested against every earlier collider
      bool covered = false;
      for (std::size_t e = 0; e < ci && !covered; ++e) {
        const Collider& o = colliders[e];
        const Vec2& p = samples[k];
        if (p.x() < o.lo.x() || p.y() < o.lo.y() || p.x() > o.hi.x() || p.y() > o.hi.y()) continue;
        if (o.kind == Collider::Kind::Polygon) {
          Real sep = -std::numeric_limits<Real>::infinity();
          for (std::size_t q = 0; q < o.vertices.size(); ++q) sep = std::max(sep, o.normals[q].dot(p - o.vertices[q]));
          covered = sep < -Real(0.01) * dx;
        } else if (o.kind == Collider::Kind::Circle) {
          covered = (p - o.center).norm() < o.radius - Real(0.01) * dx;
        }
      }
      if (covered) continue;
      samples[out] = samples[k];
      volume[out] = volume[k];
      sideNormal[out] = sideNormal[k];
      sideOffset[out] = sideOffset[k];
      ++out;
    }
    samples.resize(out);
    volume.resize(out);
    sideNormal.resize(out);
    sideOffset.resize(out);
  }
}

void BoundarySet::sample(Real dx, Real depth, ThreadPool& pool, const std::atomic<bool>* stop) {
  sampleColliders(colliders, dx, depth, samples, volume, sideNormal, sideOffset, stop);
  sampleGrid.build(samples.data(), samples.size(), depth, pool);
  // noSamplesNear's map: each occupied cell marks the block of cells whose queries visit it.
  const Grid& g = sampleGrid;
  sampleNear.assign(std::size_t(g.nx) * std::size_t(g.ny), 0);
  for (int y = 0; y < g.ny; ++y)
    for (int x = 0; x < g.nx; ++x) {
      const std::size_t c = std::size_t(y) * g.nx + x;
      if (!(g.cellStart[c] < g.cellStart[c + 1])) continue;
      for (int v = std::max(y - g.reach, 0); v <= std::min(y + g.reach, g.ny - 1); ++v)
        for (int u = std::max(x - g.reach, 0); u <= std::min(x + g.reach, g.nx - 1); ++u)
          sampleNear[std::size_t(v) * g.nx + u] = 1;
    }
}

void BoundarySet::buildBins(Real hint) {
  binStart.clear();
  binItems.clear();
  nearMap.clear();
  nearNx = nearNy = 0;
  if (colliders.empty()) {
    bnx = bny = 0;
    return;
  }
  Vec2 lo = colliders[0].lo, hi = colliders[0].hi;
  for (const Collider& c : colliders) {
    lo = lo.cwiseMin(c.lo);
    hi = hi.cwiseMax(c.hi);
  }
  binSize = hint;
  const Vec2 ext = hi - lo;
  while ((std::floor(ext.x() / binSize) + 1) * (std::floor(ext.y() / binSize) + 1) > 65536.0) binSize *= 2;
  invBin = Real(1) / binSize;
  binLo = lo;
  bnx = int(std::floor(ext.x() * invBin)) + 1;
  bny = int(std::floor(ext.y() * invBin)) + 1;
  std::vector<std::vector<std::uint32_t>> bins(std::size_t(bnx) * bny);
  for (std::uint32_t k = 0; k < colliders.size(); ++k) {
    const Collider& c = colliders[k];
    const int x0 = int(std::floor((c.lo.x() - binLo.x()) * invBin)),
              x1 = int(std::floor((c.hi.x() - binLo.x()) * invBin));
    const int y0 = int(std::floor((c.lo.y() - binLo.y()) * invBin)),
              y1 = int(std::floor((c.hi.y() - binLo.y()) * invBin));
    for (int y = std::max(y0, 0); y <= std::min(y1, bny - 1); ++y)
      for (int x = std::max(x0, 0); x <= std::min(x1, bnx - 1); ++x) bins[std::size_t(y) * bnx + x].push_back(k);
  }
  binStart.push_back(0);
  for (const auto& b : bins) {
    binItems.insert(binItems.end(), b.begin(), b.end());
    binStart.push_back(std::uint32_t(binItems.size()));
  }
  // clearOf's map (in double, with a margin of a hundredth of a cell: it may only err
  // towards marking a cell).
  const double f = double(binSize) / 4;
  nearInv = Real(1.0 / f);
  const double f1 = 1.0 / double(nearInv);  // the cell the particles' coordinates see
  nearLo = Vec2(Real(double(lo.x()) - 2 * f1), Real(double(lo.y()) - 2 * f1));
  nearNx = int(std::floor(double(ext.x()) / f1)) + 5;
  nearNy = int(std::floor(double(ext.y()) / f1)) + 5;
  nearMap.assign(std::size_t(nearNx) * std::size_t(nearNy), 0);
  const double margin = 0.01 * f1;
  for (const Collider& c : colliders) {
    // Cells u whose block [u − 1, u + 2)·f1 (closed, widened by the margin) meets [c.lo, c.hi].
    const auto range = [&](double clo, double chi, double origin, int count, int& u0, int& u1) {
      u0 = int(std::floor((clo - margin - origin) / f1)) - 1;
      u1 = int(std::floor((chi + margin - origin) / f1)) + 1;
      u0 = std::max(u0, 0);
      u1 = std::min(u1, count - 1);
    };
    int x0, x1, y0, y1;
    range(c.lo.x(), c.hi.x(), nearLo.x(), nearNx, x0, x1);
    range(c.lo.y(), c.hi.y(), nearLo.y(), nearNy, y0, y1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) nearMap[std::size_t(y) * nearNx + x] = 1;
  }
}

std::size_t BoundarySet::collidersMeeting(const Vec2& lo, const Vec2& hi, std::uint32_t* out, std::size_t cap,
                                          bool& overflow) const {
  overflow = false;
  if (bnx == 0) return 0;
  // The box in bin coordinates.
  const Real fx0 = std::floor((lo.x() - binLo.x()) * invBin), fx1 = std::floor((hi.x() - binLo.x()) * invBin);
  const Real fy0 = std::floor((lo.y() - binLo.y()) * invBin), fy1 = std::floor((hi.y() - binLo.y()) * invBin);
  if (!(fx0 <= fx1 && fy0 <= fy1)) return 0;  // not finite
  if (fx1 < 0 || fy1 < 0 || fx0 > Real(bnx - 1) || fy0 > Real(bny - 1)) return 0;
  const int x0 = int(std::max(fx0, Real(0))), x1 = int(std::min(fx1, Real(bnx - 1)));
  const int y0 = int(std::max(fy0, Real(0))), y1 = int(std::min(fy1, Real(bny - 1)));
  std::size_t n = 0;
  for (int y = y0; y <= y1; ++y)
    for (int xx = x0; xx <= x1; ++xx) {
      const std::size_t bin = std::size_t(y) * bnx + xx;
      for (std::uint32_t k = binStart[bin]; k < binStart[bin + 1]; ++k) {
        const std::uint32_t id = binItems[k];
        const Collider& c = colliders[id];
        if (c.hi.x() < lo.x() || c.hi.y() < lo.y() || c.lo.x() > hi.x() || c.lo.y() > hi.y()) continue;
        if (std::find(out, out + n, id) != out + n) continue;
        if (n == cap) {
          overflow = true;
          return n;
        }
        out[n++] = id;
      }
    }
  return n;
}

}  // namespace sph2d
