// particle_events.cpp — the game's calls about single particles (sph2d/particle_events.hpp):
// the destruction listener, each particle's own lifetime, and ray casts through the search
// grid of the current particles (particle_index.hpp).
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "world/world_impl.hpp"

namespace sph2d {

void World::setDestructionListener(DestructionListener listener) {
  impl_->destructionListener = std::move(listener);
  if (!impl_->destructionListener) impl_->removals.clear();
}

std::size_t World::setLifetimes(const std::vector<std::uint32_t>& ids, double seconds) {
  if (!(seconds >= 0))
    throw std::invalid_argument("setLifetimes: seconds must be 0 or more (infinity: no lifetime), got " +
                                std::to_string(seconds));
  Impl& w = *impl_;
  const bool had = w.P.find(ParticleStore::kLife) != nullptr;
  std::vector<Real>& life = w.P.field(ParticleStore::kLife);
  // 0 holds "none": a lifetime of 0 becomes the smallest positive value (gone next substep).
  const Real value = std::isinf(seconds) ? Real(0) : std::max(Real(seconds), std::numeric_limits<Real>::min());
  const std::size_t n = w.index.forEachId(w.P, ids, [&](std::size_t, std::size_t i) {
    life[i] = value;
    return true;
  });
  if (!had) {
    w.refreshView();  // the field is new
    w.buildStages();  // and so is its stage
  }
  return n;
}

double World::lifetimeLeft(std::uint32_t id) const {
  const Impl& w = *impl_;
  const std::vector<Real>* life = w.P.find(ParticleStore::kLife);
  const std::size_t i = life ? w.index.slotOf(w.P, id) : ParticleIndex::npos;
  if (i == ParticleIndex::npos || !((*life)[i] > 0)) return std::numeric_limits<double>::infinity();
  return double((*life)[i]);
}

namespace {

/// Where p1 + t d enters the disc of `radius` about c (t in 0..1), or false. A disc the
/// segment starts in is not entered.
bool enters(const Vec2d& p1, const Vec2d& d, const Vec2d& c, double radius, double& t) {
  const Vec2d f = p1 - c;
  const double a = d.squaredNorm(), b = f.dot(d), cc = f.squaredNorm() - radius * radius;
  if (!(a > 0) || cc <= 0 || b >= 0) return false;  // no length, inside, or heading away
  const double disc = b * b - a * cc;
  if (disc < 0) return false;
  t = (-b - std::sqrt(disc)) / a;
  return t >= 0 && t <= 1;
}

}  // namespace

void World::rayCast(const Vec2d& p1, const Vec2d& p2, const std::function<bool(const RayHit&)>& f) const {
  const Impl& w = *impl_;
  if (!(std::isfinite(p1.x()) && std::isfinite(p1.y()) && std::isfinite(p2.x()) && std::isfinite(p2.y())))
    throw std::invalid_argument("rayCast: the points must be finite");
  const double radius = 0.5 * w.scene.solver.spacing;
  const Vec2d d = p2 - p1;
  // The search grid's cells (side R ≥ a spacing) along the segment: boxes of at most R along
  // it, each grown by the disc radius; the candidates deduplicated by slot.
  const double len = d.norm(), cell = double(w.R);
  const int pieces = std::max(1, int(std::ceil(len / cell)));
  std::vector<std::size_t> slots;
  const Vec2d grow(radius, radius);
  for (int k = 0; k < pieces; ++k) {
    const Vec2d a = p1 + d * (double(k) / pieces), b = p1 + d * (double(k + 1) / pieces);
    const Vec2d lo(std::min(a.x(), b.x()), std::min(a.y(), b.y())), hi(std::max(a.x(), b.x()), std::max(a.y(), b.y()));
    w.index.forCandidates(w.P, w.steps, cell, w.origin, lo - grow, hi + grow,
                          [&](std::size_t i) { slots.push_back(i); });
  }
  std::sort(slots.begin(), slots.end());
  slots.erase(std::unique(slots.begin(), slots.end()), slots.end());
  std::vector<RayHit> hits;
  for (const std::size_t i : slots) {
    const Vec2d c = worldPosition(i);
    double t = 0;
    if (!enters(p1, d, c, radius, t)) continue;
    RayHit h;
    h.id = w.P.id[i];
    h.fraction = t;
    h.point = p1 + d * t;
    h.normal = (h.point - c) / radius;
    h.normal /= h.normal.norm();
    hits.push_back(h);
  }
  std::sort(hits.begin(), hits.end(), [](const RayHit& a, const RayHit& b) {
    return a.fraction < b.fraction || (a.fraction == b.fraction && a.id < b.id);
  });
  for (const RayHit& h : hits)
    if (!f(h)) return;
}

bool World::rayCastFirst(const Vec2d& p1, const Vec2d& p2, RayHit& hit) const {
  bool found = false;
  rayCast(p1, p2, [&](const RayHit& h) {
    hit = h;
    found = true;
    return false;
  });
  return found;
}

}  // namespace sph2d
