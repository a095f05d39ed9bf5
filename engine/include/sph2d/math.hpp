// sph2d/math.hpp — scalar and vector types of the engine.
//
// Hot particle data is single precision (Real = float): a 2D step is memory
// bound, and float halves the bytes per particle. Positions are stored
// relative to World::origin() (a double offset), so a scene 10 km from the
// world origin keeps the precision of one near it.
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace sph2d {

/// Scalar of the per-particle arrays.
using Real = float;
/// 2D vector of Real (Eigen fixed size, no alignment requirement).
using Vec2 = Eigen::Matrix<Real, 2, 1, Eigen::DontAlign>;
/// 2D vector of double, for world coordinates and scene definitions.
using Vec2d = Eigen::Matrix<double, 2, 1, Eigen::DontAlign>;

/// Pi in the requested precision.
template <class T>
constexpr T kPi = T(3.14159265358979323846264338327950288);

/// True when every component of v is finite.
template <class V>
inline bool allFinite(const V& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y());
}

}  // namespace sph2d
