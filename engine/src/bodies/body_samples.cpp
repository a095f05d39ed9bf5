// body_samples.cpp — the moving bodies' boundary samples (design note in body_samples.hpp;
// Akinci et al. 2012, "Versatile rigid-fluid coupling for incompressible SPH").
#include "bodies/body_samples.hpp"

#include <algorithm>
#include <cmath>

namespace sph2d {
namespace {

bool sameShapes(const std::vector<Collider>& a, const std::vector<Collider>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const Collider &p = a[k], &q = b[k];
    if (p.kind != q.kind || p.vertices != q.vertices || p.normals != q.normals) return false;
    if (p.kind == Collider::Kind::Circle && (p.center != q.center || p.radius != q.radius)) return false;
  }
  return true;
}

}  // namespace

void BodySamples::place(double time, Real dx, Real R, std::size_t particles, ThreadPool& pool,
                        const MovingSolids& solids) {
  const double tau = time - solids.time0;
  for (Sampled& s : cache) s.used = false;
  placed.assign(solids.bodies.size(), Placed{});
  x.clear();
  v.clear();
  arm.clear();
  volume.clear();
  body.clear();
  for (std::size_t k = 0; k < solids.bodies.size(); ++k) {
    const MovingSolid& m = solids.bodies[k];
    Sampled* found = nullptr;
    for (Sampled& s : cache)
      if (!s.used && s.body == m.body && sameShapes(s.shapes, m.shapes)) {
        found = &s;
        break;
      }
    if (!found) {  // a new body, or new shapes: sampled in its frame
      Sampled s;
      s.body = m.body;
      s.shapes = m.shapes;
      std::vector<Collider> shapes = m.shapes;
      for (Collider& sh : shapes) colliderBounds(sh);
      std::vector<Vec2> sideNormal;
      std::vector<Real> sideOffset;
      sampleColliders(shapes, dx, R, s.local, s.volume, sideNormal, sideOffset);
      // A hundredth wider than R: the lists test the distance in the local frame, the grid
      // is searched in the body's, and the two differ by rounding.
      s.grid.build(s.local.data(), s.local.size(), R * Real(1.01), pool);
      cache.push_back(std::move(s));
      found = &cache.back();
    }
    found->used = true;
  }
  // Bodies gone (or resampled) are dropped from the cache; the rest keep their samples.
  cache.erase(std::remove_if(cache.begin(), cache.end(), [](const Sampled& s) { return !s.used; }), cache.end());
  for (std::size_t k = 0; k < solids.bodies.size(); ++k) {
    const MovingSolid& m = solids.bodies[k];
    const Sampled* sp = nullptr;
    for (const Sampled& s : cache)
      if (s.body == m.body && sameShapes(s.shapes, m.shapes)) sp = &s;
    Placed& p = placed[k];
    p.sampled = sp;
    p.first = std::uint32_t(x.size());
    p.count = std::uint32_t(sp->local.size());
    double theta;
    m.pose(tau, theta, p.origin);
    p.c = std::cos(theta);
    p.s = std::sin(theta);
    const Vec2d com = m.centreAt(tau);
    p.com = Vec2(Real(com.x()), Real(com.y()));
    p.dynamic = m.dynamic();
    double reach = 0;
    for (std::size_t i = 0; i < sp->local.size(); ++i) {
      const Vec2d b(sp->local[i].x(), sp->local[i].y());
      const Vec2d q = p.origin + Vec2d(p.c * b.x() - p.s * b.y(), p.s * b.x() + p.c * b.y());
      const Vec2d r = q - com;
      const Vec2d u = m.v + m.omega * Vec2d(-r.y(), r.x());
      x.emplace_back(Real(q.x()), Real(q.y()));
      v.emplace_back(Real(u.x()), Real(u.y()));
      arm.emplace_back(Real(r.x()), Real(r.y()));
      volume.push_back(sp->volume[i]);
      body.push_back(std::uint32_t(k));
      reach = std::max(reach, r.norm());
    }
    const double rr = reach + double(R) * 1.01;
    p.reach2 = Real(rr * rr);
  }
  const std::size_t blocks = (particles + kBlock - 1) / kBlock;
  perBlock.resize(blocks);
  for (std::vector<Reaction>& r : perBlock) r.clear();
  if (x.empty()) placed.clear();  // nothing to see (no body has a solid shape)
}

void BodySamples::react(double time, double dt, MovingSolids& solids) {
  if (!active()) return;
  const double tau0 = time - solids.time0;
  force_.assign(placed.size(), Vec2d(0, 0));
  torque_.assign(placed.size(), 0.0);
  touched_.assign(placed.size(), 0);
  std::vector<Vec2d>& force = force_;
  std::vector<double>& torque = torque_;
  std::vector<std::uint8_t>& touched = touched_;
  for (const std::vector<Reaction>& block : perBlock)
    for (const Reaction& r : block) {
      force[r.body] += r.force;
      torque[r.body] += r.torque;
      touched[r.body] = 1;
    }
  for (std::size_t k = 0; k < placed.size() && k < solids.bodies.size(); ++k) {
    MovingSolid& m = solids.bodies[k];
    if (!m.dynamic() || !touched[k]) continue;
    // The fluid felt `force`; the body takes the opposite, over the substep taken.
    m.push(tau0, -force[k] * dt, -torque[k] * dt);
  }
  placed.clear();
}

}  // namespace sph2d
