// sph2d/foam.hpp — foam, spray and bubbles: diffuse particles a scene calls for (`effects.foam`).
//
// After Ihmsen, Akinci, Akinci and Teschner, "Unified spray, foam and air bubbles for particle-
// based fluids" (The Visual Computer 28, 2012). Each substep every liquid particle (not a grain,
// not in a group) has three potentials, each clamped to 0..1 between its scene thresholds:
// trapped air Σ_j |v_ij| (1 − v̂_ij·x̂_ij) W̃_ij (neighbours closing in on it, fast), a wave
// crest κ̃ = Σ_j (1 − n̂_i·n̂_j) W̃_ij over the neighbours behind its surface, counted only where
// it moves outward (v̂·n̂ ≥ 0.6), and its kinetic energy ½|v|² per kilogram; W̃ = 1 − r/R and n̂
// the outward normal of the surface particles. It sheds energy × (trapped air + wave crest) ×
// rate × dt diffuse particles (rounded up or down by a hash of its id and the time), placed
// within half a spacing of it, along its path in the substep, at its velocity. A diffuse particle
// is, by the liquid particles within R of it: spray (under 20 % of a full neighbourhood's count:
// ballistic under gravity), foam (20–60 %: carried at the liquid's velocity, W̃-weighted) or a
// bubble (over 60 %: pushed up by `buoyancy` × g and dragged towards the liquid's velocity at
// `drag` per second). Each lives a lifetime drawn between the scene's bounds and is removed
// the substep its age reaches it, or when its move would cross a static solid.
//
// The diffuse particles do not act on the liquid (state hashes do not see them) and are not
// saved (World::save). Determinism: each is updated from the liquid alone, new ones are made
// in the order of the liquid's slots with counts fixed before they are placed, removals keep the
// order: the same diffuse particles on any thread count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "sph2d/math.hpp"

namespace sph2d {

/// What a diffuse particle is this substep.
enum class DiffuseKind : std::uint8_t { Spray = 0, Foam = 1, Bubble = 2 };

/// A read-only view of the diffuse particles (World::diffuse()); valid until the next step.
struct DiffuseParticles {
  const Vec2* x = nullptr;            ///< position, in the World's local frame [m]
  const Vec2* v = nullptr;            ///< velocity [m/s]
  const Real* age = nullptr;          ///< time since it was made [s]
  const Real* life = nullptr;         ///< its lifetime [s]: removed the substep its age reaches it
  const DiffuseKind* kind = nullptr;  ///< spray, foam or bubble
  std::size_t n = 0;
  std::size_t size() const { return n; }
};

/// An owning copy of diffuse particles (a frame kept while the World steps on).
struct DiffuseBuffer {
  std::vector<Vec2> x, v;
  std::vector<Real> age, life;
  std::vector<DiffuseKind> kind;
  void assign(const DiffuseParticles& d) {
    x.assign(d.x, d.x + d.n);
    v.assign(d.v, d.v + d.n);
    age.assign(d.age, d.age + d.n);
    life.assign(d.life, d.life + d.n);
    kind.assign(d.kind, d.kind + d.n);
  }
  DiffuseParticles view() const { return {x.data(), v.data(), age.data(), life.data(), kind.data(), x.size()}; }
};

}  // namespace sph2d
