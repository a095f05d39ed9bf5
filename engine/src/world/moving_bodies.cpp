// moving_bodies.cpp — the fluid against moving Box2D bodies (kinematic and dynamic),
// both ways. After LiquidFun's particle–body contacts (b2ParticleSystem::SolveCollision),
// in the body's own frame, with the body's side of each contact from the impulse the
// particles exchange with it.
//
// At the start of each step the World reads every non-static body's pose, velocity,
// mass and inertia (moving_solid.hpp: a body moves along a piecewise-linear path
// within the step), and its shapes as the fluid meets them: a polygon with Box2D's skin
// (b2_polygonRadius, 1 cm: withSkin, faces moved out, corners mitred), a circle as it is
// (its radius is its skin); for a solver that samples moving bodies (body_samples.hpp:
// wcsph, muller2003) the fixtures themselves, which its samples stand for. Box2D rests a polygon on another at about two skins less the
// slop, core to core: seen without its skin, a crate on the floor left a 1.5 cm gap that
// the fluid entered and was squeezed in. Everything that reads a body's shape (the
// collision below, the grid's body cells and faces, its reach, movingColliders() for
// drawing) reads these; the body's area and centroid are its fixtures' (below). Static
// bodies' shapes stay cores (boundary_set.cpp; their skins would move every tank's walls and
// water level): a skinned
// crate resting on a core floor leaves 0.5 cm, room for a particle kept the clearance
// (0.25 spacing) off both only at a spacing of 1 cm or less, and then for one layer, which
// is not squeezed. Box2D's mass is the core's, and so is the area the grid's buoyancy is
// scaled to (shapeMoments of the cores): the skin keeps water out without making a body
// lighter than its density says (density 1000 stays neutral).
// Per substep:
//  - `body_gravity` (after `emit`, with a dynamic body): its velocity takes g·dt;
//  - `body_walls` (after it): where its shapes would overlap a static fixture by the substep's
//    end deeper than Box2D's contact distance, its velocity into the fixture is removed
//    (Box2D's contacts act only when Box2D next steps it);
//  - `body_jump` (with a solver that samples the bodies): where a body is not where the fluid
//    last saw it, the `bodies` push-out below for particles standing still, before the solver
//    counts them (with these solvers the scene's own b2World steps with every substep:
//    World::Impl::bodiesFollow);
//  - the game solver's grid projection treats the bodies as moving solids and solves
//    for a dynamic body's velocity together with the pressure (grid_projection.cpp);
//  - `bodies` (after the static collision): a particle whose path entered one of a body's
//    polygons or circles is stopped at the face it entered by (shape by shape, each on
//    the path the shapes before left), one that started inside or ends within the
//    clearance is put back on the surface (its start position taken in the body's frame
//    at the substep's start, its end in the frame at the substep's end, so a body's own
//    motion counts). Where that push would put it into a static solid (a gap thinner than
//    the clearance on both sides, or a body that overlaps a static solid within the step:
//    the fluid's step has no contact between them), it goes only onto the body's surface,
//    or, where that is inside the static solid too, stays where the static collision put it
//    and is squeezed out along the body's face a spacing a substep: never into a static
//    solid, at worst for a few frames within a landing body. Skins that overlap (a crate
//    resting on another, two fixtures of one body) can leave a particle pushed out of a
//    later body inside an earlier one: it is put on that one's surface again, or, where
//    that is inside another body too (the overlap has no point outside both), squeezed
//    along the face a spacing a substep. Against a kinematic body the
//    part of its velocity into the body, relative to the body's velocity there, is
//    removed. Against a dynamic
//    body the two meet as an inelastic contact: the particle (mass m) and the body
//    (effective mass 1/M_eff = 1/M + (r × n)²/I at the contact) share the relative
//    normal velocity v_n, the N contacts of the body in the substep splitting its mass
//    (impulse j = −v_n / (1/m + N/M_eff)): a light body meeting much water takes most
//    of the change, the water little, and like contacts together cannot overshoot the
//    shared velocity (with rotation or mixed normals only nearly). The body takes −j
//    (and its torque) at the substep's end; the step's sum goes to Box2D, which then
//    moves the body.
// Positions are pushed out in parallel (each particle alone); the contacts' impulses
// are summed serially in slot order: the same bits for any thread count.
#include <algorithm>
#include <cmath>

