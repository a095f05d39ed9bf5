// sph2d/world_b2vec2.hpp — World's b2Vec2 overloads, each a conversion around the Vec2d call
// of the same name (declared in world.hpp, which includes this file at its end). Positions
// come back as floats of the double world positions.
#pragma once

#include <vector>

#include "sph2d/world.hpp"

namespace sph2d {

template <class B2, World::IfB2<B2>>
inline void World::setGravity(const B2& g) {
  setGravity(Vec2d(g.x, g.y));
}

template <class B2, World::IfB2<B2>>
inline IdRange World::addDrop(const B2& center, double radius, const B2& velocity, std::uint32_t material) {
  return addDrop(Vec2d(center.x, center.y), radius, Vec2d(velocity.x, velocity.y), material);
}

template <class B2, World::IfB2<B2>>
inline IdRange World::addDrop(const B2& center, double radius) {
  return addDrop(Vec2d(center.x, center.y), radius);
}

template <class B2, World::IfB2<B2>>
inline B2 World::worldPosition(std::size_t i) const {
  const Vec2d p = worldPosition(i);
  return B2(float(p.x()), float(p.y()));
}

template <class B2, World::IfB2<B2>>
inline bool World::getParticle(std::uint32_t id, B2& position, B2& velocity) const {
  Vec2d p, v;
  if (!getParticle(id, p, v)) return false;
  position.Set(float(p.x()), float(p.y()));
  velocity.Set(float(v.x()), float(v.y()));
  return true;
}

template <class B2, World::IfB2<B2>>
inline bool World::setParticle(std::uint32_t id, const B2& position, const B2& velocity) {
  return setParticle(id, Vec2d(position.x, position.y), Vec2d(velocity.x, velocity.y));
}

template <class B2, World::IfB2<B2>>
inline bool World::setParticleVelocity(std::uint32_t id, const B2& velocity) {
  return setParticleVelocity(id, Vec2d(velocity.x, velocity.y));
}

template <class B2, World::IfB2<B2>>
inline IdRange World::addParticles(const std::vector<B2>& points, const std::vector<B2>& velocities,
                                   std::uint32_t material) {
  return addParticles(toVec2d(points), toVec2d(velocities), material);
}

template <class B2, World::IfB2<B2>>
inline IdRange World::addParticles(const std::vector<B2>& points) {
  return addParticles(toVec2d(points));
}

template <class B2, World::IfB2<B2>>
inline std::vector<std::size_t> World::slotsInRadius(const B2& center, double radius) const {
  return slotsInRadius(Vec2d(center.x, center.y), radius);
}

template <class B2, World::IfB2<B2>>
inline std::vector<std::size_t> World::slotsInBox(const B2& lo, const B2& hi) const {
  return slotsInBox(Vec2d(lo.x, lo.y), Vec2d(hi.x, hi.y));
}

template <class B2, World::IfB2<B2>>
inline World::FieldSample World::sampleAt(const B2& point) const {
  return sampleAt(Vec2d(point.x, point.y));
}

template <class B2, World::IfB2<B2>>
inline void World::moveEmitter(std::size_t index, const B2& position, const B2& direction) {
  moveEmitter(index, Vec2d(position.x, position.y), Vec2d(direction.x, direction.y));
}

template <class B2, World::IfB2<B2>>
inline std::vector<std::uint32_t> World::removeParticlesInBox(const B2& lo, const B2& hi) {
  return removeParticlesInBox(Vec2d(lo.x, lo.y), Vec2d(hi.x, hi.y));
}

template <class B2, World::IfB2<B2>>
inline IdRange World::addShape(const b2Shape& shape, const b2Transform& xf, const B2& velocity,
                               std::uint32_t material) {
  return addShape(shape, xf, Vec2d(velocity.x, velocity.y), material);
}

template <class B2, World::IfB2<B2>>
inline std::size_t World::setVelocities(const std::vector<std::uint32_t>& ids, const std::vector<B2>& velocities) {
  return setVelocities(ids, toVec2d(velocities));
}

template <class B2, World::IfB2<B2>>
inline std::size_t World::setPositions(const std::vector<std::uint32_t>& ids, const std::vector<B2>& positions) {
  return setPositions(ids, toVec2d(positions));
}

template <class B2, World::IfB2<B2>>
inline std::size_t World::getParticles(const std::vector<std::uint32_t>& ids, std::vector<B2>& positions,
                                       std::vector<B2>& velocities) const {
  std::vector<Vec2d> p, v;
  const std::size_t found = getParticles(ids, p, v);
  positions.resize(p.size());
  velocities.resize(v.size());
  for (std::size_t k = 0; k < p.size(); ++k) {
    positions[k].Set(float(p[k].x()), float(p[k].y()));
    velocities[k].Set(float(v[k].x()), float(v[k].y()));
  }
  return found;
}

template <class B2>
inline std::vector<Vec2d> World::toVec2d(const std::vector<B2>& in) {
  std::vector<Vec2d> out;
  out.reserve(in.size());
  for (const B2& q : in) out.emplace_back(q.x, q.y);
  return out;
}

}  // namespace sph2d
