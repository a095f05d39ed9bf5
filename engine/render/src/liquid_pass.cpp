// liquid_pass.cpp — the liquid mode: particles → a smooth field → water.
//
// Design: a blobby (metaball) density field, after Blinn, "A Generalization of Algebraic Surface
// Drawing" (1982), cut at an iso-level and shaded in screen space:
//  1. splat: each particle adds w = (1 − q²)³ × its age fade, and w·|v|, into an RG32F target:
//     as a point sprite (shaders/splat.*) with additive blending, or summed on the CPU in the
//     same order and uploaded (cpu_splat.hpp: RenderOptions::splat, the default on a software
//     rasterizer); when sprites are at least 8 px wide the target has half the image's
//     resolution (a quarter of the texels) and the composite reads it bilinearly;
//  2. depth grid: on the CPU, the depth of water above and the local fill (depth_grid.hpp),
//     uploaded as a small RG32F texture, and the tiles of the image the fluid can reach (with
//     the field summed on the CPU, only the cells where it can show water: a lone drop takes
//     a few cells, not the sprite's reach around it);
//  3. composite: over those tiles only, the field becomes water (shaders/composite.frag:
//     thresholded edge, depth colour, shading from the field's gradient, foam); elsewhere the
//     frame keeps its background. The tiles deep in the water take the interior program, which
//     reads the field once instead of five times and draws what the full one draws there.
// With more than one material (RenderInput::materialColors and a material per particle), the
// particles are splatted once more into an RGBA32F tint target (shaders/tint.frag: Σ w·colour,
// Σ w) and the composite (compiled with TINT) takes the surface colour from it: each material
// in its own colour, blended over a kernel's width where two meet. One material: neither the
// pass nor its target exists, and the frame is the one it was.
// A granular material (RenderInput::materialGranular) is no liquid: its particles add nothing
// to the field and the tint, and after the composite each is drawn as a grain, an opaque disc
// one spacing wide (shaders/particles.frag) in its material's colour, lighter or darker by up
// to 15 % by a hash of its id (the same grain keeps its shade). They still count in the depth
// grid's tiles, so the composite rewrites where they were each frame.
// A particle group (Particles::group) is no liquid either: its particles add nothing to the
// water's field and tint but are splatted into a target of their own (shaders/tint.frag: Σ w·
// colour, Σ w; the colour is each particle's own, World::setParticleColor / GroupDef::color, else
// its material's), which a second composite (shaders/blob.frag) draws over the water as solid
// blobs with a darker outline. A frame without group particles has neither pass nor target.
#include <algorithm>
#include <array>
#include <cmath>

#include "cpu_splat.hpp"
#include "depth_grid.hpp"
#include "render_pass.hpp"

namespace sph2d {
namespace {

std::array<float, 3> color3(const std::array<double, 3>& c) { return {float(c[0]), float(c[1]), float(c[2])}; }

class LiquidPass final : public RenderPass {
 public:
  LiquidPass(const RenderDef& def, const RenderOptions& opt, SpriteBatch& sprites)
      : def_(def), opt_(opt), sprites_(sprites) {
    splatProg_ = gl::program("splat.vert", "splat.frag");
    cpuSplat_ = opt.splat == SplatPath::Cpu || (opt.splat == SplatPath::Auto && softwareGl());
    glGenVertexArrays(1, &tileVao_);
    glGenBuffers(1, &tileVbo_);
    glBindVertexArray(tileVao_);
    glBindBuffer(GL_ARRAY_BUFFER, tileVbo_);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
  }

  const char* mode() const override { return "liquid"; }
  const char* splatPath() const override { return cpuSplat_ ? "cpu" : "gl"; }
  float spriteDiameter(double spacingPx) const override { return float(2.0 * def_.splatRadius * spacingPx); }
  int spriteShrink(double spacingPx) const override { return spriteDiameter(spacingPx) >= 8.0f ? 2 : 1; }
  bool solidsBehind() const override { return true; }

  void targetsChanged() override {
    fieldW_ = fieldH_ = 0;  // recreated at the next splat
    tintW_ = tintH_ = blobW_ = blobH_ = absorbW_ = absorbH_ = 0;
    grid_.solidsChanged();
    drawnRows_ = {0, 1 << 30};  // a new colour target: the whole background at the next frame
  }

