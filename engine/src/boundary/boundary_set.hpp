// boundary_set.hpp (internal) — what the fluid knows of the Box2D solids.
//
// Built from the static fixtures of a b2World (queried once, over the whole
// world, when the World is created): a list of Colliders in the local frame,
// a coarse bin grid over them for the per-particle broad phase, and boundary
// samples: layers of dummy particles that fill each solid to the depth of the
// kernel support (Adami, Hu & Adams 2012, "A generalized wall boundary
// condition for SPH"; sampling as in Akinci et al. 2012). Layers lie at
// depths dx/2, 3dx/2, ... below each face, so a particle half a spacing from
// a wall sees the same density as one in the bulk: no gap at the wall. Each
// sample has the volume it stands for (its share of the layer). A
// zero-thickness edge gets layers on both sides, and a particle counts only
// the layers on the far side of the edge's line.
//
// resolve() is the swept collision: a particle that crossed a surface during
// the substep (ray from its previous position) is put back on the side it
// came from, then kept `clearance` away from every surface, and never left beyond
// one (stopShort); its velocity follows the fixture's restitution and Coulomb
// friction (swept_collision.cpp; the rest here in boundary_set.cpp).
#pragma once

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/kernels.hpp"
#include "particles/neighbour_grid.hpp"
#include "sph2d/boundary.hpp"

class b2World;

namespace sph2d {

/// Fills `colliders` (each with its bounds, colliderBounds) with layers of boundary samples at
/// spacing dx down to depth `depth` (the layering and volumes described above; a sample inside
/// an earlier solid collider is left out): positions, volumes Ψ_b and, for a two-sided
/// segment's samples, the side they are visible from (BoundarySet's fields of those names).
/// BoundarySet::sample for the static solids; body_samples.cpp for each moving body, in its frame.
/// With `stop` (the World's stop flag) set, throws Interrupted (empty stage) between colliders
/// and every few thousand samples: the output is then incomplete.
void sampleColliders(const std::vector<Collider>& colliders, Real dx, Real depth, std::vector<Vec2>& samples,
                     std::vector<Real>& volume, std::vector<Vec2>& sideNormal, std::vector<Real>& sideOffset,
                     const std::atomic<bool>* stop = nullptr);

/// Sets c.lo and c.hi, the bounds of a polygon's vertices or of a circle.
void colliderBounds(Collider& c);

/// How far p lies outside collider c (≤ 0 inside a polygon or circle): a polygon's largest
/// face separation (the distance, except off a corner, where it is less), a circle's distance
/// from its rim, a segment's distance from p.
Real colliderSeparation(const Collider& c, const Vec2& p);

struct BoundarySet {
  std::vector<Collider> colliders;
  std::vector<const void*> colliderFixture;  ///< the b2Fixture each collider came from (collect)
  std::vector<Vec2> samples;                 ///< boundary sample positions (local frame)
  std::vector<Real> volume;                  ///< Ψ_b [m²]: the area the sample stands for
  /// For samples of a two-sided segment: the segment's unit normal n and offset
  /// c (n·x = c), signed so that the sample is on the negative side. A particle
  /// counts the sample only when n·x_i − c > 0. Zero normal for solid samples.
  std::vector<Vec2> sideNormal;
  std::vector<Real> sideOffset;
  Grid sampleGrid;
  /// Per cell of sampleGrid: 1 when a cell of the (2·reach + 1)² block around it holds a
  /// sample (noSamplesNear's map).
  std::vector<std::uint8_t> sampleNear;

  /// True when sampleGrid.forCandidates(x, f) would call f for nothing: no cell it visits
  /// around x holds a sample (the same cell of x as the query's, no periodic axis).
  bool noSamplesNear(const Vec2& x) const {
    const Grid& g = sampleGrid;
    if (g.wrapX || g.wrapY || sampleNear.size() != std::size_t(g.nx) * std::size_t(g.ny)) return false;
    const int cx = Grid::coord(x.x(), g.lo.x(), g.invCell, g.nx), cy = Grid::coord(x.y(), g.lo.y(), g.invCellY, g.ny);
    return sampleNear[std::size_t(cy) * std::size_t(g.nx) + std::size_t(cx)] == 0;
  }

  /// True when sample k is visible from position x (always, unless it belongs to a segment's far side).
  bool visible(std::size_t k, const Vec2& x) const {
    const Vec2& n = sideNormal[k];
    return (n.x() == 0 && n.y() == 0) || n.dot(x) - sideOffset[k] > 0;
  }

  // Broad phase over colliders.
  Vec2 binLo = Vec2::Zero();
  Real binSize = 1, invBin = 1;
  int bnx = 0, bny = 0;
  std::vector<std::uint32_t> binStart, binItems;
  /// clearOf's map: cells of a quarter bin over the colliders' bounds widened by two cells on
  /// every side (nearNx × nearNy from nearLo), a cell 1 when some collider's bounding box
  /// touches the 3×3 cells around it (closed, with a margin).
  std::vector<std::uint8_t> nearMap;
  Vec2 nearLo = Vec2::Zero();
  Real nearInv = 1;
  int nearNx = 0, nearNy = 0;

