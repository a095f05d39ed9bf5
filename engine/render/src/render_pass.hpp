// render_pass.hpp — the part of a frame that depends on the render mode, behind one interface.
//
// Design: a Renderer picks its pass once, when it is built (the mode is fixed for a renderer):
// LiquidPass (splat → depth grid → composite, liquid_pass.cpp) or ParticlesPass (one disc per
// particle coloured by a field, particles_pass.cpp). The Renderer does what both modes share —
// the camera and guard band, id order and age fades, the background and solids, readback and
// the overlay — and calls the pass at three points of the frame: prepare() (CPU packing and
// uploads), draw() (GL passes into the colour target) and annotate() (CPU drawing after
// readback). Passes record their own stage times.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "camera.hpp"
#include "gl_util.hpp"
#include "sph2d/render/renderer.hpp"
#include "sprites.hpp"

namespace sph2d {

/// The foam's colour: RenderOptions::foam, or a white tinged blue (also the outline's).
inline std::array<double, 3> foamColor(const RenderOptions& o) {
  return o.foam.value_or(std::array<double, 3>{0.9, 0.95, 1.0});
}

/// Wall time per stage; with `profile`, glFinish first so the time is the stage's own.
struct StageTimer {
  using Clock = std::chrono::steady_clock;
  bool profile = false;
  Clock::time_point t = Clock::now();
  /// Milliseconds since `since`.
  static double msSince(Clock::time_point since) {
    return std::chrono::duration<double, std::milli>(Clock::now() - since).count();
  }
  /// Ends a stage: `slot` = milliseconds since the last end (or the start); the next stage starts now.
  void end(double& slot) {
    if (profile) glFinish();
    slot = msSince(t);
    t = Clock::now();
  }
};

/// The colour target the frame is drawn into (the image plus guard bands) and its background.
struct ColorTarget {
  GLuint fbo = 0, tex = 0;
  GLuint background = 0;     ///< the background texture, same size (static solids drawn in)
  GLuint backgroundFbo = 0;  ///< its framebuffer
  /// What a frame starts from and the liquid sees through the water: the background, or the
  /// liquid's backdrop (the background with the moving bodies drawn in, Scenery::backdrop).
  GLuint source = 0, sourceFbo = 0;
  GLuint plain = 0;       ///< the background without solids (the liquid tells solids from it)
  bool copyImage = true;  ///< glCopyImageSubData exists (OpenGL 4.3); else rows are blitted (3.3)
  int EW = 0, EH = 0;
  /// Starts the frame: copies the source into the colour target and binds it.
  void startFrame() const { startFrameRows(0, EH); }
  /// Starts the frame when only rows [y0, y1) (window rows, from the world's top) differ from
  /// the source: copies the source over those rows and binds the target.
  void startFrameRows(int y0, int y1) const {
    if (y1 > y0 && copyImage) {
      glCopyImageSubData(source, GL_TEXTURE_2D, 0, 0, y0, 0, tex, GL_TEXTURE_2D, 0, 0, y0, 0, EW, y1 - y0, 1);
    } else if (y1 > y0) {  // the same texels, copied by a 1:1 blit (no filtering, no scissor: gl_state.hpp)
      glBindFramebuffer(GL_READ_FRAMEBUFFER, sourceFbo);
      glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo);
      glBlitFramebuffer(0, y0, EW, y1, 0, y0, EW, y1, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  }
};

/// What a pass sees of one frame.
struct PassFrame {
  const RenderInput& in;
  const std::vector<std::uint32_t>& order;  ///< particle slots in id order
  const std::vector<float>& weight;         ///< age fade per particle, in id order
  const FrameGeometry& geo;
  double pxPerM = 0;                            ///< image pixels per metre
  double spacingPx = 0;                         ///< particle spacing [px]
  float scale[2] = {0, 0}, offset[2] = {0, 0};  ///< local frame → NDC of the targets
  const ColorTarget& color;
};

/// The mode-specific passes of a frame (see the design note above).
class RenderPass {
 public:
  virtual ~RenderPass() = default;
  /// "liquid" or "particles".
  virtual const char* mode() const = 0;
  /// Where the splat is summed: "cpu" or "gl" (liquid), "" (a pass without one).
  virtual const char* splatPath() const { return ""; }
  /// Sprite diameter [px] at full resolution for a particle spacing of `spacingPx`.
  virtual float spriteDiameter(double spacingPx) const = 0;
  /// How many times smaller than the targets the sprites' own target is (1, or 2 for the
  /// liquid's half-resolution field).
  virtual int spriteShrink(double /*spacingPx*/) const { return 1; }
  /// The targets changed size: drop what depends on it (recreated at the next frame).
  virtual void targetsChanged() {}
  /// The static solids changed (a game edited its level): what depends on them is rebuilt,
  /// and the next draw() starts the whole target from the background.
  virtual void solidsChanged() {}
  /// Deletes the pass's GL objects (the context that made them must be current).
  virtual void release() = 0;
  /// CPU work and uploads before drawing (the upload stage). Throws std::runtime_error.
  virtual void prepare(const PassFrame& f) = 0;
  /// Draws into the colour target, starting it from the background; ends its own stages.
  virtual void draw(const PassFrame& f, StageTimer& timer, RenderTimings& timings) = 0;
  /// The rows [first, last) of the colour target that the last draw() changed (copied back from
  /// the background or drawn over); elsewhere the target still holds the last frame's pixels,
  /// solids included. Default: every row.
  virtual std::pair<int, int> changedRows() const { return {0, 1 << 30}; }
  /// Target rows [first, last) that the next draw() must give back to the background too
  /// (where moving bodies were drawn over the last frame). Passes that start every frame
  /// from the whole background need nothing.
  virtual void restoreRows(std::pair<int, int> rows) { (void)rows; }
  /// True when the solids are drawn behind what the pass draws (into the frame's source: the
  /// liquid sees them through the water); false: over it, after the pass.
  virtual bool solidsBehind() const { return false; }
  /// CPU drawing into the read-back frame (the colour bar); `textScale` is the font scale.
  virtual void annotate(Frame& /*frame*/, int /*textScale*/) const {}
  /// True when the last draw() used instanced quads instead of points.
  bool usedQuads() const { return quads_; }
  /// The colour range of the last frame (particles mode; 0..1 otherwise).
  virtual std::array<double, 2> range() const { return {0, 1}; }

 protected:
  bool quads_ = false;
};

/// The liquid mode's pass (liquid_pass.cpp); `sprites` must outlive it.
std::unique_ptr<RenderPass> makeLiquidPass(const RenderDef& def, const RenderOptions& opt, SpriteBatch& sprites);
/// The particles mode's pass (particles_pass.cpp); `sprites` must outlive it.
std::unique_ptr<RenderPass> makeParticlesPass(const RenderDef& def, const RenderOptions& opt, SpriteBatch& sprites);

}  // namespace sph2d
