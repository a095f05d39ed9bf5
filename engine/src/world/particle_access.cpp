// particle_access.cpp — particles by id for a game (World::slotOf, getParticle,
// setParticle, setVelocities, addParticles, removeParticles, colours, user data and the
// emitter tags),
// after LiquidFun's writable particle buffers (b2ParticleColor, user data) and
// b2ParticleHandle: slots move (the grid reorders the particles for locality,
// removals compact them), ids do not. Colour, user data and the emitter tag are optional
// integer fields (ParticleStore::extraU32), allocated by the first set (the tag: while
// emitter tracking is on).
//
// The id index is a vector of (id, slot) sorted by id, searched by bisection. It is
// never invalidated explicitly: a lookup checks that the slot it found still holds
// the id and rebuilds the index (O(n log n)) when it does not, so no stage has to
// remember to mark it stale, and a World whose game never asks holds no index.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <box2d/box2d.h>

#include "world/world_impl.hpp"

namespace sph2d {
namespace {

bool finite(const Vec2d& v) { return std::isfinite(v.x()) && std::isfinite(v.y()); }

constexpr const char* kColorField = ParticleStore::kColor;
constexpr const char* kUserDataField = ParticleStore::kUserData;

/// Writes `value` into integer field `field` (created on first use) for particle `id`.
bool setU32(World& w, ParticleStore& P, const char* field, std::uint32_t id, std::uint32_t value) {
  const std::size_t i = w.slotOf(id);
  if (i == World::npos) return false;
  P.fieldU32(field)[i] = value;
  return true;
}

/// Integer field `field` of particle `id`: 0 without the field or the particle.
std::uint32_t getU32(const World& w, const ParticleStore& P, const char* field, std::uint32_t id) {
  const std::vector<std::uint32_t>* f = P.findU32(field);
  if (!f) return 0;
  const std::size_t i = w.slotOf(id);
  return i == World::npos ? 0u : (*f)[i];
}

/// The bulk calls' argument check: as many values as ids.
template <class T>
void checkLengths(const char* call, const std::vector<std::uint32_t>& ids, const std::vector<T>& values,
                  const char* what) {
  if (ids.size() != values.size())
    throw std::invalid_argument(std::string(call) + ": " + std::to_string(ids.size()) + " ids but " +
                                std::to_string(values.size()) + " " + what);
}

/// The bulk calls' other argument check: every value finite ("<call>: every <what> must be finite").
void checkFinite(const char* call, const std::vector<Vec2d>& values, const char* what) {
  for (const Vec2d& v : values)
    if (!finite(v)) throw std::invalid_argument(std::string(call) + ": every " + what + " must be finite");
}

}  // namespace

bool World::Impl::teleport(std::size_t i, const Vec2d& position) {
  const Vec2 p(Real(position.x() - origin.x()), Real(position.y() - origin.y()));
  if (boundary.insideDepth(p) > 0) return false;
  P.x[i] = p;
  P.xPrev[i] = p;  // a teleport: the swept collision starts here, not on the old path
  return true;
}

std::size_t World::slotOf(std::uint32_t id) const { return impl_->index.slotOf(impl_->P, id); }

bool World::getParticle(std::uint32_t id, Vec2d& position, Vec2d& velocity) const {
  const std::size_t i = slotOf(id);
  if (i == npos) return false;
  position = worldPosition(i);
  velocity = Vec2d(impl_->P.v[i].x(), impl_->P.v[i].y());
  return true;
}

bool World::setParticle(std::uint32_t id, const Vec2d& position, const Vec2d& velocity) {
  if (!finite(position) || !finite(velocity))
    throw std::invalid_argument("setParticle: the position and the velocity must be finite");
  Impl& w = *impl_;
  const std::size_t i = slotOf(id);
  if (i == npos || !w.teleport(i, position)) return false;
  w.P.v[i] = Vec2(Real(velocity.x()), Real(velocity.y()));
  w.index.noteEdit();  // the query grid is stale
  w.refreshView();
  return true;
}

bool World::setParticleVelocity(std::uint32_t id, const Vec2d& velocity) {
  if (!finite(velocity)) throw std::invalid_argument("setParticleVelocity: the velocity must be finite");
  const std::size_t i = slotOf(id);
  if (i == npos) return false;
  impl_->P.v[i] = Vec2(Real(velocity.x()), Real(velocity.y()));
  return true;
}

std::size_t World::setVelocities(const std::vector<std::uint32_t>& ids, const std::vector<Vec2d>& velocities) {
  checkLengths("setVelocities", ids, velocities, "velocities");
  checkFinite("setVelocities", velocities, "velocity");
  Impl& w = *impl_;
  return w.index.forEachId(w.P, ids, [&](std::size_t k, std::size_t i) {
    w.P.v[i] = Vec2(Real(velocities[k].x()), Real(velocities[k].y()));
    return true;
  });
}

std::size_t World::getParticles(const std::vector<std::uint32_t>& ids, std::vector<Vec2d>& positions,
                                std::vector<Vec2d>& velocities) const {
  const Impl& w = *impl_;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  positions.assign(ids.size(), Vec2d(nan, nan));
  velocities.assign(ids.size(), Vec2d(nan, nan));
  return w.index.forEachId(w.P, ids, [&](std::size_t k, std::size_t i) {
    positions[k] = worldPosition(i);
    velocities[k] = Vec2d(w.P.v[i].x(), w.P.v[i].y());
    return true;
  });
}

std::size_t World::setPositions(const std::vector<std::uint32_t>& ids, const std::vector<Vec2d>& positions) {
  checkLengths("setPositions", ids, positions, "positions");
  checkFinite("setPositions", positions, "position");
  Impl& w = *impl_;
  const std::size_t moved =
      w.index.forEachId(w.P, ids, [&](std::size_t k, std::size_t i) { return w.teleport(i, positions[k]); });
  if (moved) {
    w.index.noteEdit();  // the query grid is stale
    w.refreshView();
  }
  return moved;
}

bool World::setParticleColor(std::uint32_t id, std::uint32_t rgb) {
  const bool found = setU32(*this, impl_->P, kColorField, id, rgb);
  impl_->refreshView();  // the field may be new
  return found;
}

std::size_t World::setParticleColors(const std::vector<std::uint32_t>& ids, const std::vector<std::uint32_t>& colors) {
  checkLengths("setParticleColors", ids, colors, "colours");
  Impl& w = *impl_;
  std::vector<std::uint32_t>& c = w.P.fieldU32(kColorField);
  w.refreshView();  // the field may be new
  return w.index.forEachId(w.P, ids, [&](std::size_t k, std::size_t i) {
    c[i] = colors[k];
    return true;
  });
}

std::uint32_t World::particleColor(std::uint32_t id) const { return getU32(*this, impl_->P, kColorField, id); }

bool World::setParticleUserData(std::uint32_t id, std::uint32_t value) {
  const bool found = setU32(*this, impl_->P, kUserDataField, id, value);
  impl_->refreshView();  // the field may be new
  return found;
}

std::uint32_t World::particleUserData(std::uint32_t id) const { return getU32(*this, impl_->P, kUserDataField, id); }

void World::setEmitterTracking(bool on) {
  Impl& w = *impl_;
  if (on)
    w.P.fieldU32(ParticleStore::kEmitter);  // every particle there now: none
  else
    w.P.dropU32(ParticleStore::kEmitter);
  w.refreshView();
}

bool World::emitterTracking() const { return impl_->P.findU32(ParticleStore::kEmitter) != nullptr; }

std::size_t World::particleEmitter(std::uint32_t id) const {
  const std::uint32_t tag = getU32(*this, impl_->P, ParticleStore::kEmitter, id);
  return tag == 0 ? npos : std::size_t(tag) - 1;
}

IdRange World::addParticles(const std::vector<Vec2d>& points, const std::vector<Vec2d>& velocities,
                            std::uint32_t material) {
  impl_->checkMaterial(material, "addParticles");
  if (!velocities.empty() && velocities.size() != points.size())
    throw std::invalid_argument("addParticles: " + std::to_string(points.size()) + " points but " +
                                std::to_string(velocities.size()) + " velocities");
  checkFinite("addParticles", points, "point");
  checkFinite("addParticles", velocities, "velocity");
  Impl& w = *impl_;
  const Real rho0 = Real(w.scene.solver.restDensity);
  IdRange ids;
  ids.first = w.nextId;  // each particle below takes the next id: the ones added are consecutive
  std::size_t inside = 0, refused = 0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Vec2 p(Real(points[k].x() - w.origin.x()), Real(points[k].y() - w.origin.y()));
    if (w.boundary.insideDepth(p) > 0) {
      ++inside;
      continue;
    }
    if (w.P.size() >= w.sources.budget) {
      refused = points.size() - k;
      break;
    }
    const Vec2d v = velocities.empty() ? Vec2d(0, 0) : velocities[k];
    ++ids.count;
    w.P.push(p, Vec2(Real(v.x()), Real(v.y())), w.nextId++, rho0);
  }
  w.setMaterial(w.P.size() - ids.count, material);
  w.index.noteEdit();  // the query grid is stale
  w.refreshView();
  if (inside) w.warnings.push_back("addParticles: skipped " + std::to_string(inside) + " points inside solids");
  if (refused) {
    std::ostringstream o;
    o << "particle budget of " << w.sources.budget << " (" << w.budgetKey() << ") reached: addParticles added "
      << ids.size() << " and refused the last " << refused << " points (raise " << w.budgetKey() << " or add less)";
    w.warnings.push_back(o.str());
  }
  return ids;
}

