// sph2d/fluid_block.hpp — a region of fluid and its initial velocity field:
// what a scene's `fluid` entries and a `block` input event both hold
// (docs/SCENES.md). scene.hpp and events.hpp include it.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "sph2d/math.hpp"

namespace sph2d {

/// An initial velocity field added to a block's uniform velocity.
struct VelocityFieldDef {
  /// None; the Taylor–Green vortex u = −U cos(kx) sin(ky), v = U sin(kx) cos(ky),
  /// k = 2π / wavelength; a pure strain u = −s·x, v = s·y (area-preserving: a drop
  /// squeezed along x and stretched along y at rate s); or a linear field u = A·x
  /// (any gradient A: strain, shear, rotation, expansion). x, y from the field's origin.
  enum class Type { None, TaylorGreen, Strain, Linear };
  Type type = Type::None;
  double amplitude = 1;   ///< U [m/s] (Taylor–Green)
  double wavelength = 1;  ///< L [m] (Taylor–Green)
  double rate = 0;        ///< s [1/s] (strain)
  /// A [1/s] (linear), row-major: u = a[0] x + a[1] y, v = a[2] x + a[3] y.
  std::array<double, 4> gradient{0, 0, 0, 0};
  Vec2d origin{0, 0};  ///< where x = y = 0 [m]

  /// The field's velocity at world point `p` [m/s] (zero for None).
  Vec2d at(const Vec2d& p) const {
    const Vec2d q = p - origin;
    switch (type) {
      case Type::TaylorGreen: {
        const double k = 2 * 3.14159265358979323846 / wavelength;
        return Vec2d(-amplitude * std::cos(k * q.x()) * std::sin(k * q.y()),
                     amplitude * std::sin(k * q.x()) * std::cos(k * q.y()));
      }
      case Type::Strain:
        return Vec2d(-rate * q.x(), rate * q.y());
      case Type::Linear:
        return Vec2d(gradient[0] * q.x() + gradient[1] * q.y(), gradient[2] * q.x() + gradient[3] * q.y());
      case Type::None:
        break;
    }
    return Vec2d(0, 0);
  }
};

/// A region of fluid filled on a square lattice: a rectangle, or a circle or polygon
/// within the rectangle [min, max] that bounds it (the lattice is the rectangle's).
struct FluidBlockDef {
  /// What the region is inside its bounding rectangle.
  enum class Shape { Box, Circle, Polygon };
  Vec2d min{0, 0};         ///< lower-left corner [m] (of the bounding box for a circle or polygon)
  Vec2d max{1, 1};         ///< upper-right corner [m]
  Vec2d velocity{0, 0};    ///< initial velocity [m/s]
  VelocityFieldDef field;  ///< initial velocity field added to `velocity`
  Shape shape = Shape::Box;
  Vec2d center{0, 0};           ///< circle centre [m]
  double radius = 0;            ///< circle radius [m]
  std::vector<Vec2d> vertices;  ///< polygon corners [m], either orientation; filled by the even-odd rule
  std::uint32_t material = 0;   ///< what it is made of: an index in the World's materials (scene: by name)

  /// The x where the polygon's edges cross the horizontal line at `y`, ascending (empty
  /// for a box or circle). A point (x, y) is inside the polygon when an odd number of
  /// them lie right of x (> x): the even-odd rule.
  void rowCrossings(double y, std::vector<double>& xs) const {
    xs.clear();
    if (shape != Shape::Polygon) return;
    for (std::size_t i = 0, j = vertices.size() - 1; i < vertices.size(); j = i++) {
      const Vec2d& a = vertices[i];
      const Vec2d& b = vertices[j];
      if ((a.y() > y) != (b.y() > y)) xs.push_back((b.x() - a.x()) * (y - a.y()) / (b.y() - a.y()) + a.x());
    }
    std::sort(xs.begin(), xs.end());
  }
  /// True when point `p` belongs to the region (inside the circle, or the polygon by the
  /// even-odd rule; any point for a box, whose lattice is the region).
  bool contains(const Vec2d& p) const {
    if (shape == Shape::Circle) return (p - center).squaredNorm() <= radius * radius;
    if (shape == Shape::Box) return true;
    std::vector<double> xs;
    rowCrossings(p.y(), xs);
    return insideRow(xs, p.x());
  }
  /// With `xs` from rowCrossings(y): true when (x, y) is inside the polygon.
  static bool insideRow(const std::vector<double>& xs, double x) {
    const auto right = xs.end() - std::upper_bound(xs.begin(), xs.end(), x);  // crossings > x
    return (right & 1) != 0;
  }
  /// The initial velocity of a particle at `p`: `velocity` plus the field's.
  Vec2d velocityAt(const Vec2d& p) const {
    return field.type == VelocityFieldDef::Type::None ? velocity : Vec2d(velocity + field.at(p));
  }
};

/// A circle region of `radius` about `center` on the lattice of spacing `dx` (a drop's): its
/// bounding box spans whole spacings each side of the centre, and half a spacing more at the
/// top right so that the count is exact in floats.
inline FluidBlockDef circleRegion(const Vec2d& center, double radius, double dx) {
  FluidBlockDef b;
  b.shape = FluidBlockDef::Shape::Circle;
  b.center = center;
  b.radius = radius;
  const double half = std::ceil(radius / dx - 1e-9) * dx;
  b.min = center - Vec2d(half, half);
  b.max = center + Vec2d(half + 0.5 * dx, half + 0.5 * dx);
  return b;
}

/// A polygon region through `vertices` (at least one), bounded by their bounding box.
inline FluidBlockDef polygonRegion(std::vector<Vec2d> vertices) {
  FluidBlockDef b;
  b.shape = FluidBlockDef::Shape::Polygon;
  b.vertices = std::move(vertices);
  b.min = b.max = b.vertices[0];
  for (const Vec2d& v : b.vertices) {
    b.min = b.min.cwiseMin(v);
    b.max = b.max.cwiseMax(v);
  }
  return b;
}

}  // namespace sph2d
