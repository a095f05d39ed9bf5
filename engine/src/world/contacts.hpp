// contacts.hpp (internal) — contact tracking (World::setContactTracking): the `contacts` stage
// and the record it keeps of which particles touched which fixture during a step.
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "bodies/moving_solid.hpp"
#include "boundary/boundary_set.hpp"
#include "particles/particle_store.hpp"
#include "step/step_context.hpp"

namespace sph2d {

/// The World's contact listener for the fluid: off until a game turns it on, and then the
/// `contacts` stage records, at the end of every substep, the particles within `reach` of
/// each fixture (contacts.cpp). Owns its record and the stage's scratch.
class ContactTracker {
 public:
  using Contact = std::pair<std::uintptr_t, std::uint32_t>;  ///< (fixture address, particle id)

  /// True while the `contacts` stage runs.
  bool on() const { return on_; }
  /// Turns the stage on or off, clearing the record; false when it already was.
  bool setOn(bool on) {
    if (on_ == on) return false;
    on_ = on;
    record_.clear();
    return true;
  }
  /// Clears the record at a step's start (the record is the step's).
  void beginStep() { record_.clear(); }
  /// The `contacts` stage: the particles within `reach` of each static collider and moving
  /// body at the substep's end, appended to the record.
  void record(StepContext& c, const ParticleStore& P, const BoundarySet& boundary, const MovingSolids& moving,
              Real reach);
  /// After a step: the record sorted by fixture, then id, without repeats.
  void finishStep();
  /// Calls f(id) for every particle the record has for `fixture`, in increasing id order;
  /// returns true when there was one.
  template <class F>
  bool forFixture(const void* fixture, F&& f) const {
    const auto key = std::uintptr_t(fixture);
    const auto b = std::lower_bound(record_.begin(), record_.end(), Contact{key, 0});
    const auto e = std::upper_bound(b, record_.end(), Contact{key, 0xffffffffu});
    for (auto it = b; it != e; ++it) f(it->second);
    return b != e;
  }

 private:
  /// A moving body as the stage sees it: its pose and centre at the substep's end.
  struct Pose {
    double theta = 0;
    Vec2d o{0, 0}, centre{0, 0};
  };
  bool on_ = false;
  std::vector<Contact> record_;               ///< this step's contacts (sorted after finishStep)
  std::vector<std::vector<Contact>> blocks_;  ///< the stage's per-block scratch
  std::vector<Pose> poses_;                   ///< the stage's scratch, one per moving body
};

}  // namespace sph2d