  void solidsChanged() override {
    grid_.solidsChanged();      // the depth grid's solid mask
    drawnRows_ = {0, 1 << 30};  // the old solids go back to the background everywhere
  }

  void release() override {
    for (GLuint p : {splatProg_, tintProg_, absorbProg_, grainProg_, blobProg_})
      if (p) glDeleteProgram(p);
    for (GLuint& p : compositeProgs_) {
      if (p) glDeleteProgram(p);
      p = 0;
    }
    const GLuint textures[5] = {fieldTex_, auxTex_, tintTex_, blobTex_, absorbTex_};
    glDeleteTextures(5, textures);
    const GLuint fbos[4] = {fieldFbo_, tintFbo_, blobFbo_, absorbFbo_};
    glDeleteFramebuffers(4, fbos);
    glDeleteVertexArrays(1, &tileVao_);
    glDeleteBuffers(1, &tileVbo_);
    splatProg_ = fieldTex_ = auxTex_ = fieldFbo_ = tileVao_ = tileVbo_ = 0;
    tintProg_ = tintTex_ = tintFbo_ = grainProg_ = absorbProg_ = absorbTex_ = absorbFbo_ = 0;
    blobProg_ = blobTex_ = blobFbo_ = 0;
    tintW_ = tintH_ = blobW_ = blobH_ = absorbW_ = absorbH_ = 0;
  }

  /// True when the current context's OpenGL is a software rasterizer: there the CPU sums the
  /// splat (cpu_splat.hpp).
  static bool softwareGl() { return softwareRasterizer(reinterpret_cast<const char*>(glGetString(GL_RENDERER))); }

  /// True for the particle in slot i when its material is granular (drawn as a grain).
  static bool grainAt(const RenderInput& in, std::size_t i) {
    const std::vector<std::uint8_t>& g = in.materialGranular;
    if (g.empty()) return false;
    const Particles& P = in.particles;
    const std::uint32_t m = P.material.size() == P.size() ? P.material[i] : 0u;
    return m < g.size() && g[m];
  }

  /// True for the particle in slot i when it is in a particle group (drawn in a blob).
  static bool blobAt(const RenderInput& in, std::size_t i) {
    const Particles& P = in.particles;
    return P.group.size() == P.size() && P.group[i] != 0;
  }

  /// The colour of a group's particle: its own, else its material's, else the water's.
  std::uint32_t blobColor(const RenderInput& in, std::size_t i) const {
    const Particles& P = in.particles;
    if (P.color.size() == P.size() && P.color[i]) return P.color[i] & 0xFFFFFFu;
    const std::uint32_t m = P.material.size() == P.size() ? P.material[i] : 0u;
    if (m < in.materialColors.size()) return in.materialColors[m] & 0xFFFFFFu;
    std::uint32_t c = 0;
    for (const double v : def_.water) c = (c << 8) | std::uint32_t(std::lround(std::clamp(v, 0.0, 1.0) * 255));
    return c;
  }

