// The scene checks (scene_checks.hpp): geometry as Box2D 2.4.1 requires it, the
// fluid blocks against the spacing and the solids, names and limits.
//
// Debian builds Box2D with assertions on, so a polygon or chain Box2D would
// assert on aborts the process. The polygon check therefore replays
// b2PolygonShape::Set in float (welding, the gift-wrapping hull, edge lengths,
// the centroid's area) besides the exact convexity test in double; vertex
// distances are tested both in double and as Box2D's float test. Memory limits
// count in doubles, so no spacing overflows them.
#include "scene/scene_checks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

namespace sph2d {
namespace {

double cross(const Vec2d& a, const Vec2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// ---- What Box2D 2.4.1 sees: the vertices as floats. --------------------------

struct F2 {
  float x, y;
};
F2 toF(const Vec2d& v) { return {static_cast<float>(v.x()), static_cast<float>(v.y())}; }
float distSqF(F2 a, F2 b) {
  const float dx = a.x - b.x, dy = a.y - b.y;
  return dx * dx + dy * dy;
}
float crossF(F2 a, F2 b) { return a.x * b.y - a.y * b.x; }

/// True when two vertices are closer than Box2D's linear slop, in double or
/// as Box2D's float check (b2ChainShape asserts distance² > slop²).
bool closerThanSlop(const Vec2d& a, const Vec2d& b) {
  const float slop = static_cast<float>(kLinearSlop);
  return (a - b).norm() < kLinearSlop || !(distSqF(toF(a), toF(b)) > slop * slop);
}

/// Replays b2PolygonShape::Set (welding, gift-wrapping hull, edge lengths,
/// centroid area) in float; returns what Box2D would assert on, or "".
std::string box2dPolygonProblem(const std::vector<Vec2d>& vertices) {
  const float epsilon = std::numeric_limits<float>::epsilon();
  const float halfSlop = 0.5f * static_cast<float>(kLinearSlop);
  std::vector<F2> ps;
  for (const Vec2d& v : vertices) {
    const F2 f = toF(v);
    bool unique = true;
    for (const F2& q : ps) unique = unique && !(distSqF(f, q) < halfSlop * halfSlop);
    if (unique) ps.push_back(f);
  }
  const std::size_t n = ps.size();
  if (n < 3) return "Box2D welds vertices closer than 0.0025 m and would keep fewer than 3";
  std::size_t i0 = 0;
  for (std::size_t i = 1; i < n; ++i)
    if (ps[i].x > ps[i0].x || (ps[i].x == ps[i0].x && ps[i].y < ps[i0].y)) i0 = i;
  std::vector<std::size_t> hull;
  std::size_t ih = i0;
  for (;;) {
    if (hull.size() >= 8) return "Box2D cannot build the convex hull of these vertices";
    hull.push_back(ih);
    std::size_t ie = 0;
    for (std::size_t j = 1; j < n; ++j) {
      if (ie == ih) {
        ie = j;
        continue;
      }
      const F2 a = ps[hull.back()];
      const F2 r{ps[ie].x - a.x, ps[ie].y - a.y}, v{ps[j].x - a.x, ps[j].y - a.y};
      const float c = crossF(r, v);
      if (c < 0.0f) ie = j;
      if (c == 0.0f && v.x * v.x + v.y * v.y > r.x * r.x + r.y * r.y) ie = j;
    }
    ih = ie;
    if (ie == i0) break;
  }
  const std::size_t m = hull.size();
  if (m < 3) return "the vertices are (almost) collinear: Box2D's convex hull has fewer than 3 vertices";
  std::vector<F2> h;
  for (std::size_t k : hull) h.push_back(ps[k]);
  for (std::size_t i = 0; i < m; ++i)
    if (!(distSqF(h[(i + 1) % m], h[i]) > epsilon * epsilon)) return "Box2D's convex hull has an edge of zero length";
  float area = 0;
  const F2 s = h[0];
  for (std::size_t i = 0; i < m; ++i) {
    const F2 e1{h[i].x - s.x, h[i].y - s.y};
    const F2 p3 = h[(i + 1) % m];
    const F2 e2{p3.x - s.x, p3.y - s.y};
    area += 0.5f * crossF(e1, e2);
  }
  // Box2D asserts area > FLT_EPSILON; keep a margin for rounding.
  if (!(area > 16 * epsilon))
    return "the polygon is too thin: its area in Box2D's float arithmetic is " + fmt(area) +
           " m^2, Box2D needs more than " + fmt(16 * epsilon) + " m^2";
  return "";
}

// ---- Fluid blocks and solids ---------------------------------------------------

/// Particles along x and y in a block (as doubles: no overflow for any input).
std::pair<double, double> blockLattice(const FluidBlockDef& b, double dx) {
  return {std::floor((b.max.x() - b.min.x()) / dx + 1e-9), std::floor((b.max.y() - b.min.y()) / dx + 1e-9)};
}

Vec2d rotate(const Vec2d& v, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return Vec2d(c * v.x() - s * v.y(), s * v.x() + c * v.y());
}

/// How deep p lies inside the solid fixture f of body b (world coordinates;
/// <= 0 outside; edges and chains have no inside).
double depthInside(const BodyDef& b, const ShapeDef& f, const Vec2d& p) {
  const Vec2d q = rotate(p - b.position, -b.angle);  // body coordinates
  switch (f.type) {
    case ShapeDef::Type::Box: {
      const Vec2d l = rotate(q - f.center, -f.angle);
      return std::min(f.halfSize.x() - std::fabs(l.x()), f.halfSize.y() - std::fabs(l.y()));
    }
    case ShapeDef::Type::Circle:
      return f.radius - (q - f.center).norm();
    case ShapeDef::Type::Polygon: {
      const std::size_t n = f.vertices.size();
      double area = 0;
      for (std::size_t i = 0; i < n; ++i) area += cross(f.vertices[i], f.vertices[(i + 1) % n]);
      const double orient = area > 0 ? 1 : -1;
      double depth = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < n; ++i) {
        const Vec2d e = f.vertices[(i + 1) % n] - f.vertices[i];
        depth = std::min(depth, orient * cross(e, q - f.vertices[i]) / e.norm());
      }
      return depth;
    }
    default:
      return 0;
  }
}

const char* shapeName(ShapeDef::Type t) {
  switch (t) {
    case ShapeDef::Type::Box:
      return "a box";
    case ShapeDef::Type::Polygon:
      return "a polygon";
    case ShapeDef::Type::Circle:
      return "a circle";
    case ShapeDef::Type::Edge:
      return "an edge";
    case ShapeDef::Type::Chain:
      return "a chain";
  }
  return "a solid";
}

}  // namespace

void checkMaxAboveMin(const Reader& r, const Vec2d& min, const Vec2d& max, const std::string& path) {
  if (!(max.x() > min.x() && max.y() > min.y()))
    r.fail(Reader::sub(path, "max"), "max must be greater than min in x and in y");
}

void checkName(const Reader& r, const std::string& name) {
  std::string why;
  if (name.empty())
    why = "the name is empty";
  else if (name.size() > 200)
    why = "the name is longer than 200 bytes";
  else if (name == "." || name == "..")
    why = "'" + name + "' is not a directory name";
  else if (name.find_first_of("/\\") != std::string::npos)
    why = "the name contains a slash";
  else
    for (const char c : name)
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) why = "the name contains a control character";
  if (!why.empty())
    r.fail("name", why + "; the name names the output directory out/<name>: use letters, digits, '_', '-' or '.'");
}

