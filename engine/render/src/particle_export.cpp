#include "sph2d/render/particle_export.hpp"

#include <box2d/box2d.h>

#include "file_io.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "sph2d/world.hpp"

namespace sph2d {
namespace {

template <typename T>
void putBigEndian(std::string& out, T v) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  for (std::size_t k = 0; k < sizeof(T); ++k) out.push_back(char(b[sizeof(T) - 1 - k]));  // x86 is little-endian
}

}  // namespace

ParticleSnapshot snapshotOf(const World& world, const Real* age) {
  const Particles& P = world.particles();
  const std::size_t n = P.size();
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return P.id[a] < P.id[b]; });
  ParticleSnapshot s;
  s.frame = world.frame();
  s.time = world.time();
  s.id.resize(n);
  s.x.resize(n);
  s.y.resize(n);
  s.vx.resize(n);
  s.vy.resize(n);
  s.rho.resize(n);
  s.p.resize(n);
  if (age) s.age.resize(n);
  if (!P.material.empty()) s.material.resize(n);
  if (!P.color.empty()) s.color.resize(n);
  if (!P.group.empty()) s.group.resize(n);
  const Vec2d o = world.origin();
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = order[k];
    s.id[k] = P.id[i];
    s.x[k] = o.x() + double(P.x[i].x());
    s.y[k] = o.y() + double(P.x[i].y());
    s.vx[k] = P.v[i].x();
    s.vy[k] = P.v[i].y();
    s.rho[k] = P.rho[i];
    s.p[k] = P.p[i];
    if (age) s.age[k] = float(age[i]);
    if (!P.material.empty()) s.material[k] = P.material[i];
    if (!P.color.empty()) s.color[k] = P.color[i];
    if (!P.group.empty()) s.group[k] = P.group[i];
  }
  // Box2D lists the newest body first: walk the list, then number in creation order.
  std::vector<const b2Body*> bodies;
  for (const b2Body* b = world.box2d().GetBodyList(); b; b = b->GetNext()) bodies.push_back(b);
  std::reverse(bodies.begin(), bodies.end());
  for (std::size_t k = 0; k < bodies.size(); ++k) {
    const b2Body* b = bodies[k];
    if (b->GetType() == b2_staticBody) continue;
    // The origin's own velocity (Box2D's linear velocity is its centre of mass's): the row's
    // x, y and vx, vy are one point's position and velocity.
    const b2Vec2 p = b->GetPosition(), v = b->GetLinearVelocityFromWorldPoint(p);
    s.bodies.push_back(BodySnapshot{int(k), p.x, p.y, b->GetAngle(), v.x, v.y, b->GetAngularVelocity()});
  }
  return s;
}

void writeBodiesCsvAtomic(const std::string& path, const ParticleSnapshot& s) {
  writeFileAtomic(path, encodeBodiesCsv(s));
}

std::string encodeBodiesCsv(const ParticleSnapshot& s) {
  std::string out;
  appendf(out, "# sph2d bodies: frame %llu, time %.9g s, %zu kinematic or dynamic bodies, world coordinates\n",
          static_cast<unsigned long long>(s.frame), s.time, s.bodies.size());
  out += "body,x,y,angle,vx,vy,omega\n";
  for (const BodySnapshot& b : s.bodies)
    appendf(out, "%d,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", b.body, b.x, b.y, b.angle, b.vx, b.vy, b.omega);
  return out;
}

bool parseExportFormat(const std::string& s, ExportFormat& out) {
  if (s == "csv")
    out = ExportFormat::Csv;
  else if (s == "vtk")
    out = ExportFormat::VtkBinary;
  else if (s == "vtk-ascii")
    out = ExportFormat::VtkAscii;
  else if (s == "surface")
    out = ExportFormat::Surface;
  else
    return false;
  return true;
}

std::string exportExtension(ExportFormat f) {
  return f == ExportFormat::Csv ? "csv" : f == ExportFormat::Surface ? "json" : "vtk";
}

std::string tempPathFor(const std::string& path) { return path + ".tmp" + std::to_string(::getpid()); }

