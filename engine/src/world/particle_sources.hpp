// particle_sources.hpp (internal) — the particle system's data: the emitters with their random
// streams, the particle budget, the count of particles removed, and the removal flags the
// emit, lifetimes and sinks stages share (particle_sources.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "sph2d/scene.hpp"

namespace sph2d {

struct ParticleSources {
  /// An emitter as it runs: its settings, its random stream and its count.
  struct Emitter {
    EmitterDef def;
    std::uint64_t rng = 0;  ///< SplitMix64 state, seeded per emitter
    std::uint64_t emitted = 0;
    bool warnedBudget = false;
  };
  static constexpr std::size_t kMaxEmitters = 4096;  ///< addEmitter's and a save's limit
  /// What is wrong with an emitter built in code or read from a save, naming the field and its
  /// range (the scene format's), or "" when nothing is.
  static std::string problem(const EmitterDef& d);

  std::vector<Emitter> emitters;
  std::size_t budget = 0;           ///< the most particles the World holds
  std::uint64_t removed = 0;        ///< particles removed by lifetimes, sinks and the budget policy
  std::vector<unsigned char> dead;  ///< scratch: removal flags
};

}  // namespace sph2d
