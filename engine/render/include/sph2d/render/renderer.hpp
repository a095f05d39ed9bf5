// sph2d/render/renderer.hpp — frames of a World through OpenGL 3.3: off screen in an OSMesa
// context of the Renderer's own (read back as RGBA8 images), or into a game's own context.
//
// Passes per frame (GLSL in shaders/, embedded at build time):
//   liquid mode
//     splat      particles → Σ w and Σ w·speed in one RG32F target (point
//                sprites, additive, w = (1 − q²)³ × the particle's age fade)
//     aux        on the CPU: a coarse grid of the fluid (cells of ≥ 4 px) giving
//                the water depth above each cell (carried down row by row and
//                blurred along each row, so light scatters sideways and no
//                vertical seams appear) and the local fill; uploaded as a small
//                RG32F texture, sampled bilinearly
//     backdrop   the background and static solids (drawn once), the moving bodies
//                drawn into a copy each frame: what the water is in front of
//     composite  field → liquid: anti-aliased edge, shading from the field's
//                gradient (light from above), colour from the depth of water
//                above, the backdrop seen through it (absorbed per channel by
//                its thickness, shifted where its surface tilts), foam where
//                the weighted speed is high
//     grains     a granular material's particles as discs in its colour
//     blobs      particle groups as solid blobs in their colour with a darker outline
//                (their own splat target, then shaders/blob.frag over the water)
//   particles mode
//     discs      one anti-aliased disc per particle coloured by a field (speed,
//                pressure, density, age) on a ramp, plus a colour bar with its range
//   both
//     solids     Box2D fixtures with their real shapes (liquid: in the backdrop; particles:
//                over the discs)
//   render(): the frame as an image
//     readback   glReadPixels into RGBA8, rows top-down (the camera flips y)
//     overlay    optional text (frame, time, particle count) and the colour bar, drawn on the CPU
//   draw() (a Renderer made with CurrentGlContext): the frame into the game's framebuffer
//     present    the finished frame drawn over the game's viewport (no readback, no CPU text)
//
// Both ways share every pass: the OSMesa path is "make an own context, draw the frame into the
// Renderer's own target, read it back"; the game's path is "draw the frame into the Renderer's
// own target made in the game's context, draw that into the game's framebuffer", saving and
// restoring every piece of GL state it changes.
//
// Determinism: particles are submitted in id order (additive float blending
// depends on order), so a frame depends only on the particles' values, not on
// how the engine stores them. The llvmpipe settings that could change pixels
// are pinned before the first context is made (pinRenderEnvironment()).
// Sprites wider than the driver's point-size limit (255 px on llvmpipe) are
// drawn as instanced quads instead, so any zoom renders correctly.
// A Renderer belongs to the thread that created it (and its context).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sph2d/boundary.hpp"
#include "sph2d/foam.hpp"
#include "sph2d/particles.hpp"
#include "sph2d/render/image.hpp"
#include "sph2d/render/render_env.hpp"  // EnvSetting, pinRenderEnvironment(), cpuSummary()
#include "sph2d/scene.hpp"

