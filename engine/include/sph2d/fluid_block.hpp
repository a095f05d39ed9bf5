// sph2d/fluid_block.hpp — a rectangle of fluid and its initial velocity field:
// what a scene's `fluid` entries and a `block` input event both hold
// (docs/SCENES.md). scene.hpp and events.hpp include it.
#pragma once

#include "sph2d/math.hpp"

namespace sph2d {

/// An initial velocity field added to a block's uniform velocity.
struct VelocityFieldDef {
  /// None; the Taylor–Green vortex u = −U cos(kx) sin(ky), v = U sin(kx) cos(ky),
  /// k = 2π / wavelength; or a pure strain u = −s·x, v = s·y (area-preserving: a drop
  /// squeezed along x and stretched along y at rate s). x, y from the field's origin.
  enum class Type { None, TaylorGreen, Strain };
  Type type = Type::None;
  double amplitude = 1;          ///< U [m/s] (Taylor–Green)
  double wavelength = 1;         ///< L [m] (Taylor–Green)
  double rate = 0;               ///< s [1/s] (strain)
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
