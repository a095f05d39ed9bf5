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
  /// `liquidWeight` (when some particles add nothing to the liquid's field: grains, groups'
  /// particles): the weights of the field, which decide the deep cells (tiles()).
  void build(const RenderInput& in, const std::vector<double>& ext, double pxPerM,
             const std::vector<std::uint32_t>& order, const std::vector<float>& weight,
             const std::vector<float>* liquidWeight = nullptr);
  /// Two triangles (NDC of targets EW × EH) per run of cells in a row that the splat can reach:
  /// cells with water, dilated by `spriteRadiusPx` plus one pixel for the gradient taps. The
  /// runs of interior cells come last, from vertex `interiorFirst` on: the cells deep in the
  /// water (their neighbours as far as that reach all hold water, none solid) take the fill
  /// kDeepFill in aux(), and the interior ones are deep cells among deep cells, over which the
  /// sampled fill is kDeepFill everywhere (the composite's interior program: a flat surface).
  /// With `onlyVisible` only the cells where markVisible()'s field can show water take tiles.
  /// Call after build(), before uploading aux().
  /// Returns the target rows [first, last) the tiles cover (first = last: none).
  std::pair<int, int> tiles(float spriteRadiusPx, int EW, int EH, std::vector<float>& out, std::size_t& interiorFirst,
                            bool onlyVisible = false);
  /// Marks the cells on whose pixels the composite can draw water, from its field (`rg`: tw × th
  /// texels of Σw and Σw·speed spanning the EW × EH target, rows as the grid's; the bulk's
  /// Σw `bulk`; the gradient's taps `tapPx` away). The composite's edge is where f' − t > −g/2
  /// (shaders/composite.frag: f' the low-passed field over the bulk's, t ≥ 0.24 its threshold,
  /// g the gradient's length), and f' ≤ M, g ≤ √2·M/(2·tapPx) for M the largest field value
  /// the pixel's five bilinear samples read: water needs M > (0.24 − 0.0005)/(1 + 0.354/tapPx).
  /// A cell can when a texel above 0.98 of that lies within its pixels' samples' reach.
  void markVisible(const float* rg, int tw, int th, int EW, int EH, float tapPx, float bulk);

  int width() const { return w_; }    ///< cells per row
  int height() const { return h_; }   ///< rows
  int cell() const { return cell_; }  ///< cell size [px]
  /// RG per cell, rows top-down: depth of water above [m] (scattered), local fill 0..1
  /// (kDeepFill in the cells deep in the water, once tiles() has run).
  const std::vector<float>& aux() const { return aux_; }

 private:
  void buildSolidMask(const RenderInput& in, double x0, double y1, double cellM);
  /// `out` = the coverage of the particles `order` with weights `weight` (in that order), each
  /// cell at most 1.
  void deposit(const RenderInput& in, const std::vector<std::uint32_t>& order, const float* weight, double x0,
               double y1, double cellM, float areaShare, std::vector<float>& out) const;
  /// out[k·stride] = the 3×3 mean of `cover` around cell k.
  void localFill(const std::vector<float>& cover, float* out, std::size_t stride) const;
  /// The local fill (the 3×3 mean of the coverage) from which a cell counts as holding water
  /// throughout: a disordered bulk's, whose coverage per cell scatters by about a tenth.
  static constexpr float kFull = 0.85f;
  /// The fill a deep cell takes (a local fill is at most 1): shaders/composite.frag fades its
  /// surface shading out as the sampled fill goes from 1 to this.
  static constexpr float kDeepFill = 2.0f;

  int w_ = 0, h_ = 0, cell_ = 0;
  bool solidsStale_ = true;
  std::vector<float> cover_, aux_;               // coverage per cell; RG = depth above, local fill
  std::vector<float> liquidCover_, liquidFill_;  // the field's own coverage and fill (empty: cover_'s)
  std::vector<float> carry_, above_;             // one row each: depth carried down, blurred along the row
  std::vector<float> open_;                      // one row: 1 where the cell is not solid
  std::vector<std::uint8_t> solid_;              // 1 where a cell's centre lies in a solid
  std::vector<std::uint8_t> active_, activeTmp_, full_;
  /// Clears the set cells of grid row cy (`row`) on whose pixels markVisible()'s field cannot
  /// show water (no texel above its limit where their samples read).
  void keepVisible(std::uint8_t* row, int cy);
  struct FieldBits {
    int w = 0, h = 0;
    float sx = 1, sy = 1;  ///< texels per pixel across and down (1 or about 1/2)
    float tapPx = 1;
    int words = 0;  ///< 64-bit words a texel row
  };
  FieldBits field_;                    // markVisible(): the field's size and the taps
  std::vector<std::uint64_t> hot_;     // markVisible(): a bit per field texel above the limit
  std::vector<std::uint64_t> joined_;  // keepVisible(): the field's rows one grid row reads, or-ed
  std::vector<int> count_;             // windowTest's running counts per column
};

}  // namespace sph2d
