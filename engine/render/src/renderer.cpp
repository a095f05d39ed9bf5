#define GL_GLEXT_PROTOTYPES 1
#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "sph2d/render/renderer.hpp"
#include "sph2d/world.hpp"

namespace sph2d {

const std::map<std::string, std::string>& embeddedShaders();

namespace {

/// Shader text: $SPH2D_SHADER_DIR/name when that is set (for shader work), else the embedded copy.
std::string shaderSource(const std::string& name) {
  if (const char* dir = std::getenv("SPH2D_SHADER_DIR")) {
    std::ifstream in(std::string(dir) + "/" + name);
    if (in) {
      std::ostringstream s;
      s << in.rdbuf();
      return s.str();
    }
  }
  const auto& m = embeddedShaders();
  auto it = m.find(name);
  if (it == m.end()) throw std::runtime_error("shader " + name + " is missing from the build");
  return it->second;
}

GLuint compile(GLenum type, const std::string& name) {
  const std::string src = shaderSource(name);
  GLuint s = glCreateShader(type);
  const char* p = src.c_str();
  glShaderSource(s, 1, &p, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    throw std::runtime_error("shader " + name + " does not compile: " + log);
  }
  return s;
}

GLuint program(const std::string& vs, const std::string& fs) {
  GLuint p = glCreateProgram();
  GLuint a = compile(GL_VERTEX_SHADER, vs), b = compile(GL_FRAGMENT_SHADER, fs);
  glAttachShader(p, a);
  glAttachShader(p, b);
  glLinkProgram(p);
  glDeleteShader(a);
  glDeleteShader(b);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetProgramInfoLog(p, sizeof log, nullptr, log);
    throw std::runtime_error("shaders " + vs + " + " + fs + " do not link: " + log);
  }
  return p;
}

GLuint target(GLenum internal, GLenum format, GLenum type, int w, int h, GLuint& tex) {
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glTexImage2D(GL_TEXTURE_2D, 0, GLint(internal), w, h, 0, format, type, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  GLuint fbo = 0;
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error("OSMesa: incomplete framebuffer");
  return fbo;
}

}  // namespace

std::vector<double> resolveCamera(const RenderDef& def, const World& world) {
  double x0, y0, x1, y1;
  if (!def.camera.automatic) {
    x0 = def.camera.min.x();
    y0 = def.camera.min.y();
    x1 = def.camera.max.x();
    y1 = def.camera.max.y();
  } else {
    bool any = false;
    Vec2d lo(0, 0), hi(0, 0);
    auto grow = [&](double x, double y) {
      const Vec2d p(x, y);
      lo = any ? lo.cwiseMin(p) : p;
      hi = any ? hi.cwiseMax(p) : p;
      any = true;
    };
    const Vec2d o = world.origin();
    for (const Collider& c : world.colliders()) {
      grow(c.lo.x() + o.x(), c.lo.y() + o.y());
      grow(c.hi.x() + o.x(), c.hi.y() + o.y());
    }
    const Particles& P = world.particles();
    for (std::size_t i = 0; i < P.size(); ++i) grow(P.x[i].x() + o.x(), P.x[i].y() + o.y());
    if (!any) {
      lo = Vec2d(-1, -1);
      hi = Vec2d(1, 1);
    }
    const double m = 0.04 * std::max(hi.x() - lo.x(), hi.y() - lo.y()) + 1e-3;
    x0 = lo.x() - m;
    y0 = lo.y() - m;
    x1 = hi.x() + m;
    y1 = hi.y() + m;
  }
  const double aspect = double(def.width) / double(def.height);
  double w = x1 - x0, h = y1 - y0;
  if (w / h < aspect) {
    const double nw = h * aspect;
    x0 -= (nw - w) / 2;
    x1 += (nw - w) / 2;
  } else {
    const double nh = w / aspect;
    y0 -= (nh - h) / 2;
    y1 += (nh - h) / 2;
  }
  return {x0, y0, x1, y1};
}

struct Renderer::Impl {
  RenderDef def;
  OSMesaContext ctx = nullptr;
  unsigned char dummy[4] = {0, 0, 0, 0};
  GLuint fieldTex = 0, fieldFbo = 0, colorTex = 0, colorFbo = 0;
  GLuint splatProg = 0, compositeProg = 0, particleProg = 0, solidProg = 0;
  GLuint vao = 0, posVbo = 0, valVbo = 0, solidVao = 0, solidVbo = 0, emptyVao = 0;
  GLsizei solidCount = 0;
  bool solidsBuilt = false;
  std::vector<double> cam;
  Frame frame;
  std::vector<float> values;
  std::string rendererName;

  void makeCurrent() {
    if (!OSMesaMakeCurrent(ctx, dummy, GL_UNSIGNED_BYTE, 1, 1)) throw std::runtime_error("OSMesaMakeCurrent failed");
  }