namespace sph2d {

class World;

/// The particle quantity the particles mode colours by.
/// What the particles mode colours by: a field on the ramp, or each particle's own colour
/// (World::setParticleColor; particles without one in the fluid's colour).
enum class ColorField { Speed, Pressure, Density, Age, Color, Material };

/// Parses "speed", "pressure", "density", "age", "color" or "material"; returns false for anything else.
bool parseColorField(const std::string& s, ColorField& out);
/// "speed", "pressure", "density", "age", "color" or "material".
std::string colorFieldName(ColorField f);

/// Where the liquid's splat is summed (RenderOptions::splat).
enum class SplatPath {
  Auto,  ///< the CPU when the OpenGL is a software rasterizer (llvmpipe, softpipe), else the GL's
  Gl,    ///< the GL's point sprites (shaders/splat.*)
  Cpu,   ///< summed on the CPU and uploaded
};
/// Parses "auto", "gl" or "cpu"; returns false for anything else.
bool parseSplatPath(const std::string& s, SplatPath& out);
/// "auto", "gl" or "cpu".
std::string splatPathName(SplatPath p);

/// Render settings that the scene format does not carry (yet): they come from
/// the command line. Unset optionals take the documented defaults.
struct RenderOptions {
  std::string mode;                            ///< "" = RenderDef::mode, else "liquid" or "particles"
  ColorField colorBy = ColorField::Speed;      ///< particles mode: the field shown
  std::optional<std::array<double, 2>> range;  ///< particles mode: fixed colour range (default: this frame's min..max)
  bool overlay = false;                        ///< frame number, simulated time and particle count in the frame
  /// The fluid's outline (surfaceCurves of the particles, sph2d/surface.hpp) drawn over it,
  /// 1.5 px wide in the foam colour, under the solids.
  bool outline = false;
  double foamSpeed = 0;       ///< liquid: speed [m/s] where foam starts (0 = 0.35·sqrt(g·view height)); full at 2×
  double depthScale = 0;      ///< liquid: metres of water above that darken by 1/e (0 = 1 m)
  double ageFadeStart = 1.0;  ///< a particle with an age fades from this age [s] ...
  double ageFadeEnd = 3.0;    ///< ... to nothing at this age [s]
  std::optional<std::array<double, 3>> deepWater;  ///< colour under deep water (default: water × 0.3)
  std::optional<std::array<double, 3>> foam;       ///< foam colour (default: 0.9, 0.95, 1)
  std::optional<std::array<double, 3>> text;       ///< overlay and colour-bar text (default: 0.92 grey)
  bool profile = false;                            ///< glFinish after each stage so lastTimings() is per stage (slower)
  /// Liquid mode: where the splat's sums are made (SplatPath). Auto: on the CPU when the OpenGL
  /// is a software rasterizer (llvmpipe, softpipe: their cost is each point's set-up, not the
  /// sum), else by the GL's point sprites. The two give the same frame to float rounding.
  SplatPath splat = SplatPath::Auto;
};

/// What to draw. Particles are in the engine's local frame (add `origin` for world coordinates).
struct RenderInput {
  Particles
      particles;  ///< what to draw: views whose arrays outlive the call (World::particles(), ParticleBuffer::view())
  Vec2d origin{0, 0};                                ///< local frame offset [m]
  double spacing = 0.02;                             ///< particle spacing dx [m]
  const std::vector<Collider>* colliders = nullptr;  ///< solids in the local frame (may be null)
  std::vector<Collider> moving;  ///< moving bodies at their pose this frame (local frame), drawn every frame
  const Real* age =
      nullptr;  ///< optional: one age [s] per particle slot (null: particles.age when it has one per particle)
  /// 0xRRGGBB per material (materialColors(World)): particles mode, `color_by` material draws
  /// each particle in its material's colour, and `color` those without one of their own.
  std::vector<std::uint32_t> materialColors;
  /// 1 per granular material, by index (materialGranular(World)): the liquid mode draws their
  /// particles as grains, each a disc in its material's colour, and no liquid surface for them.
  std::vector<std::uint8_t> materialGranular;
  /// Each material's transmission (materialTransmission(World): MaterialDef::transmission), 0..1
  /// per channel: the liquid mode sees through each material by its own (with materialColors and
  /// a material per particle; else all by the first's). Empty: the render's.
  std::vector<std::array<float, 3>> materialTransmission;
  /// Foam, spray and bubbles (World::diffuse(), local frame): the liquid mode draws them over
  /// the water as small light discs, fading out over the last 30 % of their lifetimes.
  DiffuseParticles diffuse;
  double gravity = 9.81;    ///< |g| [m/s²], scales the default foam speed
  std::uint64_t frame = 0;  ///< for the overlay
  double time = 0;          ///< simulated time [s], for the overlay
};

/// Wall time of the stages of the last render() or draw() [ms]; per stage only with
/// RenderOptions::profile.
struct RenderTimings {
  double upload = 0;     ///< CPU packing (id order, values, aux grid) and buffer uploads
  double splat = 0;      ///< splat (liquid) or discs (particles)
  double composite = 0;  ///< liquid composite (0 in particles mode)
  double solids = 0;     ///< Box2D fixtures
  double readback = 0;   ///< glReadPixels (includes the GPU work not yet finished without profile)
  double overlay = 0;    ///< CPU text and colour bar
  double present = 0;    ///< draw(): the frame into the caller's framebuffer (0 in render())
  double total = 0;      ///< the whole render() or draw()
};

/// The tag of the Renderer that draws into the caller's OpenGL context:
/// `sph2d::Renderer renderer(sph2d::currentGlContext, scene.render);`
struct CurrentGlContext {};
/// The value of the tag.
inline constexpr CurrentGlContext currentGlContext{};

/// Where Renderer::draw() puts a frame in the caller's OpenGL context.
struct GlTarget {
  /// The framebuffer object to draw into, by its GL name (0: the default framebuffer, the
  /// window); unset: the one bound to GL_DRAW_FRAMEBUFFER when draw() is called.
  std::optional<unsigned int> framebuffer;
  /// The rectangle the frame fills: x, y (its lower-left corner, GL's convention), width,
  /// height [px]; unset: the viewport set when draw() is called. At RenderDef::width × height
  /// the frame's pixels are copied exactly; at any other size it is scaled (bilinear).
  std::optional<std::array<int, 4>> viewport;
};

/// Renders frames of a World: into images through an OSMesa context of its own
/// (Renderer(def)), or into the game's OpenGL context (Renderer(currentGlContext, def)).
class Renderer {
 public:
  /// The memory a renderer of `width` × `height` frames holds at most [bytes]: the OSMesa
  /// context and llvmpipe (about 40 MB, measured) and eight RGBA images (framebuffers,
  /// readback, the PNG writer's queue).
  static double estimateBytes(int width, int height) { return 40e6 + 8.0 * 4.0 * double(width) * double(height); }
  /// Creates the OSMesa context and GL resources for `def`. Throws std::runtime_error.
  explicit Renderer(const RenderDef& def, const RenderOptions& options = {});
  /// Draws into the OpenGL context current on the calling thread (a game's window or its own
  /// framebuffers) instead of an OSMesa context of its own: its shaders, buffers and
  /// intermediate targets (the splat field, the background, the frame) are created in that
  /// context, and the context's state is left as it was found. The context must be desktop
  /// OpenGL 3.3 or later (core or compatibility profile) and must be current whenever this
  /// Renderer is used or destroyed. Sets no Mesa environment (pinRenderEnvironment()): the
  /// context exists already. Throws std::runtime_error when no context is current, when it is
  /// OpenGL ES or below 3.3 (naming the version found), or when an OpenGL error of the
  /// caller's was pending.
  Renderer(CurrentGlContext, const RenderDef& def, const RenderOptions& options = {});
  /// Frees the GL resources: with its own context, by destroying it; in the caller's context,
  /// by deleting them there (skipped when no context is current).
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Renders the current state of `world`; `age` (optional) holds one age [s] per particle
  /// slot, by default the world's "age" field when its scene has lifetimes. The frame
  /// stays valid until the next call. With its own context, makes that context current on
  /// this thread (it stays current); in the caller's context, draws with the caller's state
  /// saved and restored and reads the frame back (the game's framebuffer is not touched).
  /// Throws std::runtime_error.
  const Frame& render(const World& world, const Real* age = nullptr);
  /// Renders `in`; the camera is fixed by the first call. Throws std::runtime_error.
  const Frame& render(const RenderInput& in);
  /// Draws the current state of `world` into the caller's framebuffer (a Renderer made with
  /// CurrentGlContext only: else std::logic_error): the same passes as render(), composited
  /// opaque (the scene's background included) over `target` (by default the bound draw
  /// framebuffer and the current viewport), rows the right way up in GL's convention. No
  /// readback, and no overlay text or colour bar (render() draws those on the CPU). Every piece
  /// of GL state it changes is restored before it returns, also when it throws (the list is in
  /// docs/EMBEDDING.md); scissor, blending, depth and stencil tests of the caller do not apply
  /// to it. Throws std::invalid_argument for an empty viewport or a name that is no framebuffer,
  /// std::runtime_error when no context is current, the framebuffer is incomplete, a GL error
  /// of the caller's was pending, or a GL call fails.
  void draw(const World& world, const GlTarget& target = {}, const Real* age = nullptr);
  /// Draws `in` into the caller's framebuffer, as draw(world, target).
  void draw(const RenderInput& in, const GlTarget& target = {});
  /// True when this Renderer draws into the caller's context (made with CurrentGlContext).
  bool usesCurrentContext() const;
  /// GL_RENDERER and GL_VERSION of the context, e.g. "llvmpipe (LLVM 15.0.6, 256 bits) / 4.5 (Core Profile)
  /// Mesa 22.3.6".
  std::string rendererString() const;
  /// The world rectangle shown (after aspect correction), min x, min y, max x, max y.
  std::vector<double> cameraRect() const;
  /// The mode in use: "liquid" or "particles".
  std::string mode() const;
  /// Where the liquid's splat is summed (RenderOptions::splat): "cpu" or "gl"; "" in particles mode.
  std::string splatPath() const;
  /// Stage times of the last render() or draw().
  RenderTimings lastTimings() const;
  /// True when the last render() or draw() drew instanced quads because sprites exceeded the point-size limit.
  bool usedQuads() const;
  /// The driver's largest point sprite [px] (255 on llvmpipe).
  float maxPointSize() const;
  /// The colour range of the last particles-mode frame (lo, hi).
  std::array<double, 2> lastRange() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

/// The camera of `def` for `world`: its own rectangle, or the solids and fluid
/// with a margin; widened to the image's aspect ratio.
std::vector<double> resolveCamera(const RenderDef& def, const World& world);
/// The ages a frame of `in` uses: in.age, else the particles' own when they have one per
/// particle, else null.
inline const Real* agesOf(const RenderInput& in) {
  if (in.age) return in.age;
  const Particles& P = in.particles;
  return P.age.size() == P.size() && P.size() > 0 ? P.age.data() : nullptr;
}
/// The colours of `world`'s materials as 0xRRGGBB, by index (one for a World of one material).
std::vector<std::uint32_t> materialColors(const World& world);
/// 1 for each granular material of `world`, by index (empty when it has none).
std::vector<std::uint8_t> materialGranular(const World& world);
/// Each material's transmission (MaterialDef::transmission), by index.
std::vector<std::array<float, 3>> materialTransmission(const World& world);

/// The camera of `def` for a RenderInput (same rules as above).
std::vector<double> resolveCamera(const RenderDef& def, const RenderInput& in);

}  // namespace sph2d
