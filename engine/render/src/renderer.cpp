// renderer.cpp — the Renderer: its context (an OSMesa one of its own, or the caller's) and the
// frame loop shared by both modes and both contexts.
//
// Design: per frame, on the thread that created the Renderer: set the state the passes rely on
// (gl_state.hpp), fix the camera (first frame), size the targets' guard band for the sprites
// (camera.hpp), order the particles by id and weigh them by their age fade (sprites.hpp), let
// the mode's pass pack and draw them (render_pass.hpp: liquid or particles, chosen once in the
// constructor), draw the solids on top (scenery.hpp): drawFrame(), into the Renderer's own
// colour target. Then render() reads the image back with glReadPixels (rows come out top-down:
// the camera flips y) and draws text on the CPU, and draw() draws the target into the caller's
// framebuffer (present.hpp). In the caller's context both run inside a GlStateGuard; in the
// Renderer's own OSMesa context nothing needs restoring. Stage times are taken with glFinish
// between stages only when RenderOptions::profile is set. Every public call first makes the
// Renderer's table of GL functions the thread's (gl_api.hpp): OSMesa's entry points in its own
// context, so that a program that links libglvnd's libOpenGL still reaches it; in the caller's
// context the gl* functions the program links, as the game's own calls.
#include "sph2d/render/renderer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>

#include "gl_state.hpp"
#include "present.hpp"
#include "render_pass.hpp"
#include "scenery.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/world.hpp"

namespace sph2d {
namespace {

float smoothstepf(float e0, float e1, float x) {
  const float t = std::min(1.0f, std::max(0.0f, (x - e0) / (e1 - e0)));
  return t * t * (3.0f - 2.0f * t);
}

RenderInput inputOf(const World& world, const Real* age) {
  RenderInput in;
  in.particles = world.particles();
  in.origin = world.origin();
  in.spacing = world.spacing();
  in.colliders = &world.colliders();
  in.moving = world.movingColliders();
  // Ages come from the caller, or from the engine's "age" field when the scene has lifetimes.
  in.age = age;  // null: the World's own ages when its scene has lifetimes (agesOf)
  in.materialColors = materialColors(world);
  in.materialGranular = materialGranular(world);
  in.materialTransmission = materialTransmission(world);
  in.diffuse = world.diffuse();
  in.gravity = world.scene().gravity.norm();
  in.frame = world.frame();
  in.time = world.time();
  return in;
}

}  // namespace

std::vector<std::uint32_t> materialColors(const World& world) {
  std::vector<std::uint32_t> out;
  for (const MaterialDef& m : world.materials()) {
    std::uint32_t c = 0;
    for (const double v : m.color) c = (c << 8) | std::uint32_t(std::lround(std::clamp(v, 0.0, 1.0) * 255));
    out.push_back(c);
  }
  return out;
}

std::vector<std::array<float, 3>> materialTransmission(const World& world) {
  std::vector<std::array<float, 3>> out;
  for (const MaterialDef& m : world.materials())
    out.push_back({float(m.transmission[0]), float(m.transmission[1]), float(m.transmission[2])});
  return out;
}

std::vector<std::uint8_t> materialGranular(const World& world) {
  std::vector<std::uint8_t> out;
  bool any = false;
  for (const MaterialDef& m : world.materials()) {
    out.push_back(m.granular() ? 1 : 0);
    any = any || m.granular();
  }
  if (!any) out.clear();
  return out;
}

std::vector<double> resolveCamera(const RenderDef& def, const World& world) {
  return resolveCamera(def, inputOf(world, nullptr));
}

struct Renderer::Impl {
  RenderDef def;
  RenderOptions opt;
  bool ownContext = false;  // an OSMesa context of the Renderer's, else the caller's
  OSMesaContext ctx = nullptr;
  // The GL functions every call uses (made the thread's by a gl::UseApi at its top): OSMesa's in
  // the own context; in the caller's, the linked ones, or OSMesa's when the linked ones (then
  // libglvnd's libOpenGL) reach no context while an OSMesa one is current (the caller's).
  const gl::Api* api = &gl::linkedApi();
  // The caller's context only: OSMesa's current context when the Renderer was made. For a game's
  // EGL or GLX context on Mesa it is not null: OSMesa reads Mesa's shared dispatch, which gives
  // the same pointer for the same context (tests/egl); a driver that is not Mesa's OSMesa cannot
  // see (docs/EMBEDDING.md). Another one current later (e.g. an OSMesa Renderer's, which render()
  // leaves current) means the wrong context: its object names are not ours.
  OSMesaContext callerOsmesa = nullptr;
  unsigned char dummy[4] = {0, 0, 0, 0};
  gl::ContextInfo glInfo;
  SpriteBatch sprites;
  Scenery scenery;
  std::vector<Vec2d> outlinePoints;  ///< drawOutline's scratch: the particles in world coordinates
  std::unique_ptr<RenderPass> pass;
  Presenter presenter;  // the caller's context only
  FrameGeometry geo;
  ColorTarget color;
  double spacingSeen = -1;
  std::uint64_t solidsSeen = 0;          // solidsHash of the static solids the scenery holds
  std::pair<int, int> movingRows{0, 0};  // target rows the moving bodies covered in the last frame
  Frame frame;
  std::vector<std::uint32_t> order, slotOfId;  // slots in id order; scratch
  std::vector<float> weight;                   // age fade per particle, id order
  RenderTimings timings;

