// box2d_bridge.hpp (internal) — the static boundary bridge: what the fluid reads of the static
// bodies of a b2World (its solids and their samples), when it reads them again, and the static
// bodies a game slides between frames (box2d_bridge.cpp).
#pragma once

#include <box2d/box2d.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "boundary/boundary_set.hpp"
#include "core/thread_pool.hpp"
#include "sph2d/scene.hpp"

namespace sph2d {

/// A b2World with the scene's gravity and static bodies.
std::unique_ptr<b2World> makeSceneWorld(const SceneDef& scene);

/// Follows the static bodies of the b2World the fluid collides with. Owns its record of them:
/// their poses at the last step, the signature of the fixtures last read, and the static
/// bodies that slide through the current step.
class StaticBridge {
 public:
  /// A static body the game moved (SetTransform) since the last step, no faster than
  /// kStaticPushSpeed: through this step it moves as a kinematic body from its old pose to
  /// its new one (the water sees a moving wall), and it rejoins the static solids when it stops.
  struct Sliding {
    b2Body* body = nullptr;
    Vec2d p0{0, 0};     ///< its origin at time t0 (world)
    double angle0 = 0;  ///< its angle at t0 [rad]
    Vec2d v{0, 0};      ///< its velocity over the step [m/s]
    double omega = 0;   ///< its angular velocity over the step [rad/s]
    double t0 = 0;      ///< the step's start
  };
  /// The static bodies sliding through the current step.
  const std::vector<Sliding>& sliding() const { return sliding_; }
  /// The sliding body `body` is, or null.
  const Sliding* slidingOf(const b2Body* body) const {
    for (const Sliding& s : sliding_)
      if (s.body == body) return &s;
    return nullptr;
  }
  /// No static body slides (a re-read takes each where it is).
  void stopSliding() { sliding_.clear(); }
  /// At a step of `dt` from time `t0`: the static bodies moved since recordPoses() slowly
  /// enough to slide (none when dt is 0).
  void findSliding(b2World& world, double dt, double t0);
  /// True when the static fixtures, the sliding ones left out, differ from those last read.
  bool changed(const b2World& world) const { return signature(world) != signature_; }
  /// Reads the colliders and boundary samples of the static bodies into `boundary`, the
  /// sliding ones left out. A stop midway leaves them to be read again.
  void read(BoundarySet& boundary, b2World& world, const Vec2d& origin, Real dx, Real R, ThreadPool& pool,
            const std::atomic<bool>* stop);
  /// Records every static body's pose (the next findSliding compares with them).
  void recordPoses(const b2World& world);
  /// How many times the colliders were read (StepContext::boundaryVersion): a count, not the
  /// signature, as a rebuilt fixture may reuse a freed one's address.
  std::uint64_t version() const { return version_; }

 private:
  /// XXH64 of the static fixtures' identities and transforms, the sliding ones left out.
  std::uint64_t signature(const b2World& world) const;

  std::vector<Sliding> sliding_;
  std::vector<std::pair<const void*, b2Transform>> poses_;  ///< the static bodies' poses by body
  std::uint64_t signature_ = 0;                             ///< signature() when the colliders were last read
  std::uint64_t version_ = 0;
};

}  // namespace sph2d
