// sph2d/particle_events.hpp — what a game hears about single particles: why one left the
// World (the destruction listener, World::setDestructionListener) and where a ray meets one
// (World::rayCast).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "sph2d/math.hpp"

namespace sph2d {

/// Why a particle left the World.
enum class RemovalReason : std::uint8_t {
  lifetime,  ///< its own lifetime (World::setLifetimes) or the scene's `effects.lifetime` ran out
  sink,      ///< it entered a sink (`effects.sinks`)
  budget,    ///< an emitter at the particle budget removed the oldest (`effects.budget`)
  solid,     ///< a static solid now covers it (a body the game added or teleported)
  game,      ///< a game call: removeParticles, removeParticlesInBox, removeParticlesInShape
};

/// One particle that left the World, and why.
struct Removal {
  std::uint32_t id = 0;
  RemovalReason reason = RemovalReason::game;
};

/// Receives the particles removed since the last call: once after each step (stepFrame,
/// step) that removed any, and once after each game call that removed any; in the order of
/// their removals, each removal's ids increasing. It may read the World and replace or clear
/// itself, not change the World otherwise. In a step that fails (SimulationError,
/// Interrupted) it hears what left before, and an exception it throws there is dropped.
using DestructionListener = std::function<void(const std::vector<Removal>&)>;

/// Two particles touching at the end of a step: their centres less than 1.5 spacings apart (a
/// resting particle touches its nearest and diagonal neighbours on the lattice).
struct ParticleContact {
  std::uint32_t a = 0, b = 0;  ///< their ids, a < b
  bool began = false;          ///< true when they did not touch at the end of the step before
};

/// Which pairs a particle contact listener hears of: a pair whose one particle is of side A and
/// the other of side B. A side is a material (an index in World::materials()) and a group
/// (kNoGroup: in none), each kAny for any.
struct ParticleContactFilter {
  static constexpr std::uint32_t kAny = 0xffffffffu;
  static constexpr std::uint32_t kNoGroup = 0xfffffffeu;
  std::uint32_t materialA = kAny, groupA = kAny;
  std::uint32_t materialB = kAny, groupB = kAny;
};

/// Receives, once after each step, every pair the filter takes that touches then, in
/// increasing (a, b) order (none: no call). It may read the World, not change it. Pairs across
/// a periodic seam are not reported.
using ParticleContactListener = std::function<void(const std::vector<ParticleContact>&)>;

/// Where a ray p1 → p2 enters a particle's disc (radius half the spacing).
struct RayHit {
  std::uint32_t id = 0;
  Vec2d point{0, 0};    ///< where the ray enters the disc (world coordinates)
  Vec2d normal{0, 0};   ///< the disc's outward normal there (unit)
  double fraction = 0;  ///< point = p1 + fraction (p2 − p1), 0..1
};

}  // namespace sph2d