  ~Impl() {
    const gl::UseApi use(*api);
    if (ownContext) {
      if (ctx) OSMesaDestroyContext(ctx);  // with it, every GL object of the passes
    } else if (glInfo.major > 0 && glGetString(GL_VERSION) && OSMesaGetCurrentContext() == callerOsmesa) {
      releaseGl();  // the caller's context (probed: 3.3 or later): the objects made there are ours to delete
    }  // another context current: deleting by name would hit its objects; ours are left to the caller's context
  }

  void makeCurrent() {
    if (!OSMesaMakeCurrent(ctx, dummy, GL_UNSIGNED_BYTE, 1, 1)) throw std::runtime_error("OSMesaMakeCurrent failed");
  }

  /// The GL objects of the passes, in the current context (probed into glInfo first).
  void init(const std::string& mode) {
    color.copyImage = glInfo.copyImage;
    sprites.init();
    scenery.init();
    pass = mode == "liquid" ? makeLiquidPass(def, opt, sprites) : makeParticlesPass(def, opt, sprites);
    if (!ownContext) presenter.init();
    frame.width = def.width;
    frame.height = def.height;
    gl::throwOnError("while creating the renderer");
  }

  /// Deletes every GL object made by init() and the frames (the caller's context).
  void releaseGl() {
    if (pass) pass->release();
    scenery.release();
    sprites.release();
    presenter.release();
    glDeleteFramebuffers(1, &color.fbo);
    glDeleteTextures(1, &color.tex);
    color.fbo = color.tex = 0;
  }

  /// Before using the caller's context: one must be current, and no error of the caller's pending
  /// (glGetError would take it and blame sph2d's calls). `call` is "Renderer" for the constructor.
  void enterCallerContext(const char* call) const {
    if (!glGetString(GL_VERSION)) {
      if (std::string(call) == "Renderer")
        throw std::runtime_error(
            "Renderer(currentGlContext, ...): no OpenGL context is current on this thread: make the game's OpenGL "
            "3.3 context current before creating the Renderer (a Renderer made without currentGlContext renders "
            "in an OSMesa context of its own and needs none)");
      throw std::runtime_error(std::string("Renderer::") + call +
                               " (a Renderer made with currentGlContext): no OpenGL context is current on this "
                               "thread: make the game's context it was created in current first");
    }
    if (OSMesaGetCurrentContext() != callerOsmesa)
      throw std::runtime_error(
          std::string("Renderer::") + call +
          ": another OpenGL context is current than the one this Renderer was created in "
          "(an OSMesa Renderer's render() leaves its own current); make the game's current (with EGL, "
          "eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT) first: Mesa's "
          "EGL skips making current the context it believes is current already)");
    const GLenum err = glGetError();
    if (err != GL_NO_ERROR) {
      char code[16];
      std::snprintf(code, sizeof code, "0x%x", err);
      throw std::runtime_error(std::string("Renderer::") + call + ": an OpenGL error (" + code +
                               ") was pending in the caller's context before the call; sph2d checks its own calls "
                               "with glGetError, so clear (and handle) the caller's errors first");
    }
  }

