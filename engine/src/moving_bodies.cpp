// moving_bodies.cpp — the fluid against moving Box2D bodies (kinematic, and a game's
// dynamic ones): one-way coupling, bodies push the fluid. After LiquidFun's particle–
// body contacts (b2ParticleSystem::SolveCollision), in the body's own frame.
//
// At the start of each step the World reads every non-static body's pose and velocity;
// within the step a body moves with that velocity (its centre of mass along v, turning
// at ω about it: what Box2D does to a kinematic body over the step). The `bodies` stage
// runs after the static collision: a particle that ends a substep inside a body's
// polygon or circle (or within the clearance of it) is put back on the surface, through
// the face it came in by (its start position is taken in the body's frame at the
// substep's start, its end in the frame at the substep's end, so a body's own motion
// counts), and the part of its velocity into the body, relative to the body's velocity
// at that point, is removed. Particles are independent: the stage gives the same bits
// for any thread count.
//
// Not yet: the fluid's pressure on dynamic bodies (the bodies do not feel the water),
// boundary samples on moving bodies (a particle beside one sees less density), and
// moving bodies in the grid projection of the game solver.
#include <algorithm>
#include <cmath>

#include "world_impl.hpp"

namespace sph2d {
namespace {

Vec2d rot(double theta, const Vec2d& p) {
  const double c = std::cos(theta), s = std::sin(theta);
  return Vec2d(c * p.x() - s * p.y(), s * p.x() + c * p.y());
}

/// Signed distance of body-frame point b outside collider k (negative inside) and the
/// outward normal it is measured along; for a polygon, the face the particle entered by
/// when its start a was outside (else the least deep face).
double outside(const Collider& k, const Vec2d& a, const Vec2d& b, Vec2d& normal) {
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

}  // namespace

void World::Impl::MovingBody::pose(double tau, double& theta, Vec2d& o) const {
  theta = angle0 + omega * tau;
  o = com0 + v * tau - rot(theta, localCenter);
}

void World::Impl::captureBodies() {
  const bool had = !moving.empty();
  moving.clear();
  bodyTime0 = time;
  for (b2Body* body = b2->GetBodyList(); body; body = body->GetNext()) {
    if (body->GetType() == b2_staticBody) continue;
    MovingBody m;
    m.body = body;
    for (b2Fixture* fx = body->GetFixtureList(); fx; fx = fx->GetNext()) {
      const b2Shape* shape = fx->GetShape();
      Collider c;
      if (shape->GetType() == b2Shape::e_polygon) {
        const auto* poly = static_cast<const b2PolygonShape*>(shape);
        c.kind = Collider::Kind::Polygon;
        for (int i = 0; i < poly->m_count; ++i) {
          c.vertices.push_back(Vec2(poly->m_vertices[i].x, poly->m_vertices[i].y));
          c.normals.push_back(Vec2(poly->m_normals[i].x, poly->m_normals[i].y));
        }
      } else if (shape->GetType() == b2Shape::e_circle) {
        const auto* circle = static_cast<const b2CircleShape*>(shape);
        c.kind = Collider::Kind::Circle;
        c.sourceShape = Collider::SourceShape::Circle;
        c.center = Vec2(circle->m_p.x, circle->m_p.y);
        c.radius = circle->m_radius;
      } else {
        continue;  // edges and chains enclose nothing
      }
      m.shapes.push_back(std::move(c));
    }
    if (m.shapes.empty()) continue;
    const b2Vec2 com = body->GetWorldCenter(), lc = body->GetLocalCenter(), v = body->GetLinearVelocity();
    m.com0 = Vec2d(com.x, com.y) - origin;
    m.localCenter = Vec2d(lc.x, lc.y);
    m.angle0 = body->GetAngle();
    m.v = Vec2d(v.x, v.y);
    m.omega = body->GetAngularVelocity();
    for (const Collider& c : m.shapes) {
      if (c.kind == Collider::Kind::Circle)
        m.radius = std::max(m.radius, (Vec2d(c.center.x(), c.center.y()) - m.localCenter).norm() + double(c.radius));
      for (const Vec2& p : c.vertices) m.radius = std::max(m.radius, (Vec2d(p.x(), p.y()) - m.localCenter).norm());
    }
    moving.push_back(std::move(m));
  }
  if (had != !moving.empty()) buildStages();  // the `bodies` stage exists only with moving bodies
}

void World::Impl::moveOwnBodies(double dt) {
  if (!ownWorld || moving.empty() || !(dt > 0)) return;
  ownWorld->Step(float(dt), 8, 3);
}

bool World::Impl::insideMoving(const Vec2& p) const {
  const Vec2d x(p.x(), p.y());
  for (const MovingBody& m : moving) {
    double theta;
    Vec2d o;
    m.pose(time - bodyTime0, theta, o);
    const Vec2d b = rot(-theta, x - o);
    for (const Collider& c : m.shapes) {
      Vec2d n;
      if (outside(c, b, b, n) < 0) return true;
    }
  }
  return false;
}

void World::Impl::collideMoving(StepContext& c) {
  if (moving.empty()) return;
  const double tau0 = c.time - bodyTime0, tau1 = tau0 + double(c.dt), clearance = double(c.clearance);
  struct Pose {
    double theta0, theta1;
    Vec2d o0, o1, com1;
  };
  std::vector<Pose> poses(moving.size());
  for (std::size_t k = 0; k < moving.size(); ++k) {
    moving[k].pose(tau0, poses[k].theta0, poses[k].o0);
    moving[k].pose(tau1, poses[k].theta1, poses[k].o1);
    poses[k].com1 = moving[k].com0 + moving[k].v * tau1;
  }
  c.pool.parallelFor(c.P.size(), kStreamBlock, [&](std::size_t b0, std::size_t e0) {
    for (std::size_t i = b0; i < e0; ++i) {
      for (std::size_t k = 0; k < moving.size(); ++k) {
        const MovingBody& m = moving[k];
        const Pose& q = poses[k];
        const Vec2d xw(c.P.x[i].x(), c.P.x[i].y());
        if ((xw - q.com1).squaredNorm() > (m.radius + clearance) * (m.radius + clearance)) continue;
        const Vec2d a = rot(-q.theta0, Vec2d(c.P.xPrev[i].x(), c.P.xPrev[i].y()) - q.o0);
        Vec2d b = rot(-q.theta1, xw - q.o1);
        bool hit = false;
        Vec2d nb(0, 0);
        for (const Collider& s : m.shapes) {
          Vec2d n;
          const double d = outside(s, a, b, n);
          if (d >= clearance) continue;
          b += (clearance - d) * n;  // back on the surface, the clearance off it
          nb = n;
          hit = true;
        }
        if (!hit) continue;
        const Vec2d x = q.o1 + rot(q.theta1, b), n = rot(q.theta1, nb);
        const Vec2d r = x - q.com1, vb = m.v + m.omega * Vec2d(-r.y(), r.x());
        Vec2d v(c.P.v[i].x(), c.P.v[i].y());
        const double vn = (v - vb).dot(n);
        if (vn < 0) v -= vn * n;  // no velocity into the body: it carries the particle along
        c.P.x[i] = Vec2(Real(x.x()), Real(x.y()));
        c.P.v[i] = Vec2(Real(v.x()), Real(v.y()));
      }
    }
  });
}

std::vector<Collider> World::movingColliders() const {
  const Impl& w = *impl_;
  std::vector<Collider> out;
  for (const Impl::MovingBody& m : w.moving) {
    double theta;
    Vec2d o;
    m.pose(w.time - w.bodyTime0, theta, o);
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

}  // namespace sph2d