void checkFrameCount(const Reader& r, double duration, double fps, const std::string& key) {
  if (duration * fps > kMaxFrames)
    r.fail(key, "duration x fps = " + fmt(duration) + " s x " + fmt(fps) + " = " + fmt(duration * fps) +
                    " frames, more than " + fmt(kMaxFrames) +
                    "; shorten the duration (sph2d run --frames N renders fewer frames)");
}

void checkBoxHalfSize(const Reader& r, const Vec2d& halfSize, const std::string& path) {
  if (!(halfSize.x() > 0 && halfSize.y() > 0))
    r.fail(Reader::sub(path, "half_size"),
           "both half sizes must be > 0, got [" + fmt(halfSize.x()) + ", " + fmt(halfSize.y()) + "]");
  if (!(halfSize.x() >= kLinearSlop / 2 && halfSize.y() >= kLinearSlop / 2))
    r.fail(Reader::sub(path, "half_size"),
           "both half sizes must be >= 0.0025 (a box at least 0.005 m across, Box2D's linear slop), got [" +
               fmt(halfSize.x()) + ", " + fmt(halfSize.y()) + "]");
}

void checkCircleRadius(const Reader& r, double radius, const std::string& path) {
  if (radius < kLinearSlop / 2)
    r.fail(Reader::sub(path, "radius"),
           "value " + fmt(radius) +
               " is too small; a circle is at least 0.005 m across (radius >= 0.0025, Box2D's linear slop)");
}