#include "world/world_impl.hpp"

namespace sph2d {
namespace {

Vec2d rot(double theta, const Vec2d& p) {
  const double c = std::cos(theta), s = std::sin(theta);
  return Vec2d(c * p.x() - s * p.y(), s * p.x() + c * p.y());
}

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

}  // namespace

double outsideCollider(const Collider& k, const Vec2d& a, const Vec2d& b, Vec2d& normal) {
  if (k.kind == Collider::Kind::Circle) {
    const Vec2d c(k.center.x(), k.center.y());
    Vec2d d = b - c;
    double r = d.norm();
    if (!(r > 1e-12)) {  // at the centre: out the way it came
      d = a - c;
      r = d.norm();
      if (!(r > 1e-12)) d = Vec2d(0, 1), r = 1;
    }
    normal = d / r;
    return (b - c).norm() - double(k.radius);
  }
  double best = -1e300, entry = -1e300;
  std::size_t bi = 0, ei = 0;
  for (std::size_t f = 0; f < k.vertices.size(); ++f) {
    const Vec2d n(k.normals[f].x(), k.normals[f].y()), v(k.vertices[f].x(), k.vertices[f].y());
    const double sb = n.dot(b - v), sa = n.dot(a - v);
    if (sb > best) best = sb, bi = f;
    if (sa > entry) entry = sa, ei = f;
  }
  if (best >= 0) {  // outside, perhaps within the clearance of face bi
    normal = Vec2d(k.normals[bi].x(), k.normals[bi].y());
    return best;
  }
  const std::size_t f = entry >= 0 ? ei : bi;  // entered through face ei, or was inside already
  normal = Vec2d(k.normals[f].x(), k.normals[f].y());
  return normal.dot(b - Vec2d(k.vertices[f].x(), k.vertices[f].y()));
}

bool sweptEntry(const Collider& k, const Vec2d& a, const Vec2d& b, double& t, Vec2d& normal) {
  const Vec2d d = b - a;
  if (k.kind == Collider::Kind::Circle) {
    const Vec2d f = a - Vec2d(k.center.x(), k.center.y());
    const double r = double(k.radius), A = d.squaredNorm(), B = f.dot(d), C = f.squaredNorm() - r * r;
    if (!(A > 0) || C < 0) return false;  // no move, or starts inside (not a crossing)
    const double disc = B * B - A * C;
    if (disc < 0) return false;
    t = (-B - std::sqrt(disc)) / A;
    if (!(t >= 0 && t <= 1)) return false;
    normal = (f + t * d) / r;
    return true;
  }
  // Cyrus–Beck: the segment's part inside every face's half plane.
  double tIn = 0, tOut = 1;
  std::size_t entry = k.vertices.size();
  for (std::size_t f = 0; f < k.vertices.size(); ++f) {
    const Vec2d n(k.normals[f].x(), k.normals[f].y()), v(k.vertices[f].x(), k.vertices[f].y());
    const double s0 = n.dot(a - v), sd = n.dot(d);
    if (sd == 0) {
      if (s0 > 0) return false;  // parallel and outside this face
      continue;
    }
    const double tf = -s0 / sd;
    if (sd < 0) {
      if (tf > tIn) tIn = tf, entry = f;
    } else {
      tOut = std::min(tOut, tf);
    }
    if (tIn > tOut) return false;
  }
  if (entry == k.vertices.size()) return false;  // starts inside: not a crossing
  t = tIn;
  normal = Vec2d(k.normals[entry].x(), k.normals[entry].y());
  return true;
}

double MovingSolid::depth(double tau, const Vec2d& p) const {
  if ((p - centreAt(tau)).squaredNorm() > radius * radius) return -1e300;
  double theta;
  Vec2d o;
  pose(tau, theta, o);
  const Vec2d b = rot(-theta, p - o);
  double best = -1e300;
  for (const Collider& c : shapes) {
    Vec2d n;
    best = std::max(best, -outsideCollider(c, b, b, n));
  }
  return best;
}

int solidAt(const MovingSolids& s, double tau, const Vec2d& p) {
  for (std::size_t k = 0; k < s.bodies.size(); ++k)
    if (s.bodies[k].contains(tau, p)) return int(k);
  return -1;
}

namespace {

/// Box2D's polygon `poly` as the fluid meets it, into `c` (body coordinates): its core with
/// Box2D's skin (m_radius, b2_polygonRadius = 1 cm), where Box2D's own contacts put it. The
/// skinned polygon is the core's Minkowski sum with a disc of the skin's radius (rounded
/// corners); the fluid gets a simpler polygon: every face moved out along its normal by the
/// skin, the corners mitred (each new vertex where the two moved faces meet), so the
/// collision code keeps reading a convex polygon by its faces' planes, and every face lies
/// exactly where Box2D's skin has it. A corner sharper than a right angle (its normals
/// turning by more than 90°) is bevelled: a face of the mean normal, also the skin off the
/// core's corner, splits the turn in two, so no mitre reaches past √2 skins (a box's corner
/// is mitred: √2 skins out, against the rounded corner's one).
void withSkin(const b2PolygonShape& poly, Collider& c) {
  const double r = double(poly.m_radius);
  const int n = poly.m_count;
  auto at = [&](int i) { return Vec2d(poly.m_vertices[(i + n) % n].x, poly.m_vertices[(i + n) % n].y); };
  auto normal = [&](int i) { return Vec2d(poly.m_normals[(i + n) % n].x, poly.m_normals[(i + n) % n].y); };
  auto add = [&](const Vec2d& v, const Vec2d& na, const Vec2d& nb) {  // faces na (in) and nb (out) at core vertex v
    const Vec2d p = v + r / (1.0 + na.dot(nb)) * (na + nb);       // on both moved faces: nₐ·(p − v) = n_b·(p − v) = r
    c.vertices.push_back(Vec2(Real(p.x()), Real(p.y())));
    c.normals.push_back(Vec2(Real(nb.x()), Real(nb.y())));
  };
  for (int i = 0; i < n; ++i) {  // vertex i starts face i (from vertex i to i + 1)
    const Vec2d v = at(i), na = normal(i - 1), nb = normal(i);
    if (na.dot(nb) < 0) {
      const Vec2d bevel = (na + nb).normalized();
      add(v, na, bevel);
      add(v, bevel, nb);
    } else {
      add(v, na, nb);
    }
  }
}

/// A moving body's area and centroid (body coordinates, offset from its centre of mass) from
/// `shapes`: exact for one shape; for several, which may overlap, their union sampled on a
/// 96 × 96 lattice over their bounds (the grid's face correction scales the pressure to this
/// area). Given the fixtures' cores, as Box2D weighs them, not the skinned shapes the fluid is
/// kept out of: so a body floats by Archimedes for its fixtures (density 1000 is neutral),
/// the skin only closing the gaps Box2D leaves between resting bodies.
void shapeMoments(MovingSolid& m, const std::vector<Collider>& shapes) {
  Vec2d sum(0, 0);
  if (shapes.size() == 1) {
    const Collider& c = shapes[0];
    if (c.kind == Collider::Kind::Circle) {
      m.area = 3.14159265358979323846 * double(c.radius) * double(c.radius);
      sum = m.area * Vec2d(c.center.x(), c.center.y());
    } else {
      for (std::size_t e = 0; e < c.vertices.size(); ++e) {  // counter-clockwise (Box2D)
        const Vec2d p(c.vertices[e].x(), c.vertices[e].y());
        const Vec2d q(c.vertices[(e + 1) % c.vertices.size()].x(), c.vertices[(e + 1) % c.vertices.size()].y());
        const double cross = p.x() * q.y() - q.x() * p.y();
        m.area += 0.5 * cross;
        sum += cross / 6.0 * (p + q);
      }
    }
  } else {
    Vec2d lo(1e300, 1e300), hi(-1e300, -1e300);
    for (const Collider& c : shapes) {
      const double r = c.kind == Collider::Kind::Circle ? double(c.radius) : 0.0;
      if (c.kind == Collider::Kind::Circle) {
        lo = lo.cwiseMin(Vec2d(c.center.x() - r, c.center.y() - r));
        hi = hi.cwiseMax(Vec2d(c.center.x() + r, c.center.y() + r));
      }
      for (const Vec2& p : c.vertices) {
        lo = lo.cwiseMin(Vec2d(p.x(), p.y()));
        hi = hi.cwiseMax(Vec2d(p.x(), p.y()));
      }
    }
    constexpr int kSamples = 96;
    const Vec2d step = (hi - lo) / double(kSamples);
    const double cell = step.x() * step.y();
    for (int j = 0; j < kSamples; ++j)
      for (int i = 0; i < kSamples; ++i) {
        const Vec2d p = lo + Vec2d((i + 0.5) * step.x(), (j + 0.5) * step.y());
        for (const Collider& c : shapes) {
          Vec2d n;
          if (outsideCollider(c, p, p, n) < 0) {
            m.area += cell;
            sum += cell * p;
            break;
          }
        }
      }
  }
  m.centroid = m.area > 0 ? Vec2d(sum / m.area - m.localCenter) : Vec2d(0, 0);
}

}  // namespace

void World::Impl::captureBodies() {
  const bool had = !moving.bodies.empty(), hadDynamic = moving.anyDynamic();
  moving.bodies.clear();
  moving.time0 = time;
  const b2Vec2 g = b2->GetGravity();
  // A solver that samples the moving bodies (Solver::movingSamples: wcsph, muller2003) meets
  // them at their fixtures, as its samples stand for them: their pressure keeps the water out
  // of the gaps Box2D leaves, as at a static wall. The others meet a polygon at its skin.
  const bool skinned = !(solver && solver->movingSamples());
  for (b2Body* body = b2->GetBodyList(); body; body = body->GetNext()) {
    // A static body the game slid moves as a kinematic one through the step (box2d_bridge.cpp).
    const SlidingStatic* slide = nullptr;
    for (const SlidingStatic& s : sliding)
      if (s.body == body) slide = &s;
    if (body->GetType() == b2_staticBody && !slide) continue;
    MovingSolid m;
    m.body = body;
    for (b2Fixture* fx = body->GetFixtureList(); fx; fx = fx->GetNext()) {
      const b2Shape* shape = fx->GetShape();
      Collider c;
      if (shape->GetType() == b2Shape::e_polygon) {
        const auto* poly = static_cast<const b2PolygonShape*>(shape);
        Collider core;
        core.kind = Collider::Kind::Polygon;
        for (int i = 0; i < poly->m_count; ++i) {
          core.vertices.push_back(Vec2(poly->m_vertices[i].x, poly->m_vertices[i].y));
          core.normals.push_back(Vec2(poly->m_normals[i].x, poly->m_normals[i].y));
        }
        if (skinned && !slide) {  // the static solids are their cores, sliding or not
          c.kind = Collider::Kind::Polygon;
          withSkin(*poly, c);
        } else {
          c = core;
        }
        m.cores.push_back(std::move(core));
      } else if (shape->GetType() == b2Shape::e_circle) {
        const auto* circle = static_cast<const b2CircleShape*>(shape);
        c.kind = Collider::Kind::Circle;
        c.sourceShape = Collider::SourceShape::Circle;
        c.center = Vec2(circle->m_p.x, circle->m_p.y);
        c.radius = circle->m_radius;
      } else {
        continue;  // edges and chains enclose nothing
      }
      if (c.kind == Collider::Kind::Circle) m.cores.push_back(c);
      m.shapes.push_back(std::move(c));
      m.fixtures.push_back(fx);
    }
    if (m.shapes.empty()) continue;
    const b2Vec2 com = body->GetWorldCenter(), lc = body->GetLocalCenter(), v = body->GetLinearVelocity();
    m.com0 = Vec2d(com.x, com.y) - origin;
    m.localCenter = Vec2d(lc.x, lc.y);
    m.angle0 = body->GetAngle();
    m.v = Vec2d(v.x, v.y);
    m.omega = body->GetAngularVelocity();
    if (slide) {  // its path from the pose the game moved it from (a static body's centre is its origin)
      const double tau = time - slide->t0;
      m.com0 = slide->p0 + slide->v * tau - origin;
      m.localCenter = Vec2d(0, 0);
      m.angle0 = slide->angle0 + slide->omega * tau;
      m.v = slide->v;
      m.omega = slide->omega;
    }
    if (body->GetType() == b2_dynamicBody && body->GetMass() > 0) {
      const double bodyMass = body->GetMass();
      m.invMass = 1.0 / bodyMass;
      // Box2D gives the inertia about the body origin; the contacts turn it about its centre of mass.
      const double ic = double(body->GetInertia()) - bodyMass * m.localCenter.squaredNorm();
      m.invInertia = body->IsFixedRotation() || !(ic > 0) ? 0.0 : 1.0 / ic;
      m.gravity = Vec2d(g.x, g.y) * double(body->GetGravityScale());
    }
    for (const Collider& c : m.shapes) {
      if (c.kind == Collider::Kind::Circle)
        m.radius = std::max(m.radius, (Vec2d(c.center.x(), c.center.y()) - m.localCenter).norm() + double(c.radius));
      for (const Vec2& p : c.vertices) m.radius = std::max(m.radius, (Vec2d(p.x(), p.y()) - m.localCenter).norm());
    }
    shapeMoments(m, m.cores);
    double theta;
    m.pose(0, theta, m.sweptOrigin);
    m.sweptTheta = theta;
    // A dynamic body's jump (Box2D moved it by more than the fluid saw: a contact's impulse
    // acts on its pose too) is swept; a kinematic body moves as the fluid saw it, up to float
    // rounding. Farther than its reach it was teleported (or is a new body at a freed address).
    for (const MovingSolids::LastPose& l : moving.last)
      if (m.dynamic() && l.body == body && (l.origin - m.sweptOrigin).norm() <= m.radius) {
        m.sweptTheta = l.theta;
        m.sweptOrigin = l.origin;
      }
    moving.bodies.push_back(std::move(m));
  }
  // The `bodies` stage exists only with moving bodies, `body_gravity` and `body_walls` only with a dynamic one.
  if (had != !moving.bodies.empty() || hadDynamic != moving.anyDynamic()) buildStages();
}

// A body whose pose at a substep's start differs from where the fluid last saw it by less than
// this share of the clearance did not jump: Box2D's float poses round to about a micrometre.
constexpr double kJumpShare = 1e-3;

// An impulse at most this in each component [N·s per metre of depth] is none: the fluid did not
// touch the body, and applying it would wake a sleeping body for nothing.
constexpr double kNegligibleImpulse = 1e-12;

void World::Impl::moveOwnBodies(double dt) {
  moving.last.clear();
  for (const MovingSolid& m : moving.bodies) moving.last.push_back({m.body, m.sweptTheta, m.sweptOrigin});
  for (const MovingSolid& m : moving.bodies) {
    const bool noImpulse = std::abs(m.impulse.x()) <= kNegligibleImpulse && std::abs(m.impulse.y()) <= kNegligibleImpulse;
    if (!m.dynamic() || (noImpulse && m.angularImpulse == 0)) continue;
    m.body->ApplyLinearImpulse(b2Vec2(float(m.impulse.x()), float(m.impulse.y())), m.body->GetWorldCenter(), true);
    m.body->ApplyAngularImpulse(float(m.angularImpulse), true);
  }
  if (!ownWorld || moving.bodies.empty() || !(dt > 0)) return;
  ownWorld->Step(float(dt), 8, 3);
}

bool World::Impl::insideMoving(const Vec2& p) const {
  return solidAt(moving, time - moving.time0, Vec2d(p.x(), p.y())) >= 0;
}

void World::Impl::bodyGravity(StepContext& c) {
  const double tau0 = c.time - moving.time0;
  for (MovingSolid& m : moving.bodies)
    if (m.dynamic()) m.changeVelocity(tau0, m.gravity * double(c.dt), 0);
}

namespace {

// Overlap of the skins deeper than this is a body running into a static solid, not resting on
// it: Box2D keeps resting shapes at about b2_linearSlop (0.5 cm) into each other's skins, and
// a resting crate sinks a further g·dt²/2 (1.4 mm) within a frame before Box2D steps it.
constexpr double kRunInto = 3 * b2_linearSlop;

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
        b2CollidePolygonAndCircle(&m, static_cast<const b2PolygonShape*>(other), xb, static_cast<const b2CircleShape*>(a), xa);
        flip = true;
      }
      break;
    case b2Shape::e_circle:
      if (aPoly)
        b2CollidePolygonAndCircle(&m, static_cast<const b2PolygonShape*>(a), xa, static_cast<const b2CircleShape*>(other), xb);
      else
        b2CollideCircles(&m, static_cast<const b2CircleShape*>(a), xa, static_cast<const b2CircleShape*>(other), xb);
      break;
    case b2Shape::e_edge:
      if (aPoly)
        b2CollideEdgeAndPolygon(&m, static_cast<const b2EdgeShape*>(other), xb, static_cast<const b2PolygonShape*>(a), xa);
      else
        b2CollideEdgeAndCircle(&m, static_cast<const b2EdgeShape*>(other), xb, static_cast<const b2CircleShape*>(a), xa);
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
  const double tau0 = c.time - moving.time0, tau1 = tau0 + double(c.dt);
  for (MovingSolid& m : moving.bodies) {
    if (!m.dynamic()) continue;
    double theta;
    Vec2d o;
    m.pose(tau1, theta, o);
    const b2Transform xa(b2Vec2(float(o.x() + origin.x()), float(o.y() + origin.y())), b2Rot(float(theta)));
    for (const b2Fixture* fa = m.body->GetFixtureList(); fa; fa = fa->GetNext()) {
      if (fa->IsSensor()) continue;
      b2AABB boxA;
      fa->GetShape()->ComputeAABB(&boxA, xa, 0);
      for (const b2Body* sb = b2->GetBodyList(); sb; sb = sb->GetNext()) {
        if (sb->GetType() != b2_staticBody) continue;
        for (const b2Fixture* fb = sb->GetFixtureList(); fb; fb = fb->GetNext()) {
          if (fb->IsSensor()) continue;
          const b2Shape* shape = fb->GetShape();
          for (int child = 0; child < shape->GetChildCount(); ++child) {
            b2AABB boxB;
            shape->ComputeAABB(&boxB, sb->GetTransform(), child);
            if (!b2TestOverlap(boxA, boxB)) continue;
            b2WorldManifold wm;
            int points = 0;
            if (!collideWithStatic(fa->GetShape(), xa, shape, child, sb->GetTransform(), wm, points) || points == 0) continue;
            double deepest = 0;
            for (int k = 0; k < points; ++k) deepest = std::min(deepest, double(wm.separations[k]));
            if (deepest > -kRunInto) continue;
            const Vec2d n(wm.normal.x, wm.normal.y);  // from the body into the static fixture
            const double vn = m.v.dot(n);
            if (vn > 0) m.changeVelocity(tau0, -vn * n, 0);
          }
        }
      }
    }
  }
}