  /// Throws std::invalid_argument naming the array whose length is not the particles' count.
  static void checkParticles(const RenderInput& in) {
    const Particles& P = in.particles;
    const std::size_t n = P.size();
    auto need = [&](const char* name, std::size_t size, bool optional) {
      if (size == n || (optional && size == 0)) return;
      throw std::invalid_argument(std::string("Renderer: RenderInput.particles.") + name + " holds " +
                                  std::to_string(size) + " values for " + std::to_string(n) + " particles" +
                                  (optional ? " (it must be empty or one per particle)" : ""));
    };
    need("v", P.v.size(), false);
    need("rho", P.rho.size(), false);
    need("p", P.p.size(), false);
    need("id", P.id.size(), false);
    need("age", P.age.size(), true);
    need("color", P.color.size(), true);
    need("material", P.material.size(), true);
    need("mixedColor", P.mixedColor.size(), true);
    need("group", P.group.size(), true);
  }

  float fade(const RenderInput& in, std::size_t slot) const {
    const Real* age = agesOf(in);
    if (!age) return 1.0f;
    const float a = float(age[slot]);
    if (!(opt.ageFadeEnd > opt.ageFadeStart)) return 1.0f;
    return 1.0f - smoothstepf(float(opt.ageFadeStart), float(opt.ageFadeEnd), a);
  }

  /// XXH64 of the static solids of `in` (their kinds and geometry), 0 for none.
  static std::uint64_t solidsHash(const RenderInput& in) {
    if (!in.colliders || in.colliders->empty()) return 0;
    Xxh64 h;
    for (const Collider& c : *in.colliders) {
      const int kind = int(c.kind);
      h.update(&kind, sizeof kind);
      if (!c.vertices.empty()) h.update(c.vertices.data(), c.vertices.size() * sizeof(Vec2));
      h.update(&c.center, sizeof c.center);
      h.update(&c.radius, sizeof c.radius);
    }
    return h.digest() | 1;  // never 0
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
    // Only the presentation samples the frame, bilinearly when it scales it (present.frag).
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    scenery.build(def, geo, in);
    solidsSeen = solidsHash(in);
    color.background = scenery.background();
    color.backgroundFbo = scenery.backgroundFbo();
    color.plain = scenery.plainBackground();
    color.EW = geo.EW;
    color.EH = geo.EH;
    pass->targetsChanged();
  }

  /// The frame of `in` into the colour target: every pass, in both contexts. Ends the upload,
  /// splat, composite and solids stages.
  void drawFrame(const RenderInput& in, StageTimer& timer) {
    checkParticles(in);
    gl::setDrawState(glInfo);
    const RenderDef& d = def;
    if (geo.cam.empty()) geo.cam = resolveCamera(d, in);
    ensureFrame(in);
    // A game edited its level (a static body added, removed, or at rest after sliding): the
    // solids are drawn again where they are, and where they were goes back to the background.
    if (const std::uint64_t h = solidsHash(in); h != solidsSeen) {
      solidsSeen = h;
      scenery.rebuildSolids(def, geo, in);
      color.background = scenery.background();
      color.backgroundFbo = scenery.backgroundFbo();
      color.plain = scenery.plainBackground();
      pass->solidsChanged();
    }

    const Particles& P = in.particles;
    const std::size_t n = P.size();
    PassFrame f{in, order, weight, geo, geo.pxPerM(d.width), 0, {0, 0}, {0, 0}, color};
    f.spacingPx = in.spacing * f.pxPerM;
    geo.ndcTransform(in.origin, f.scale, f.offset);

    // Id order and age fades, then the pass's own packing and uploads.
    idOrder(P, order, slotOfId);
    weight.resize(n);
    for (std::size_t k = 0; k < n; ++k) weight[k] = fade(in, order[k]);
    pass->prepare(f);
    glViewport(0, 0, geo.EW, geo.EH);
    timer.end(timings.upload);

    if (pass->solidsBehind()) {
      // The moving bodies into the backdrop the water is seen against; the target's rows where
      // they were and are start from it.
      std::pair<int, int> now;
      const auto [tex, fbo] = scenery.backdrop(d, geo, in, movingRows, now);
      color.source = tex;
      color.sourceFbo = fbo;
      pass->restoreRows(movingRows);
      pass->restoreRows(now);
      movingRows = now;
      pass->draw(f, timer, timings);
      if (opt.outline) drawOutline(in, pass->changedRows());
      timer.end(timings.solids);
      return;
    }
    color.source = color.background;
    color.sourceFbo = color.backgroundFbo;
    pass->restoreRows(movingRows);  // where moving bodies were last frame goes back to the background
    pass->draw(f, timer, timings);
    const auto rows = pass->changedRows();  // solids on top, where the pass may have drawn over them
    if (opt.outline) drawOutline(in, rows);
    scenery.drawSolids(d, rows.first, rows.second);
    movingRows = scenery.drawMoving(d, geo, in);
    timer.end(timings.solids);
  }