  void buildSolids(const World& world) {
    // Triangles in NDC (the camera is fixed for a run).
    const Vec2d o = world.origin();
    const double sx = 2.0 / (cam[2] - cam[0]), sy = -2.0 / (cam[3] - cam[1]);
    auto ndc = [&](const Vec2& p) {
      return std::array<float, 2>{float((p.x() + o.x() - cam[0]) * sx - 1.0), float(1.0 - (p.y() + o.y() - cam[1]) * (-sy))};
    };
    std::vector<float> tri;
    auto put = [&](const std::array<float, 2>& a) {
      tri.push_back(a[0]);
      tri.push_back(a[1]);
    };
    const double pxX = 2.0 / def.width, pxY = 2.0 / def.height;
    for (const Collider& c : world.colliders()) {
      if (c.kind == Collider::Kind::Polygon) {
        for (std::size_t k = 1; k + 1 < c.vertices.size(); ++k) {
          put(ndc(c.vertices[0]));
          put(ndc(c.vertices[k]));
          put(ndc(c.vertices[k + 1]));
        }
      } else if (c.kind == Collider::Kind::Circle) {
        const int n = 64;
        for (int k = 0; k < n; ++k) {
          const Real a0 = 2 * kPi<Real> * Real(k) / n, a1 = 2 * kPi<Real> * Real(k + 1) / n;
          put(ndc(c.center));
          put(ndc(c.center + c.radius * Vec2(std::cos(a0), std::sin(a0))));
          put(ndc(c.center + c.radius * Vec2(std::cos(a1), std::sin(a1))));
        }
      } else {
        // A zero-thickness segment drawn 3 px wide.
        const auto a = ndc(c.vertices[0]), b = ndc(c.vertices[1]);
        double dxp = (b[0] - a[0]) / pxX, dyp = (b[1] - a[1]) / pxY;
        const double len = std::sqrt(dxp * dxp + dyp * dyp);
        if (len <= 0) continue;
        const double nxp = -dyp / len * 1.5, nyp = dxp / len * 1.5;
        const float ox = float(nxp * pxX), oy = float(nyp * pxY);
        const std::array<float, 2> p0{a[0] + ox, a[1] + oy}, p1{a[0] - ox, a[1] - oy}, p2{b[0] + ox, b[1] + oy},
            p3{b[0] - ox, b[1] - oy};
        put(p0);
        put(p1);
        put(p2);
        put(p2);
        put(p1);
        put(p3);
      }
    }
    solidCount = GLsizei(tri.size() / 2);
    glBindVertexArray(solidVao);
    glBindBuffer(GL_ARRAY_BUFFER, solidVbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(tri.size() * sizeof(float)), tri.data(), GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
    solidsBuilt = true;
  }
};

Renderer::Renderer(const RenderDef& def) : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.def = def;
  // Hermetic runs: no shader cache under $HOME.
  setenv("MESA_SHADER_CACHE_DISABLE", "true", 0);
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

  r.fieldFbo = target(GL_R32F, GL_RED, GL_FLOAT, def.width, def.height, r.fieldTex);
  r.colorFbo = target(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, def.width, def.height, r.colorTex);
  r.splatProg = program("splat.vert", "splat.frag");
  r.compositeProg = program("fullscreen.vert", "composite.frag");
  r.particleProg = program("splat.vert", "particles.frag");
  r.solidProg = program("solid.vert", "solid.frag");

