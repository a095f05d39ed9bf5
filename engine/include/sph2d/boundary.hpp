// sph2d/boundary.hpp — the solids the fluid sees, taken from a b2World.
//
// Every static fixture becomes one or more Colliders in the engine's local
// frame (world minus World::origin()): a convex polygon (boxes and polygons),
// a circle, or a two-sided segment (edges and each segment of a chain).
#pragma once

#include <vector>

#include "sph2d/math.hpp"

namespace sph2d {

/// One solid primitive in the local frame.
struct Collider {
  /// What the primitive is.
  enum class Kind { Polygon, Circle, Segment };
  /// The Box2D shape a primitive came from (for drawing and stats: an edge and
  /// each segment of a chain are both Kind::Segment).
  enum class SourceShape {
    Polygon,  ///< a b2PolygonShape (boxes and polygons)
    Circle,   ///< a b2CircleShape
    Edge,     ///< a b2EdgeShape
    Chain,    ///< one segment of a b2ChainShape
  };
  Kind kind = Kind::Polygon;
  std::vector<Vec2> vertices;                      ///< polygon (counter-clockwise) or segment end points
  std::vector<Vec2> normals;                       ///< polygon outward face normals (normals[k] for edge k→k+1)
  Vec2 center = Vec2::Zero();                      ///< circle centre
  Real radius = 0;                                 ///< circle radius
  Real friction = 0.2f;                            ///< Coulomb friction used against the fluid
  Real restitution = 0.0f;                         ///< normal restitution used against the fluid
  Vec2 lo = Vec2::Zero();                          ///< bounding box, low corner
  Vec2 hi = Vec2::Zero();                          ///< bounding box, high corner
  SourceShape sourceShape = SourceShape::Polygon;  ///< the Box2D shape it came from
};

}  // namespace sph2d
