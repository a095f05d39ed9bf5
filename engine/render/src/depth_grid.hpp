// depth_grid.hpp — the liquid's coarse CPU grid: how much water each cell holds, the depth of
// water the light crosses to reach it, how full its neighbourhood is, and which tiles of the
// image the composite must shade.
//
// Design: cells of max(4 px, one particle spacing) over the extended targets, rows top-down.
// Particles are deposited cloud-in-cell (bilinear weights: no aliasing between the particle
// lattice and the cells), in id order so the sums are the same however the engine stores them.
// The depth is carried down row by row and blurred along each row (light scattered sideways,
// docs/RENDERING.md "Depth grid"); cells whose centre lies in a solid take no part in the blur.
// Everything here is plain float arithmetic in a fixed order: the same particles give the same
// grid on every machine. The liquid pass uploads `aux()` as an RG32F texture.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "sph2d/render/renderer.hpp"

namespace sph2d {

/// The coarse grid of the liquid mode (see the design note above).
class DepthGrid {
 public:
  /// Sizes the grid for targets EW × EH px and a particle spacing of `spacingPx`; returns true
  /// when the grid's size changed (the solid mask is then rebuilt at the next build()).
  bool resize(int EW, int EH, double spacingPx);
  /// The solids or the camera changed: rebuild the solid mask at the next build().
  void solidsChanged() { solidsStale_ = true; }
  /// Deposits the particles of `in` (slots `order`, weights `weight` in that order) and computes
  /// the depth above and the local fill of every cell. `ext` is the targets' world rectangle.
  void build(const RenderInput& in, const std::vector<double>& ext, double pxPerM,
             const std::vector<std::uint32_t>& order, const std::vector<float>& weight);
  /// Two triangles (NDC of targets EW × EH) per run of cells in a row that the splat can reach:
  /// cells with water, dilated by `spriteRadiusPx` plus one pixel for the gradient taps.
  /// Returns the target rows [first, last) the tiles cover (first = last: none).
  std::pair<int, int> tiles(float spriteRadiusPx, int EW, int EH, std::vector<float>& out);

  int width() const { return w_; }    ///< cells per row
  int height() const { return h_; }   ///< rows
  int cell() const { return cell_; }  ///< cell size [px]
  /// RG per cell, rows top-down: depth of water above [m] (scattered), local fill 0..1.
  const std::vector<float>& aux() const { return aux_; }

 private:
  void buildSolidMask(const RenderInput& in, double x0, double y1, double cellM);

  int w_ = 0, h_ = 0, cell_ = 0;
  bool solidsStale_ = true;
  std::vector<float> cover_, aux_;    // coverage per cell; RG = depth above, local fill
  std::vector<float> carry_, above_;  // one row each: depth carried down, blurred along the row
  std::vector<float> open_;           // one row: 1 where the cell is not solid
  std::vector<std::uint8_t> solid_;   // 1 where a cell's centre lies in a solid
  std::vector<std::uint8_t> active_, activeTmp_;
};

}  // namespace sph2d