  /// The fluid's outline (surfaceCurves of every particle, world coordinates) over the rows the
  /// pass drew this frame, in the foam colour.
  void drawOutline(const RenderInput& in, std::pair<int, int> rows) {
    const Particles& P = in.particles;
    outlinePoints.resize(P.size());
    for (std::size_t k = 0; k < P.size(); ++k) outlinePoints[k] = in.origin + P.x[k].cast<double>();
    const std::vector<SurfaceCurve> curves = surfaceCurves(outlinePoints, in.spacing);
    const std::array<double, 3> c = foamColor(opt);
    const float rgb[3] = {float(c[0]), float(c[1]), float(c[2])};
    scenery.drawOutline(geo, curves, rgb, 1.5, rows.first, rows.second);
  }

  /// The image into `frame` (glReadPixels from the colour target, bound by drawFrame), then the
  /// CPU text. Ends the readback and overlay stages.
  void readback(const RenderInput& in, StageTimer& timer) {
    const RenderDef& d = def;
    frame.rgba.resize(std::size_t(d.width) * d.height * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(geo.guard, geo.guard, d.width, d.height, GL_RGBA, GL_UNSIGNED_BYTE, frame.rgba.data());
    gl::throwOnError("while rendering");
    timer.end(timings.readback);

    // Text and colour bar on the CPU (bit-identical everywhere).
    const int textScale = std::max(1, d.height / 270);
    pass->annotate(frame, textScale);
    if (opt.overlay) drawOverlay(in, textScale);
    timer.end(timings.overlay);
  }

  /// Frame number, time and particle count in the top-left corner, on a translucent box.
  void drawOverlay(const RenderInput& in, int textScale) {
    const Rgba8 textColor = toRgba8(opt.text.value_or(std::array<double, 3>{0.92, 0.92, 0.92}));
    char line[128];
    std::snprintf(line, sizeof line, "FRAME %llu  T %.3f S  %zu PARTICLES", static_cast<unsigned long long>(in.frame),
                  in.time, in.particles.size());
    const int pad = 2 * textScale;
    fillRect(frame, 0, 0, textWidth(line, textScale) + 2 * pad + 2 * textScale,
             textHeight(textScale) + 2 * pad + 2 * textScale, Rgba8{0, 0, 0, 140});
    drawText(frame, pad + textScale, pad + textScale, line, textScale, textColor);
  }
};

namespace {

std::string checkedMode(const RenderDef& def, const RenderOptions& options) {
  const std::string mode = options.mode.empty() ? def.mode : options.mode;
  if (mode != "liquid" && mode != "particles")
    throw std::runtime_error("unknown render mode '" + mode + "' (liquid or particles)");
  return mode;
}

}  // namespace

Renderer::Renderer(const RenderDef& def, const RenderOptions& options) : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.def = def;
  r.opt = options;
  r.ownContext = true;
  const std::string mode = checkedMode(def, options);
  pinRenderEnvironment();
  const int attribs[] = {OSMESA_FORMAT,
                         OSMESA_RGBA,
                         OSMESA_DEPTH_BITS,
                         0,
                         OSMESA_STENCIL_BITS,
                         0,
                         OSMESA_ACCUM_BITS,
                         0,
                         OSMESA_PROFILE,
                         OSMESA_CORE_PROFILE,
                         OSMESA_CONTEXT_MAJOR_VERSION,
                         3,
                         OSMESA_CONTEXT_MINOR_VERSION,
                         3,
                         0};
  r.api = &gl::osmesaApi();
  const gl::UseApi use(*r.api);
  r.ctx = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!r.ctx) throw std::runtime_error("OSMesa could not create a 3.3 core-profile context (is libosmesa6 installed?)");
  r.makeCurrent();
  OSMesaPixelStore(OSMESA_Y_UP, 0);
  if (!glGetString(GL_VERSION))
    throw std::runtime_error(
        "Renderer (its own OSMesa context): OSMesaMakeCurrent succeeded, but glGetString(GL_VERSION) through "
        "OSMesaGetProcAddress's entry points gives nothing, so OpenGL calls do not reach the context: libOSMesa "
        "and the libglapi it loads must come from one Mesa (Debian: libosmesa6 and libglapi-mesa of one version)");
  r.glInfo = gl::currentContext();
  r.init(mode);
}