  void prepare(const PassFrame& f) override {
    const Particles& P = f.in.particles;
    const std::size_t n = f.order.size();
    packed_.resize(n * 4);
    grains_.clear();
    blobs_.clear();
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t i = f.order[k];
      const bool grain = grainAt(f.in, i);
      const bool blob = !grain && blobAt(f.in, i);
      packed_[4 * k] = P.x[i].x();
      packed_[4 * k + 1] = P.x[i].y();
      packed_[4 * k + 2] = P.v[i].norm();
      packed_[4 * k + 3] = grain || blob ? 0.0f : f.weight[k];
      if (blob) blobs_.insert(blobs_.end(), {P.x[i].x(), P.x[i].y(), float(blobColor(f.in, i)), f.weight[k]});
      if (grain) {
        const std::uint32_t m = P.material.size() == P.size() ? P.material[i] : 0u;
        const std::uint32_t base = m < f.in.materialColors.size() ? f.in.materialColors[m] : 0xC8A870u;
        std::uint32_t h = P.id.size() == P.size() ? P.id[i] * 2654435761u : std::uint32_t(i) * 2654435761u;
        h ^= h >> 16;
        const double shade = 0.85 + 0.3 * double(h & 1023u) / 1023.0;  // 0.85 .. 1.15
        std::uint32_t c = 0;
        for (int s = 16; s >= 0; s -= 8)
          c = (c << 8) | std::uint32_t(std::min(255.0, std::round(double((base >> s) & 255u) * shade)));
        grains_.insert(grains_.end(), {P.x[i].x(), P.x[i].y(), float(c), f.weight[k]});
      }
    }
    // More than one material: each particle's material colour too (uploaded by splat()).
    const std::vector<std::uint32_t>& colors = f.in.materialColors;
    tinted_ = !colors.empty() && P.material.size() == P.size();
    if (tinted_) {
      const std::uint32_t* mixed = P.mixedColor.size() == P.size() ? P.mixedColor.data() : nullptr;  // mixing
      packedTint_.resize(n * 4);
      for (std::size_t k = 0; k < n; ++k) {
        const std::size_t i = f.order[k];
        const std::uint32_t m = P.material[i];
        packedTint_[4 * k] = P.x[i].x();
        packedTint_[4 * k + 1] = P.x[i].y();
        packedTint_[4 * k + 2] = float(mixed ? mixed[i] & 0xFFFFFFu : m < colors.size() ? colors[m] & 0xFFFFFFu : 0u);
        packedTint_[4 * k + 3] = grainAt(f.in, i) || blobAt(f.in, i) ? 0.0f : f.weight[k];
      }
    }
    chooseTransmission(f);
    const int EW = f.geo.EW, EH = f.geo.EH;
    if (grid_.resize(EW, EH, f.spacingPx))
      gl::makeTexture(auxTex_, GL_RG32F, GL_RG, GL_FLOAT, grid_.width(), grid_.height(), GL_LINEAR);
    // Grains and groups' particles add nothing to the field: the deep cells are the field's.
    const bool onlyLiquid = grains_.empty() && blobs_.empty();
    if (!onlyLiquid) {
      liquidWeight_.resize(n);
      for (std::size_t k = 0; k < n; ++k) liquidWeight_[k] = packed_[4 * k + 3];
    }
    grid_.build(f.in, f.geo.ext, f.pxPerM, f.order, f.weight, onlyLiquid ? nullptr : &liquidWeight_);
  }

  std::pair<int, int> changedRows() const override { return changedRows_; }
  void restoreRows(std::pair<int, int> rows) override {
    if (rows.first >= rows.second) return;
    if (drawnRows_.first >= drawnRows_.second)
      drawnRows_ = rows;
    else
      drawnRows_ = {std::min(drawnRows_.first, rows.first), std::max(drawnRows_.second, rows.second)};
  }

  void draw(const PassFrame& f, StageTimer& timer, RenderTimings& timings) override {
    splat(f);
    timer.end(timings.splat);
    layTiles(f);
    composite(f);
    if (anyDiffuse()) drawDiffuse(f);
    if (!blobs_.empty()) drawBlobs(f);
    if (!grains_.empty()) drawGrains(f);
    timer.end(timings.composite);
  }

 private:
  /// Makes the float target `fbo` (texture `tex`, now w × h) fw × fh when its size changed
  /// (then returns true), sampled bilinearly when the field is shrunk: the splat field (RG), the
  /// tint and the blobs (RGBA).
  static bool sizeTarget(GLenum internal, GLenum format, int fw, int fh, int shrink, GLuint& fbo, GLuint& tex, int& w,
                         int& h) {
    if (fw == w && fh == h) return false;
    if (fbo) glDeleteFramebuffers(1, &fbo);
    fbo = gl::target(internal, format, GL_FLOAT, fw, fh, tex);
    const GLint filter = shrink > 1 ? GL_LINEAR : GL_NEAREST;
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
    w = fw;
    h = fh;
    return true;
  }

