// swept_collision.cpp — the colliders' swept collision (BoundarySet::resolve, stopShort,
// blocks; boundary_set.hpp): a particle that crossed a surface during its move is put back on
// the side it came from, then kept the clearance away, with the fixture's restitution and
// Coulomb friction; a path's first crossing; and whether a segment crosses any solid.
//
// Design: each collider kind has a sweep (the first crossing of a path, with the normal facing
// the path's start) and a push (out to the clearance); resolve() runs them over the colliders
// near the move in collider order, twice (the second pass sees the first's corrections), and
// stopShort() then sweeps the whole corrected path once more from the start.
#include <algorithm>
#include <cmath>
#include <limits>

#include "boundary/boundary_set.hpp"

namespace sph2d {
namespace {

inline Real cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

/// Closest point on segment ab to p.
inline Vec2 closestOnSegment(const Vec2& a, const Vec2& b, const Vec2& p) {
  const Vec2 ab = b - a;
  const Real l2 = ab.squaredNorm();
  Real t = l2 > 0 ? (p - a).dot(ab) / l2 : Real(0);
  t = std::min(std::max(t, Real(0)), Real(1));
  return a + ab * t;
}

inline void respond(Vec2& v, const Vec2& n, Real friction, Real restitution) {
  const Real vn = v.dot(n);
  if (vn >= 0) return;
  const Vec2 vt = v - n * vn;
  const Real vtLen = vt.norm();
  const Real dvn = -(Real(1) + restitution) * vn;  // change of normal speed
  Real scale = 1;
  if (vtLen > 0) scale = std::max(Real(0), Real(1) - friction * dvn / vtLen);
  v = vt * scale - n * (restitution * vn);
}

// --- polygon ---------------------------------------------------------------
bool polygonSweep(const Collider& c, const Vec2& p0, const Vec2& p1, Vec2& hit, Vec2& nHit) {
  Real tE = 0, tL = 1;
  int face = -1;
  const Vec2 d = p1 - p0;
  const std::size_t m = c.vertices.size();
  for (std::size_t k = 0; k < m; ++k) {
    const Real num = c.normals[k].dot(c.vertices[k] - p0);
    const Real den = c.normals[k].dot(d);
    if (den == 0) {
      if (num < 0) return false;
      continue;
    }
    const Real t = num / den;
    if (den < 0) {
      if (t > tE || face < 0) {
        if (t >= tE) {
          tE = t;
          face = int(k);
        }
      }
    } else {
      tL = std::min(tL, t);
    }
    if (tE > tL) return false;
  }
  if (face < 0) return false;  // started inside: handled by the depth push
  if (tE > 1) return false;
  hit = p0 + d * tE;
  nHit = c.normals[face];
  return true;
}

/// Pushes x out of / away from a convex polygon. Returns true and the normal on contact.
bool polygonPush(const Collider& c, Vec2& x, Real clearance, Vec2& nOut) {
  const std::size_t m = c.vertices.size();
  Real best = -std::numeric_limits<Real>::infinity();
  int bestFace = 0;
  for (std::size_t k = 0; k < m; ++k) {
    const Real s = c.normals[k].dot(x - c.vertices[k]);
    if (s > best) {
      best = s;
      bestFace = int(k);
    }
  }
  if (best >= clearance) return false;
  if (best <= 0) {  // inside: leave through the nearest face
    nOut = c.normals[bestFace];
    x += nOut * (clearance - best);
    return true;
  }
  // Outside but within `clearance` of the face plane: use the true distance.
  Real dBest = std::numeric_limits<Real>::infinity();
  Vec2 cp = x;
  for (std::size_t k = 0; k < m; ++k) {
    const Vec2 q = closestOnSegment(c.vertices[k], c.vertices[(k + 1) % m], x);
    const Real d2 = (x - q).squaredNorm();
    if (d2 < dBest) {
      dBest = d2;
      cp = q;
    }
  }
  const Real dist = std::sqrt(dBest);
  if (dist >= clearance) return false;
  nOut = dist > 0 ? Vec2((x - cp) / dist) : c.normals[bestFace];
  x = cp + nOut * clearance;
  return true;
}

// --- circle ----------------------------------------------------------------
bool circleSweep(const Collider& c, const Vec2& p0, const Vec2& p1, Vec2& hit, Vec2& nHit) {
  const Vec2 f = p0 - c.center;
  const Real cc = f.squaredNorm() - c.radius * c.radius;
  if (cc <= 0) return false;  // started inside
  const Vec2 d = p1 - p0;
  const Real a = d.squaredNorm();
  if (a == 0) return false;
  const Real b = f.dot(d);
  const Real disc = b * b - a * cc;
  if (disc < 0) return false;
  const Real t = (-b - std::sqrt(disc)) / a;
  if (t < 0 || t > 1) return false;
  hit = p0 + d * t;
  const Vec2 r = hit - c.center;
  const Real len = r.norm();
  nHit = len > 0 ? Vec2(r / len) : Vec2(0, 1);
  return true;
}

bool circlePush(const Collider& c, Vec2& x, Real clearance, Vec2& nOut) {
  const Vec2 r = x - c.center;
  const Real len = r.norm();
  if (len >= c.radius + clearance) return false;
  nOut = len > 0 ? Vec2(r / len) : Vec2(0, 1);
  x = c.center + nOut * (c.radius + clearance);
  return true;
}

// --- two-sided segment ------------------------------------------------------
// A segment's ends count 16 float steps of their coordinates beyond themselves: a path through a
// chain's vertex, between its two segments, is then seen by one of them despite the rounding
// (it passed between them: 1 of 116,000 random moves in acute valleys).
bool segmentSweep(const Collider& c, const Vec2& p0, const Vec2& p1, Vec2& hit, Vec2& nHit) {
  const Vec2& a = c.vertices[0];
  const Vec2& b = c.vertices[1];
  const Vec2 e = b - a;
  const Real s0 = cross2(e, p0 - a), s1 = cross2(e, p1 - a);
  if ((s0 > 0 && s1 > 0) || (s0 < 0 && s1 < 0) || s0 == s1) return false;
  const Vec2 d = p1 - p0;
  const Real den = cross2(d, e);
  if (den == 0) return false;
  const Real t = cross2(a - p0, e) / den;  // along the path
  const Real u = cross2(a - p0, d) / den;  // along the segment
  if (t < 0 || t > 1) return false;
  if (u < 0 || u > 1) {
    const Real size = std::max({Real(1), std::abs(a.x()), std::abs(a.y()), std::abs(b.x()), std::abs(b.y())});
    const Real reach = Real(16) * std::numeric_limits<Real>::epsilon() * size / e.norm();
    if (u < -reach || u > 1 + reach) return false;
  }
  hit = p0 + d * t;
  Vec2 n(-e.y(), e.x());
  n.normalize();
  if (s0 < 0 || (s0 == 0 && s1 > 0)) n = -n;  // face the side the particle came from
  nHit = n;
  return true;
}

bool segmentPush(const Collider& c, Vec2& x, const Vec2& xOld, Real clearance, Vec2& nOut) {
  const Vec2& a = c.vertices[0];
  const Vec2& b = c.vertices[1];
  const Vec2 q = closestOnSegment(a, b, x);
  const Vec2 r = x - q;
  const Real dist = r.norm();
  if (dist >= clearance) return false;
  if (dist > Real(1e-7) * clearance) {
    nOut = r / dist;
  } else {
    const Vec2 e = b - a;
    Vec2 n(-e.y(), e.x());
    n.normalize();
    if (cross2(e, xOld - a) < 0) n = -n;
    nOut = n;
  }
  x = q + nOut * clearance;
  return true;
}

// --- near a box ---------------------------------------------------------------
/// The colliders whose bounding box meets [lo, hi]: up to 64 from the bins, in index order.
struct Near {
  std::uint32_t ids[64];
  std::size_t n = 0;
  bool overflow = false;  ///< more than 64: every collider is scanned (BoundarySet::forCollidersNear)
  Vec2 lo, hi;
};

Near near(const BoundarySet& set, const Vec2& lo, const Vec2& hi) {
  Near r;
  r.lo = lo;
  r.hi = hi;
  r.n = set.collidersMeeting(lo, hi, r.ids, 64, r.overflow);
  std::sort(r.ids, r.ids + r.n);  // a fixed order: collider index
  return r;
}

/// Calls f(c) for each collider of `r`, in index order (a finely cut chain or a dense level
/// meets more than 64 boxes: then all of them, by a scan; dropping the rest let a particle
/// through a chain of 1 cm segments).
template <class F>
void forEach(const BoundarySet& set, const Near& r, F&& f) {
  if (!r.overflow) {
    for (std::size_t q = 0; q < r.n; ++q) f(set.colliders[r.ids[q]]);
    return;
  }
  for (const Collider& c : set.colliders)
    if (!(c.hi.x() < r.lo.x() || c.hi.y() < r.lo.y() || c.lo.x() > r.hi.x() || c.lo.y() > r.hi.y())) f(c);
}

// --- by kind ------------------------------------------------------------------
/// The first crossing of the path p0 → p1 with collider c, its normal facing p0's side.
bool sweep(const Collider& c, const Vec2& p0, const Vec2& p1, Vec2& hit, Vec2& n) {
  switch (c.kind) {
    case Collider::Kind::Polygon:
      return polygonSweep(c, p0, p1, hit, n);
    case Collider::Kind::Circle:
      return circleSweep(c, p0, p1, hit, n);
    case Collider::Kind::Segment:
      return segmentSweep(c, p0, p1, hit, n);
  }
  return false;
}

/// Moves x out to the clearance from collider c (a segment: on the side of `from` when x lies
/// on it); true when it moved.
bool push(const Collider& c, Vec2& x, const Vec2& from, Real clearance, Vec2& n) {
  switch (c.kind) {
    case Collider::Kind::Polygon:
      return polygonPush(c, x, clearance, n);
    case Collider::Kind::Circle:
      return circlePush(c, x, clearance, n);
    case Collider::Kind::Segment:
      return segmentPush(c, x, from, clearance, n);
  }
  return false;
}

}  // namespace

bool BoundarySet::blocks(const Vec2& a, const Vec2& b) const {
  if (insideDepth(a) > 0 || insideDepth(b) > 0) return true;
  const Vec2 lo = a.cwiseMin(b), hi = a.cwiseMax(b);
  for (const Collider& c : colliders) {
    if (c.hi.x() < lo.x() || c.hi.y() < lo.y() || c.lo.x() > hi.x() || c.lo.y() > hi.y()) continue;
    Vec2 hit, n;
    if (sweep(c, a, b, hit, n)) return true;
  }
  return false;
}

bool BoundarySet::resolve(Vec2& x, Vec2& v, const Vec2& xOld, Real clearance) const {
  // Swept box of the move, grown by the clearance.
  const Near cand =
      near(*this, x.cwiseMin(xOld) - Vec2(clearance, clearance), x.cwiseMax(xOld) + Vec2(clearance, clearance));
  if (cand.n == 0) return false;

  bool contact = false;
  Vec2 from = xOld;
  for (int pass = 0; pass < 2; ++pass) {
    bool moved = false;
    forEach(*this, cand, [&](const Collider& c) {
      Vec2 hit, n;
      if (sweep(c, from, x, hit, n)) {
        x = hit + n * clearance;
        respond(v, n, c.friction, c.restitution);
        contact = moved = true;
      }
      if (push(c, x, from, clearance, n)) {
        respond(v, n, c.friction, c.restitution);
        contact = moved = true;
      }
    });
    if (!moved) break;
    from = x;  // the second pass checks the corrections themselves
  }
  if (contact) stopShort(x, v, xOld, clearance);
  return contact;
}

const Collider* BoundarySet::firstCrossing(const Vec2& p0, const Vec2& p1, Real margin, Vec2& hit, Vec2& n) const {
  const Near cand = near(*this, p0.cwiseMin(p1) - Vec2(margin, margin), p0.cwiseMax(p1) + Vec2(margin, margin));
  const Vec2 d = p1 - p0;
  const Real len2 = d.squaredNorm();
  if (cand.n == 0 || !(len2 > 0)) return nullptr;
  Real tFirst = 2;
  const Collider* first = nullptr;
  forEach(*this, cand, [&](const Collider& c) {
    Vec2 h, m;
    if (!sweep(c, p0, p1, h, m)) return;
    const Real t = (h - p0).dot(d) / len2;
    // A path that starts on a two-sided segment's line leaves it to the side resolve() chose
    // (which side it came from is not known): not a crossing.
    if (c.kind == Collider::Kind::Segment && !(t > 0)) return;
    if (t < tFirst) {  // ties: the lower collider index (candidates in index order)
      tFirst = t;
      hit = h;
      n = m;
      first = &c;
    }
  });
  return first;
}

void BoundarySet::stopShort(Vec2& x, Vec2& v, const Vec2& xOld, Real clearance) const {
  // The corrections move the particle too, and in an acute valley of vertex angle θ a point is
  // the clearance away from both edges only clearance / sin(θ/2) from the vertex: pushed off one
  // edge nearer than that, a particle went through the other (a 70 m/s jet into 30° chain teeth
  // left one inside the wall), and the second pass, starting from the pushed point, could not
  // see it. So the path from xOld to the corrected x is swept once more; at its first crossing
  // the particle stops short of that surface (back along the path by a quarter clearance or
  // half the way, and a hundredth of a clearance off the surface, so that the next substep's
  // sweep still tells its side), and where even that point is not reachable without a
  // crossing (the far side of a valley within reach), it stays at xOld.
  Vec2 hit, n;
  const Collider* first = firstCrossing(xOld, x, clearance, hit, n);
  if (!first) return;
  const Vec2 d = x - xOld;
  const Real len = d.norm(), t = (hit - xOld).norm() / len;
  const Real back = std::min(Real(0.25) * clearance, Real(0.5) * t * len);
  Vec2 y = hit - d * (back / len) + n * (Real(0.01) * clearance);
  Vec2 hit2, n2;
  const Collider* second = firstCrossing(xOld, y, clearance, hit2, n2);
  if (second) {
    y = xOld;
    respond(v, n2, second->friction, second->restitution);  // nor into that one
  }
  x = y;
  respond(v, n, first->friction, first->restitution);
}

}  // namespace sph2d
