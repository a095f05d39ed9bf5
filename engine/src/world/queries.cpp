// What readers ask of a World's state: searches by region, the particles
// touching each fixture (LiquidFun's particle-body contacts), field samples,
// the state hash, density and energy statistics, memory, and the names of
// the fields, effects and stages.
#include <algorithm>
#include <cmath>

#include <box2d/b2_distance.h>
#include <box2d/box2d.h>

#include "sph2d/hash.hpp"
#include "world/world_impl.hpp"

namespace sph2d {

std::vector<std::size_t> World::slotsInRadius(const Vec2d& c, double radius) const {
  const Vec2d r(radius, radius);
  return impl_->slotsWhere(c - r, c + r,
                           [&](std::size_t i) { return (worldPosition(i) - c).squaredNorm() <= radius * radius; });
}

std::vector<std::size_t> World::slotsInBox(const Vec2d& lo, const Vec2d& hi) const {
  const RegionDef r{lo, hi};
  return impl_->slotsWhere(lo, hi, [&](std::size_t i) { return r.contains(worldPosition(i)); });
}

std::vector<std::size_t> World::slotsInShape(const b2Shape& shape, const b2Transform& xf) const {
  b2AABB box;
  box.lowerBound = box.upperBound = b2Vec2(0, 0);
  for (int c = 0; c < shape.GetChildCount(); ++c) {
    b2AABB a;
    shape.ComputeAABB(&a, xf, c);
    if (c == 0)
      box = a;
    else
      box.Combine(a);
  }
  const Vec2d lo(box.lowerBound.x, box.lowerBound.y), hi(box.upperBound.x, box.upperBound.y);
  return impl_->slotsWhere(lo, hi, [&](std::size_t i) {
    const Vec2d p = worldPosition(i);
    return shape.TestPoint(xf, b2Vec2(float(p.x()), float(p.y())));
  });
}

std::vector<std::uint32_t> World::idsTouching(const b2Fixture& fixture) const {
  const Impl& w = *impl_;
  const double reach = double(w.dx);  // the first layer of resting water sits 0.25–0.5 dx off a wall
  const b2Shape& shape = *fixture.GetShape();
  const b2Transform& xf = fixture.GetBody()->GetTransform();
  std::vector<std::uint32_t> ids;
  for (int child = 0; child < shape.GetChildCount(); ++child) {
    b2AABB box;
    shape.ComputeAABB(&box, xf, child);
    const Vec2d lo(box.lowerBound.x - reach, box.lowerBound.y - reach),
        hi(box.upperBound.x + reach, box.upperBound.y + reach);
    b2DistanceProxy part;
    part.Set(&shape, child);
    // Distances are to the core shape, less the radius the fluid meets it at: a circle's own, a
    // moving body's polygon's skin (b2_polygonRadius: moving_bodies.cpp) unless the solver
    // samples moving bodies and meets their fixtures; a static body's polygons, edges and
    // chains are seen without their skin.
    const bool skinned = shape.GetType() == b2Shape::e_polygon && fixture.GetBody()->GetType() != b2_staticBody &&
                         !w.solver->movingSamples();
    const double radius = shape.GetType() == b2Shape::e_circle || skinned ? double(shape.m_radius) : 0.0;
    const std::vector<std::size_t> near = w.slotsWhere(lo, hi, [&](std::size_t i) {
      const Vec2d p = worldPosition(i);
      const b2Vec2 q(float(p.x()), float(p.y()));
      b2DistanceProxy point;
      point.m_vertices = &q;
      point.m_count = 1;
      point.m_radius = 0;
      b2DistanceInput in;
      in.proxyA = part;
      in.proxyB = point;
      in.transformA = xf;
      in.transformB.SetIdentity();
      in.useRadii = false;
      b2SimplexCache cache;
      cache.count = 0;
      b2DistanceOutput out;
      b2Distance(&out, &cache, &in);
      return double(out.distance) - radius <= reach;
    });
    for (const std::size_t i : near) ids.push_back(w.P.id[i]);
  }
  // With contact tracking, also those that touched it at the end of a substep of the last
  // step (and are still there: not removed since).
  const bool merged = w.contacts.forFixture(&fixture, [&](std::uint32_t id) {
    if (slotOf(id) != npos) ids.push_back(id);
  });
  if (shape.GetChildCount() > 1 ||
      merged) {  // a particle found twice (two links, or now and before) once, in slot order
    std::vector<std::pair<std::size_t, std::uint32_t>> bySlot;
    for (const std::uint32_t id : ids) bySlot.push_back({slotOf(id), id});
    std::sort(bySlot.begin(), bySlot.end());
    bySlot.erase(std::unique(bySlot.begin(), bySlot.end()), bySlot.end());
    ids.clear();
    for (const auto& s : bySlot) ids.push_back(s.second);
  }
  return ids;
}

void World::forEachContact(const std::function<void(const b2Fixture&, const std::vector<std::uint32_t>&)>& f) const {
  const b2World& b2 = box2d();
  for (const b2Body* body = b2.GetBodyList(); body; body = body->GetNext())
    for (const b2Fixture* fx = body->GetFixtureList(); fx; fx = fx->GetNext()) {
      const std::vector<std::uint32_t> ids = idsTouching(*fx);
      if (!ids.empty()) f(*fx, ids);
    }
}

World::FieldSample World::sampleAt(const Vec2d& point) const {
  const Impl& w = *impl_;
  const WendlandC2<double> W(double(w.R));
  FieldSample s;
  double rho = 0;
  Vec2d vel(0, 0);
  // The particles within R, summed in slot order (the same sum as a scan of every particle).
  const Vec2d reach(W.R, W.R);
  const std::vector<Real>* ratio = w.P.find(ParticleStore::kRestRatio);  // m_j = r_j m with a density contrast
  for (const std::size_t i : w.slotsWhere(point - reach, point + reach, [](std::size_t) { return true; })) {
    const double r = (worldPosition(i) - point).norm();
    if (r >= W.R) continue;
    const double mj = ratio ? double(w.mass) * double((*ratio)[i]) : double(w.mass);
    const double wv = W.value(r) * mj / double(w.P.rho[i]);  // V_j W
    s.weight += wv;
    rho += wv * double(w.P.rho[i]);
    vel += wv * Vec2d(w.P.v[i].x(), w.P.v[i].y());
  }
  if (s.weight > 0) {
    s.density = rho / s.weight;
    s.velocity = vel / s.weight;
  }
  return s;
}

std::uint64_t World::stateHash() const {
  const ParticleStore& P = impl_->P;
  std::vector<std::uint32_t> slotOf(impl_->nextId, 0xffffffffu);
  for (std::size_t i = 0; i < P.size(); ++i) slotOf[P.id[i]] = std::uint32_t(i);
  // With more than one material, each particle's too (a World of one hashes as before materials).
  const std::vector<std::uint32_t>* material = P.findU32(ParticleStore::kMaterial);
  std::vector<const std::vector<double>*> conc;  // with mixing, the concentrations too
  for (std::size_t k = 0; P.findD(ParticleStore::concentration(k)); ++k)
    conc.push_back(P.findD(ParticleStore::concentration(k)));
  Xxh64 h;
  h.update(impl_->origin.data(), sizeof(double) * 2);
  for (std::uint32_t id = 0; id < impl_->nextId; ++id) {
    const std::uint32_t s = slotOf[id];
    if (s == 0xffffffffu) continue;
    h.update(&id, sizeof id);
    h.update(P.x[s].data(), sizeof(Real) * 2);
    h.update(P.v[s].data(), sizeof(Real) * 2);
    if (material) h.update(&(*material)[s], sizeof(std::uint32_t));
    for (const std::vector<double>* c : conc) h.update(&(*c)[s], sizeof(double));
  }
  return h.digest();
}

DensityStats World::densityStats() const {
  const ParticleStore& P = impl_->P;
  DensityStats s;
  if (P.size() == 0) return s;
  const double rho0 = impl_->scene.solver.restDensity;
  const std::vector<Real>* ratio = P.find(ParticleStore::kRestRatio);  // each material's own ρ0
  double sumErr = 0, sumRho = 0, maxErr = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    const double rho0i = ratio ? rho0 * double((*ratio)[i]) : rho0;
    const double e = std::max(0.0, (double(P.rho[i]) - rho0i) / rho0i);
    sumErr += e;
    sumRho += P.rho[i];
    maxErr = std::max(maxErr, e);
  }
  s.meanError = sumErr / double(P.size());
  s.maxError = maxErr;
  s.meanDensity = sumRho / double(P.size());
  return s;
}