std::vector<std::uint32_t> World::removeParticles(const std::vector<std::uint32_t>& ids) {
  Impl& w = *impl_;
  std::vector<std::uint32_t> sorted(ids);
  std::sort(sorted.begin(), sorted.end());
  w.sources.dead.assign(w.P.size(), 0);
  std::size_t n = 0;
  for (std::size_t i = 0; i < w.P.size(); ++i) {
    w.sources.dead[i] = std::binary_search(sorted.begin(), sorted.end(), w.P.id[i]);
    n += w.sources.dead[i];
  }
  std::vector<std::uint32_t> removed;
  if (n) w.removeFlagged(RemovalReason::game, &removed);
  w.deliverRemovals();
  return removed;
}

std::vector<std::uint32_t> World::removeParticlesInShape(const b2Shape& shape, const b2Transform& xf) {
  const std::vector<std::size_t> in = slotsInShape(shape, xf);
  std::vector<std::uint32_t> ids;
  for (const std::size_t i : in) ids.push_back(impl_->P.id[i]);
  return removeParticles(ids);
}

IdRange World::addShape(const b2Shape& shape, const b2Transform& xf, const Vec2d& velocity, std::uint32_t material) {
  FluidBlockDef b;
  if (shape.GetType() == b2Shape::e_circle) {
    const auto& c = static_cast<const b2CircleShape&>(shape);
    const b2Vec2 p = b2Mul(xf, c.m_p);
    b = circleRegion(Vec2d(p.x, p.y), c.m_radius, impl_->scene.solver.spacing);
  } else if (shape.GetType() == b2Shape::e_polygon) {
    const auto& poly = static_cast<const b2PolygonShape&>(shape);
    std::vector<Vec2d> vertices;
    for (int k = 0; k < poly.m_count; ++k) {
      const b2Vec2 p = b2Mul(xf, poly.m_vertices[k]);
      vertices.push_back(Vec2d(p.x, p.y));
    }
    b = polygonRegion(std::move(vertices));
  } else {
    throw std::invalid_argument("addShape: only a polygon or a circle holds fluid (an edge or chain has no inside)");
  }
  b.velocity = velocity;
  b.material = material;
  return addBlock(b);
}

}  // namespace sph2d
