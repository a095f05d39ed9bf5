// scenery.hpp — what does not move during a run: the background and the solids.
//
// Design: the background (shaders/background.frag, a vertical gradient, tiles when asked) is
// drawn once per target size into a texture, and into a second one with the static solids drawn
// over it; each frame starts as a copy of that, and the liquid composite reads both (what is
// behind the water, and where solids are), so all agree to the bit. The solids are the World's
// colliders as triangles in the targets' NDC, built once per camera: polygons as fans, circles as
// 64-gons, segments (edges, chain links, zero thickness) as 3 px wide quads. Both are rebuilt
// when the guard band changes or the solids change (a game edits its level: Renderer compares a
// hash of them). Moving bodies are the exception: their triangles are built every frame, drawn
// over the frame (particles mode) or into the backdrop, a copy of the background that the liquid
// composite sees through the water (backdrop()).
#pragma once

#include "camera.hpp"
#include "gl_util.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/surface.hpp"

namespace sph2d {

/// The background texture and the solid triangles of a renderer.
class Scenery {
 public:
  /// Compiles the programs and creates the buffers in the current context.
  void init();
  /// Deletes every GL object of the scenery (the context that made them must be current).
  void release();
  /// (Re)draws the background for targets of `geo` and rebuilds the solids of `in` (local frame).
  void build(const RenderDef& def, const FrameGeometry& geo, const RenderInput& in);
  /// Rebuilds the solids of `in` and the background they are drawn into (the static solids changed).
  void rebuildSolids(const RenderDef& def, const FrameGeometry& geo, const RenderInput& in) { build(def, geo, in); }
  /// The background texture (RGBA8, the targets' size), static solids included.
  GLuint background() const { return sceneTex_; }
  /// The framebuffer of the background texture.
  GLuint backgroundFbo() const { return sceneFbo_; }
  /// The plain background, without solids (the liquid composite tells solids from it).
  GLuint plainBackground() const { return bgTex_; }
  /// Draws the solids in `def.solid`'s colour into the bound framebuffer, over the target rows
  /// [rowFirst, rowLast) only (the rest still shows them from an earlier frame).
  void drawSolids(const RenderDef& def, int rowFirst, int rowLast) const;
  /// Draws the moving bodies of `in` (their pose this frame) over the whole bound target;
  /// returns the target rows [first, last) they cover (empty when there are none).
  std::pair<int, int> drawMoving(const RenderDef& def, const FrameGeometry& geo, const RenderInput& in);
  /// The liquid mode's backdrop of this frame: the background with the moving bodies of `in`
  /// drawn in. Target rows `restore` (where they were drawn last frame) go back to the background
  /// first; `rows` gets the rows they cover now. Returns the backdrop's texture and framebuffer:
  /// the background's own while no moving body was ever drawn.
  std::pair<GLuint, GLuint> backdrop(const RenderDef& def, const FrameGeometry& geo, const RenderInput& in,
                                     std::pair<int, int> restore, std::pair<int, int>& rows);
  /// Draws `curves` (world coordinates) as lines `widthPx` wide in `color` into the bound
  /// target, over the target rows [rowFirst, rowLast) only.
  void drawOutline(const FrameGeometry& geo, const std::vector<SurfaceCurve>& curves, const float color[3],
                   double widthPx, int rowFirst, int rowLast);

 private:
  void buildBackground(const RenderDef& def, const FrameGeometry& geo);
  void buildSolids(const FrameGeometry& geo, const RenderInput& in);

  GLuint bgProg_ = 0, solidProg_ = 0, emptyVao_ = 0, solidVao_ = 0, solidVbo_ = 0, bgTex_ = 0, bgFbo_ = 0;
  GLsizei solidCount_ = 0;
  /// The moving bodies' triangles of `in` (NDC) uploaded and drawn into the bound framebuffer;
  /// returns the target rows they cover.
  std::pair<int, int> drawMovingTriangles(const RenderDef& def, const FrameGeometry& geo,
                                          const std::vector<float>& tri);

  GLuint movingVao_ = 0, movingVbo_ = 0;      // also the outline's: each uploads its triangles before drawing
  GLuint sceneTex_ = 0, sceneFbo_ = 0;        // the background with the static solids
  GLuint backdropTex_ = 0, backdropFbo_ = 0;  // the liquid's backdrop, made at the first moving body
};

}  // namespace sph2d
