// sph2d/fluid_block.hpp — a rectangle of fluid and its initial velocity field:
// what a scene's `fluid` entries and a `block` input event both hold
// (docs/SCENES.md). scene.hpp and events.hpp include it.
#pragma once

#include "sph2d/math.hpp"

namespace sph2d {

/// An initial velocity field added to a block's uniform velocity.
struct VelocityFieldDef {
  /// None, or the Taylor–Green vortex u = −U cos(kx) sin(ky), v = U sin(kx) cos(ky),
  /// k = 2π / wavelength (x, y measured from the field's origin).
  enum class Type { None, TaylorGreen };
  Type type = Type::None;
  double amplitude = 1;          ///< U [m/s]
  double wavelength = 1;         ///< L [m]
  Vec2d origin{0, 0};            ///< where x = y = 0 [m]
};

/// A rectangle of fluid filled on a square lattice.
struct FluidBlockDef {
  Vec2d min{0, 0};               ///< lower-left corner [m]
  Vec2d max{1, 1};               ///< upper-right corner [m]
  Vec2d velocity{0, 0};          ///< initial velocity [m/s]
  VelocityFieldDef field;        ///< initial velocity field added to `velocity`
};

}  // namespace sph2d
