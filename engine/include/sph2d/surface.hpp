// sph2d/surface.hpp — the fluid's outline as closed curves a game can use without rendering.
//
// The fluid is read as a field: the fraction of the plane its particles' squares (a spacing
// wide) cover near a point. Each particle gives its area to the four nodes around it (bilinear
// weights over a node's cell, `cell` spacings), and `smoothing` passes of the (1 2 1)/4 filter
// along each axis spread it (a B-spline kernel about a spacing wide): φ = 1 inside fluid at
// rest, 1/2 where its particles' squares end (the nodes on a half plane's edge take half a row
// before the filter, and the symmetric filter keeps that), and a lone particle of spray
// reaches at most 1/4 and makes no curve. Marching squares finds where φ crosses `level`, each
// crossing placed along its edge by linear interpolation; a saddle cell (two opposite corners
// in the fluid) is decided by the mean of its corners. Every crossing joins the next, so each
// curve is closed, and each runs with the fluid on its left: the outline of a region of fluid
// counter-clockwise (positive area), a hole in it (a bubble) clockwise (negative area).
// Deterministic: the particles are summed in their order and the filter runs row by row, so
// World::surfaceCurves, which runs the rows on the World's threads, gives the same curves on
// any thread count; the curves come in the order of their first edge on the grid (rows from
// the bottom), region by region.
#pragma once

#include <cstdint>
#include <vector>

#include "sph2d/math.hpp"

namespace sph2d {

/// How surfaceCurves() samples the fluid.
struct SurfaceOptions {
  double cell = 1;     ///< the node grid's cell, in particle spacings (1 to 4: finer cells see single particles)
  int smoothing = 1;   ///< passes of the (1 2 1)/4 filter along each axis (1 to 4)
  double level = 0.5;  ///< the covered fraction the curves follow (strictly between 0 and 1)
  /// World::surfaceCurves only: the material (an index in World::materials()) whose particles
  /// count; kAllMaterials counts every particle.
  std::uint32_t material = kAllMaterials;
  static constexpr std::uint32_t kAllMaterials = 0xFFFFFFFFu;
};

/// One closed outline.
struct SurfaceCurve {
  std::vector<Vec2d> points;  ///< in order, world coordinates [m]; the last joins the first (not repeated)
  double area = 0;            ///< enclosed area [m²]: > 0 fluid (counter-clockwise), < 0 a hole (clockwise)
  /// True for the outline of a hole in the fluid (a bubble, a pocket of air).
  bool hole() const { return area < 0; }
};

/// The outlines of the fluid made of particles at `points` (world coordinates) of spacing
/// `spacing` [m]. Particles far apart (spray across a level) are taken in regions, each with a
/// grid of its own, so a stray particle costs its region only; one region larger than
/// max(64 n, 2^16) nodes gets larger cells. Throws std::invalid_argument for a spacing that is
/// not positive, options outside their ranges, a position that is not finite, or points that
/// span more than 2^30 spacings.
std::vector<SurfaceCurve> surfaceCurves(const std::vector<Vec2d>& points, double spacing,
                                        const SurfaceOptions& options = {});

}  // namespace sph2d
