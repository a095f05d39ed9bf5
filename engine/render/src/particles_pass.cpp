// particles_pass.cpp — the particles mode: one anti-aliased disc per particle, coloured by a
// field (speed, pressure, density or age) on the ramp of image.hpp, and a colour bar; or by
// each particle's own colour (the "color" field a game sets, World::setParticleColor).
//
// Design: the field is mapped to 0..1 on the CPU over the frame's min..max (or a fixed range;
// speed and age start at 0) in double precision, so the colours do not depend on the GPU's
// arithmetic; shaders/particles.frag draws the discs one spacing wide (at least 3 px) with
// alpha blending in id order. The colour bar is drawn on the CPU after readback.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "render_pass.hpp"

namespace sph2d {

namespace {

class ParticlesPass final : public RenderPass {
 public:
  ParticlesPass(const RenderOptions& opt, SpriteBatch& sprites) : opt_(opt), sprites_(sprites) {
    discProg_ = gl::program("splat.vert", "particles.frag");
  }

  const char* mode() const override { return "particles"; }
  float spriteDiameter(double spacingPx) const override { return float(std::max(3.0, spacingPx)); }
  std::array<double, 2> range() const override { return range_; }
  void release() override {
    if (discProg_) glDeleteProgram(discProg_);
    discProg_ = 0;
  }

  void prepare(const PassFrame& f) override {
    const RenderInput& in = f.in;
    const Particles& P = in.particles;
    const std::size_t n = f.order.size();
    if (agesOf(in) == nullptr && n > 0 && opt_.colorBy == ColorField::Age)
      throw std::runtime_error("colour by age needs particle ages, and none were given");
    if (ownColors()) {
      // Each particle's own 0xRRGGBB (an integer below 2^24: exact in a float); none: its
      // material's (by index, when the input names that material), else the fluid's.
      const std::uint32_t* own =
          opt_.colorBy == ColorField::Color && P.color.size() == P.size() ? P.color.data() : nullptr;
      const std::uint32_t* mat = P.material.size() == P.size() ? P.material.data() : nullptr;
      const std::vector<std::uint32_t>& matColor = in.materialColors;
      // With mixing, each particle's colour from its concentrations.
      const std::uint32_t* mixed = P.mixedColor.size() == P.size() ? P.mixedColor.data() : nullptr;
      // Colour by material without a material per particle (one material): that material's colour.
      const std::uint32_t none =
          opt_.colorBy == ColorField::Material && !mat && !matColor.empty() ? matColor[0] & 0xFFFFFFu : kFluidColor;
      packed_.resize(n * 4);
      for (std::size_t k = 0; k < n; ++k) {
        const std::size_t i = f.order[k];
        const std::uint32_t c = own && own[i] != 0                ? own[i] & 0xFFFFFFu
                                : mixed                           ? mixed[i] & 0xFFFFFFu
                                : mat && mat[i] < matColor.size() ? matColor[mat[i]] & 0xFFFFFFu
                                                                  : none;
        packed_[4 * k] = P.x[i].x();
        packed_[4 * k + 1] = P.x[i].y();
        packed_[4 * k + 2] = float(c);
        packed_[4 * k + 3] = f.weight[k];
      }
      range_ = {0, 1};
      sprites_.upload(packed_);
      return;
    }
    double lo = 0, hi = 1;
    if (opt_.range) {
      lo = (*opt_.range)[0];
      hi = (*opt_.range)[1];
    } else if (n) {
      lo = hi = valueOf(in, f.order[0]);
      for (std::size_t k = 1; k < n; ++k) {
        const double v = valueOf(in, f.order[k]);
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
      if (opt_.colorBy == ColorField::Speed || opt_.colorBy == ColorField::Age) lo = 0;
    }
    if (!(hi > lo)) hi = lo + 1e-6 * std::max(1.0, std::fabs(lo));
    range_ = {lo, hi};
    const double inv = 1.0 / (hi - lo);
    packed_.resize(n * 4);
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t i = f.order[k];
      packed_[4 * k] = P.x[i].x();
      packed_[4 * k + 1] = P.x[i].y();
      packed_[4 * k + 2] = float((valueOf(in, i) - lo) * inv);
      packed_[4 * k + 3] = f.weight[k];
    }
    sprites_.upload(packed_);
  }

  void draw(const PassFrame& f, StageTimer& timer, RenderTimings& timings) override {
    const float diameter = spriteDiameter(f.spacingPx);
    quads_ = diameter > sprites_.maxPoint();
    f.color.startFrame();
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    sprites_.setUniforms(discProg_, f.scale, f.offset, diameter, f.geo.EW, f.geo.EH, quads_);
    glUniform1i(glGetUniformLocation(discProg_, "uOwnColor"), ownColors() ? 1 : 0);
    sprites_.draw(GLsizei(f.order.size()), quads_);
    glDisable(GL_BLEND);
    timer.end(timings.splat);
  }

  void annotate(Frame& frame, int textScale) const override {
    if (ownColors()) return;  // own colours: no scale to show
    static const char* titles[] = {"SPEED M/S", "PRESSURE PA", "DENSITY KG/M3", "AGE S"};
    drawColorBar(frame, range_[0], range_[1], titles[int(opt_.colorBy)], textScale);
  }

 private:
  /// True when each particle is drawn in a colour of its own or of its material (no scale).
  bool ownColors() const { return opt_.colorBy == ColorField::Color || opt_.colorBy == ColorField::Material; }
  double valueOf(const RenderInput& in, std::size_t i) const {
    const Particles& P = in.particles;
    switch (opt_.colorBy) {
      case ColorField::Speed:
        return double(P.v[i].norm());
      case ColorField::Pressure:
        return double(P.p[i]);
      case ColorField::Density:
        return double(P.rho[i]);
      case ColorField::Age:
        return agesOf(in) ? double(agesOf(in)[i]) : 0.0;
      case ColorField::Color:
      case ColorField::Material:
        return 0.0;
    }
    return 0.0;
  }

  static constexpr std::uint32_t kFluidColor = 0x2F7FD8;  ///< a particle without a colour of its own
  RenderOptions opt_;
  SpriteBatch& sprites_;
  GLuint discProg_ = 0;
  std::array<double, 2> range_{0, 1};
  std::vector<float> packed_;
};

}  // namespace

std::unique_ptr<RenderPass> makeParticlesPass(const RenderDef& /*def*/, const RenderOptions& opt,
                                              SpriteBatch& sprites) {
  return std::make_unique<ParticlesPass>(opt, sprites);
}

}  // namespace sph2d