void writeFileAtomic(const std::string& path, const std::string& bytes) {
  if (isSpecialFile(path))
    return writeInPlace(path, bytes.data(), bytes.size());  // a device, a FIFO: no rename over it
  const std::string tmp = tempPathFor(path);
  FILE* f = createTempFile(tmp);
  bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  ok = (std::fflush(f) == 0) && ok;
  std::string why = ok ? "" : std::strerror(errno);
  if (std::fclose(f) != 0 && ok) {
    ok = false;
    why = std::strerror(errno);
  }
  if (!ok) {
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot write " + path + ": " + why);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    why = std::strerror(errno);
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot rename " + tmp + " to " + path + ": " + why);
  }
}

void writeParticlesAtomic(const std::string& path, const ParticleSnapshot& s, ExportFormat f) {
  writeFileAtomic(path, encodeParticles(s, f));
}

std::string encodeParticles(const ParticleSnapshot& s, ExportFormat f) {
  if (f == ExportFormat::Surface) return encodeSurfaceJson(s);
  const std::size_t n = s.size();
  const bool hasAge = !s.age.empty(), hasMaterial = !s.material.empty();
  const bool hasColor = !s.color.empty(), hasGroup = !s.group.empty();
  std::string out;
  if (f == ExportFormat::Csv) {
    out.reserve(n * 100 + 128);
    appendf(out, "# sph2d particles: frame %llu, time %.9g s, %zu particles, world coordinates\n",
            static_cast<unsigned long long>(s.frame), s.time, n);
    out += "id,x,y,vx,vy,density,pressure";
    out += hasAge ? ",age" : "";
    out += hasMaterial ? ",material" : "";
    out += hasColor ? ",color" : "";
    out += hasGroup ? ",group\n" : "\n";
    for (std::size_t k = 0; k < n; ++k) {
      appendf(out, "%u,%.17g,%.17g,%.9g,%.9g,%.9g,%.9g", s.id[k], s.x[k], s.y[k], double(s.vx[k]), double(s.vy[k]),
              double(s.rho[k]), double(s.p[k]));
      if (hasAge) appendf(out, ",%.9g", double(s.age[k]));
      if (hasMaterial) appendf(out, ",%u", s.material[k]);
      if (hasColor) appendf(out, ",%u", s.color[k]);
      if (hasGroup) appendf(out, ",%u", s.group[k]);
      out += '\n';
    }
  } else {
    const bool bin = f == ExportFormat::VtkBinary;
    out.reserve(n * (bin ? 48 : 120) + 512);
    out += "# vtk DataFile Version 3.0\n";
    appendf(out, "sph2d particles frame %llu time %.9g\n", static_cast<unsigned long long>(s.frame), s.time);
    out += bin ? "BINARY\n" : "ASCII\n";
    out += "DATASET POLYDATA\n";
    appendf(out, "POINTS %zu double\n", n);
    for (std::size_t k = 0; k < n; ++k) {
      if (bin) {
        putBigEndian(out, s.x[k]);
        putBigEndian(out, s.y[k]);
        putBigEndian(out, 0.0);
      } else {
        appendf(out, "%.17g %.17g 0\n", s.x[k], s.y[k]);
      }
    }
    if (bin) out += '\n';
    appendf(out, "VERTICES %zu %zu\n", n, 2 * n);
    for (std::size_t k = 0; k < n; ++k) {
      if (bin) {
        putBigEndian(out, std::int32_t(1));
        putBigEndian(out, std::int32_t(k));
      } else {
        appendf(out, "1 %zu\n", k);
      }
    }
    if (bin) out += '\n';
    appendf(out, "POINT_DATA %zu\n", n);
    auto scalars = [&](const char* name, const char* type, auto get) {
      appendf(out, "SCALARS %s %s 1\nLOOKUP_TABLE default\n", name, type);
      for (std::size_t k = 0; k < n; ++k) {
        const auto v = get(k);
        if (bin)
          putBigEndian(out, v);
        else if constexpr (std::is_integral_v<decltype(v)>)
          appendf(out, "%d\n", int(v));
        else
          appendf(out, "%.9g\n", double(v));
      }
      if (bin) out += '\n';
    };
    scalars("id", "int", [&](std::size_t k) { return std::int32_t(s.id[k]); });
    appendf(out, "VECTORS velocity float\n");
    for (std::size_t k = 0; k < n; ++k) {
      if (bin) {
        putBigEndian(out, s.vx[k]);
        putBigEndian(out, s.vy[k]);
        putBigEndian(out, 0.0f);
      } else {
        appendf(out, "%.9g %.9g 0\n", double(s.vx[k]), double(s.vy[k]));
      }
    }
    if (bin) out += '\n';
    scalars("density", "float", [&](std::size_t k) { return s.rho[k]; });
    scalars("pressure", "float", [&](std::size_t k) { return s.p[k]; });
    if (hasAge) scalars("age", "float", [&](std::size_t k) { return s.age[k]; });
    if (hasMaterial) scalars("material", "int", [&](std::size_t k) { return std::int32_t(s.material[k]); });
    if (hasColor) scalars("color", "int", [&](std::size_t k) { return std::int32_t(s.color[k]); });
    if (hasGroup) scalars("group", "int", [&](std::size_t k) { return std::int32_t(s.group[k]); });
  }
  return out;
}

