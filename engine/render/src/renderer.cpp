#define GL_GLEXT_PROTOTYPES 1
#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "sph2d/render/renderer.hpp"
#include "sph2d/world.hpp"

namespace sph2d {

const std::map<std::string, std::string>& embeddedShaders();

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

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

void makeTexture(GLuint& tex, GLenum internal, GLenum format, GLenum type, int w, int h, GLint filter) {
  if (!tex) glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glTexImage2D(GL_TEXTURE_2D, 0, GLint(internal), w, h, 0, format, type, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

GLuint target(GLenum internal, GLenum format, GLenum type, int w, int h, GLuint& tex) {
  makeTexture(tex, internal, format, type, w, h, GL_NEAREST);
  GLuint fbo = 0;
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error("OSMesa: incomplete framebuffer");
  return fbo;
}

float smoothstepf(float e0, float e1, float x) {
  const float t = std::min(1.0f, std::max(0.0f, (x - e0) / (e1 - e0)));
  return t * t * (3.0f - 2.0f * t);
}

std::array<float, 3> color3(const std::array<double, 3>& c) { return {float(c[0]), float(c[1]), float(c[2])}; }

// Environment variables recorded in manifests. Values that sph2d pins when unset come first.
struct EnvPin {
  const char* name;
  const char* pinned;  // nullptr: record only
};
const EnvPin kEnv[] = {
    {"GALLIUM_DRIVER", "llvmpipe"},  // softpipe rasterises point sprites differently
    {"MESA_SHADER_CACHE_DISABLE", "true"},  // hermetic runs: nothing read from or written to ~/.cache
    {"LP_NUM_THREADS", nullptr},  // measured: 0, 1, 2, 8 give identical pixels (docs/RENDERING.md)
    {"LP_NATIVE_VECTOR_WIDTH", nullptr},  // measured: 128 and 256 give identical pixels
    {"GALLIUM_OVERRIDE_CPU_CAPS", nullptr},  // changes pixels when it removes AVX/FMA (measured)
    {"LP_DEBUG", nullptr},
    {"LP_PERF", nullptr},
    {"MESA_LOADER_DRIVER_OVERRIDE", nullptr},
};

}  // namespace

bool parseColorField(const std::string& s, ColorField& out) {
  if (s == "speed") out = ColorField::Speed;
  else if (s == "pressure") out = ColorField::Pressure;
  else if (s == "density") out = ColorField::Density;
  else if (s == "age") out = ColorField::Age;
  else return false;
  return true;
}

std::string colorFieldName(ColorField f) {
  switch (f) {
    case ColorField::Speed: return "speed";
    case ColorField::Pressure: return "pressure";
    case ColorField::Density: return "density";
    case ColorField::Age: return "age";
  }
  return "?";
}

std::vector<EnvSetting> pinRenderEnvironment() {
  static std::mutex m;
  static std::vector<EnvSetting> record;
  std::lock_guard<std::mutex> lock(m);
  if (record.empty()) {
    for (const EnvPin& e : kEnv) {
      const char* v = std::getenv(e.name);
      if (v) record.push_back({e.name, v, "user"});
      else if (e.pinned) {
        setenv(e.name, e.pinned, 1);
        record.push_back({e.name, e.pinned, "sph2d"});
      } else {
        record.push_back({e.name, "", "unset"});
      }
    }
  }
  return record;
}

std::string cpuSummary() {
  std::ifstream in("/proc/cpuinfo");
  std::string line, model, flags;
  while (std::getline(in, line) && (model.empty() || flags.empty())) {
    auto value = [&] {
      const auto c = line.find(':');
      return c == std::string::npos ? std::string() : line.substr(std::min(line.size(), c + 2));
    };
    if (model.empty() && line.rfind("model name", 0) == 0) model = value();
    if (flags.empty() && line.rfind("flags", 0) == 0) flags = " " + value() + " ";
  }
  std::string out = model.empty() ? "unknown CPU" : model;
  out += ";";
  for (const char* f : {"sse4_1", "avx", "avx2", "fma", "f16c", "avx512f"})
    if (flags.find(std::string(" ") + f + " ") != std::string::npos) out += std::string(" ") + f;
  return out;
}

std::vector<double> resolveCamera(const RenderDef& def, const RenderInput& in) {
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
    const Vec2d o = in.origin;
    if (in.colliders)
      for (const Collider& c : *in.colliders) {
        grow(c.lo.x() + o.x(), c.lo.y() + o.y());
        grow(c.hi.x() + o.x(), c.hi.y() + o.y());
      }
    const Particles& P = *in.particles;
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

namespace {
RenderInput inputOf(const World& world, const Real* age) {
  RenderInput in;
  in.particles = &world.particles();
  in.origin = world.origin();
  in.spacing = world.spacing();
  in.colliders = &world.colliders();
  // Ages come from the caller, or from the engine's "age" field when the scene has lifetimes.
  const std::vector<Real>* engineAge = world.particles().find("age");
  in.age = age ? age : (engineAge ? engineAge->data() : nullptr);
  in.gravity = world.scene().gravity.norm();
  in.frame = world.frame();
  in.time = world.time();
  return in;
}
}  // namespace

std::vector<double> resolveCamera(const RenderDef& def, const World& world) {
  return resolveCamera(def, inputOf(world, nullptr));
}

struct Renderer::Impl {
  RenderDef def;
  RenderOptions opt;
  bool liquid = true;
  OSMesaContext ctx = nullptr;
  unsigned char dummy[4] = {0, 0, 0, 0};
  GLuint fieldTex = 0, fieldFbo = 0, colorTex = 0, colorFbo = 0, auxTex = 0, bgTex = 0, bgFbo = 0;
  GLuint splatProg = 0, compositeProg = 0, discProg = 0, solidProg = 0, bgProg = 0;
  GLuint pointVao = 0, quadVao = 0, particleVbo = 0, cornerVbo = 0, solidVao = 0, solidVbo = 0, emptyVao = 0;
  GLuint tileVao = 0, tileVbo = 0;
  GLsizei tileVertices = 0;
  std::vector<float> tiles;
  std::vector<std::uint8_t> active, activeTmp;
  GLsizei solidCount = 0;
  float maxPoint = 255.0f;
  std::vector<double> cam;  // the world rectangle of the image
  // The targets are the image plus a guard band of `guard` pixels on each side: point sprites
  // are culled when their centre leaves the viewport, so particles just outside the image
  // must still fall inside the targets to draw their part of the image.
  int guard = -1, EW = 0, EH = 0;
  std::vector<double> ext;  // the world rectangle of the extended targets
  double spacingSeen = -1;
  Frame frame;
  std::vector<float> packed;           // x, y, value, weight per particle, id order
  std::vector<std::uint32_t> order;    // slots in id order
  std::vector<std::uint32_t> slotOfId;
  std::vector<float> cover, aux;       // coarse grid: coverage; RG = depth above, local fill
  std::vector<float> carry, above;     // one row each: depth carried down, blurred along the row
  std::vector<std::uint8_t> solidMask; // coarse grid: 1 where a cell's centre lies in a solid
  bool solidMaskStale = true;
  int auxW = 0, auxH = 0, auxCell = 0;
  int fieldW = 0, fieldH = 0;  // the splat target: full resolution, or half when sprites are wide
  std::string rendererName;
  RenderTimings timings;
  bool quads = false;
  std::array<double, 2> range{0, 1};

  void makeCurrent() {
    if (!OSMesaMakeCurrent(ctx, dummy, GL_UNSIGNED_BYTE, 1, 1)) throw std::runtime_error("OSMesaMakeCurrent failed");
  }

  void stageEnd(double& slot, Clock::time_point& t) {
    if (opt.profile) glFinish();
    slot = msSince(t);
    t = Clock::now();
  }

  void buildSolids(const RenderInput& in) {
    // Triangles in NDC (the camera is fixed for a run).
    const Vec2d o = in.origin;
    const double sx = 2.0 / (ext[2] - ext[0]), sy = 2.0 / (ext[3] - ext[1]);
    auto ndc = [&](const Vec2& p) {
      return std::array<float, 2>{float((p.x() + o.x() - ext[0]) * sx - 1.0), float(1.0 - (p.y() + o.y() - ext[1]) * sy)};
    };
    std::vector<float> tri;
    auto put = [&](const std::array<float, 2>& a) {
      tri.push_back(a[0]);
      tri.push_back(a[1]);
    };
    const double pxX = 2.0 / EW, pxY = 2.0 / EH;
    if (in.colliders)
      for (const Collider& c : *in.colliders) {
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
          const double dxp = (b[0] - a[0]) / pxX, dyp = (b[1] - a[1]) / pxY;
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
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(tri.size() * sizeof(float)), tri.empty() ? nullptr : tri.data(),
                 GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
  }

  /// Slots in id order: a frame must not depend on how the engine stores particles.
  void sortById(const Particles& P) {
    const std::size_t n = P.size();
    order.resize(n);
    std::uint32_t maxId = 0;
    for (std::size_t i = 0; i < n; ++i) maxId = std::max(maxId, P.id[i]);
    if (n && std::size_t(maxId) < 4 * n + 64) {
      const std::uint32_t none = 0xffffffffu;
      slotOfId.assign(std::size_t(maxId) + 1, none);
      bool unique = true;
      for (std::size_t i = 0; i < n; ++i) {
        std::uint32_t& s = slotOfId[P.id[i]];
        if (s != none) unique = false;
        s = std::uint32_t(i);
      }
      if (unique) {
        std::size_t k = 0;
        for (std::uint32_t s : slotOfId)
          if (s != none) order[k++] = s;
        return;
      }
    }
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return P.id[a] < P.id[b]; });
  }

  float fade(const RenderInput& in, std::size_t slot) const {
    if (!in.age) return 1.0f;
    const float a = float(in.age[slot]);
    if (!(opt.ageFadeEnd > opt.ageFadeStart)) return 1.0f;
    return 1.0f - smoothstepf(float(opt.ageFadeStart), float(opt.ageFadeEnd), a);
  }

  double valueOf(const RenderInput& in, std::size_t i) const {
    const Particles& P = *in.particles;
    switch (opt.colorBy) {
      case ColorField::Speed: return double(P.v[i].norm());
      case ColorField::Pressure: return double(P.p[i]);
      case ColorField::Density: return double(P.rho[i]);
      case ColorField::Age: return in.age ? double(in.age[i]) : 0.0;
    }
    return 0.0;
  }

  /// Marks the coarse grid's cells whose centre lies inside a collider (segments: within half a
  /// cell of it). The colliders are static, so this runs when the grid or the camera changes.
  void buildSolidMask(const RenderInput& in, double pxPerM) {
    const double cellM = auxCell / pxPerM;
    const double x0 = ext[0] - in.origin.x(), y1 = ext[3] - in.origin.y();
    solidMask.assign(std::size_t(auxW) * std::size_t(auxH), 0);
    solidMaskStale = false;
    if (!in.colliders) return;
    for (const Collider& c : *in.colliders) {
      const double pad = c.kind == Collider::Kind::Segment ? 0.5 * cellM : 0.0;
      // Cells whose centre can lie in the collider's bounding box (grid rows run top-down).
      const int ix0 = std::max(0, int(std::floor((c.lo.x() - pad - x0) / cellM - 0.5)));
      const int ix1 = std::min(auxW - 1, int(std::ceil((c.hi.x() + pad - x0) / cellM - 0.5)));
      const int iy0 = std::max(0, int(std::floor((y1 - c.hi.y() - pad) / cellM - 0.5)));
      const int iy1 = std::min(auxH - 1, int(std::ceil((y1 - c.lo.y() + pad) / cellM - 0.5)));
      for (int iy = iy0; iy <= iy1; ++iy)
        for (int ix = ix0; ix <= ix1; ++ix) {
          const Vec2d p(x0 + (ix + 0.5) * cellM, y1 - (iy + 0.5) * cellM);
          bool inside = true;
          if (c.kind == Collider::Kind::Polygon) {
            for (std::size_t k = 0; k < c.vertices.size() && inside; ++k)
              inside = c.normals[k].cast<double>().dot(p - c.vertices[k].cast<double>()) <= 0.0;
          } else if (c.kind == Collider::Kind::Circle) {
            inside = (p - c.center.cast<double>()).squaredNorm() <= double(c.radius) * double(c.radius);
          } else {
            const Vec2d a = c.vertices[0].cast<double>(), b = c.vertices[1].cast<double>(), ab = b - a;
            const double t = ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
            inside = (p - (a + t * ab)).norm() <= pad;
          }
          if (inside) solidMask[std::size_t(iy) * std::size_t(auxW) + std::size_t(ix)] = 1;
        }
    }
  }

  /// The coarse grid: coverage per cell, then depth of water above and local fill.
  void buildAux(const RenderInput& in, double pxPerM, const std::vector<float>& weight) {
    const double spacingPx = in.spacing * pxPerM;
    const int cell = std::max(4, int(std::ceil(spacingPx)));
    const int w = (EW + cell - 1) / cell, h = (EH + cell - 1) / cell;
    if (w != auxW || h != auxH || cell != auxCell) {
      auxW = w;
      auxH = h;
      auxCell = cell;
      makeTexture(auxTex, GL_RG32F, GL_RG, GL_FLOAT, w, h, GL_LINEAR);
      solidMaskStale = true;
    }
    cover.assign(std::size_t(w) * std::size_t(h), 0.0f);
    const Particles& P = *in.particles;
    const double cellM = cell / pxPerM;
    const double x0 = ext[0] - in.origin.x(), y1 = ext[3] - in.origin.y();
    const float areaShare = float((spacingPx * spacingPx) / (double(cell) * double(cell)));
    // Cloud-in-cell deposit (bilinear weights): no aliasing between the lattice and the cells.
    for (std::size_t k = 0; k < order.size(); ++k) {
      const std::size_t i = order[k];
      const double cx = (double(P.x[i].x()) - x0) / cellM - 0.5, cy = (y1 - double(P.x[i].y())) / cellM - 0.5;
      if (!(cx > -1 && cy > -1 && cx < w && cy < h)) continue;
      const int ix = int(std::floor(cx)), iy = int(std::floor(cy));
      const float tx = float(cx - ix), ty = float(cy - iy);
      const float m = areaShare * weight[k];
      const float wgt[4] = {(1 - tx) * (1 - ty) * m, tx * (1 - ty) * m, (1 - tx) * ty * m, tx * ty * m};
      for (int q = 0; q < 4; ++q) {
        const int xx = ix + (q & 1), yy = iy + (q >> 1);
        if (xx >= 0 && yy >= 0 && xx < w && yy < h) cover[std::size_t(yy) * std::size_t(w) + std::size_t(xx)] += wgt[q];
      }
    }
    for (float& c : cover) c = std::min(c, 1.0f);
    if (solidMaskStale) buildSolidMask(in, pxPerM);
    aux.assign(std::size_t(w) * std::size_t(h) * 2, 0.0f);
    // Depth of water above, with the light scattered sideways as it goes down: row by row from
    // the top, the depth carried into a row is the row above's, blurred along the row by a
    // binomial kernel [1 4 6 4 1]/16 (variance one cell² per row) over the cells that are not
    // solid. A step in depth between neighbouring columns (under a bump, at the foot of a
    // splash) thus widens like a diffusion, about sqrt(rows below the step) cells, instead of
    // running down as a vertical seam; solids neither pass light nor lend their depth of zero
    // to the water beside them (a wall would otherwise light the water along it).
    carry.assign(std::size_t(w), 0.0f);
    above.assign(std::size_t(w), 0.0f);
    static const float kBlur[5] = {1.0f / 16, 4.0f / 16, 6.0f / 16, 4.0f / 16, 1.0f / 16};
    for (int y = 0; y < h; ++y) {
      const std::size_t row = std::size_t(y) * std::size_t(w);
      for (int x = 0; x < w; ++x) {
        const float c = cover[row + std::size_t(x)];
        aux[(row + std::size_t(x)) * 2] = float((carry[std::size_t(x)] + 0.5f * c) * cellM);
        carry[std::size_t(x)] += c;
      }
      for (int x = 0; x < w; ++x) {
        float s = 0, n = 0;
        for (int d = -2; d <= 2; ++d) {
          const int xx = x + d;
          if (xx < 0 || xx >= w || solidMask[row + std::size_t(xx)]) continue;
          s += kBlur[d + 2] * carry[std::size_t(xx)];
          n += kBlur[d + 2];
        }
        above[std::size_t(x)] = n > 0 ? s / n : carry[std::size_t(x)];
      }
      carry.swap(above);
    }
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        float s = 0;
        int n = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx, yy = y + dy;
            if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
            s += cover[std::size_t(yy) * std::size_t(w) + std::size_t(xx)];
            ++n;
          }
        aux[(std::size_t(y) * std::size_t(w) + std::size_t(x)) * 2 + 1] = s / float(n);
      }
    glBindTexture(GL_TEXTURE_2D, auxTex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RG, GL_FLOAT, aux.data());
  }