Renderer::Renderer(CurrentGlContext, const RenderDef& def, const RenderOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.def = def;
  r.opt = options;
  const std::string mode = checkedMode(def, options);
  r.callerOsmesa = OSMesaGetCurrentContext();
  if (!gl::linkedApi().GetString(GL_VERSION) && r.callerOsmesa && gl::osmesaApi().GetString(GL_VERSION))
    r.api = &gl::osmesaApi();  // the game's own OSMesa context, which libOpenGL's gl* functions do not reach
  const gl::UseApi use(*r.api);
  r.enterCallerContext("Renderer");
  r.glInfo = gl::currentContext();
  gl::GlStateGuard saved(r.glInfo);
  r.init(mode);  // on a throw, ~Impl deletes what was made
}

Renderer::~Renderer() = default;

std::string Renderer::rendererString() const { return impl_->glInfo.renderer + " / " + impl_->glInfo.version; }
std::vector<double> Renderer::cameraRect() const { return impl_->geo.cam; }
std::string Renderer::mode() const { return impl_->pass->mode(); }
std::string Renderer::splatPath() const { return impl_->pass->splatPath(); }
RenderTimings Renderer::lastTimings() const { return impl_->timings; }
bool Renderer::usedQuads() const { return impl_->pass->usedQuads(); }
float Renderer::maxPointSize() const { return impl_->sprites.maxPoint(); }
std::array<double, 2> Renderer::lastRange() const { return impl_->pass->range(); }
bool Renderer::usesCurrentContext() const { return !impl_->ownContext; }

const Frame& Renderer::render(const World& world, const Real* age) { return render(inputOf(world, age)); }

const Frame& Renderer::render(const RenderInput& in) {
  Impl& r = *impl_;
  StageTimer timer;
  timer.profile = r.opt.profile;
  const auto tStart = timer.t;
  r.timings = RenderTimings{};
  const gl::UseApi use(*r.api);
  std::optional<gl::GlStateGuard> saved;
  if (r.ownContext) {
    r.makeCurrent();
  } else {
    r.enterCallerContext("render");
    saved.emplace(r.glInfo);
  }
  r.drawFrame(in, timer);
  r.readback(in, timer);
  r.timings.total = StageTimer::msSince(tStart);
  return r.frame;
}

void Renderer::draw(const World& world, const GlTarget& target, const Real* age) { draw(inputOf(world, age), target); }

void Renderer::draw(const RenderInput& in, const GlTarget& target) {
  Impl& r = *impl_;
  if (r.ownContext)
    throw std::logic_error(
        "Renderer::draw: this Renderer has an OSMesa context of its own (render() gives its frames); draw() needs "
        "one made with sph2d::currentGlContext in the game's OpenGL context");
  StageTimer timer;
  timer.profile = r.opt.profile;
  const auto tStart = timer.t;
  r.timings = RenderTimings{};
  const gl::UseApi use(*r.api);
  r.enterCallerContext("draw");
  const gl::GlStateGuard saved(r.glInfo);
  const GLuint fbo = target.framebuffer ? GLuint(*target.framebuffer) : saved.drawFramebuffer();
  GLint viewport[4];
  for (int k = 0; k < 4; ++k) viewport[k] = target.viewport ? (*target.viewport)[std::size_t(k)] : saved.viewport()[k];
  Presenter::check(fbo, viewport);  // before any work
  r.drawFrame(in, timer);
  r.presenter.draw(r.color.tex, r.geo.guard, r.def.width, r.def.height, fbo, viewport);
  gl::throwOnError("while drawing into the caller's framebuffer");
  timer.end(r.timings.present);
  r.timings.total = StageTimer::msSince(tStart);
}

}  // namespace sph2d