  /// True when resolve(x, v, xOld, clearance) provably finds no candidate collider (and so
  /// changes nothing and returns false). When the move plus the clearance is at most half a
  /// cell of nearMap, resolve's swept box lies in the 3×3 cells around x's cell, and x's cell
  /// is unmarked: no collider's bounding box touches them. A longer move (the swept box over
  /// at most kClearSpan cells a side): every cell the box covers is unmarked. False means
  /// "call resolve" (also for positions off the map and non-finite ones).
  bool clearOf(const Vec2& x, const Vec2& xOld, Real clearance) const {
    if (bnx == 0) return true;  // resolve's own first test
    const Real d = std::max(std::abs(x.x() - xOld.x()), std::abs(x.y() - xOld.y())) + clearance;
    if (d * nearInv <= Real(0.5)) {
      const Real tx = (x.x() - nearLo.x()) * nearInv, ty = (x.y() - nearLo.y()) * nearInv;
      if (!(tx >= 0 && tx < Real(nearNx) && ty >= 0 && ty < Real(nearNy))) return false;
      return nearMap[std::size_t(ty) * std::size_t(nearNx) + std::size_t(tx)] == 0;
    }
    // resolve's swept box, in cells (a cell's neighbours are unmarked too, so a box whose
    // corner's cell is off by one through rounding is still covered).
    const Real lx = (std::min(x.x(), xOld.x()) - clearance - nearLo.x()) * nearInv;
    const Real hx = (std::max(x.x(), xOld.x()) + clearance - nearLo.x()) * nearInv;
    const Real ly = (std::min(x.y(), xOld.y()) - clearance - nearLo.y()) * nearInv;
    const Real hy = (std::max(x.y(), xOld.y()) + clearance - nearLo.y()) * nearInv;
    if (!(lx >= 0 && ly >= 0 && hx < Real(nearNx) && hy < Real(nearNy))) return false;  // off the map, or not finite
    const int x0 = int(lx), x1 = int(hx), y0 = int(ly), y1 = int(hy);
    if (x1 - x0 >= kClearSpan || y1 - y0 >= kClearSpan) return false;
    for (int cy = y0; cy <= y1; ++cy)
      for (int cx = x0; cx <= x1; ++cx)
        if (nearMap[std::size_t(cy) * std::size_t(nearNx) + std::size_t(cx)]) return false;
    return true;
  }
  /// The longest swept box clearOf tests cell by cell, in its cells a side (longer: resolve).
  static constexpr int kClearSpan = 4;

  /// The colliders whose bounding box meets the box [lo, hi], each once, into out[0, cap)
  /// in bin order (the bins the box covers): returns how many. `overflow` is set when more
  /// than cap meet it (those are left out). No bin for a non-finite box: 0.
  std::size_t collidersMeeting(const Vec2& lo, const Vec2& hi, std::uint32_t* out, std::size_t cap,
                               bool& overflow) const;
  /// Calls f(k) once for every collider k whose bounding box, grown by `reach`, holds x.
  template <class F>
  void forCollidersNear(const Vec2& x, Real reach, F&& f) const {
    std::uint32_t ids[64];
    bool overflow = false;
    const Vec2 lo = x - Vec2(reach, reach), hi = x + Vec2(reach, reach);
    const std::size_t n = collidersMeeting(lo, hi, ids, 64, overflow);
    for (std::size_t q = 0; q < n; ++q) f(ids[q]);
    if (!overflow) return;
    for (std::uint32_t k = 0; k < colliders.size(); ++k) {  // more than 64 (a dense level): the rest, by a scan
      const Collider& c = colliders[k];
      if (c.hi.x() < lo.x() || c.hi.y() < lo.y() || c.lo.x() > hi.x() || c.lo.y() > hi.y()) continue;
      if (std::find(ids, ids + n, k) == ids + n) f(k);
    }
  }
  /// Collects every static fixture of `world` as colliders in the frame shifted by −origin,
  /// the bodies in `skip` left out.
  void collect(b2World& world, const Vec2d& origin, const std::vector<const void*>& skip = {});
  /// Fills every collider with layers of samples at spacing dx down to depth `depth`.
  void sample(Real dx, Real depth, ThreadPool& pool, const std::atomic<bool>* stop = nullptr);
  /// Builds the collider bins.
  void buildBins(Real binSizeHint);
  /// Depth of p inside any solid collider (polygon or circle); ≤ 0 when outside all.
  Real insideDepth(const Vec2& p) const;
  /// True when the segment a → b crosses a solid's surface or an end lies inside a
  /// solid (a coarse grid's face between two cell centres is then closed).
  bool blocks(const Vec2& a, const Vec2& b) const;
  /// Swept collision of one particle (x, v) that moved from xOld. Returns true on contact.
  bool resolve(Vec2& x, Vec2& v, const Vec2& xOld, Real clearance) const;
  /// resolve()'s last step: x, once corrected, must be reachable from xOld without crossing a
  /// surface; at the first crossing it stops short of it (and v loses the speed into it).
  void stopShort(Vec2& x, Vec2& v, const Vec2& xOld, Real clearance) const;
  /// The first solid surface the path p0 → p1 crosses (colliders within `margin` of it): its
  /// point and normal (facing p0's side); nullptr when it crosses none.
  const Collider* firstCrossing(const Vec2& p0, const Vec2& p1, Real margin, Vec2& hit, Vec2& n) const;
};

}  // namespace sph2d
