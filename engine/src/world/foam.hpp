// world/foam.hpp (internal) — the diffuse particles of `effects.foam` (sph2d/foam.hpp): their
// arrays and the stage that moves, ages, removes and makes them (foam.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include "sph2d/foam.hpp"
#include "sph2d/scene.hpp"
#include "step/step_context.hpp"

namespace sph2d {

class FoamSystem {
 public:
  /// `granular[m]` is 1 for a granular material m (its grains shed nothing).
  FoamSystem(const FoamDef& def, std::vector<std::uint8_t> granular) : def_(def), granular_(std::move(granular)) {}
  /// The stage: the diffuse particles move and age by the liquid of `c` (its positions and
  /// velocities at the substep's end, its neighbour lists and grid), the dead are removed, and
  /// the liquid sheds new ones.
  void step(StepContext& c);
  DiffuseParticles view() const { return {x_.data(), v_.data(), age_.data(), life_.data(), kind_.data(), x_.size()}; }
  /// No diffuse particle (World::load: those of another state would not belong).
  void clear();
  /// The World's materials changed.
  void setGranular(std::vector<std::uint8_t> granular) { granular_ = std::move(granular); }

 private:
  /// True for a particle of the liquid: not in a group, not of a granular material.
  bool liquid(const std::vector<std::uint32_t>* group, const std::vector<std::uint32_t>* material, std::size_t i) const;
  void advance(StepContext& c);
  void shed(StepContext& c);

  FoamDef def_;
  std::vector<std::uint8_t> granular_;
  std::vector<Vec2> x_, v_;
  std::vector<Real> age_, life_;
  std::vector<DiffuseKind> kind_;
  std::vector<std::uint8_t> alive_;
  std::vector<Vec2> normal_;           // per liquid slot: outward unit normal, 0 off the surface
  std::vector<std::uint32_t> count_;   // per liquid slot: how many it sheds this substep
  std::vector<std::uint64_t> offset_;  // per liquid slot: where its first new one goes
};

}  // namespace sph2d