  /// Quads (NDC, two triangles each) over the grid cells the splat can reach: cells with fluid,
  /// dilated by the sprite radius plus one pixel for the gradient taps. Rows are merged into runs.
  void buildTiles(float spriteRadiusPx) {
    const int w = auxW, h = auxH;
    const int reach = int(std::ceil((spriteRadiusPx + 1.0f) / float(auxCell)));
    active.assign(std::size_t(w) * std::size_t(h), 0);
    activeTmp.assign(active.size(), 0);
    for (std::size_t k = 0; k < cover.size(); ++k) active[k] = cover[k] > 0.0f;
    for (int y = 0; y < h; ++y)  // dilate along rows
      for (int x = 0; x < w; ++x) {
        std::uint8_t a = 0;
        for (int dx = -reach; dx <= reach && !a; ++dx) {
          const int xx = x + dx;
          if (xx >= 0 && xx < w) a = active[std::size_t(y) * std::size_t(w) + std::size_t(xx)];
        }
        activeTmp[std::size_t(y) * std::size_t(w) + std::size_t(x)] = a;
      }
    for (int y = 0; y < h; ++y)  // then along columns
      for (int x = 0; x < w; ++x) {
        std::uint8_t a = 0;
        for (int dy = -reach; dy <= reach && !a; ++dy) {
          const int yy = y + dy;
          if (yy >= 0 && yy < h) a = activeTmp[std::size_t(yy) * std::size_t(w) + std::size_t(x)];
        }
        active[std::size_t(y) * std::size_t(w) + std::size_t(x)] = a;
      }
    tiles.clear();
    auto ndcX = [&](int px) { return float(std::min(px, EW)) / float(EW) * 2.0f - 1.0f; };
    auto ndcY = [&](int py) { return float(std::min(py, EH)) / float(EH) * 2.0f - 1.0f; };
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w;) {
        if (!active[std::size_t(y) * std::size_t(w) + std::size_t(x)]) {
          ++x;
          continue;
        }
        int e = x;
        while (e < w && active[std::size_t(y) * std::size_t(w) + std::size_t(e)]) ++e;
        const float x0 = ndcX(x * auxCell), x1 = ndcX(e * auxCell), y0 = ndcY(y * auxCell), y1 = ndcY((y + 1) * auxCell);
        const float q[12] = {x0, y0, x1, y0, x0, y1, x0, y1, x1, y0, x1, y1};
        tiles.insert(tiles.end(), q, q + 12);
        x = e;
      }
    tileVertices = GLsizei(tiles.size() / 2);
    glBindBuffer(GL_ARRAY_BUFFER, tileVbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(tiles.size() * sizeof(float)), tiles.empty() ? nullptr : tiles.data(),
                 GL_STREAM_DRAW);
  }

  /// The background texture, drawn once with shaders/background.frag.
  void buildBackground() {
    if (bgFbo) glDeleteFramebuffers(1, &bgFbo);
    bgFbo = target(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, EW, EH, bgTex);
    glViewport(0, 0, EW, EH);
    glUseProgram(bgProg);
    glUniform3f(glGetUniformLocation(bgProg, "uBackground"), float(def.background[0]), float(def.background[1]),
                float(def.background[2]));
    glUniform1f(glGetUniformLocation(bgProg, "uGuard"), float(guard));
    glUniform1f(glGetUniformLocation(bgProg, "uHeight"), float(def.height));
    glBindVertexArray(emptyVao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }

  /// Sprite diameter [px] at full resolution for this input.
  float spriteDiameter(double spacingPx) const {
    return liquid ? float(2.0 * def.splatRadius * spacingPx) : float(std::max(3.0, spacingPx));
  }
  /// 2 when the liquid field is splatted at half resolution, else 1.
  int fieldShrink(double spacingPx) const { return liquid && spriteDiameter(spacingPx) >= 8.0f ? 2 : 1; }

  /// Sizes the guard band for the sprites of `in` and (re)creates what depends on it.
  void ensureFrame(const RenderInput& in) {
    if (in.spacing == spacingSeen) return;
    spacingSeen = in.spacing;
    const double pxPerM = def.width / (cam[2] - cam[0]);
    const double spacingPx = in.spacing * pxPerM;
    const float d = spriteDiameter(spacingPx);
    const int shrink = fieldShrink(spacingPx);
    const bool asQuads = d / float(shrink) > maxPoint;
    const int g = asQuads ? 2 : int(std::ceil(0.5 * d)) + 2;
    if (g == guard) return;
    guard = g;
    EW = def.width + 2 * g;
    EH = def.height + 2 * g;
    const double m = g / pxPerM;
    ext = {cam[0] - m, cam[1] - m, cam[2] + m, cam[3] + m};
    if (colorFbo) glDeleteFramebuffers(1, &colorFbo);
    colorFbo = target(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, EW, EH, colorTex);
    buildBackground();
    buildSolids(in);
    solidMaskStale = true;
    fieldW = fieldH = 0;  // recreated at the next splat
  }

  void setSpriteUniforms(GLuint prog, const float scale[2], const float offset[2], float diameterPx, int vw, int vh) {
    glUseProgram(prog);
    glUniform2fv(glGetUniformLocation(prog, "uScale"), 1, scale);
    glUniform2fv(glGetUniformLocation(prog, "uOffset"), 1, offset);
    glUniform1f(glGetUniformLocation(prog, "uPointSize"), std::min(diameterPx, maxPoint));
    glUniform1i(glGetUniformLocation(prog, "uQuads"), quads ? 1 : 0);
    glUniform2f(glGetUniformLocation(prog, "uHalfNdc"), diameterPx / float(vw), diameterPx / float(vh));
    glUniform1f(glGetUniformLocation(prog, "uRadiusPx"), 0.5f * diameterPx);
  }

  void drawSprites(GLsizei n) {
    if (!n) return;
    if (quads) {
      glBindVertexArray(quadVao);
      glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, n);
    } else {
      glBindVertexArray(pointVao);
      glDrawArrays(GL_POINTS, 0, n);
    }
  }
};

