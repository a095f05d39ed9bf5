// camera.cpp — the camera rectangle, the guard band and the targets' extent (see camera.hpp).
#include "camera.hpp"

#include <algorithm>
#include <cmath>

#include "sph2d/render/renderer.hpp"

namespace sph2d {

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
    const Particles& P = in.particles;
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

void FrameGeometry::setGuard(int g, int width, int height) {
  guard = g;
  EW = width + 2 * g;
  EH = height + 2 * g;
  const double m = g / pxPerM(width);
  ext = {cam[0] - m, cam[1] - m, cam[2] + m, cam[3] + m};
}

void FrameGeometry::ndcTransform(const Vec2d& o, float scale[2], float offset[2]) const {
  const double extW = ext[2] - ext[0], extH = ext[3] - ext[1];
  scale[0] = float(2.0 / extW);
  scale[1] = float(-2.0 / extH);
  offset[0] = float((o.x() - ext[0]) * 2.0 / extW - 1.0);
  offset[1] = float(1.0 - (o.y() - ext[1]) * 2.0 / extH);
}

int guardBand(float diameterPx, int shrink, float maxPoint) {
  const bool asQuads = diameterPx / float(shrink) > maxPoint;
  return asQuads ? 2 : int(std::ceil(0.5 * diameterPx)) + 2;
}

}  // namespace sph2d
