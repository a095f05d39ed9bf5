// renderer.cpp — the Renderer: one OSMesa context and the frame loop shared by both modes.
//
// Design: per frame, on the thread that created the Renderer: fix the camera (first frame),
// size the targets' guard band for the sprites (camera.hpp), order the particles by id and
// weigh them by their age fade (sprites.hpp), let the mode's pass pack and draw them
// (render_pass.hpp: liquid or particles, chosen once in the constructor), draw the solids on
// top (scenery.hpp), read the image back with glReadPixels (rows come out top-down: the
// camera flips y) and draw text on the CPU. Stage times are taken with glFinish between
// stages only when RenderOptions::profile is set.
#include "sph2d/render/renderer.hpp"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "render_pass.hpp"
#include "scenery.hpp"
#include "sph2d/world.hpp"

namespace sph2d {
namespace {

float smoothstepf(float e0, float e1, float x) {
  const float t = std::min(1.0f, std::max(0.0f, (x - e0) / (e1 - e0)));
  return t * t * (3.0f - 2.0f * t);
}

// `view` is world.particles(), held by the caller for as long as the input is used.
RenderInput inputOf(const World& world, const Particles& view, const Real* age) {
  RenderInput in;
  in.particles = &view;
  in.origin = world.origin();
  in.spacing = world.spacing();
  in.colliders = &world.colliders();
  in.moving = world.movingColliders();
  // Ages come from the caller, or from the engine's "age" field when the scene has lifetimes.
  in.age = age ? age : (view.age.empty() ? nullptr : view.age.data());
  in.gravity = world.scene().gravity.norm();
  in.frame = world.frame();
  in.time = world.time();
  return in;
}

}  // namespace

std::vector<double> resolveCamera(const RenderDef& def, const World& world) {
  const Particles view = world.particles();
  return resolveCamera(def, inputOf(world, view, nullptr));
}

struct Renderer::Impl {
  RenderDef def;
  RenderOptions opt;
  OSMesaContext ctx = nullptr;
  unsigned char dummy[4] = {0, 0, 0, 0};
  SpriteBatch sprites;
  Scenery scenery;
  std::unique_ptr<RenderPass> pass;
  FrameGeometry geo;
  ColorTarget color;
  double spacingSeen = -1;
  std::pair<int, int> movingRows{0, 0};  // target rows the moving bodies covered in the last frame
  Frame frame;
  std::vector<std::uint32_t> order, slotOfId;  // slots in id order; scratch
  std::vector<float> weight;                   // age fade per particle, id order
  std::string rendererName;
  RenderTimings timings;

  void makeCurrent() {
    if (!OSMesaMakeCurrent(ctx, dummy, GL_UNSIGNED_BYTE, 1, 1)) throw std::runtime_error("OSMesaMakeCurrent failed");
  }

  float fade(const RenderInput& in, std::size_t slot) const {
    if (!in.age) return 1.0f;
    const float a = float(in.age[slot]);
    if (!(opt.ageFadeEnd > opt.ageFadeStart)) return 1.0f;
    return 1.0f - smoothstepf(float(opt.ageFadeStart), float(opt.ageFadeEnd), a);
  }

  /// Sizes the guard band for the sprites of `in` and (re)creates what depends on it.
  void ensureFrame(const RenderInput& in) {
    if (in.spacing == spacingSeen) return;
    spacingSeen = in.spacing;
    const double spacingPx = in.spacing * geo.pxPerM(def.width);
    const int g = guardBand(pass->spriteDiameter(spacingPx), pass->spriteShrink(spacingPx), sprites.maxPoint());
    if (g == geo.guard) return;
    geo.setGuard(g, def.width, def.height);
    if (color.fbo) glDeleteFramebuffers(1, &color.fbo);
    color.fbo = gl::target(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, geo.EW, geo.EH, color.tex);
    scenery.build(def, geo, in);
    color.background = scenery.background();
    color.EW = geo.EW;
    color.EH = geo.EH;
    pass->targetsChanged();
  }