Renderer::Renderer(const RenderDef& def, const RenderOptions& options) : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.def = def;
  r.opt = options;
  const std::string mode = options.mode.empty() ? def.mode : options.mode;
  if (mode != "liquid" && mode != "particles")
    throw std::runtime_error("unknown render mode '" + mode + "' (liquid or particles)");
  r.liquid = mode == "liquid";
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
  GLfloat range[2] = {1, 255};
  glGetFloatv(GL_POINT_SIZE_RANGE, range);
  r.maxPoint = std::max(1.0f, range[1]);

  r.splatProg = program("splat.vert", "splat.frag");
  r.discProg = program("splat.vert", "particles.frag");
  r.solidProg = program("solid.vert", "solid.frag");
  r.bgProg = program("fullscreen.vert", "background.frag");
  r.compositeProg = program("solid.vert", "composite.frag");

  glGenBuffers(1, &r.particleVbo);
  glGenBuffers(1, &r.cornerVbo);
  const float corners[8] = {-1, -1, 1, -1, -1, 1, 1, 1};
  glBindBuffer(GL_ARRAY_BUFFER, r.cornerVbo);
  glBufferData(GL_ARRAY_BUFFER, sizeof corners, corners, GL_STATIC_DRAW);
  // Points: one vertex per particle. Quads: four corners per instance, the particle per instance.
  for (int q = 0; q < 2; ++q) {
    GLuint& vao = q ? r.quadVao : r.pointVao;
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, r.particleVbo);
    const GLsizei stride = 4 * sizeof(float);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, stride, nullptr);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 1, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<const void*>(2 * sizeof(float)));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<const void*>(3 * sizeof(float)));
    if (q) {
      for (GLuint a = 0; a < 3; ++a) glVertexAttribDivisor(a, 1);
      glBindBuffer(GL_ARRAY_BUFFER, r.cornerVbo);
      glEnableVertexAttribArray(3);
      glVertexAttribPointer(3, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
    }
  }
  glGenVertexArrays(1, &r.solidVao);
  glGenBuffers(1, &r.solidVbo);
  glGenVertexArrays(1, &r.emptyVao);
  glGenVertexArrays(1, &r.tileVao);
  glGenBuffers(1, &r.tileVbo);
  glBindVertexArray(r.tileVao);
  glBindBuffer(GL_ARRAY_BUFFER, r.tileVbo);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
  glEnable(GL_PROGRAM_POINT_SIZE);
  r.frame.width = def.width;
  r.frame.height = def.height;
  r.frame.rgba.assign(std::size_t(def.width) * def.height * 4, 0);
  if (glGetError() != GL_NO_ERROR) throw std::runtime_error("OpenGL error while creating the renderer");
}