void World::Impl::collideMoving(StepContext& c, bool atStart) {
  if (moving.bodies.empty()) return;
  const double tau0 = c.time - moving.time0, tau1 = atStart ? tau0 : tau0 + double(c.dt),
               clearance = double(c.clearance);
  using Pose = BodyPose;
  const std::vector<MovingSolid>& bodies = moving.bodies;
  std::vector<Pose>& poses = bodyPoses;
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
  const bool anyDynamic = moving.anyDynamic();
  if (anyDynamic) {
    hitBody.assign(c.P.size(), -1);
    hitNormal.resize(c.P.size());
  }
  // Body frame from the local frame: rotate by −θ about the body origin.
  auto toBody = [](double co, double si, const Vec2d& p) { return Vec2d(co * p.x() + si * p.y(), -si * p.x() + co * p.y()); };
  // A particle body k has just put at x (local) with world normal n: a dynamic body's contact
  // is solved below with its other contacts; a kinematic one carries the particle along.
  auto settle = [&](std::size_t i, std::size_t k, const Vec2d& x, const Vec2d& n) {
    const MovingSolid& m = bodies[k];
    if (m.dynamic()) {
      hitBody[i] = std::int32_t(k);
      hitNormal[i] = n;
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
        auto toLocal = [&](const Vec2d& p) { return q.o1 + Vec2d(q.c1 * p.x() - q.s1 * p.y(), q.s1 * p.x() + q.c1 * p.y()); };
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
                if (!intoStatic(xw + tw)) x = xw + tw;
                else if (!intoStatic(xw - tw)) x = xw - tw;
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
      auto toLocal = [&](const Vec2d& p) { return q.o1 + Vec2d(q.c1 * p.x() - q.s1 * p.y(), q.s1 * p.x() + q.c1 * p.y()); };
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
    moving.bodies[k].sweptTheta = poses[k].theta1;
    moving.bodies[k].sweptOrigin = poses[k].o1;
  }
  if (!anyDynamic) return;
  // The dynamic bodies' contacts, in slot order: count each body's approaching contacts,
  // then solve each as inelastic with the body's mass split among them.
  std::vector<int>& count = contactCount;
  count.assign(bodies.size(), 0);
  auto approach = [&](std::size_t i, Vec2d& r, double& vn) {
    const MovingSolid& m = bodies[std::size_t(hitBody[i])];
    const Vec2d x(c.P.x[i].x(), c.P.x[i].y());
    r = x - m.centreAt(tau1);
    vn = (Vec2d(c.P.v[i].x(), c.P.v[i].y()) - m.velocityAt(tau1, x)).dot(hitNormal[i]);
    return vn < 0;
  };
  for (std::size_t i = 0; i < c.P.size(); ++i) {
    Vec2d r;
    double vn;
    if (hitBody[i] >= 0 && approach(i, r, vn)) ++count[std::size_t(hitBody[i])];
  }
  std::vector<Vec2d>& J = contactImpulse;
  std::vector<double>& L = contactTorque;
  J.assign(bodies.size(), Vec2d(0, 0));
  L.assign(bodies.size(), 0.0);
  const double m0 = double(c.mass);
  for (std::size_t i = 0; i < c.P.size(); ++i) {
    Vec2d r;
    double vn;
    if (hitBody[i] < 0 || !approach(i, r, vn)) continue;
    const std::size_t k = std::size_t(hitBody[i]);
    const MovingSolid& m = bodies[k];
    const Vec2d& n = hitNormal[i];
    const double rn = r.x() * n.y() - r.y() * n.x();
    const double invMeff = m.invMass + rn * rn * m.invInertia;
    const double j = -vn / (1.0 / m0 + double(count[k]) * invMeff);  // > 0, along n for the particle
    c.P.v[i] += (j / m0 * n).cast<Real>();
    J[k] -= j * n;
    L[k] -= j * rn;
  }
  for (std::size_t k = 0; k < bodies.size(); ++k)
    if (count[k] > 0) moving.bodies[k].push(tau1, J[k], L[k]);
}

std::vector<Collider> World::movingColliders() const {
  const Impl& w = *impl_;
  std::vector<Collider> out;
  for (const MovingSolid& m : w.moving.bodies) {
    double theta;
    Vec2d o;
    m.pose(w.time - w.moving.time0, theta, o);
    for (Collider c : m.shapes) {
      auto place = [&](const Vec2& p) {
        const Vec2d q = o + rot(theta, Vec2d(p.x(), p.y()));
        return Vec2(Real(q.x()), Real(q.y()));
      };
      for (Vec2& p : c.vertices) p = place(p);
      for (Vec2& n : c.normals) {
        const Vec2d q = rot(theta, Vec2d(n.x(), n.y()));
        n = Vec2(Real(q.x()), Real(q.y()));
      }
      if (c.kind == Collider::Kind::Circle) c.center = place(c.center);
      c.lo = c.hi = c.kind == Collider::Kind::Circle ? c.center : c.vertices[0];
      for (const Vec2& p : c.vertices) {
        c.lo = c.lo.cwiseMin(p);
        c.hi = c.hi.cwiseMax(p);
      }
      if (c.kind == Collider::Kind::Circle) {
        c.lo -= Vec2(c.radius, c.radius);
        c.hi += Vec2(c.radius, c.radius);
      }
      out.push_back(std::move(c));
    }
  }
  return out;
}

bool World::Impl::nearMovingSamples(const Vec2& p) const {
  if (!bodySamplesOn()) return false;
  const double tau = time - moving.time0, limit = -0.4 * double(dx);
  for (const MovingSolid& m : moving.bodies)
    if (m.depth(tau, Vec2d(p.x(), p.y())) > limit) return true;
  return false;
}

}  // namespace sph2d