double World::kineticEnergy() const {
  const ParticleStore& P = impl_->P;
  const std::vector<Real>* ratio = P.find(ParticleStore::kRestRatio);  // m_i = r_i m
  double e = 0;
  for (std::size_t i = 0; i < P.size(); ++i)
    e += 0.5 * double(impl_->momentumMass) * (ratio ? double((*ratio)[i]) : 1.0) * double(P.v[i].squaredNorm());
  return e;
}

std::vector<std::string> World::particleFields() const {
  std::vector<std::string> f;
  impl_->P.forEachField([&](const char* name, const auto&) { f.push_back(name); });
  return f;
}

std::vector<std::string> World::effects() const {
  std::vector<std::string> out;
  for (const auto& e : impl_->effects) out.push_back(e->name());
  return out;
}

std::vector<std::string> World::stages() const {
  std::vector<std::string> s;
  for (const Stage& st : impl_->stages.stages()) s.push_back(st.name);
  return s;
}

WorldProfile World::profile() const { return WorldProfile{impl_->stages.timings()}; }

void World::resetProfile() { impl_->stages.resetTimings(); }

WorldCounters World::counters() const {
  const Impl& w = *impl_;
  WorldCounters c;
  c.frames = w.frames;
  c.substeps = w.steps;
  c.lastFrameSubsteps = w.lastSubsteps;
  c.solverIterations = w.iterations;
  c.lastSolve = w.solver->stats();
  c.particles = w.P.size();
  c.neighbourPairs = w.nbr.pairs();
  c.removed = w.sources.removed;
  c.memoryBytes = w.memoryBytes();
  c.particleBytes = w.P.bytes();
  return c;
}

WallImpulse World::wallImpulse() const { return impl_->wall.sum; }

void World::resetWallImpulse() { impl_->wall.sum = WallImpulse{}; }

std::size_t World::Impl::memoryBytes() const {
  const Impl& w = *this;
  auto cap = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  std::size_t b = w.P.bytes();
  b += cap(w.grid.cellStart) + cap(w.grid.sorted) + cap(w.grid.cellOf);
  b += cap(w.nbr.start) + cap(w.nbr.count) + cap(w.nbr.boundaryStart) + cap(w.nbr.boundaryCount);
  for (const auto& v : w.nbr.perBlock) b += cap(v);
  for (const auto& v : w.nbr.boundaryPerBlock) b += cap(v);
  b += cap(w.scratch.v) + cap(w.scratch.r) + cap(w.scratch.u);
  b += cap(w.boundary.samples) + cap(w.boundary.volume) + cap(w.boundary.sideNormal) + cap(w.boundary.sideOffset);
  b += w.index.bytes();  // only once a game looked a particle up or searched
  return b;
}

}  // namespace sph2d