void checkPolygon(const Reader& r, const std::vector<Vec2d>& vertices, const std::string& p) {
  const std::size_t n = vertices.size();
  if (n < 3 || n > 8) r.fail(p, "a polygon needs 3 to 8 vertices (Box2D 2.4.1), got " + std::to_string(n));
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = a + 1; b < n; ++b)
      if (closerThanSlop(vertices[a], vertices[b]))
        r.fail(p, "vertices [" + std::to_string(a) + "] and [" + std::to_string(b) +
                      "] are closer than 0.005 m (Box2D's linear slop)");
  // Convex: every turn has the same sign (straight turns aside) and the
  // turns add up to one full revolution (a star polygon turns twice).
  double area = 0, turning = 0;
  int sign = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2d& a = vertices[i];
    const Vec2d& b = vertices[(i + 1) % n];
    const Vec2d& c = vertices[(i + 2) % n];
    area += cross(a, b);
    const Vec2d u = b - a, v = c - b;
    const double turn = cross(u, v) / (u.norm() * v.norm());
    turning += std::atan2(cross(u, v), u.dot(v));
    const int sg = turn > 1e-9 ? 1 : (turn < -1e-9 ? -1 : 0);
    if (sg == 0 && u.dot(v) < 0)
      r.fail(p, "the polygon must be convex: its outline doubles back at vertex [" + std::to_string((i + 1) % n) + "]");
    if (sg != 0) {
      if (sign != 0 && sg != sign)
        r.fail(p, "the polygon must be convex (split a concave shape into several fixtures)");
      sign = sg;
    }
  }
  if (std::fabs(turning) > 3 * 3.14159265358979)
    r.fail(p, "the polygon must be convex: its edges cross (the outline winds around more than once)");
  if (std::fabs(area) < 1e-10) r.fail(p, "the polygon has no area");
  const std::string problem = box2dPolygonProblem(vertices);
  if (!problem.empty()) r.fail(p, problem);
}

void checkEdge(const Reader& r, const std::vector<Vec2d>& vertices, const std::string& p) {
  if (vertices.size() != 2) r.fail(p, "an edge needs exactly 2 vertices, got " + std::to_string(vertices.size()));
  if (closerThanSlop(vertices[0], vertices[1])) r.fail(p, "the edge is shorter than 0.005 m (Box2D's linear slop)");
}