  /// Σw and Σw·speed into the RG32F field (shaders/splat.* or the CPU's sums); at half
  /// resolution when sprites are at least 8 px wide (the composite samples it bilinearly).
  /// Then, alike, the materials' colours, their transmissions and the groups' particles into
  /// their RGBA32F targets, when the frame has them.
  void splat(const PassFrame& f) {
    const int EW = f.geo.EW, EH = f.geo.EH;
    const int shrink = spriteShrink(f.spacingPx);
    SplatTarget t;
    t.w = (EW + shrink - 1) / shrink;
    t.h = (EH + shrink - 1) / shrink;
    t.shrink = shrink;
    t.diameter = spriteDiameter(f.spacingPx) * float(t.w) / float(EW);
    quads_ = !cpuSplat_ && t.diameter > sprites_.maxPoint();
    glViewport(0, 0, t.w, t.h);
    glClearColor(0, 0, 0, 0);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    const std::size_t n = f.order.size();
    fillTarget(f, t, SplatSum::Field, splatProg_, packed_, n, cpuTargets_[0], fieldFbo_, fieldTex_, fieldW_, fieldH_);
    if (tinted_) {  // the materials' colours
      if (!tintProg_) tintProg_ = gl::program("splat.vert", "tint.frag");
      fillTarget(f, t, SplatSum::Tint, tintProg_, packedTint_, n, cpuTargets_[1], tintFbo_, tintTex_, tintW_, tintH_);
    }
    if (perMaterial_) {  // the materials' transmissions
      if (!absorbProg_) absorbProg_ = gl::program("splat.vert", "tint.frag", "#define ABSORB\n");
      fillTarget(f, t, SplatSum::Absorb, absorbProg_, packedAbsorb_, n, cpuTargets_[2], absorbFbo_, absorbTex_,
                 absorbW_, absorbH_);
    }
    if (!blobs_.empty()) {  // the groups' particles, in their colours
      if (!tintProg_) tintProg_ = gl::program("splat.vert", "tint.frag");
      fillTarget(f, t, SplatSum::Tint, tintProg_, blobs_, blobs_.size() / 4, cpuTargets_[3], blobFbo_, blobTex_, blobW_,
                 blobH_);
    }
    glDisable(GL_BLEND);
    glViewport(0, 0, EW, EH);
  }