ParticleSnapshot readParticlesCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  ParticleSnapshot s;
  std::string line;
  int lineNo = 0;
  bool header = false, hasAge = false, hasMaterial = false, hasColor = false, hasGroup = false;
  while (std::getline(in, line)) {
    ++lineNo;
    if (line.empty()) continue;
    if (line[0] == '#') {
      unsigned long long fr = 0;
      double t = 0;
      if (std::sscanf(line.c_str(), "# sph2d particles: frame %llu, time %lf", &fr, &t) == 2) {
        s.frame = fr;
        s.time = t;
      }
      continue;
    }
    if (!header) {
      if (line.rfind("id,x,y,vx,vy,density,pressure", 0) != 0)
        throw std::runtime_error(path + ":" + std::to_string(lineNo) + ": not an sph2d particle CSV header");
      hasAge = line.find(",age") != std::string::npos;
      hasMaterial = line.find(",material") != std::string::npos;
      hasColor = line.find(",color") != std::string::npos;
      hasGroup = line.find(",group") != std::string::npos;
      header = true;
      continue;
    }
    // The optional whole-number columns at the end, last first: group, color, material.
    auto trailing = [&](const char* name, const char* what) {
      const std::size_t comma = line.rfind(',');
      unsigned value = 0;
      char end = 0;
      if (comma == std::string::npos || std::sscanf(line.c_str() + comma + 1, "%u%c", &value, &end) != 1)
        throw std::runtime_error(path + ":" + std::to_string(lineNo) + ": column " + name + " is not " + what);
      line.resize(comma);
      return value;
    };
    const unsigned group = hasGroup ? trailing("group", "a group number") : 0u;
    const unsigned color = hasColor ? trailing("color", "a colour 0xRRGGBB as a whole number") : 0u;
    const unsigned material = hasMaterial ? trailing("material", "a material index") : 0u;
    unsigned id = 0;
    double x = 0, y = 0, vx = 0, vy = 0, rho = 0, p = 0, age = 0;
    const int want = hasAge ? 8 : 7;
    if (std::sscanf(line.c_str(), "%u,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &id, &x, &y, &vx, &vy, &rho, &p, &age) != want)
      throw std::runtime_error(path + ":" + std::to_string(lineNo) + ": expected " + std::to_string(want) + " values");
    {
      // Every value must be a finite number (in float for the stored columns): a NaN or an
      // infinity would be drawn as garbage, or nothing, without a word.
      const char* names[8] = {"x", "y", "vx", "vy", "density", "pressure", "age", ""};
      const double values[8] = {x, y, vx, vy, rho, p, age, 0};
      for (int k = 0; k < want - 1; ++k) {
        const bool asFloat = k >= 2;  // x, y are kept in double
        if (!std::isfinite(values[k]) || (asFloat && !std::isfinite(float(values[k]))))
          throw std::runtime_error(path + ":" + std::to_string(lineNo) + ": column " + names[k] + " is " +
                                   std::to_string(values[k]) + "; every value must be a finite number");
      }
    }
    s.id.push_back(id);
    s.x.push_back(x);
    s.y.push_back(y);
    s.vx.push_back(float(vx));
    s.vy.push_back(float(vy));
    s.rho.push_back(float(rho));
    s.p.push_back(float(p));
    if (hasAge) s.age.push_back(float(age));
    if (hasMaterial) s.material.push_back(material);
    if (hasColor) s.color.push_back(color);
    if (hasGroup) s.group.push_back(group);
  }
  if (!header) throw std::runtime_error(path + ": empty");
  return s;
}

}  // namespace sph2d
