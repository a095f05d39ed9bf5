// surface_export.cpp — a frame's fluid outlines (ParticleSnapshot::surface, from
// World::surfaceCurves) as JSON and as an SVG drawing (particle_export.hpp).
#include <algorithm>
#include <cstdio>
#include <string>

#include "file_io.hpp"
#include "sph2d/render/particle_export.hpp"

namespace sph2d {

std::string encodeSurfaceJson(const ParticleSnapshot& s) {
  std::string out;
  appendf(out, "{\"format\": \"sph2d-surface\", \"frame\": %llu, \"time\": %.9g, \"curves\": [",
          static_cast<unsigned long long>(s.frame), s.time);
  for (std::size_t c = 0; c < s.surface.size(); ++c) {
    const SurfaceCurve& k = s.surface[c];
    appendf(out, "%s\n  {\"area\": %.9g, \"hole\": %s, \"points\": [", c ? "," : "", k.area,
            k.hole() ? "true" : "false");
    for (std::size_t i = 0; i < k.points.size(); ++i)
      appendf(out, "%s[%.9g, %.9g]", i ? ", " : "", k.points[i].x(), k.points[i].y());
    out += "]}";
  }
  out += s.surface.empty() ? "]}\n" : "\n]}\n";
  return out;
}

std::string encodeSurfaceSvg(const ParticleSnapshot& s) {
  double lo[2] = {0, 0}, hi[2] = {1, 1};
  bool any = false;
  for (const SurfaceCurve& k : s.surface)
    for (const Vec2d& p : k.points) {
      if (!any) lo[0] = hi[0] = p.x(), lo[1] = hi[1] = p.y();
      any = true;
      lo[0] = std::min(lo[0], p.x()), lo[1] = std::min(lo[1], p.y());
      hi[0] = std::max(hi[0], p.x()), hi[1] = std::max(hi[1], p.y());
    }
  const double margin = 0.05 * std::max({hi[0] - lo[0], hi[1] - lo[1], 1e-3});
  const double x0 = lo[0] - margin, y0 = lo[1] - margin, w = hi[0] - lo[0] + 2 * margin, h = hi[1] - lo[1] + 2 * margin;
  std::string out;
  // World y points up, SVG's down: the group flips y about the frame's middle.
  appendf(out,
          "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"%.9g %.9g %.9g %.9g\" width=\"800\" height=\"%d\">\n",
          x0, y0, w, h, int(800 * h / w + 0.5));
  appendf(out, "<!-- sph2d surface: frame %llu, time %.9g s, %zu curves, world coordinates (m) -->\n",
          static_cast<unsigned long long>(s.frame), s.time, s.surface.size());
  appendf(out, "<g transform=\"matrix(1 0 0 -1 0 %.9g)\">\n", 2 * y0 + h);
  out += "<path fill=\"#3a7bd5\" fill-opacity=\"0.6\" fill-rule=\"evenodd\" stroke=\"#0b2a55\" stroke-width=\"";
  appendf(out, "%.9g", 0.002 * std::max(w, h));
  out += "\" d=\"";
  for (const SurfaceCurve& k : s.surface) {
    for (std::size_t i = 0; i < k.points.size(); ++i)
      appendf(out, "%s%.7g %.7g ", i ? "L" : "M", k.points[i].x(), k.points[i].y());
    out += "Z ";
  }
  out += "\"/>\n</g>\n</svg>\n";
  return out;
}

}  // namespace sph2d
