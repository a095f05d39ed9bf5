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
// wcsph, muller2003) the fixtures themselves, which its samples stand for. Box2D rests a polygon on another at about
// two skins less the slop, core to core: seen without its skin, a crate on the floor left a 1.5 cm gap that the fluid
// entered and was squeezed in. Everything that reads a body's shape (the collision below, the grid's body cells and
// faces, its reach, movingColliders() for drawing) reads these; the body's area and centroid are its fixtures' (below).
// Static bodies' shapes stay cores (boundary_set.cpp; their skins would move every tank's walls and water level): a
// skinned crate resting on a core floor leaves 0.5 cm, room for a particle kept the clearance (0.25 spacing) off both
// only at a spacing of 1 cm or less, and then for one layer, which is not squeezed. Box2D's mass is the core's, and so
// is the area the grid's buoyancy is scaled to (shapeMoments of the cores): the skin keeps water out without making a
// body lighter than its density says (density 1000 stays neutral). Per substep:
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
    const Vec2d p = v + r / (1.0 + na.dot(nb)) * (na + nb);  // on both moved faces: nₐ·(p − v) = n_b·(p − v) = r
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
  const bool had = !moving.solids.bodies.empty(), hadDynamic = moving.solids.anyDynamic();
  moving.solids.bodies.clear();
  moving.solids.time0 = time;
  const b2Vec2 g = b2->GetGravity();
  // A solver that samples the moving bodies (Solver::movingSamples: wcsph, muller2003) meets
  // them at their fixtures, as its samples stand for them: their pressure keeps the water out
  // of the gaps Box2D leaves, as at a static wall. The others meet a polygon at its skin.
  const bool skinned = !(solver && solver->movingSamples());
  for (b2Body* body = b2->GetBodyList(); body; body = body->GetNext()) {
    // A static body the game slid moves as a kinematic one through the step (box2d_bridge.cpp).
    const StaticBridge::Sliding* slide = statics.slidingOf(body);
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
    for (const MovingSolids::LastPose& l : moving.solids.last)
      if (m.dynamic() && l.body == body && (l.origin - m.sweptOrigin).norm() <= m.radius) {
        m.sweptTheta = l.theta;
        m.sweptOrigin = l.origin;
      }
    if (m.dynamic()) holdBody(m);
    moving.solids.bodies.push_back(std::move(m));
  }
  // The `bodies` stage exists only with moving bodies, `body_gravity` and `body_walls` only with a dynamic one.
  if (had != !moving.solids.bodies.empty() || hadDynamic != moving.solids.anyDynamic()) buildStages();
}

// An impulse at most this in each component [N·s per metre of depth] is none: the fluid did not
// touch the body, and applying it would wake a sleeping body for nothing.
constexpr double kNegligibleImpulse = 1e-12;

void World::Impl::moveOwnBodies(double dt) {
  moving.solids.last.clear();
  for (const MovingSolid& m : moving.solids.bodies) moving.solids.last.push_back({m.body, m.sweptTheta, m.sweptOrigin});
  for (const MovingSolid& m : moving.solids.bodies) {
    const bool noImpulse =
        std::abs(m.impulse.x()) <= kNegligibleImpulse && std::abs(m.impulse.y()) <= kNegligibleImpulse;
    if (!m.dynamic() || (noImpulse && m.angularImpulse == 0)) continue;
    m.body->ApplyLinearImpulse(b2Vec2(float(m.impulse.x()), float(m.impulse.y())), m.body->GetWorldCenter(), true);
    m.body->ApplyAngularImpulse(float(m.angularImpulse), true);
  }
  if (!ownWorld || moving.solids.bodies.empty() || !(dt > 0)) return;
  ownWorld->Step(float(dt), 8, 3);
}

bool World::Impl::insideMoving(const Vec2& p) const {
  return solidAt(moving.solids, time - moving.solids.time0, Vec2d(p.x(), p.y())) >= 0;
}

void World::Impl::bodyGravity(StepContext& c) {
  const double tau0 = c.time - moving.solids.time0;
  for (MovingSolid& m : moving.solids.bodies)
    if (m.dynamic()) m.changeVelocityResting(tau0, m.gravity * double(c.dt), 0);
}

std::vector<Collider> World::movingColliders() const {
  const Impl& w = *impl_;
  std::vector<Collider> out;
  for (const MovingSolid& m : w.moving.solids.bodies) {
    double theta;
    Vec2d o;
    m.pose(w.time - w.moving.solids.time0, theta, o);
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
  const double tau = time - moving.solids.time0, limit = -0.4 * double(dx);
  for (const MovingSolid& m : moving.solids.bodies)
    if (m.depth(tau, Vec2d(p.x(), p.y())) > limit) return true;
  return false;
}

}  // namespace sph2d
