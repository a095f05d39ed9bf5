// The bridge between the fluid and Box2D: the scene's bodies built in
// a real b2World, and the colliders and boundary samples read back from any
// b2World (the scene's or a game's), again whenever its static fixtures change. A static
// body the game slides (SetTransform each frame) is a kinematic body while it moves, so it
// pushes the water as a paddle does (moving_bodies.cpp), and a static solid again once it stops.
#include "core/constants.hpp"
#include "sph2d/hash.hpp"
#include "world/world_impl.hpp"

namespace sph2d {

namespace {

b2Vec2 bv(const Vec2d& v) { return b2Vec2(float(v.x()), float(v.y())); }

/// Builds one body of the scene (static; kinematic with its velocity; dynamic with its
/// initial velocity and its fixtures' density) with its fixtures.
void addBody(b2World& world, const BodyDef& def) {
  b2BodyDef bd;
  bd.type = def.type == BodyDef::Type::Kinematic ? b2_kinematicBody
            : def.type == BodyDef::Type::Dynamic ? b2_dynamicBody
                                                 : b2_staticBody;
  bd.position = bv(def.position);
  bd.angle = float(def.angle);
  b2Body* body = world.CreateBody(&bd);
  for (const ShapeDef& s : def.fixtures) {
    b2FixtureDef fd;
    fd.friction = float(s.friction);
    fd.restitution = float(s.restitution);
    fd.density = float(s.density);
    b2PolygonShape poly;
    b2CircleShape circle;
    b2EdgeShape edge;
    b2ChainShape chain;
    std::vector<b2Vec2> pts;
    for (const Vec2d& v : s.vertices) pts.push_back(bv(v));
    switch (s.type) {
      case ShapeDef::Type::Box:
        poly.SetAsBox(float(s.halfSize.x()), float(s.halfSize.y()), bv(s.center), float(s.angle));
        fd.shape = &poly;
        break;
      case ShapeDef::Type::Polygon:
        poly.Set(pts.data(), int(pts.size()));
        fd.shape = &poly;
        break;
      case ShapeDef::Type::Circle:
        circle.m_p = bv(s.center);
        circle.m_radius = float(s.radius);
        fd.shape = &circle;
        break;
      case ShapeDef::Type::Edge:
        edge.SetTwoSided(pts[0], pts[1]);
        fd.shape = &edge;
        break;
      case ShapeDef::Type::Chain:
        if (s.loop) {
          chain.CreateLoop(pts.data(), int(pts.size()));
        } else {
          const b2Vec2 prev = pts[0] + (pts[0] - pts[1]);
          const b2Vec2 next = pts.back() + (pts.back() - pts[pts.size() - 2]);
          chain.CreateChain(pts.data(), int(pts.size()), prev, next);
        }
        fd.shape = &chain;
        break;
    }
    body->CreateFixture(&fd);
  }
  if (def.type != BodyDef::Type::Static) {
    // Box2D turns a kinematic body about its origin (it has no mass): `position`.
    body->SetLinearVelocity(bv(def.velocity));
    body->SetAngularVelocity(float(def.angularVelocity));
  }
}

}  // namespace

std::unique_ptr<b2World> makeSceneWorld(const SceneDef& scene) {
  auto world = std::make_unique<b2World>(bv(scene.gravity));
  for (const BodyDef& b : scene.bodies) addBody(*world, b);
  return world;
}

std::uint64_t StaticBridge::signature(const b2World& world) const {
  Xxh64 h;
  for (const b2Body* body = world.GetBodyList(); body; body = body->GetNext()) {
    if (body->GetType() != b2_staticBody || slidingOf(body)) continue;
    const b2Transform& xf = body->GetTransform();
    h.update(&xf, sizeof xf);
    for (const b2Fixture* f = body->GetFixtureList(); f; f = f->GetNext()) {
      const void* ptr = f;
      h.update(&ptr, sizeof ptr);
      const int type = int(f->GetType());
      h.update(&type, sizeof type);
    }
  }
  return h.digest();
}

void StaticBridge::read(BoundarySet& boundary, b2World& world, const Vec2d& origin, Real dx, Real R, ThreadPool& pool,
                        const std::atomic<bool>* stop) {
  std::vector<const void*> skip;
  for (const Sliding& s : sliding_) skip.push_back(s.body);
  signature_ = 0;  // until the samples are complete: a stop midway leaves them to be read again
  boundary.collect(world, origin, skip);
  boundary.sample(dx, R, pool, stop);
  boundary.buildBins(Real(4) * R);
  signature_ = signature(world);
  ++version_;
}

void StaticBridge::recordPoses(const b2World& world) {
  poses_.clear();
  for (const b2Body* body = world.GetBodyList(); body; body = body->GetNext())
    if (body->GetType() == b2_staticBody) poses_.emplace_back(body, body->GetTransform());
}

namespace {
/// The farthest a fixture of `body` reaches from its origin [m].
double reach(const b2Body& body) {
  double r = 0;
  for (const b2Fixture* f = body.GetFixtureList(); f; f = f->GetNext()) {
    const b2Shape* shape = f->GetShape();
    if (shape->GetType() == b2Shape::e_circle) {
      const auto* c = static_cast<const b2CircleShape*>(shape);
      r = std::max(r, double(c->m_p.Length() + c->m_radius));
    } else if (shape->GetType() == b2Shape::e_polygon) {
      const auto* p = static_cast<const b2PolygonShape*>(shape);
      for (int i = 0; i < p->m_count; ++i) r = std::max(r, double(p->m_vertices[i].Length()));
    } else if (shape->GetType() == b2Shape::e_edge) {
      const auto* e = static_cast<const b2EdgeShape*>(shape);
      r = std::max({r, double(e->m_vertex1.Length()), double(e->m_vertex2.Length())});
    } else if (shape->GetType() == b2Shape::e_chain) {
      const auto* c = static_cast<const b2ChainShape*>(shape);
      for (int i = 0; i < c->m_count; ++i) r = std::max(r, double(c->m_vertices[i].Length()));
    }
  }
  return r;
}
}  // namespace

void StaticBridge::findSliding(b2World& world, double dt, double t0) {
  sliding_.clear();
  std::size_t next = 0;  // poses_ is in the body list's order: a walk, unless the game edited the list
  for (b2Body* body = world.GetBodyList(); body; body = body->GetNext()) {
    if (body->GetType() != b2_staticBody || !(dt > 0)) continue;
    const b2Transform now = body->GetTransform();
    if (!(next < poses_.size() && poses_[next].first == body))
      for (next = 0; next < poses_.size() && poses_[next].first != body;) ++next;
    if (next == poses_.size()) continue;  // a new body
    const b2Transform was = poses_[next++].second;
    if (was.p.x == now.p.x && was.p.y == now.p.y && was.q.s == now.q.s && was.q.c == now.q.c) continue;
    const double a0 = std::atan2(double(was.q.s), double(was.q.c));
    const double turn = std::remainder(std::atan2(double(now.q.s), double(now.q.c)) - a0, 2 * kPi<double>);
    const Vec2d move(double(now.p.x) - was.p.x, double(now.p.y) - was.p.y);
    // Faster than a game slides a door: a teleport (the static solids take it where it is).
    if ((move.norm() + std::abs(turn) * reach(*body)) / dt > double(kStaticPushSpeed)) continue;
    sliding_.push_back({body, Vec2d(was.p.x, was.p.y), a0, move / dt, turn / dt, t0});
  }
}

void World::Impl::readStatics(double dt) {
  statics.findSliding(*b2, dt, time);
  if (statics.changed(*b2)) {
    readBoundary();
    dropBuried();
  }
  statics.recordPoses(*b2);
}

void World::Impl::readBoundary() { statics.read(boundary, *b2, origin, dx, R, pool, stop); }

void World::Impl::dropBuried() {
  // Particles a new solid buries (a body the game added, or teleported) are dropped: pushing
  // them out stacks them on its faces, and the solver then threw some at 50–100 m/s.
  sources.dead.assign(P.size(), 0);
  std::size_t n = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    sources.dead[i] = boundary.insideDepth(P.x[i]) > 0;
    n += sources.dead[i];
  }
  if (n) {
    removeFlagged(RemovalReason::solid);
    warnings.push_back("dropped " + std::to_string(n) + " particles now inside solids (the level changed at frame " +
                       std::to_string(frames) + ")");
  }
}

void World::refreshBoundaries() {
  Impl& w = *impl_;
  w.statics.stopSliding();
  w.readBoundary();
  w.dropBuried();
  w.statics.recordPoses(*w.b2);
  w.deliverRemovals();
}

}  // namespace sph2d
