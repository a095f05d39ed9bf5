// moving_collision.cpp — the fluid's collision with moving bodies within a substep: the
// `body_walls` stage (a dynamic body's velocity into a static fixture it would run into is
// removed) and the `bodies` stage (particles stopped at, or put back on, the face of a body they
// entered; against a dynamic body an inelastic contact whose impulse the body takes at the
// substep's end). What each does and why: the header of moving_bodies.cpp, "Per substep".
#include <algorithm>
#include <cmath>

#include "world/world_impl.hpp"

namespace sph2d {
namespace {

/// The way out for a particle at `p` (body coordinates, on or in polygon `k`) squeezed along
/// the face it is nearest: the unit vector along the face towards its nearer end. False for a
/// circle (no face to run along).
bool squeezeDirection(const Collider& k, const Vec2d& p, Vec2d& t) {
  if (k.kind != Collider::Kind::Polygon) return false;
  const std::size_t m = k.vertices.size();
  std::size_t f = 0;
  double best = -1e300;
  for (std::size_t e = 0; e < m; ++e) {
    const double s = Vec2d(k.normals[e].x(), k.normals[e].y()).dot(p - Vec2d(k.vertices[e].x(), k.vertices[e].y()));
    if (s > best) best = s, f = e;
  }
  const Vec2d v0(k.vertices[f].x(), k.vertices[f].y()), v1(k.vertices[(f + 1) % m].x(), k.vertices[(f + 1) % m].y());
  t = (v1 - v0).normalized();
  if ((p - v0).dot(t) <= 0.5 * (v1 - v0).norm()) t = -t;
  return true;
}

// A body whose pose at a substep's start differs from where the fluid last saw it by less than
// this share of the clearance did not jump: Box2D's float poses round to about a micrometre.
constexpr double kJumpShare = 1e-3;

}  // namespace

namespace {

// Overlap of the skins deeper than this is a body running into a static solid, not resting on
// it: Box2D keeps resting shapes at about b2_linearSlop (0.5 cm) into each other's skins, and
// a resting crate sinks a further g·dt²/2 (1.4 mm) within a frame before Box2D steps it.
constexpr double kRunInto = 3 * b2_linearSlop;

// A manifold point overlapping less than its deepest point by more than this has lifted off
// (MovingSolid::rests): half of Box2D's slop, the depth it settles resting shapes within.
constexpr double kResting = 0.5 * b2_linearSlop;

/// Box2D's manifold of shape a (placed by xa) against child `child` of static shape b (placed
/// by xb), its normal from a to b; false for a pair Box2D has no collide function for here.
bool collideWithStatic(const b2Shape* a, const b2Transform& xa, const b2Shape* b, int child, const b2Transform& xb,
                       b2WorldManifold& out, int& points) {
  b2Manifold m;
  m.pointCount = 0;
  const bool aPoly = a->GetType() == b2Shape::e_polygon, aCircle = a->GetType() == b2Shape::e_circle;
  if (!aPoly && !aCircle) return false;
  bool flip = false;
  b2EdgeShape edge;
  const b2Shape* other = b;
  if (b->GetType() == b2Shape::e_chain) {
    static_cast<const b2ChainShape*>(b)->GetChildEdge(&edge, child);
    other = &edge;
  }
  switch (other->GetType()) {
    case b2Shape::e_polygon:
      if (aPoly) {
        b2CollidePolygons(&m, static_cast<const b2PolygonShape*>(a), xa, static_cast<const b2PolygonShape*>(other), xb);
      } else {
        b2CollidePolygonAndCircle(&m, static_cast<const b2PolygonShape*>(other), xb,
                                  static_cast<const b2CircleShape*>(a), xa);
        flip = true;
      }
      break;
    case b2Shape::e_circle:
      if (aPoly)
        b2CollidePolygonAndCircle(&m, static_cast<const b2PolygonShape*>(a), xa,
                                  static_cast<const b2CircleShape*>(other), xb);
      else
        b2CollideCircles(&m, static_cast<const b2CircleShape*>(a), xa, static_cast<const b2CircleShape*>(other), xb);
      break;
    case b2Shape::e_edge:
      if (aPoly)
        b2CollideEdgeAndPolygon(&m, static_cast<const b2EdgeShape*>(other), xb, static_cast<const b2PolygonShape*>(a),
                                xa);
      else
        b2CollideEdgeAndCircle(&m, static_cast<const b2EdgeShape*>(other), xb, static_cast<const b2CircleShape*>(a),
                               xa);
      flip = true;
      break;
    default:
      return false;
  }
  points = m.pointCount;
  if (points == 0) return true;
  if (flip) {
    out.Initialize(&m, xb, other->m_radius, xa, a->m_radius);
    out.normal = -out.normal;
  } else {
    out.Initialize(&m, xa, a->m_radius, xb, other->m_radius);
  }
  return true;
}

}  // namespace

template <class F>
void World::Impl::forStaticContacts(const MovingSolid& m, const b2Transform& xa, F f) const {
  b2ContactFilter filter;  // Box2D's default: the fixtures' categories, masks and groups
  for (const b2Fixture* fa = m.body->GetFixtureList(); fa; fa = fa->GetNext()) {
    if (fa->IsSensor()) continue;
    b2AABB boxA;
    fa->GetShape()->ComputeAABB(&boxA, xa, 0);
    for (const b2Body* sb = b2->GetBodyList(); sb; sb = sb->GetNext()) {
      if (sb->GetType() != b2_staticBody) continue;
      for (const b2Fixture* fb = sb->GetFixtureList(); fb; fb = fb->GetNext()) {
        if (fb->IsSensor() || !filter.ShouldCollide(const_cast<b2Fixture*>(fa), const_cast<b2Fixture*>(fb))) continue;
        const b2Shape* shape = fb->GetShape();
        for (int child = 0; child < shape->GetChildCount(); ++child) {
          b2AABB boxB;
          shape->ComputeAABB(&boxB, sb->GetTransform(), child);
          if (!b2TestOverlap(boxA, boxB)) continue;
          b2WorldManifold wm;
          int points = 0;
          if (!collideWithStatic(fa->GetShape(), xa, shape, child, sb->GetTransform(), wm, points) || points == 0)
            continue;
          double deepest = 0;
          for (int k = 0; k < points; ++k) deepest = std::min(deepest, double(wm.separations[k]));
          f(Vec2d(wm.normal.x, wm.normal.y), deepest, wm, points);  // normal: from the body into the fixture
        }
      }
    }
  }
}

void World::Impl::holdBody(MovingSolid& m) const {
  // Box2D holds a body that has a joint or rests on a static fixture (a touching manifold: its
  // points within the shapes' skins): the grid's momentum balance leaves its cluster alone.
  // Each point of such a manifold is a resting contact for the step (MovingSolid::rests).
  m.held = m.body->GetJointList() != nullptr;
  m.rests.clear();
  double theta;
  Vec2d o;
  m.pose(0, theta, o);
  const b2Transform xa(b2Vec2(float(o.x() + origin.x()), float(o.y() + origin.y())), b2Rot(float(theta)));
  const Vec2d com = m.centreAt(0);
  // Every point of the manifold rests (its skins touch or overlap: Box2D settles resting shapes
  // anywhere from touching to b2_linearSlop deep) except one lifted off: overlapping less than
  // the manifold's deepest point by more than kResting (a tilted crate's raised corner, free to
  // fall back). Only the normals: along the face the body stays free within the step, so that
  // its path runs at least as far as Box2D's friction then lets it go (the water it pushed is
  // ahead of it, never inside it).
  forStaticContacts(m, xa, [&](const Vec2d& n, double deepest, const b2WorldManifold& wm, int points) {
    m.held = true;
    for (int k = 0; k < points; ++k) {
      if (double(wm.separations[k]) > deepest + kResting) continue;
      const Vec2d r = Vec2d(double(wm.points[k].x), double(wm.points[k].y)) - origin - com;
      m.rests.push_back({n.x(), n.y(), r.x() * n.y() - r.y() * n.x()});
    }
  });
}

void World::Impl::bodyWalls(StepContext& c) {
  // A dynamic body moves through a step along its velocity (moving_solid.hpp); Box2D's contacts
  // act on it only when Box2D next steps it (once a frame in a game's b2World, and in the
  // scene's own with the game solver and pbf). Flung at a wall, it would run into the wall for
  // the rest of the frame, taking the particles it meets with it, and Box2D would then put it
  // back in front of the wall with those particles behind it (a 50 m/s jet's box with
  // muller2003: 11 particles a frame). So at each substep's start, its pose at the substep's
  // end is tested against the static fixtures with Box2D's own collide functions; where the
  // skins would overlap deeper than kRunInto, the part of its velocity into the fixture (its
  // centre of mass's, along the contact normal) is removed, as Box2D's inelastic contact would.
  const double tau0 = c.time - moving.solids.time0, tau1 = tau0 + double(c.dt);
  for (MovingSolid& m : moving.solids.bodies) {
    if (!m.dynamic()) continue;
    double theta;
    Vec2d o;
    m.pose(tau1, theta, o);
    const b2Transform xa(b2Vec2(float(o.x() + origin.x()), float(o.y() + origin.y())), b2Rot(float(theta)));
    forStaticContacts(m, xa, [&](const Vec2d& n, double deepest, const b2WorldManifold&, int) {
      if (deepest > -kRunInto) return;
      const double vn = m.v.dot(n);
      if (vn > 0) m.changeVelocity(tau0, -vn * n, 0);
    });
  }
}

void World::Impl::collideMoving(StepContext& c, bool atStart) {
  if (moving.solids.bodies.empty()) return;
  const double tau0 = c.time - moving.solids.time0, tau1 = atStart ? tau0 : tau0 + double(c.dt),
               clearance = double(c.clearance);
  using Pose = MovingBodies::Pose;
  const std::vector<MovingSolid>& bodies = moving.solids.bodies;
  std::vector<Pose>& poses = moving.poses;
  poses.resize(bodies.size());
  for (std::size_t k = 0; k < bodies.size(); ++k) {
    Pose& q = poses[k];
    q.theta0 = bodies[k].sweptTheta;  // where the particles last saw it
    q.o0 = bodies[k].sweptOrigin;
    bodies[k].pose(tau1, q.theta1, q.o1);
    q.com1 = bodies[k].centreAt(tau1);
    q.c0 = std::cos(q.theta0), q.s0 = std::sin(q.theta0), q.c1 = std::cos(q.theta1), q.s1 = std::sin(q.theta1);
    // The shapes' reach, plus how far any of the body's points moved over the substep.
    const Vec2d& lc = bodies[k].localCenter;
    const Vec2d com0 = q.o0 + Vec2d(q.c0 * lc.x() - q.s0 * lc.y(), q.s0 * lc.x() + q.c0 * lc.y());
    const double reach = bodies[k].radius + double(c.clearance) + (q.com1 - com0).norm() +
                         std::fabs(q.theta1 - q.theta0) * bodies[k].radius;
    q.reach2 = reach * reach;
  }
  if (atStart) {  // only where a body is not where the fluid last saw it (beyond float rounding)
    const double tol = kJumpShare * clearance;
    bool jumped = false;
    for (std::size_t k = 0; k < bodies.size(); ++k)
      jumped = jumped || (poses[k].o1 - poses[k].o0).norm() > tol ||
               std::fabs(poses[k].theta1 - poses[k].theta0) * bodies[k].radius > tol;
    if (!jumped) return;
  }
  const bool anyDynamic = moving.solids.anyDynamic();
  if (anyDynamic) {
    moving.hitBody.assign(c.P.size(), -1);
    moving.hitNormal.resize(c.P.size());
  }
  // Body frame from the local frame: rotate by −θ about the body origin.
  auto toBody = [](double co, double si, const Vec2d& p) {
    return Vec2d(co * p.x() + si * p.y(), -si * p.x() + co * p.y());
  };
  // A particle body k has just put at x (local) with world normal n: a dynamic body's contact
  // is solved below with its other contacts; a kinematic one carries the particle along.
  auto settle = [&](std::size_t i, std::size_t k, const Vec2d& x, const Vec2d& n) {
    const MovingSolid& m = bodies[k];
    if (m.dynamic()) {
      moving.hitBody[i] = std::int32_t(k);
      moving.hitNormal[i] = n;
      return;
    }
    const Vec2d r = x - poses[k].com1, vb = m.v + m.omega * Vec2d(-r.y(), r.x());
    Vec2d v(c.P.v[i].x(), c.P.v[i].y());
    const double vn = (v - vb).dot(n);
    if (vn < 0) v -= vn * n;  // no velocity into the body
    c.P.v[i] = Vec2(Real(v.x()), Real(v.y()));
  };
  // The first body whose shapes contain local point x at the substep's end (deeper than a
  // micrometre: a point put on a surface stays on it), with the shape, x in its frame, the
  // face's depth (negative) and outward normal there.
  struct Inside {
    std::size_t k;
    const Collider* shape;
    Vec2d at, n;
    double d;
  };
  auto insideAny = [&](const Vec2d& x, Inside& in) {
    for (std::size_t k = 0; k < bodies.size(); ++k) {
      const Pose& q = poses[k];
      if ((x - q.com1).squaredNorm() > q.reach2) continue;
      const Vec2d at = toBody(q.c1, q.s1, x - q.o1);
      for (const Collider& s : bodies[k].shapes) {
        Vec2d n;
        const double d = outsideCollider(s, at, at, n);
        if (d < -1e-6) {
          in = Inside{k, &s, at, n, d};
          return true;
        }
      }
    }
    return false;
  };
  c.pool.parallelFor(c.P.size(), kStreamBlock, [&](std::size_t b0, std::size_t e0) {
    for (std::size_t i = b0; i < e0; ++i) {
      bool moved = false;
      for (std::size_t k = 0; k < bodies.size(); ++k) {
        const MovingSolid& m = bodies[k];
        const Pose& q = poses[k];
        const Vec2d xw(c.P.x[i].x(), c.P.x[i].y());
        const Vec2d xp = atStart ? xw : Vec2d(c.P.xPrev[i].x(), c.P.xPrev[i].y());
        {  // a first cull in the local frame: the path from xp to xw against the swept reach
          const Vec2d d = xw - xp, e = q.com1 - xp;
          const double l2 = d.squaredNorm(), u = l2 > 0 ? std::clamp(e.dot(d) / l2, 0.0, 1.0) : 0.0;
          if ((xp + u * d - q.com1).squaredNorm() > q.reach2) continue;
        }
        const Vec2d a = toBody(q.c0, q.s0, xp - q.o0);
        const Vec2d bEnd = toBody(q.c1, q.s1, xw - q.o1);
        // Beyond reach: the path from a to bEnd passes farther than the shapes reach.
        const Vec2d ab = bEnd - a, ac = m.localCenter - a;
        const double len2 = ab.squaredNorm();
        const double t = len2 > 0 ? std::clamp(ac.dot(ab) / len2, 0.0, 1.0) : 0.0;
        const double reach = m.radius + clearance;
        if ((a + t * ab - m.localCenter).squaredNorm() > reach * reach) continue;
        Vec2d nb(0, 0), b = bEnd;
        bool hit = false;
        for (const Collider& s : m.shapes) {
          Vec2d n;
          double te;
          if (sweptEntry(s, a, b, te, n)) {
            // It entered on the way (and may have crossed it: a fast particle, a thin body):
            // stopped at the face it entered by, the clearance off it. The path is the one
            // left by the shapes before (b moves).
            b = a + te * (b - a) + clearance * n;
          } else {
            // It started inside, or ends within the clearance outside: back on the surface.
            const double d = outsideCollider(s, a, b, n);
            if (d >= clearance) continue;
            b += (clearance - d) * n;
          }
          nb = n;
          hit = true;
        }
        if (!hit) continue;
        auto toLocal = [&](const Vec2d& p) {
          return q.o1 + Vec2d(q.c1 * p.x() - q.s1 * p.y(), q.s1 * p.x() + q.c1 * p.y());
        };
        Vec2d x = toLocal(b);
        {
          // Pushed into a static solid: the particle is in a gap between the body and a static
          // solid thinner than the clearance on both sides (beside or under a crate resting on
          // the floor or against a wall: its skin leaves 0.5 cm or less), or where the two
          // overlap within the step (the fluid's step has no contact between them: a crate
          // landing on the floor sinks into it until Box2D's next step). First it is put only
          // on the body's surface (its skin, outside its core), along the face nearest its end
          // point and not stopped where it entered (which would pin it, and every particle
          // after it, at one point): it moves along the gap. Where that is inside the static
          // solid too, it stays where the static collision left it and is squeezed out along
          // the body's face: one spacing a substep towards the face's nearer end (or the
          // farther, where a static solid is in the way; or not at all). All the particles
          // there move alike, so none lands on another. Never into a static solid.
          const Vec2 from = c.P.x[i];
          auto intoStatic = [&](const Vec2d& p) {
            const Vec2 to(Real(p.x()), Real(p.y()));
            return !c.boundary.clearOf(to, from, 0) && c.boundary.blocks(from, to);
          };
          if (intoStatic(x)) {
            b = bEnd;
            const Collider* last = nullptr;
            for (const Collider& s : m.shapes) {
              Vec2d n;
              const double d = outsideCollider(s, a, b, n);
              if (d >= 0) continue;
              b -= d * n;
              nb = n;
              last = &s;
            }
            x = toLocal(b);
            if (intoStatic(x)) {
              x = xw;
              Vec2d way;
              if (last && squeezeDirection(*last, b, way)) {
                const Vec2d tw = double(c.dx) * Vec2d(q.c1 * way.x() - q.s1 * way.y(), q.s1 * way.x() + q.c1 * way.y());
                if (!intoStatic(xw + tw))
                  x = xw + tw;
                else if (!intoStatic(xw - tw))
                  x = xw - tw;
              }
            }
          }
        }
        const Vec2d n(q.c1 * nb.x() - q.s1 * nb.y(), q.s1 * nb.x() + q.c1 * nb.y());
        c.P.x[i] = Vec2(Real(x.x()), Real(x.y()));
        settle(i, k, x, n);
        moved = true;
      }
      // Skins that overlap: a crate resting on another (Box2D keeps their cores about 1.5 cm
      // apart, the game solver's skins are 1 cm each), or two fixtures of one body. A later
      // body's push can end inside one handled before it. Put on that body's surface once
      // more; where that is inside another body too, the particle is in the overlap, where no
      // point is outside both: it is squeezed along the face, one spacing a substep towards
      // the face's nearer end, where the gap opens (as beside a static solid above).
      Inside in;
      const Vec2 from = c.P.x[i];
      if (!moved || !insideAny(Vec2d(from.x(), from.y()), in)) continue;
      const Pose& q = poses[in.k];
      auto toLocal = [&](const Vec2d& p) {
        return q.o1 + Vec2d(q.c1 * p.x() - q.s1 * p.y(), q.s1 * p.x() + q.c1 * p.y());
      };
      auto turn = [&](const Vec2d& p) { return Vec2d(q.c1 * p.x() - q.s1 * p.y(), q.s1 * p.x() + q.c1 * p.y()); };
      Vec2d x = toLocal(in.at + (clearance - in.d) * in.n);
      Inside other;
      if (insideAny(x, other)) {
        Vec2d way;
        if (!squeezeDirection(*in.shape, in.at, way)) continue;
        x = Vec2d(from.x(), from.y()) + double(c.dx) * turn(way);
      }
      const Vec2 to(Real(x.x()), Real(x.y()));
      if (!c.boundary.clearOf(to, from, 0) && c.boundary.blocks(from, to)) continue;  // never into a static solid
      c.P.x[i] = to;
      settle(i, in.k, x, turn(in.n));
    }
  });
  for (std::size_t k = 0; k < bodies.size(); ++k) {
    moving.solids.bodies[k].sweptTheta = poses[k].theta1;
    moving.solids.bodies[k].sweptOrigin = poses[k].o1;
  }
  if (!anyDynamic) return;
  // The dynamic bodies' contacts, in slot order: count each body's approaching contacts,
  // then solve each as inelastic with the body's mass split among them.
  std::vector<int>& count = moving.contactCount;
  count.assign(bodies.size(), 0);
  auto approach = [&](std::size_t i, Vec2d& r, double& vn) {
    const MovingSolid& m = bodies[std::size_t(moving.hitBody[i])];
    const Vec2d x(c.P.x[i].x(), c.P.x[i].y());
    r = x - m.centreAt(tau1);
    vn = (Vec2d(c.P.v[i].x(), c.P.v[i].y()) - m.velocityAt(tau1, x)).dot(moving.hitNormal[i]);
    return vn < 0;
  };
  for (std::size_t i = 0; i < c.P.size(); ++i) {
    Vec2d r;
    double vn;
    if (moving.hitBody[i] >= 0 && approach(i, r, vn)) ++count[std::size_t(moving.hitBody[i])];
  }
  std::vector<Vec2d>& J = moving.contactImpulse;
  std::vector<double>& L = moving.contactTorque;
  J.assign(bodies.size(), Vec2d(0, 0));
  L.assign(bodies.size(), 0.0);
  const std::vector<Real>* ratio = c.P.find(ParticleStore::kRestRatio);  // m_i = r_i m with a density contrast
  // Each body's response as its resting contacts leave it (MovingSolid::restingResponse): a
  // body held still by them meets the particle as a wall would.
  std::vector<MovingBodies::Response>& W = moving.contactResponse;
  W.resize(bodies.size());
  for (std::size_t k = 0; k < bodies.size(); ++k)
    if (count[k] > 0) bodies[k].restingResponse(W[k].w);
  for (std::size_t i = 0; i < c.P.size(); ++i) {
    Vec2d r;
    double vn;
    if (moving.hitBody[i] < 0 || !approach(i, r, vn)) continue;
    const double m0 = ratio ? double(c.momentumMass) * double((*ratio)[i]) : double(c.momentumMass);
    const std::size_t k = std::size_t(moving.hitBody[i]);
    const Vec2d& n = moving.hitNormal[i];
    const double rn = r.x() * n.y() - r.y() * n.x();
    const double g[3] = {n.x(), n.y(), rn};
    double invMeff = 0;  // g W gᵀ: 1/m + rn²/I for a body resting on nothing
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) invMeff += g[a] * W[k].w[a][b] * g[b];
    const double j = -vn / (1.0 / m0 + double(count[k]) * invMeff);  // > 0, along n for the particle
    c.P.v[i] += (j / m0 * n).cast<Real>();
    J[k] -= j * n;
    L[k] -= j * rn;
  }
  for (std::size_t k = 0; k < bodies.size(); ++k)
    if (count[k] > 0) moving.solids.bodies[k].push(tau1, J[k], L[k]);
}
}  // namespace sph2d