  glGenVertexArrays(1, &r.vao);
  glGenBuffers(1, &r.posVbo);
  glGenBuffers(1, &r.valVbo);
  glGenVertexArrays(1, &r.solidVao);
  glGenBuffers(1, &r.solidVbo);
  glGenVertexArrays(1, &r.emptyVao);
  glEnable(GL_PROGRAM_POINT_SIZE);
  r.frame.width = def.width;
  r.frame.height = def.height;
  r.frame.rgba.assign(std::size_t(def.width) * def.height * 4, 0);
}

Renderer::~Renderer() {
  if (impl_ && impl_->ctx) OSMesaDestroyContext(impl_->ctx);
}

std::string Renderer::rendererString() const { return impl_->rendererName; }
std::vector<double> Renderer::cameraRect() const { return impl_->cam; }

const Frame& Renderer::render(const World& world) {
  Impl& r = *impl_;
  r.makeCurrent();
  const RenderDef& d = r.def;
  if (r.cam.empty()) r.cam = resolveCamera(d, world);
  if (!r.solidsBuilt) r.buildSolids(world);

  const Particles& P = world.particles();
  const Vec2d o = world.origin();
  const double camW = r.cam[2] - r.cam[0], camH = r.cam[3] - r.cam[1];
  const float scale[2] = {float(2.0 / camW), float(-2.0 / camH)};
  const float offset[2] = {float((o.x() - r.cam[0]) * 2.0 / camW - 1.0), float(1.0 - (o.y() - r.cam[1]) * 2.0 / camH)};
  const double pxPerM = d.width / camW;
  const float radiusPx = float(d.splatRadius * world.spacing() * pxPerM);
  const float pointSize = std::min(2.0f * radiusPx, 255.0f);

  glBindVertexArray(r.vao);
  glBindBuffer(GL_ARRAY_BUFFER, r.posVbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(P.size() * sizeof(Vec2)), P.size() ? P.x.data() : nullptr, GL_STREAM_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, sizeof(Vec2), nullptr);
  r.values.resize(P.size());
  if (d.mode == "particles") {
    float vmax = 1e-6f;
    for (std::size_t i = 0; i < P.size(); ++i) vmax = std::max(vmax, P.v[i].norm());
    for (std::size_t i = 0; i < P.size(); ++i) r.values[i] = P.v[i].norm() / vmax;
  }
  glBindBuffer(GL_ARRAY_BUFFER, r.valVbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(r.values.size() * sizeof(float)), r.values.empty() ? nullptr : r.values.data(),
               GL_STREAM_DRAW);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 1, GL_FLOAT, GL_FALSE, sizeof(float), nullptr);
  glViewport(0, 0, d.width, d.height);

  if (d.mode == "liquid") {
    // 1. Splat into the float field.
    glBindFramebuffer(GL_FRAMEBUFFER, r.fieldFbo);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glUseProgram(r.splatProg);
    glUniform2fv(glGetUniformLocation(r.splatProg, "uScale"), 1, scale);
    glUniform2fv(glGetUniformLocation(r.splatProg, "uOffset"), 1, offset);
    glUniform1f(glGetUniformLocation(r.splatProg, "uPointSize"), pointSize);
    glBindVertexArray(r.vao);
    glDrawArrays(GL_POINTS, 0, GLsizei(P.size()));
    glDisable(GL_BLEND);
    // 2. Composite into the colour target.
    glBindFramebuffer(GL_FRAMEBUFFER, r.colorFbo);
    glUseProgram(r.compositeProg);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, r.fieldTex);
    glUniform1i(glGetUniformLocation(r.compositeProg, "uField"), 0);
    glUniform2f(glGetUniformLocation(r.compositeProg, "uTexel"), 1.0f / float(d.width), 1.0f / float(d.height));
    // Bulk value of the field: Σ (1 − q²)³ over a lattice ≈ π s²/4 with s = radius in spacings.
    const float rs = pointSize * 0.5f / float(world.spacing() * pxPerM);
    const float bulk = std::max(1e-3f, 3.14159265f * rs * rs / 4.0f);
    glUniform1f(glGetUniformLocation(r.compositeProg, "uInvBulk"), 1.0f / bulk);
    glUniform3f(glGetUniformLocation(r.compositeProg, "uBackground"), float(d.background[0]), float(d.background[1]),
                float(d.background[2]));
    glUniform3f(glGetUniformLocation(r.compositeProg, "uWater"), float(d.water[0]), float(d.water[1]), float(d.water[2]));
    glBindVertexArray(r.emptyVao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  } else {
    glBindFramebuffer(GL_FRAMEBUFFER, r.colorFbo);
    glClearColor(float(d.background[0]), float(d.background[1]), float(d.background[2]), 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    glUseProgram(r.particleProg);
    glUniform2fv(glGetUniformLocation(r.particleProg, "uScale"), 1, scale);
    glUniform2fv(glGetUniformLocation(r.particleProg, "uOffset"), 1, offset);
    glUniform1f(glGetUniformLocation(r.particleProg, "uPointSize"),
                std::max(2.0f, std::min(float(world.spacing() * pxPerM), 255.0f)));
    glBindVertexArray(r.vao);
    glDrawArrays(GL_POINTS, 0, GLsizei(P.size()));
  }
  // 3. Solids on top.
  glUseProgram(r.solidProg);
  glUniform3f(glGetUniformLocation(r.solidProg, "uColor"), float(d.solid[0]), float(d.solid[1]), float(d.solid[2]));
  glBindVertexArray(r.solidVao);
  if (r.solidCount) glDrawArrays(GL_TRIANGLES, 0, r.solidCount);

  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, d.width, d.height, GL_RGBA, GL_UNSIGNED_BYTE, r.frame.rgba.data());
  const GLenum err = glGetError();
  if (err != GL_NO_ERROR) {
    std::ostringstream msg;
    msg << "OpenGL error 0x" << std::hex << err << " while rendering";
    throw std::runtime_error(msg.str());
  }
  return r.frame;
}

}  // namespace sph2d
