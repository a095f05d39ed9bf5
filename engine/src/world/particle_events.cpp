// particle_events.cpp — the game's calls about single particles (sph2d/particle_events.hpp):
// the destruction listener, each particle's own lifetime, ray casts through the search
// grid of the current particles (particle_index.hpp), and the particle contact listener.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "world/world_impl.hpp"

namespace sph2d {

void World::setDestructionListener(DestructionListener listener) {
  impl_->destructionListener = std::move(listener);
  if (!impl_->destructionListener) impl_->removals.clear();  // a later listener hears nothing of before
}

std::size_t World::setLifetimes(const std::vector<std::uint32_t>& ids, double seconds) {
  if (!(seconds >= 0))
    throw std::invalid_argument("setLifetimes: seconds must be 0 or more (infinity: no lifetime), got " +
                                std::to_string(seconds));
  Impl& w = *impl_;
  const bool had = w.P.findD(ParticleStore::kLifeEnd) != nullptr;
  std::vector<double>& end = w.P.fieldD(ParticleStore::kLifeEnd);
  // The World time it leaves at, in double (no drift over long lives); 0 holds "never", so
  // an end at time 0 becomes the smallest positive double (gone in the next substep).
  const double value = std::isinf(seconds) ? 0.0 : std::max(w.time + seconds, std::numeric_limits<double>::min());
  const std::size_t n = w.index.forEachId(w.P, ids, [&](std::size_t, std::size_t i) {
    end[i] = value;
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
  const std::vector<double>* end = w.P.findD(ParticleStore::kLifeEnd);
  const std::size_t i = end ? w.index.slotOf(w.P, id) : ParticleIndex::npos;
  if (i == ParticleIndex::npos || !((*end)[i] > 0)) return std::numeric_limits<double>::infinity();
  return std::max(0.0, (*end)[i] - w.time);
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
  const double cell = double(w.R);
  // The part of the segment within the search grid's box grown by the disc radius (Liang &
  // Barsky's clipping): a ray of any length visits the cells it crosses there, no more.
  Vec2d lo, hi;
  if (!w.index.bounds(w.P, w.steps, cell, w.origin, lo, hi)) return;
  double t0 = 0, t1 = 1;
  for (int axis = 0; axis < 2; ++axis) {
    const double o = axis == 0 ? p1.x() : p1.y(), v = axis == 0 ? d.x() : d.y();
    const double a = (axis == 0 ? lo.x() : lo.y()) - radius, b = (axis == 0 ? hi.x() : hi.y()) + radius;
    if (v == 0) {
      if (o < a || o > b) return;
      continue;
    }
    const double ta = (a - o) / v, tb = (b - o) / v;
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
  if (!(t0 <= t1)) return;
  // The grid's cells (side R ≥ a spacing) along that part: boxes of at most R along it, each
  // grown by the disc radius; the candidates deduplicated by slot.
  const double len = d.norm() * (t1 - t0);
  const int pieces = std::max(1, int(std::ceil(len / cell)));
  std::vector<std::size_t> slots;
  const Vec2d grow(radius, radius);
  for (int k = 0; k < pieces; ++k) {
    const Vec2d a = p1 + d * (t0 + (t1 - t0) * double(k) / pieces),
                b = p1 + d * (t0 + (t1 - t0) * double(k + 1) / pieces);
    const Vec2d boxLo(std::min(a.x(), b.x()), std::min(a.y(), b.y()));
    const Vec2d boxHi(std::max(a.x(), b.x()), std::max(a.y(), b.y()));
    w.index.forCandidates(w.P, w.steps, cell, w.origin, boxLo - grow, boxHi + grow,
                          [&](std::size_t i) { slots.push_back(i); });
  }
  std::sort(slots.begin(), slots.end());
  slots.erase(std::unique(slots.begin(), slots.end()), slots.end());
  // Entries from the clipped part's start (no cancellation for a ray from far away).
  const Vec2d q1 = p1 + d * t0, e = d * (t1 - t0);
  std::vector<RayHit> hits;
  for (const std::size_t i : slots) {
    const Vec2d c = worldPosition(i);
    double t = 0;
    if (!enters(q1, e, c, radius, t)) continue;
    RayHit h;
    h.id = w.P.id[i];
    h.fraction = t0 + (t1 - t0) * t;
    h.point = q1 + e * t;
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

void World::setParticleContactListener(const ParticleContactFilter& filter, ParticleContactListener listener) {
  impl_->contactFilter = filter;
  impl_->contactListener = std::move(listener);
  impl_->lastContacts.clear();
}

namespace {
/// How far apart two particles' centres touch, in spacings: a resting particle's nearest and
/// diagonal neighbours on the lattice (1 and 1.41), not the next ring (2).
constexpr double kTouch = 1.5;
}  // namespace

void World::Impl::deliverParticleContacts() {
  const ParticleContactFilter& f = contactFilter;
  const std::vector<std::uint32_t>* material = P.findU32(ParticleStore::kMaterial);
  const std::vector<std::uint32_t>* group = P.findU32(ParticleStore::kGroup);
  auto side = [&](std::size_t i, std::uint32_t m, std::uint32_t g) {
    const std::uint32_t mi = material ? (*material)[i] : 0u, gi = group ? (*group)[i] : 0u;
    const bool groupOk =
        g == ParticleContactFilter::kAny || (g == ParticleContactFilter::kNoGroup ? gi == 0 : gi == g + 1);
    return (m == ParticleContactFilter::kAny || mi == m) && groupOk;
  };
  const double reach = kTouch * double(dx), reach2 = reach * reach, cell = double(R);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  for (std::size_t i = 0; i < P.size(); ++i) {
    const bool inA = side(i, f.materialA, f.groupA), inB = side(i, f.materialB, f.groupB);
    if (!inA && !inB) continue;
    const Vec2d xi = Vec2d(double(P.x[i].x()), double(P.x[i].y())) + origin;
    index.forCandidates(P, steps, cell, origin, xi - Vec2d(reach, reach), xi + Vec2d(reach, reach), [&](std::size_t j) {
      if (P.id[j] <= P.id[i]) return;  // each pair once, from its lower id
      Real ddx = P.x[i].x() - P.x[j].x(), ddy = P.x[i].y() - P.x[j].y();
      periodic.nearest(ddx, ddy);
      if (double(ddx) * double(ddx) + double(ddy) * double(ddy) >= reach2) return;
      if ((inA && side(j, f.materialB, f.groupB)) || (inB && side(j, f.materialA, f.groupA)))
        pairs.emplace_back(P.id[i], P.id[j]);
    });
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<ParticleContact> out;
  out.reserve(pairs.size());
  for (const auto& [a, b] : pairs)
    out.push_back(
        ParticleContact{a, b, !std::binary_search(lastContacts.begin(), lastContacts.end(), std::make_pair(a, b))});
  lastContacts = std::move(pairs);
  if (out.empty()) return;
  const ParticleContactListener listener = contactListener;  // it may replace or clear itself
  listener(out);
}

}  // namespace sph2d