  /// The composite's tiles (DepthGrid::tiles) and the depth grid's upload; with the field
  /// summed on the CPU and nothing but liquid in the frame (no grains, no groups' blobs, which
  /// are drawn over the tiles' rows), only the cells where the field can show water
  /// (DepthGrid::markVisible) take tiles. The frame is the same either way.
  void layTiles(const PassFrame& f) {
    const bool byField = cpuSplat_ && grains_.empty() && blobs_.empty();
    if (byField)
      grid_.markVisible(cpuTargets_[0].texels(), fieldW_, fieldH_, f.geo.EW, f.geo.EH,
                        float(std::max(1.0, 0.75 * f.spacingPx)), bulk(f));
    std::size_t interiorFirst = 0;
    tileRows_ = grid_.tiles(float(def_.splatRadius * f.spacingPx), f.geo.EW, f.geo.EH, tiles_, interiorFirst, byField);
    glBindTexture(GL_TEXTURE_2D, auxTex_);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, grid_.width(), grid_.height(), GL_RG, GL_FLOAT, grid_.aux().data());
    packDiffuse(f);
    tileVertices_ = GLsizei(tiles_.size() / 2);
    interiorFirst_ = GLsizei(interiorFirst);
    glBindBuffer(GL_ARRAY_BUFFER, tileVbo_);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(tiles_.size() * sizeof(float)), tiles_.empty() ? nullptr : tiles_.data(),
                 GL_STREAM_DRAW);
  }

  /// The size of this frame's splat targets and the sprites' diameter in their texels.
  struct SplatTarget {
    int w = 0, h = 0, shrink = 1;
    float diameter = 0;
  };

  /// One splat target (`fbo`, `tex`, made t.w × t.h when its size changed) filled with the first
  /// `n` sprites of `packed`: drawn by `prog` with additive blending (the caller's), or summed
  /// on the CPU into `cpu` (cpu_splat.hpp) and its changed rows uploaded.
  void fillTarget(const PassFrame& f, const SplatTarget& t, SplatSum kind, GLuint prog,
                  const std::vector<float>& packed, std::size_t n, CpuSplatTarget& cpu, GLuint& fbo, GLuint& tex,
                  int& w, int& h) {
    const bool rg = kind == SplatSum::Field;
    if (sizeTarget(rg ? GL_RG32F : GL_RGBA32F, rg ? GL_RG : GL_RGBA, t.w, t.h, t.shrink, fbo, tex, w, h)) cpu.reset();
    if (cpuSplat_) {
      // The GL draws a point at least its smallest size wide (1 px on llvmpipe): so does the CPU.
      const auto [y0, y1] =
          cpu.sum(packed, n, f.scale, f.offset, std::max(t.diameter, sprites_.minPoint()), t.w, t.h, kind);
      if (y0 >= y1) return;
      glBindTexture(GL_TEXTURE_2D, tex);
      glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
      const std::size_t rowFloats = std::size_t(t.w) * std::size_t(splatChannels(kind));
      glTexSubImage2D(GL_TEXTURE_2D, 0, 0, y0, t.w, y1 - y0, rg ? GL_RG : GL_RGBA, GL_FLOAT,
                      cpu.texels() + std::size_t(y0) * rowFloats);
      return;
    }
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glClear(GL_COLOR_BUFFER_BIT);
    sprites_.upload(packed);
    sprites_.setUniforms(prog, f.scale, f.offset, t.diameter, t.w, t.h, quads_);
    sprites_.draw(GLsizei(n), quads_);
  }

  /// Foam, spray and bubbles' sprites (x, y, colour, alpha; one list per kind), and the target
  /// rows they cover joined to the tiles' (where the next frame starts from the backdrop again).
  void packDiffuse(const PassFrame& f) {
    for (auto& v : diffuse_) v.clear();
    const DiffuseParticles& d = f.in.diffuse;
    if (d.size() == 0) return;
    const double radius = 0.5 * diffuseDiameter(f, 1) + 1;  // foam's: the largest
    int lo = f.geo.EH, hi = 0;
    for (std::size_t k = 0; k < d.size(); ++k) {
      // White spray and foam, pale blue bubbles (dimmer: seen through the water).
      static const std::uint32_t kColor[3] = {0xF0F6FFu, 0xF8FAFCu, 0xDCEEFFu};
      static const float kAlpha[3] = {0.9f, 0.95f, 0.6f};
      const int kind = std::min(2, int(d.kind[k]));
      const float life = float(d.life[k]), age = float(d.age[k]);
      const float t = std::min(1.0f, std::max(0.0f, (age - 0.7f * life) / std::max(0.3f * life, 1e-6f)));
      const float alpha = kAlpha[kind] * (1.0f - t * t * (3.0f - 2.0f * t));
      const Vec2& x = d.x[k];
      diffuse_[std::size_t(kind)].insert(diffuse_[std::size_t(kind)].end(), {x.x(), x.y(), float(kColor[kind]), alpha});
      const double ndcY = double(x.y()) * f.scale[1] + f.offset[1];
      const double row = (ndcY + 1) * 0.5 * f.geo.EH;
      if (!(row > -radius && row < f.geo.EH + radius)) continue;
      lo = std::min(lo, int(std::floor(row - radius)));
      hi = std::max(hi, int(std::ceil(row + radius)));
    }
    lo = std::max(lo, 0);
    hi = std::min(hi, f.geo.EH);
    if (lo < hi)
      tileRows_ = tileRows_.first < tileRows_.second
                      ? std::pair<int, int>{std::min(tileRows_.first, lo), std::max(tileRows_.second, hi)}
                      : std::pair<int, int>{lo, hi};
  }

  /// A diffuse particle's disc [px]: spray 0.8 spacings, foam 1.2, bubbles 0.8 (at least 2 px).
  static float diffuseDiameter(const PassFrame& f, int kind) {
    return float(std::max(2.0, (kind == 1 ? 1.2 : 0.8) * f.spacingPx));
  }

  bool anyDiffuse() const { return !diffuse_[0].empty() || !diffuse_[1].empty() || !diffuse_[2].empty(); }

  /// The diffuse particles over the water, each a small disc (shaders/particles.frag): bubbles,
  /// then spray, then foam on top.
  void drawDiffuse(const PassFrame& f) {
    if (!grainProg_) grainProg_ = gl::program("splat.vert", "particles.frag");
    glViewport(0, 0, f.geo.EW, f.geo.EH);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    for (const int kind : {2, 0, 1}) {
      const std::vector<float>& s = diffuse_[std::size_t(kind)];
      if (s.empty()) continue;
      const float diameter = diffuseDiameter(f, kind);
      const bool quads = diameter > sprites_.maxPoint();
      sprites_.upload(s);
      sprites_.setUniforms(grainProg_, f.scale, f.offset, diameter, f.geo.EW, f.geo.EH, quads);
      glUniform1i(glGetUniformLocation(grainProg_, "uOwnColor"), 1);
      sprites_.draw(GLsizei(s.size() / 4), quads);
    }
    glDisable(GL_BLEND);
  }

  /// The groups' blobs over the water (shaders/blob.frag), over the tiles the fluid can reach.
  void drawBlobs(const PassFrame& f) {
    if (!blobProg_) blobProg_ = gl::program("solid.vert", "blob.frag");
    glViewport(0, 0, f.geo.EW, f.geo.EH);
    glUseProgram(blobProg_);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, blobTex_);
    glUniform1i(gl::uniform(blobProg_, "uBlob"), 0);
    glUniform2f(gl::uniform(blobProg_, "uTexel"), 1.0f / float(f.geo.EW), 1.0f / float(f.geo.EH));
    glUniform1f(gl::uniform(blobProg_, "uInvBulk"), 1.0f / bulk(f));
    glUniform1f(gl::uniform(blobProg_, "uOutlinePx"), float(std::clamp(0.35 * f.spacingPx, 1.5, 4.0)));
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    glBindVertexArray(tileVao_);
    if (tileVertices_) glDrawArrays(GL_TRIANGLES, 0, tileVertices_);
    glDisable(GL_BLEND);
  }

  /// The field's value inside a bulk of particles: Σ (1 − q²)³ over a square lattice ≈ π s²/4,
  /// s = the sprite's radius in spacings.
  float bulk(const PassFrame& f) const {
    const float rs = float(spriteDiameter(f.spacingPx) * 0.5 / f.spacingPx);
    return std::max(1e-3f, 3.14159265f * rs * rs / 4.0f);
  }

  /// The granular particles, each a disc one spacing wide in its shade of its material's colour.
  void drawGrains(const PassFrame& f) {
    if (!grainProg_) grainProg_ = gl::program("splat.vert", "particles.frag");
    const float diameter = float(std::max(3.0, f.spacingPx));
    const bool quads = diameter > sprites_.maxPoint();
    sprites_.upload(grains_);
    glViewport(0, 0, f.geo.EW, f.geo.EH);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    sprites_.setUniforms(grainProg_, f.scale, f.offset, diameter, f.geo.EW, f.geo.EH, quads);
    glUniform1i(glGetUniformLocation(grainProg_, "uOwnColor"), 1);
    sprites_.draw(GLsizei(grains_.size() / 4), quads);
    glDisable(GL_BLEND);
  }

  /// This frame's transmission: each material's own (RenderInput::materialTransmission) where
  /// materials of different transmission meet, splatted like their colours (packedAbsorb_: each
  /// one's 8 bits a channel); else the one they share, or the render's. `seeThrough_` when any
  /// lets something through: the composite's SEE_THROUGH (without it the program neither samples
  /// the backdrop nor mixes it in).
  void chooseTransmission(const PassFrame& f) {
    const auto& mt = f.in.materialTransmission;
    transmission_ = mt.empty() ? color3(def_.transmission) : mt.front();
    perMaterial_ = false;
    bool any = false;
    for (const auto& t : mt) {
      perMaterial_ = perMaterial_ || t != mt.front();
      any = any || t[0] > 0 || t[1] > 0 || t[2] > 0;
    }
    perMaterial_ = perMaterial_ && tinted_;
    seeThrough_ = transmission_[0] > 0 || transmission_[1] > 0 || transmission_[2] > 0 || (perMaterial_ && any);
    if (!perMaterial_) return;
    const Particles& P = f.in.particles;
    const std::size_t n = f.order.size();
    packedAbsorb_.resize(n * 4);
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t i = f.order[k];
      const std::uint32_t m = P.material[i];
      std::uint32_t c = 0;
      for (int ch = 0; ch < 3; ++ch)
        c = (c << 8) | std::uint32_t(std::lround(std::clamp(m < mt.size() ? mt[m][ch] : 0.0f, 0.0f, 1.0f) * 255));
      packedAbsorb_[4 * k] = packedTint_[4 * k];
      packedAbsorb_[4 * k + 1] = packedTint_[4 * k + 1];
      packedAbsorb_[4 * k + 2] = float(c);
      packedAbsorb_[4 * k + 3] = packedTint_[4 * k + 3];
    }
  }

  /// The composite's program for this frame (TINT, SEE_THROUGH, MATERIAL_T; INTERIOR: the
  /// interior tiles' program), compiled at first use.
  GLuint compositeProgram(bool interior) {
    const int key = (tinted_ ? 1 : 0) | (seeThrough_ ? 2 : 0) | (perMaterial_ ? 4 : 0) | (interior ? 8 : 0);
    GLuint& p = compositeProgs_[std::size_t(key)];
    if (!p)
      p = gl::program("solid.vert", "composite.frag",
                      std::string(tinted_ ? "#define TINT\n" : "") + (seeThrough_ ? "#define SEE_THROUGH\n" : "") +
                          (perMaterial_ ? "#define MATERIAL_T\n" : "") + (interior ? "#define INTERIOR\n" : ""));
    return p;
  }

  /// The field becomes water over the tiles the fluid can reach (shaders/composite.frag): the
  /// full program over the tiles at the surface, the interior program over the rest.
  void composite(const PassFrame& f) {
    const int EH = f.geo.EH;
    // The colour target still holds the last frame: background and solids, and water over the
    // rows its tiles covered. Only those rows go back to the background; the tiles of this
    // frame write every pixel they cover.
    f.color.startFrameRows(drawnRows_.first, std::min(drawnRows_.second, EH));
    changedRows_ = drawnRows_;
    if (tileRows_.first < tileRows_.second) {
      changedRows_.first =
          changedRows_.first < changedRows_.second ? std::min(changedRows_.first, tileRows_.first) : tileRows_.first;
      changedRows_.second = std::max(changedRows_.second, tileRows_.second);
    }
    drawnRows_ = tileRows_;
    glBindVertexArray(tileVao_);
    if (interiorFirst_ > 0) {
      useComposite(f, compositeProgram(false));
      glDrawArrays(GL_TRIANGLES, 0, interiorFirst_);
    }
    if (tileVertices_ > interiorFirst_) {
      useComposite(f, compositeProgram(true));
      glDrawArrays(GL_TRIANGLES, interiorFirst_, tileVertices_ - interiorFirst_);
    }
  }

  /// Makes `cp` (a composite program) current with this frame's textures and uniforms.
  void useComposite(const PassFrame& f, GLuint cp) {
    const int EW = f.geo.EW, EH = f.geo.EH;
    glUseProgram(cp);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, fieldTex_);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, auxTex_);
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D, f.color.source);
    glActiveTexture(GL_TEXTURE4);
    glBindTexture(GL_TEXTURE_2D, f.color.plain);
    glUniform1i(gl::uniform(cp, "uPlain"), 4);
    if (tinted_) {
      glActiveTexture(GL_TEXTURE3);
      glBindTexture(GL_TEXTURE_2D, tintTex_);
      glUniform1i(gl::uniform(cp, "uTint"), 3);
    }
    if (perMaterial_) {
      glActiveTexture(GL_TEXTURE5);
      glBindTexture(GL_TEXTURE_2D, absorbTex_);
      glUniform1i(gl::uniform(cp, "uAbsorb"), 5);
    }
    glActiveTexture(GL_TEXTURE0);
    glUniform1i(gl::uniform(cp, "uField"), 0);
    glUniform1i(gl::uniform(cp, "uAux"), 1);
    glUniform1i(gl::uniform(cp, "uBg"), 2);
    glUniform2f(gl::uniform(cp, "uAuxScale"), float(EW) / float(grid_.width() * grid_.cell()),
                float(EH) / float(grid_.height() * grid_.cell()));
    glUniform2f(gl::uniform(cp, "uTexel"), 1.0f / float(EW), 1.0f / float(EH));
    glUniform1f(gl::uniform(cp, "uInvBulk"), 1.0f / bulk(f));
    const auto water = color3(def_.water);
    const std::array<float, 3> deep = opt_.deepWater
                                          ? color3(*opt_.deepWater)
                                          : std::array<float, 3>{water[0] * 0.3f, water[1] * 0.3f, water[2] * 0.3f};
    const auto foam = color3(foamColor(opt_));
    glUniform3fv(gl::uniform(cp, "uWater"), 1, water.data());
    glUniform3fv(gl::uniform(cp, "uDeep"), 1, deep.data());
    glUniform3fv(gl::uniform(cp, "uFoam"), 1, foam.data());
    const double depthScale = opt_.depthScale > 0 ? opt_.depthScale : 1.0;
    glUniform1f(gl::uniform(cp, "uInvDepth"), float(1.0 / depthScale));
    const double camH = f.geo.cam[3] - f.geo.cam[1];
    const double foamLo = opt_.foamSpeed > 0 ? opt_.foamSpeed : 0.35 * std::sqrt(std::max(f.in.gravity, 1e-6) * camH);
    glUniform2f(gl::uniform(cp, "uFoamSpeed"), float(foamLo), float(2 * foamLo));
    glUniform1f(gl::uniform(cp, "uSpacingPx"), float(f.spacingPx));
    glUniform1f(gl::uniform(cp, "uTapPx"), float(std::max(1.0, 0.75 * f.spacingPx)));
    // Beer–Lambert per channel: ln of what a full layer lets through (a floor for a channel it
    // stops). Without SEE_THROUGH the uniforms are not in the program (location −1: ignored).
    float logT[3];
    for (int k = 0; k < 3; ++k) logT[k] = float(std::log(std::max(double(transmission_[std::size_t(k)]), 1e-9)));
    glUniform3fv(gl::uniform(cp, "uLogTransmission"), 1, logT);
    const auto bgColor = color3(def_.background);
    glUniform3fv(gl::uniform(cp, "uBgColor"), 1, bgColor.data());
    // The field's steepest slope, across the straight edge of a bulk, is (32/35) r / (π r²/4)
    // = 1.164/r per pixel (r = the sprite's radius in pixels; the kernel (1 − q²)³'s integral
    // across the edge over its integral over the disc): the shift in pixels per unit of slope
    // that makes the steepest shift `refraction` spacings.
    const double rPx = def_.splatRadius * f.spacingPx;
    glUniform1f(gl::uniform(cp, "uRefractPx"), float(def_.refraction * f.spacingPx * rPx / 1.164));
  }

  RenderDef def_;
  RenderOptions opt_;
  SpriteBatch& sprites_;
  GLuint splatProg_ = 0;
  bool cpuSplat_ = false;                     // the splat targets summed on the CPU (cpu_splat.hpp), not drawn
  std::array<CpuSplatTarget, 4> cpuTargets_;  // theirs: the field, tint, transmissions, blobs
  // More than one material (made on the first such frame): the tint pass and its target.
  GLuint tintProg_ = 0, tintTex_ = 0, tintFbo_ = 0;
  int tintW_ = 0, tintH_ = 0;
  // Each material's transmission where they differ: its splat target and packing (chooseTransmission).
  GLuint absorbProg_ = 0, absorbTex_ = 0, absorbFbo_ = 0;
  int absorbW_ = 0, absorbH_ = 0;
  std::vector<float> packedAbsorb_;
  bool perMaterial_ = false, seeThrough_ = false;
  std::array<float, 3> transmission_{0, 0, 0};
  std::array<GLuint, 16> compositeProgs_{};  // by TINT | SEE_THROUGH | MATERIAL_T | INTERIOR
  bool tinted_ = false;                      // this frame draws each material in its colour
  GLuint grainProg_ = 0;                     // the grains' discs (made on the first frame with grains)
  // Particle groups (made on the first frame with one): their splat target and composite.
  GLuint blobProg_ = 0, blobTex_ = 0, blobFbo_ = 0;
  int blobW_ = 0, blobH_ = 0;
  std::vector<float> blobs_;       // group particles (x, y, colour, weight) in id order
  std::vector<float> grains_;      // granular particles (x, y, shaded colour, weight) in id order
  std::vector<float> packedTint_;  // particles (x, y, material colour, weight) in id order
  GLuint fieldTex_ = 0, fieldFbo_ = 0, auxTex_ = 0, tileVao_ = 0, tileVbo_ = 0;
  int fieldW_ = 0, fieldH_ = 0;  // the splat target: full resolution, or half when sprites are wide
  GLsizei tileVertices_ = 0;
  GLsizei interiorFirst_ = 0;                    // the interior tiles' first vertex (DepthGrid::tiles)
  std::array<std::vector<float>, 3> diffuse_;    // spray, foam, bubbles: x, y, colour, alpha (packDiffuse)
  std::pair<int, int> tileRows_{0, 0};           // target rows this frame's tiles cover
  std::pair<int, int> drawnRows_{0, 1 << 30};    // rows of the colour target that are not background
  std::pair<int, int> changedRows_{0, 1 << 30};  // rows the last composite restored or drew
  std::vector<float> packed_, tiles_;            // particles (x, y, speed, weight) in id order; tile quads
  std::vector<float> liquidWeight_;              // the field's weights in id order (with grains or blobs)
  DepthGrid grid_;
};

}  // namespace

std::unique_ptr<RenderPass> makeLiquidPass(const RenderDef& def, const RenderOptions& opt, SpriteBatch& sprites) {
  return std::make_unique<LiquidPass>(def, opt, sprites);
}

}  // namespace sph2d
