// The bridge between the fluid and Box2D: the scene's bodies built in
// a real b2World, and the colliders and boundary samples read back from any
// b2World (the scene's or a game's), again whenever its static fixtures change.
#include "sph2d/hash.hpp"
#include "world_impl.hpp"

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

std::uint64_t World::Impl::staticSignature() const {
  Xxh64 h;
  for (b2Body* body = b2->GetBodyList(); body; body = body->GetNext()) {
    if (body->GetType() != b2_staticBody) continue;
    const b2Transform& xf = body->GetTransform();
    h.update(&xf, sizeof xf);
    for (b2Fixture* f = body->GetFixtureList(); f; f = f->GetNext()) {
      const void* ptr = f;
      h.update(&ptr, sizeof ptr);
      const int type = int(f->GetType());
      h.update(&type, sizeof type);
    }
  }
  return h.digest();
}

void World::Impl::rebuildBoundary() {
  boundary.collect(*b2, origin);
  boundary.sample(dx, R, pool);
  boundary.buildBins(Real(4) * R);
  boundarySignature = staticSignature();
  ++boundaryVersion;  // a count, not the signature: a rebuilt fixture may reuse a freed one's address
}

void World::refreshBoundaries() {
  Impl& w = *impl_;
  w.rebuildBoundary();
  // Particles a new solid buries are dropped (pushing them out would be an explosion).
  w.dead.assign(w.P.size(), 0);
  std::size_t n = 0;
  for (std::size_t i = 0; i < w.P.size(); ++i) {
    w.dead[i] = w.boundary.insideDepth(w.P.x[i]) > 0;
    n += w.dead[i];
  }
  if (n) {
    w.removeFlagged();
    w.warnings.push_back("dropped " + std::to_string(n) + " particles now inside solids (the level changed at frame " +
                         std::to_string(w.frames) + ")");
  }
}

}  // namespace sph2d