void checkChain(const Reader& r, const std::vector<Vec2d>& vertices, bool loop, const std::string& p) {
  const std::size_t need = loop ? 3 : 2;
  if (vertices.size() < need)
    r.fail(p, std::string(loop ? "a looped" : "an open") + " chain needs at least " + std::to_string(need) +
                  " vertices, got " + std::to_string(vertices.size()));
  for (std::size_t i = 1; i < vertices.size(); ++i)
    if (closerThanSlop(vertices[i], vertices[i - 1]))
      r.fail(p + "[" + std::to_string(i) + "]", "chain vertices [" + std::to_string(i - 1) + "] and [" +
                                                    std::to_string(i) +
                                                    "] are closer than 0.005 m (Box2D's linear slop)");
  if (loop && closerThanSlop(vertices.back(), vertices.front()))
    r.fail(
        p + "[" + std::to_string(vertices.size() - 1) + "]",
        "the last vertex of a looped chain is closer than 0.005 m to the first (the loop closes itself: do not repeat the first vertex)");
}

void checkFluidPolygon(const Reader& r, const std::vector<Vec2d>& v, const std::string& p) {
  if (v.size() < 3 || v.size() > 256)
    r.fail(p, "a fluid polygon has 3 to 256 vertices, got " + std::to_string(v.size()));
  double area2 = 0, extent = 0;
  for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i++) {
    area2 += v[j].x() * v[i].y() - v[i].x() * v[j].y();
    extent = std::max(extent, (v[i] - v[0]).norm());
  }
  if (!(std::fabs(area2) > 1e-12 * extent * extent))
    r.fail(p, "the polygon encloses no area (its vertices are on one line or repeat)");
}

double regionLatticeCount(const FluidBlockDef& b, double dx) {
  const auto [nx, ny] = blockLattice(b, dx);
  if (!(nx >= 1 && ny >= 1)) return 0;
  // Beyond 10^7 rows (circles) or 2·10^5 rows (polygons, up to 256 edges a row) the box's count,
  // an upper bound: a hostile scene must not make the loader count for seconds.
  if (b.shape == FluidBlockDef::Shape::Box || ny > 1e7 || (b.shape == FluidBlockDef::Shape::Polygon && ny > 2e5))
    return nx * ny;
  // Row by row: the points inside form intervals of the row (the circle's chord; for a
  // polygon, between crossings, by parity). Each interval's ends are found from an
  // estimate and settled with contains() itself, so the count is exactly the points
  // World's fill keeps, in O(rows × vertices) however many points the box holds.
  const long n = long(nx);
  auto x = [&](long i) { return b.min.x() + (double(i) + 0.5) * dx; };
  double count = 0, y = 0;
  std::vector<double> xs;
  for (long j = 0; j < long(ny); ++j) {
    y = j == 0 ? b.min.y() + 0.5 * dx * 1.0 : y + 0.5 * dx * (1.0 + 1.0);  // the rows as fillBlock steps them
    auto in = [&](long i) { return b.contains(Vec2d(x(i), y)); };
    /// The first index whose point is at or right of `xc` (n when none is).
    auto firstAtOrRight = [&](double xc) {
      long i = long(std::clamp(std::ceil((xc - b.min.x()) / dx - 0.5), 0.0, double(n)));
      while (i > 0 && x(i - 1) >= xc) --i;
      while (i < n && x(i) < xc) ++i;
      return i;
    };
    if (b.shape == FluidBlockDef::Shape::Circle) {
      const double dy = y - b.center.y(), h2 = b.radius * b.radius - dy * dy;
      if (!(h2 >= 0)) continue;
      const double h = std::sqrt(h2);
      long lo = firstAtOrRight(b.center.x() - h), hi = firstAtOrRight(b.center.x() + h);  // about [lo, hi)
      while (lo > 0 && in(lo - 1)) --lo;
      while (lo < hi && !in(lo)) ++lo;
      while (hi < n && in(hi)) ++hi;
      while (hi > lo && !in(hi - 1)) --hi;
      count += double(hi - lo);
      continue;
    }
    b.rowCrossings(y, xs);
    // A point in [xs[m-1], xs[m]) has xs.size() − m crossings right of it (> x); inside
    // when that is odd. Left of xs[0] there is an even number (a closed outline).
    for (std::size_t m = 1; m < xs.size(); ++m)
      if (((xs.size() - m) & 1) != 0) count += double(firstAtOrRight(xs[m]) - firstAtOrRight(xs[m - 1]));
  }
  return count;
}