Renderer::~Renderer() {
  if (impl_ && impl_->ctx) OSMesaDestroyContext(impl_->ctx);
}

std::string Renderer::rendererString() const { return impl_->rendererName; }
std::vector<double> Renderer::cameraRect() const { return impl_->cam; }
std::string Renderer::mode() const { return impl_->liquid ? "liquid" : "particles"; }
RenderTimings Renderer::lastTimings() const { return impl_->timings; }
bool Renderer::usedQuads() const { return impl_->quads; }
float Renderer::maxPointSize() const { return impl_->maxPoint; }
std::array<double, 2> Renderer::lastRange() const { return impl_->range; }

const Frame& Renderer::render(const World& world, const Real* age) { return render(inputOf(world, age)); }

const Frame& Renderer::render(const RenderInput& in) {
  Impl& r = *impl_;
  if (!in.particles) throw std::invalid_argument("Renderer::render: no particles");
  const auto tStart = Clock::now();
  auto t = tStart;
  r.timings = RenderTimings{};
  r.makeCurrent();
  const RenderDef& d = r.def;
  if (r.cam.empty()) r.cam = resolveCamera(d, in);
  r.ensureFrame(in);
  if (in.age == nullptr && in.particles->size() > 0 && r.opt.colorBy == ColorField::Age && !r.liquid)
    throw std::runtime_error("colour by age needs particle ages, and none were given");

  const Particles& P = *in.particles;
  const std::size_t n = P.size();
  const Vec2d o = in.origin;
  const double camW = r.cam[2] - r.cam[0], camH = r.cam[3] - r.cam[1];
  const double extW = r.ext[2] - r.ext[0], extH = r.ext[3] - r.ext[1];
  const float scale[2] = {float(2.0 / extW), float(-2.0 / extH)};
  const float offset[2] = {float((o.x() - r.ext[0]) * 2.0 / extW - 1.0), float(1.0 - (o.y() - r.ext[1]) * 2.0 / extH)};
  const double pxPerM = d.width / camW;
  const double spacingPx = in.spacing * pxPerM;

  // Pack the particles in id order: position, value, weight.
  r.sortById(P);
  std::vector<float> weight(n);
  for (std::size_t k = 0; k < n; ++k) weight[k] = r.fade(in, r.order[k]);
  r.packed.resize(n * 4);
  double lo = 0, hi = 1;
  if (r.liquid) {
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t i = r.order[k];
      r.packed[4 * k] = P.x[i].x();
      r.packed[4 * k + 1] = P.x[i].y();
      r.packed[4 * k + 2] = P.v[i].norm();
      r.packed[4 * k + 3] = weight[k];
    }
  } else {
    if (r.opt.range) {
      lo = (*r.opt.range)[0];
      hi = (*r.opt.range)[1];
    } else if (n) {
      lo = hi = r.valueOf(in, r.order[0]);
      for (std::size_t k = 1; k < n; ++k) {
        const double v = r.valueOf(in, r.order[k]);
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
      if (r.opt.colorBy == ColorField::Speed || r.opt.colorBy == ColorField::Age) lo = 0;
    }
    if (!(hi > lo)) hi = lo + 1e-6 * std::max(1.0, std::fabs(lo));
    r.range = {lo, hi};
    const double inv = 1.0 / (hi - lo);
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t i = r.order[k];
      r.packed[4 * k] = P.x[i].x();
      r.packed[4 * k + 1] = P.x[i].y();
      r.packed[4 * k + 2] = float((r.valueOf(in, i) - lo) * inv);
      r.packed[4 * k + 3] = weight[k];
    }
  }
  glBindBuffer(GL_ARRAY_BUFFER, r.particleVbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(r.packed.size() * sizeof(float)), n ? r.packed.data() : nullptr,
               GL_STREAM_DRAW);
  if (r.liquid) {
    r.buildAux(in, pxPerM, weight);
    r.buildTiles(float(d.splatRadius * spacingPx));
  }
  glViewport(0, 0, r.EW, r.EH);
  r.stageEnd(r.timings.upload, t);

  if (r.liquid) {
    // 1. Splat Σw and Σw·speed into the RG32F field; at half resolution when sprites are at
    //    least 8 px wide (a quarter of the fragments; the composite samples it bilinearly).
    const float diameter = r.spriteDiameter(spacingPx);
    const int shrink = r.fieldShrink(spacingPx);
    const int fw = (r.EW + shrink - 1) / shrink, fh = (r.EH + shrink - 1) / shrink;
    if (fw != r.fieldW || fh != r.fieldH) {
      if (r.fieldFbo) glDeleteFramebuffers(1, &r.fieldFbo);
      r.fieldFbo = target(GL_RG32F, GL_RG, GL_FLOAT, fw, fh, r.fieldTex);
      const GLint filter = shrink > 1 ? GL_LINEAR : GL_NEAREST;
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
      r.fieldW = fw;
      r.fieldH = fh;
    }
    const float fieldDiameter = diameter * float(fw) / float(r.EW);
    r.quads = fieldDiameter > r.maxPoint;
    glViewport(0, 0, fw, fh);
    glBindFramebuffer(GL_FRAMEBUFFER, r.fieldFbo);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    r.setSpriteUniforms(r.splatProg, scale, offset, fieldDiameter, fw, fh);
    r.drawSprites(GLsizei(n));
    glDisable(GL_BLEND);
    glViewport(0, 0, r.EW, r.EH);
    r.stageEnd(r.timings.splat, t);
    // 2. Composite into the colour target.
    const GLuint cp = r.compositeProg;
    glCopyImageSubData(r.bgTex, GL_TEXTURE_2D, 0, 0, 0, 0, r.colorTex, GL_TEXTURE_2D, 0, 0, 0, 0, r.EW, r.EH, 1);
    glBindFramebuffer(GL_FRAMEBUFFER, r.colorFbo);
    glUseProgram(cp);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, r.fieldTex);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, r.auxTex);
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D, r.bgTex);
    glActiveTexture(GL_TEXTURE0);
    glUniform1i(glGetUniformLocation(cp, "uField"), 0);
    glUniform1i(glGetUniformLocation(cp, "uAux"), 1);
    glUniform1i(glGetUniformLocation(cp, "uBg"), 2);
    glUniform2f(glGetUniformLocation(cp, "uAuxScale"), float(r.EW) / float(r.auxW * r.auxCell),
                float(r.EH) / float(r.auxH * r.auxCell));
    glUniform2f(glGetUniformLocation(cp, "uTexel"), 1.0f / float(r.EW), 1.0f / float(r.EH));
    // Bulk value of the field: Σ (1 − q²)³ over a square lattice ≈ π s²/4, s = sprite radius in spacings.
    const float rs = float(diameter * 0.5 / spacingPx);
    const float bulk = std::max(1e-3f, 3.14159265f * rs * rs / 4.0f);
    glUniform1f(glGetUniformLocation(cp, "uInvBulk"), 1.0f / bulk);
    const auto water = color3(d.water);
    const std::array<float, 3> deep =
        r.opt.deepWater ? color3(*r.opt.deepWater) : std::array<float, 3>{water[0] * 0.3f, water[1] * 0.3f, water[2] * 0.3f};
    const auto foam = color3(r.opt.foam.value_or(std::array<double, 3>{0.9, 0.95, 1.0}));
    glUniform3fv(glGetUniformLocation(cp, "uWater"), 1, water.data());
    glUniform3fv(glGetUniformLocation(cp, "uDeep"), 1, deep.data());
    glUniform3fv(glGetUniformLocation(cp, "uFoam"), 1, foam.data());
    const double depthScale = r.opt.depthScale > 0 ? r.opt.depthScale : 1.0;
    glUniform1f(glGetUniformLocation(cp, "uInvDepth"), float(1.0 / depthScale));
    const double foamLo = r.opt.foamSpeed > 0 ? r.opt.foamSpeed : 0.35 * std::sqrt(std::max(in.gravity, 1e-6) * camH);
    glUniform2f(glGetUniformLocation(cp, "uFoamSpeed"), float(foamLo), float(2 * foamLo));
    glUniform1f(glGetUniformLocation(cp, "uSpacingPx"), float(spacingPx));
    glBindVertexArray(r.tileVao);
    if (r.tileVertices) glDrawArrays(GL_TRIANGLES, 0, r.tileVertices);
    r.stageEnd(r.timings.composite, t);
  } else {
    const float diameter = r.spriteDiameter(spacingPx);
    r.quads = diameter > r.maxPoint;
    glCopyImageSubData(r.bgTex, GL_TEXTURE_2D, 0, 0, 0, 0, r.colorTex, GL_TEXTURE_2D, 0, 0, 0, 0, r.EW, r.EH, 1);
    glBindFramebuffer(GL_FRAMEBUFFER, r.colorFbo);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    r.setSpriteUniforms(r.discProg, scale, offset, diameter, r.EW, r.EH);
    r.drawSprites(GLsizei(n));
    glDisable(GL_BLEND);
    r.stageEnd(r.timings.splat, t);
  }
  // 3. Solids on top.
  glUseProgram(r.solidProg);
  glUniform3f(glGetUniformLocation(r.solidProg, "uColor"), float(d.solid[0]), float(d.solid[1]), float(d.solid[2]));
  glBindVertexArray(r.solidVao);
  if (r.solidCount) glDrawArrays(GL_TRIANGLES, 0, r.solidCount);
  r.stageEnd(r.timings.solids, t);

  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(r.guard, r.guard, d.width, d.height, GL_RGBA, GL_UNSIGNED_BYTE, r.frame.rgba.data());
  const GLenum err = glGetError();
  if (err != GL_NO_ERROR) {
    std::ostringstream msg;
    msg << "OpenGL error 0x" << std::hex << err << " while rendering";
    throw std::runtime_error(msg.str());
  }
  r.stageEnd(r.timings.readback, t);

  // 4. Text and colour bar on the CPU (bit-identical everywhere).
  const int textScale = std::max(1, d.height / 270);
  const Rgba8 textColor = toRgba8(r.opt.text.value_or(std::array<double, 3>{0.92, 0.92, 0.92}));
  if (!r.liquid) {
    static const char* titles[] = {"SPEED M/S", "PRESSURE PA", "DENSITY KG/M3", "AGE S"};
    drawColorBar(r.frame, lo, hi, titles[int(r.opt.colorBy)], textScale);
  }
  if (r.opt.overlay) {
    char line[128];
    std::snprintf(line, sizeof line, "FRAME %llu  T %.3f S  %zu PARTICLES", static_cast<unsigned long long>(in.frame),
                  in.time, n);
    const int pad = 2 * textScale;
    fillRect(r.frame, 0, 0, textWidth(line, textScale) + 2 * pad + 2 * textScale, textHeight(textScale) + 2 * pad + 2 * textScale,
             Rgba8{0, 0, 0, 140});
    drawText(r.frame, pad + textScale, pad + textScale, line, textScale, textColor);
  }
  r.stageEnd(r.timings.overlay, t);
  r.timings.total = msSince(tStart);
  return r.frame;
}

}  // namespace sph2d