  /// Frame number, time and particle count in the top-left corner, on a translucent box.
  void drawOverlay(const RenderInput& in, int textScale) {
    const Rgba8 textColor = toRgba8(opt.text.value_or(std::array<double, 3>{0.92, 0.92, 0.92}));
    char line[128];
    std::snprintf(line, sizeof line, "FRAME %llu  T %.3f S  %zu PARTICLES", static_cast<unsigned long long>(in.frame),
                  in.time, in.particles->size());
    const int pad = 2 * textScale;
    fillRect(frame, 0, 0, textWidth(line, textScale) + 2 * pad + 2 * textScale,
             textHeight(textScale) + 2 * pad + 2 * textScale, Rgba8{0, 0, 0, 140});
    drawText(frame, pad + textScale, pad + textScale, line, textScale, textColor);
  }
};

Renderer::Renderer(const RenderDef& def, const RenderOptions& options) : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.def = def;
  r.opt = options;
  const std::string mode = options.mode.empty() ? def.mode : options.mode;
  if (mode != "liquid" && mode != "particles")
    throw std::runtime_error("unknown render mode '" + mode + "' (liquid or particles)");
  pinRenderEnvironment();
  const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0, OSMESA_STENCIL_BITS, 0, OSMESA_ACCUM_BITS, 0,
                         OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 3,
                         OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
  r.ctx = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!r.ctx) throw std::runtime_error("OSMesa could not create a 3.3 core-profile context (is libosmesa6 installed?)");
  r.makeCurrent();
  OSMesaPixelStore(OSMESA_Y_UP, 0);
  const char* ren = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const char* ver = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  r.rendererName = std::string(ren ? ren : "?") + " / " + (ver ? ver : "?");
  r.sprites.init();
  r.scenery.init();
  r.pass = mode == "liquid" ? makeLiquidPass(def, options, r.sprites) : makeParticlesPass(def, options, r.sprites);
  r.frame.width = def.width;
  r.frame.height = def.height;
  r.frame.rgba.assign(std::size_t(def.width) * def.height * 4, 0);
  gl::throwOnError("while creating the renderer");
}

Renderer::~Renderer() {
  if (impl_ && impl_->ctx) OSMesaDestroyContext(impl_->ctx);  // with it, every GL object of the passes
}

std::string Renderer::rendererString() const { return impl_->rendererName; }
std::vector<double> Renderer::cameraRect() const { return impl_->geo.cam; }
std::string Renderer::mode() const { return impl_->pass->mode(); }
RenderTimings Renderer::lastTimings() const { return impl_->timings; }
bool Renderer::usedQuads() const { return impl_->pass->usedQuads(); }
float Renderer::maxPointSize() const { return impl_->sprites.maxPoint(); }
std::array<double, 2> Renderer::lastRange() const { return impl_->pass->range(); }

const Frame& Renderer::render(const World& world, const Real* age) {
  const Particles view = world.particles();
  return render(inputOf(world, view, age));
}

const Frame& Renderer::render(const RenderInput& in) {
  Impl& r = *impl_;
  if (!in.particles) throw std::invalid_argument("Renderer::render: no particles");
  StageTimer timer;
  timer.profile = r.opt.profile;
  const auto tStart = timer.t;
  r.timings = RenderTimings{};
  r.makeCurrent();
  const RenderDef& d = r.def;
  if (r.geo.cam.empty()) r.geo.cam = resolveCamera(d, in);
  r.ensureFrame(in);

  const Particles& P = *in.particles;
  const std::size_t n = P.size();
  PassFrame f{in, r.order, r.weight, r.geo, r.geo.pxPerM(d.width), 0, {0, 0}, {0, 0}, r.color};
  f.spacingPx = in.spacing * f.pxPerM;
  r.geo.ndcTransform(in.origin, f.scale, f.offset);

  // Id order and age fades, then the pass's own packing and uploads.
  idOrder(P, r.order, r.slotOfId);
  r.weight.resize(n);
  for (std::size_t k = 0; k < n; ++k) r.weight[k] = r.fade(in, r.order[k]);
  r.pass->prepare(f);
  glViewport(0, 0, r.geo.EW, r.geo.EH);
  timer.end(r.timings.upload);

  r.pass->restoreRows(r.movingRows);  // where moving bodies were last frame goes back to the background
  r.pass->draw(f, timer, r.timings);
  const auto rows = r.pass->changedRows();  // solids on top, where the pass may have drawn over them
  r.scenery.drawSolids(d, rows.first, rows.second);
  r.movingRows = r.scenery.drawMoving(d, r.geo, in);
  timer.end(r.timings.solids);

  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(r.geo.guard, r.geo.guard, d.width, d.height, GL_RGBA, GL_UNSIGNED_BYTE, r.frame.rgba.data());
  gl::throwOnError("while rendering");
  timer.end(r.timings.readback);

  // Text and colour bar on the CPU (bit-identical everywhere).
  const int textScale = std::max(1, d.height / 270);
  r.pass->annotate(r.frame, textScale);
  if (r.opt.overlay) r.drawOverlay(in, textScale);
  timer.end(r.timings.overlay);
  r.timings.total = StageTimer::msSince(tStart);
  return r.frame;
}

}  // namespace sph2d