void checkBlock(const Reader& r, const SceneDef& s, const FluidBlockDef& blk, const std::string& p) {
  const double dx = s.solver.spacing;
  const auto [nx, ny] = blockLattice(blk, dx);
  if (blk.shape != FluidBlockDef::Shape::Box && nx >= 1 && ny >= 1 && regionLatticeCount(blk, dx) == 0)
    r.fail(Reader::sub(p, blk.shape == FluidBlockDef::Shape::Circle ? "radius" : "vertices"),
           "the region holds no point of the particle lattice (spacing " + fmt(dx) + " m): it would hold no particle");
  if (nx < 1 || ny < 1)
    r.fail(Reader::sub(p, "max"), "the block is " + fmt(blk.max.x() - blk.min.x()) + " m x " +
                                      fmt(blk.max.y() - blk.min.y()) + " m, less than one particle spacing (" +
                                      fmt(dx) + " m) " + (nx < 1 ? "wide" : "high") + ": it would hold no particle");
  // The lattice spans x in [min + dx/2, min + (nx - 1/2) dx]; the rows, compressed
  // downwards at most, y in [min, min + (ny - 1/2) dx]. A convex solid holding
  // the four corners holds every particle.
  const double x0 = blk.min.x() + 0.5 * dx, x1 = blk.min.x() + (nx - 0.5) * dx;
  const double y0 = blk.min.y(), y1 = blk.min.y() + (ny - 0.5) * dx;
  const double margin = 0.01 * dx + 1e-6 * std::max({1.0, std::fabs(x0), std::fabs(x1), std::fabs(y0), std::fabs(y1)});
  for (std::size_t bi = 0; bi < s.bodies.size(); ++bi)
    for (std::size_t fi = 0; fi < s.bodies[bi].fixtures.size(); ++fi) {
      const BodyDef& b = s.bodies[bi];
      const ShapeDef& f = b.fixtures[fi];
      bool all = true;
      for (const Vec2d& c : {Vec2d(x0, y0), Vec2d(x1, y0), Vec2d(x0, y1), Vec2d(x1, y1)})
        all = all && depthInside(b, f, c) > margin;
      if (all)
        r.fail(p, "the block lies entirely inside boundaries[" + std::to_string(bi) + "].fixtures[" +
                      std::to_string(fi) + "] (" + shapeName(f.type) + "): every particle would be dropped");
    }
}

void checkPeriod(const Reader& r, const Vec2d& range, double R, const std::string& p) {
  // The neighbour grid needs five cells of R/2 across the period, and one
  // particle must not meet two images of another: a period of at least 3R.
  if (!(range.y() - range.x() >= 3 * R))
    r.fail(p, "the period [" + fmt(range.x()) + ", " + fmt(range.y()) + "] is " + fmt(range.y() - range.x()) +
                  " m long; it must be at least 3 support radii (3 x " + fmt(R) + " m) long, min < max");
}

void checkCamera(const Reader& r, const CameraDef& camera, const std::string& p) {
  checkMaxAboveMin(r, camera.min, camera.max, p);
  const Vec2d size = camera.max - camera.min;
  if (size.x() < kMinCameraSize || size.y() < kMinCameraSize) {
    // Enough digits that a size just under the limit does not print as the limit itself.
    auto exact = [](double v) {
      std::ostringstream o;
      o.precision(12);
      o << v;
      return o.str();
    };
    r.fail(Reader::sub(p, "max"), "the camera shows " + exact(size.x()) + " m x " + exact(size.y()) +
                                      " m; it must be at least 0.001 m wide and high");
  }
}

