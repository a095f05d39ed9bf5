// test_util.hpp — helpers shared by the tests: scene paths and small probes.
#pragma once

#include <string>

#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace sph2d::test {

/// Absolute path of a file under assets/.
inline std::string asset(const std::string& rel) { return std::string(SPH2D_ASSETS) + "/" + rel; }

/// Loads a scene under assets/scenes/.
inline SceneDef scene(const std::string& rel) { return loadScene(asset("scenes/" + rel)); }

/// True when every position, velocity and density is finite.
inline bool allFiniteState(const World& w) {
  const Particles& P = w.particles();
  for (std::size_t i = 0; i < P.size(); ++i)
    if (!allFinite(P.x[i]) || !allFinite(P.v[i]) || !std::isfinite(P.rho[i])) return false;
  return true;
}

}  // namespace sph2d::test