void checkParticleBudget(const Reader& r, const SceneDef& s) {
  const std::size_t n = countBlockParticles(s);
  if (n > s.maxParticles)
    r.fail("solver.spacing",
           "spacing " + fmt(s.solver.spacing) + " fills the fluid blocks with " +
               (n >= std::numeric_limits<std::size_t>::max() / 2 ? std::string("too many") : std::to_string(n)) +
               " particles, more than max_particles = " + std::to_string(s.maxParticles) +
               "; use a larger spacing or raise max_particles");
  const double samples = estimateBoundarySamples(s);
  const std::size_t sampleBudget = std::max<std::size_t>(s.maxParticles, kMinSampleBudget);
  if (samples > double(sampleBudget))
    r.fail("solver.spacing", "spacing " + fmt(s.solver.spacing) + " lines the solids with about " + fmt(samples) +
                                 " boundary samples, more than max(max_particles, " + std::to_string(kMinSampleBudget) +
                                 ") = " + std::to_string(sampleBudget) + "; use a larger spacing or smaller solids");
}

/// An upper estimate of the boundary samples the World will lay in the solids
/// (layers of ceil(R/dx) rows under every face, both sides of segments).
double estimateBoundarySamples(const SceneDef& s) {
  const double dx = s.solver.spacing;
  const double layers = std::max(1.0, std::ceil(s.solver.supportRatio - 1e-9));
  const auto along = [&](double len) { return std::max(1.0, std::round(len / dx)); };
  double total = 0;
  for (const BodyDef& b : s.bodies)
    for (const ShapeDef& f : b.fixtures) {
      switch (f.type) {
        case ShapeDef::Type::Box:
          total += layers * 2 * (along(2 * f.halfSize.x()) + along(2 * f.halfSize.y()));
          break;
        case ShapeDef::Type::Polygon:
          for (std::size_t i = 0; i < f.vertices.size(); ++i)
            total += layers * along((f.vertices[(i + 1) % f.vertices.size()] - f.vertices[i]).norm());
          break;
        case ShapeDef::Type::Circle:
          total += layers * std::max(3.0, std::round(2 * 3.14159265358979 * f.radius / dx));
          break;
        case ShapeDef::Type::Edge:
        case ShapeDef::Type::Chain:
          for (std::size_t i = 0; i + 1 < f.vertices.size(); ++i)
            total += 2 * layers * along((f.vertices[i + 1] - f.vertices[i]).norm());
          if (f.loop) total += 2 * layers * along((f.vertices.front() - f.vertices.back()).norm());
          break;
      }
    }
  return total;
}

std::size_t peakParticles(const SceneDef& scene) {
  const double dx = scene.solver.spacing;
  double n = double(countBlockParticles(scene));
  for (const EmitterDef& e : scene.effects.emitters) {
    const double from = std::max(0.0, e.start), to = std::min(e.stop, scene.duration);
    if (to > from && e.rate > 0) n += e.rate * (to - from);
  }
  for (const EventDef& e : scene.events) {
    if (e.type == EventDef::Type::Block) {
      const auto [nx, ny] = blockLattice(e.block, dx);
      if (nx > 0 && ny > 0) n += nx * ny;
    } else if (e.type == EventDef::Type::Drop) {
      n += 3.14159265358979323846 * (e.radius / dx + 1) * (e.radius / dx + 1);
    }
  }
  const std::size_t budget = scene.effects.budget > 0 ? scene.effects.budget : scene.maxParticles;
  return n >= double(budget) ? budget : std::size_t(n);
}

double estimateWorldBytes(const SceneDef& scene) {
  return kProcessBytes + kBytesPerParticle * double(peakParticles(scene)) +
         kBytesPerSample * estimateBoundarySamples(scene);
}

std::size_t countBlockParticles(const SceneDef& scene) {
  double n = 0;
  for (const auto& b : scene.blocks) n += regionLatticeCount(b, scene.solver.spacing);
  for (const auto& g : scene.groups) n += regionLatticeCount(g.region, scene.solver.spacing);
  const double most = double(std::numeric_limits<std::size_t>::max() / 2);
  return !(n < most) ? std::numeric_limits<std::size_t>::max() / 2 : static_cast<std::size_t>(n);
}

}  // namespace sph2d
