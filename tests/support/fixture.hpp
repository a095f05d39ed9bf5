// tests/support/fixture.hpp — the shared test fixture (in the spirit of Jolt's
// PhysicsTestContext): the tanks and shapes the tests build scenes from, and
// the measurements they take of a World. One definition of each, so that two
// tests that say "outside the tank" or "kinetic energy" mean the same thing.
//
// Scene builders: boxShape, pointsShape, tank (a closed W × H box of four
// static boxes), arena (4 m × 4 m), block. Measurements (world coordinates, every
// particle): outside, meanSpeed, maxSpeed, frontX, sumY, potentialEnergy,
// momentum, velocityVariance, layerVelocityDifference, centroid,
// minPairDistance(Periodic), inertiaAspect, cornerRatio, surfaceHeight,
// PressureProbe (fitLine). Flows:
// wallScene, periodicShearLayer (shearLayerDecay), freeMovingBlock (momentumOver). Floating bodies:
// crateScene, dynamicBody, crateSurface, bottomOf, insideMovingCount.
#pragma once

#include <box2d/box2d.h>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"
#include "test_util.hpp"

namespace sph2d::test {

constexpr double kPi = 3.14159265358979323846;

// --- scenes ------------------------------------------------------------------

/// A static box fixture centred at `center` with half extents `half`, rotated by `angle` [rad].
inline ShapeDef boxShape(const Vec2d& center, const Vec2d& half, double angle = 0) {
  ShapeDef s;
  s.type = ShapeDef::Type::Box;
  s.center = center;
  s.halfSize = half;
  s.angle = angle;
  return s;
}

/// A polygon, edge or chain fixture through `vertices`.
inline ShapeDef pointsShape(ShapeDef::Type type, std::vector<Vec2d> vertices, bool loop = false) {
  ShapeDef s;
  s.type = type;
  s.vertices = std::move(vertices);
  s.loop = loop;
  return s;
}

/// The four walls, 0.2 m thick, of the closed tank [0, W] × [0, H] (floor, lid, left, right).
inline BodyDef tankWalls(double W, double H) {
  BodyDef b;
  b.fixtures = {boxShape({W / 2, -0.1}, {W / 2 + 0.2, 0.1}), boxShape({W / 2, H + 0.1}, {W / 2 + 0.2, 0.1}),
                boxShape({-0.1, H / 2}, {0.1, H / 2 + 0.2}), boxShape({W + 0.1, H / 2}, {0.1, H / 2 + 0.2})};
  return b;
}

/// A scene with `solver` at `spacing` (the solver's and the scene's defaults
/// otherwise) in the closed tank [0, W] × [0, H]; no fluid yet.
inline SceneDef tank(const std::string& solver, double W, double H, double spacing) {
  SceneDef s;
  s.solver = solverDefaults(solver);  // the solver's own defaults (game: its viscosity and support)
  s.solver.spacing = spacing;
  s.bodies.push_back(tankWalls(W, H));
  return s;
}

/// A closed 4 m × 4 m arena [0, 4]², walls 0.2 m thick.
inline BodyDef arena() {
  BodyDef b;
  b.fixtures = {boxShape({2, -0.2}, {2.4, 0.2}), boxShape({2, 4.2}, {2.4, 0.2}), boxShape({-0.2, 2}, {0.2, 2.4}),
                boxShape({4.2, 2}, {0.2, 2.4})};
  return b;
}

/// A fluid block [lo, hi] moving at `velocity`.
inline FluidBlockDef block(const Vec2d& lo, const Vec2d& hi, const Vec2d& velocity = Vec2d(0, 0)) {
  FluidBlockDef b;
  b.min = lo;
  b.max = hi;
  b.velocity = velocity;
  return b;
}

/// validation/taylor_green.json's fully periodic 1 m box (zero gravity, no walls,
/// pressure of either sign) with `solver` (its defaults) at `spacing`, holding a
/// shear layer: the lower half [0, 1] × [0, 0.5] moving at (−U, 0), the upper half
/// at (+U, 0). No effects (ν = 0, no shifting). The lower half's particles are
/// created first: ids below the lower half's count.
inline SceneDef periodicShearLayer(const std::string& solver, double U, double spacing) {
  SceneDef s = scene("validation/taylor_green.json");
  const SolverDef defaults = solverDefaults(solver);
  s.solver.type = solver;
  s.solver.params = defaults.params;
  s.solver.supportRatio = defaults.supportRatio;
  s.solver.spacing = spacing;
  s.solver.viscosity = 0;
  s.effects.shifting = false;
  s.blocks = {block({0, 0}, {1, 0.5}, {-U, 0}), block({0, 0.5}, {1, 1}, {U, 0})};
  return s;
}

/// A scene with gravity and no bodies for fluid falling onto Box2D solids, with
/// `solver` (default wcsph) at `spacing` and the settings such scenes need: they fall up to 3 m
/// (v ≈ 7.7 m/s), and a weakly compressible fluid needs c0 ≥ 10 v_max (at c0 = 25 m/s
/// an impact compresses it by v/c ≈ 15 % and the rebound throws particles out of
/// cups). wcsph: c0 = 10 × 8 m/s, ν = 0 (its artificial viscosity damps). muller2003
/// (p = c²(ρ − ρ0)): the same c = 80 m/s, and ν = 0.02 m²/s: its pressure force is not
/// conservative (poly6 density, spiky gradient), so it needs a physical viscosity to stay
/// calm (docs/SCENES.md: ν ≳ 0.005 at dx = 0.02 and c = 25; the heating grows with c).
/// Measured on the 10° wedge at c = 80: ν = 0 gains 97 % of the potential energy
/// released, ν = 0.01 comes to rest slowly, ν = 0.02 rests within 2 s.
/// pbf and dfsph have no sound speed and run with their defaults and ν = 0.
inline SceneDef wallScene(double spacing, const std::string& solver = "wcsph") {
  SceneDef s;
  s.solver = solverDefaults(solver);
  s.solver.spacing = spacing;
  s.solver.viscosity = solver == "muller2003" ? 0.02 : 0.0;
  if (solver == "wcsph") s.solver.params["expected_speed"] = 8;
  if (solver == "muller2003") s.solver.soundSpeed = 80;
  s.gravity = Vec2d(0, -9.81);
  return s;
}

/// A free block [0, 0.8]² moving at (0.3, −0.2) m/s in zero gravity, no walls:
/// wcsph at dx = 0.04, ν = 0, no effects (the pairwise-momentum tests add theirs).
inline SceneDef freeMovingBlock() {
  SceneDef s;
  s.solver = solverDefaults("wcsph");
  s.solver.spacing = 0.04;
  s.solver.viscosity = 0.0;
  s.gravity = Vec2d(0, 0);
  s.blocks.push_back(block({0, 0}, {0.8, 0.8}, {0.3, -0.2}));
  return s;
}

// --- measurements --------------------------------------------------------------

/// A static box body of a game's own b2World, centre (cx, cy), half sizes (hx, hy), turned by `angle`.
inline b2Body* addStaticBox(b2World& world, float cx, float cy, float hx, float hy, float angle = 0) {
  b2BodyDef bd;
  bd.position.Set(cx, cy);
  bd.angle = angle;
  b2Body* body = world.CreateBody(&bd);
  b2PolygonShape box;
  box.SetAsBox(hx, hy);
  body->CreateFixture(&box, 0);
  return body;
}

/// Mean vx of the particles in [x0, x1] × [y0, y1] (world coordinates) and how many there are.
struct MeanVx {
  double mean = 0;
  int count = 0;
};
inline MeanVx meanVxIn(const World& w, double x0, double x1, double y0, double y1) {
  MeanVx r;
  double sum = 0;
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const Vec2d x = w.worldPosition(i);
    if (x.x() > x0 && x.x() < x1 && x.y() > y0 && x.y() < y1) {
      sum += double(w.particles().v[i].x());
      ++r.count;
    }
  }
  r.mean = r.count ? sum / r.count : 0;
  return r;
}

/// Particles outside the rectangle [x0, x1] × [y0, y1] (world frame; the edges count as inside).
inline std::size_t outside(const World& w, double x0, double y0, double x1, double y1) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const Vec2d p = w.worldPosition(i);
    n += !(p.x() >= x0 && p.x() <= x1 && p.y() >= y0 && p.y() <= y1);
  }
  return n;
}

/// Particles outside the tank [0, W] × [0, H].
inline std::size_t outside(const World& w, double W, double H) { return outside(w, 0, 0, W, H); }

/// Mean particle speed [m/s] (0 without particles).
inline double meanSpeed(const World& w) {
  double s = 0;
  for (std::size_t i = 0; i < w.particleCount(); ++i) s += double(w.particles().v[i].norm());
  return w.particleCount() ? s / double(w.particleCount()) : 0;
}

/// Largest particle speed [m/s].
inline double maxSpeed(const World& w) {
  double s = 0;
  for (std::size_t i = 0; i < w.particleCount(); ++i) s = std::max(s, double(w.particles().v[i].norm()));
  return s;
}

/// The largest x of any particle: a surge front moving right.
inline double frontX(const World& w) {
  double m = -1e300;
  for (std::size_t i = 0; i < w.particleCount(); ++i) m = std::max(m, w.worldPosition(i).x());
  return m;
}

/// Σ y over the particles [m].
inline double sumY(const World& w) {
  double s = 0;
  for (std::size_t i = 0; i < w.particleCount(); ++i) s += w.worldPosition(i).y();
  return s;
}

/// Σ m g y over the particles [J per metre of depth]: the potential energy for gravity g downwards
/// (materials of one density: m is World::particleMass for all; World::kineticEnergy weighs each).
inline double potentialEnergy(const World& w, double g = 9.81) { return double(w.particleMass()) * g * sumY(w); }

/// Σ m v [kg m/s per metre of depth] (materials of one density, as potentialEnergy).
inline Vec2d momentum(const World& w) {
  Vec2d m(0, 0);
  for (std::size_t i = 0; i < w.particleCount(); ++i)
    m += Vec2d(w.particles().v[i].x(), w.particles().v[i].y()) * double(w.particleMass());
  return m;
}

/// The mean of |v − v̄|² over the particles, v̄ their mean velocity [m²/s²].
inline double velocityVariance(const World& w) {
  Vec2d mean(0, 0);
  for (std::size_t i = 0; i < w.particleCount(); ++i) mean += Vec2d(w.particles().v[i].x(), w.particles().v[i].y());
  if (w.particleCount() == 0) return 0;
  mean /= double(w.particleCount());
  double s = 0;
  for (std::size_t i = 0; i < w.particleCount(); ++i)
    s += (Vec2d(w.particles().v[i].x(), w.particles().v[i].y()) - mean).squaredNorm();
  return s / double(w.particleCount());
}

/// Δ(t)/Δ(0) for a shear layer ±U in a periodic box of side L = 2π/k (periodicShearLayer): u(y, 0)
/// is a square wave, u = (4U/π) Σ_{n odd} sin(nky)/n, each mode decays as e^{−ν n²k² t}, and the
/// halves' mean velocities differ by (16U/π²) Σ_{n odd} e^{−ν n²k² t}/n².
inline double shearLayerDecay(double nu, double k, double t) {
  double s = 0;
  for (int n = 1; n < 400; n += 2) s += std::exp(-nu * n * n * k * k * t) / (n * n);
  return 8 / (kPi * kPi) * s;
}

/// Mean x velocity of the particles with id ≥ firstId minus that of those below it
/// (a shear layer's velocity difference, periodicShearLayer).
inline double layerVelocityDifference(const World& w, std::uint32_t firstId) {
  double lo = 0, hi = 0;
  std::size_t nLo = 0, nHi = 0;
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const double vx = w.particles().v[i].x();
    if (w.particles().id[i] < firstId) {
      lo += vx;
      ++nLo;
    } else {
      hi += vx;
      ++nHi;
    }
  }
  return hi / double(std::max<std::size_t>(nHi, 1)) - lo / double(std::max<std::size_t>(nLo, 1));
}

/// The smallest distance between two particles, nearest image in the periodic box
/// [0, L]² (all pairs: for small tests).
inline double minPairDistancePeriodic(const World& w, double L) {
  double m = 1e300;
  for (std::size_t i = 0; i < w.particleCount(); ++i)
    for (std::size_t j = i + 1; j < w.particleCount(); ++j) {
      Vec2d d = w.worldPosition(i) - w.worldPosition(j);
      d.x() -= L * std::round(d.x() / L);
      d.y() -= L * std::round(d.y() / L);
      m = std::min(m, d.norm());
    }
  return m;
}

/// What `substeps` substeps did to the total momentum of a scene's World (2 threads).
struct MomentumRun {
  double change = 0;    ///< |Σ m v after − Σ m v before|
  double scale = 0;     ///< N m · 0.36 m/s (freeMovingBlock's momentum is N m · 0.36 m/s)
  bool finite = false;  ///< every position, velocity and density finite at the end
};

/// Runs `scene` for `substeps` substeps and measures the change of its momentum.
inline MomentumRun momentumOver(const SceneDef& scene, int substeps) {
  World w(scene, WorldOptions{2});
  const Vec2d m0 = momentum(w);
  for (int i = 0; i < substeps; ++i) sph2d::bench::stepSubstep(w);
  MomentumRun r;
  r.change = (momentum(w) - m0).norm();
  r.scale = double(w.particleCount()) * double(w.particleMass()) * 0.36;
  r.finite = allFiniteState(w);
  return r;
}

/// The free-surface height near x = xc: the mean height of the particles within
/// one spacing of the highest one and within `halfWidth` of xc, plus half a spacing.
inline double surfaceHeight(const World& w, double xc, double halfWidth) {
  const double dx = double(w.spacing());
  double top = -1e300;
  for (std::size_t i = 0; i < w.particleCount(); ++i) top = std::max(top, w.worldPosition(i).y());
  double H = 0;
  int n = 0;
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const Vec2d q = w.worldPosition(i);
    if (q.y() > top - dx && std::fabs(q.x() - xc) < halfWidth) {
      H += q.y();
      ++n;
    }
  }
  return H / std::max(n, 1) + 0.5 * dx;
}

/// A pressure probe: the particles' pressure averaged in horizontal bands centred
/// at y = k·band (those within 0.3 band of the centre and within halfWidth of
/// x = xc), summed over every add() (so a probe averages slow sloshing out).
struct PressureProbe {
  double xc, halfWidth, band;
  std::vector<double> sum = std::vector<double>(400, 0.0);
  std::vector<int> count = std::vector<int>(400, 0);
  /// Adds the particles of the current state.
  void add(const World& w) {
    for (std::size_t i = 0; i < w.particleCount(); ++i) {
      const Vec2d q = w.worldPosition(i);
      const long k = std::lround(q.y() / band);
      if (k < 0 || k >= long(sum.size()) || std::fabs(q.x() - xc) >= halfWidth ||
          std::fabs(q.y() - band * double(k)) >= 0.3 * band)
        continue;
      sum[std::size_t(k)] += double(w.particles().p[i]);
      ++count[std::size_t(k)];
    }
  }
  /// (y, mean pressure) of the bands with particles, from y0 to y1.
  std::vector<std::pair<double, double>> profile(double y0, double y1) const {
    std::vector<std::pair<double, double>> out;
    for (std::size_t k = 0; k < sum.size(); ++k) {
      const double y = band * double(k);
      if (y >= y0 && y <= y1 && count[k] > 0) out.emplace_back(y, sum[k] / count[k]);
    }
    return out;
  }
};

/// Least-squares line p = intercept + slope·y through (y, p) points.
struct Line {
  double intercept = 0, slope = 0;
  /// Where the line crosses p = 0.
  double zero() const { return -intercept / slope; }
};
inline Line fitLine(const std::vector<std::pair<double, double>>& pts) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = double(pts.size());
  for (const auto& [x, y] : pts) {
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  Line l;
  l.slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  l.intercept = (sy - l.slope * sx) / n;
  return l;
}

/// The mean position of the particles.
inline Vec2d centroid(const World& w) {
  Vec2d c(0, 0);
  for (std::size_t i = 0; i < w.particleCount(); ++i) c += w.worldPosition(i);
  return w.particleCount() ? Vec2d(c / double(w.particleCount())) : c;
}

/// The smallest distance between two particles (all pairs: for small tests).
inline double minPairDistance(const World& w) {
  double m = 1e300;
  for (std::size_t i = 0; i < w.particleCount(); ++i)
    for (std::size_t j = i + 1; j < w.particleCount(); ++j)
      m = std::min(m, (w.worldPosition(i) - w.worldPosition(j)).norm());
  return m;
}

/// sqrt(λmax/λmin) of the second-moment matrix Σ (x − c)(x − c)ᵀ about the
/// centroid: the axis ratio of the ellipse with the same second moments (a 2:1
/// block: 2, a disc: 1; a square also reads 1, see cornerRatio).
inline double inertiaAspect(const World& w) {
  const Vec2d c = centroid(w);
  Eigen::Matrix2d M = Eigen::Matrix2d::Zero();
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const Vec2d d = w.worldPosition(i) - c;
    const Eigen::Vector2d e(d.x(), d.y());
    M += e * e.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(M);
  return std::sqrt(es.eigenvalues()(1) / es.eigenvalues()(0));
}

/// The farthest particle's distance from the centroid in each of 16 equal
/// angular sectors, largest over smallest (a square: 1.39; a lattice disc of
/// 20 spacings: 1.02).
inline double cornerRatio(const World& w) {
  const Vec2d c = centroid(w);
  std::vector<double> far(16, 0.0);
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const Vec2d d = w.worldPosition(i) - c;
    const double a = std::atan2(d.y(), d.x()) + kPi;  // 0..2π
    const int k = std::min(15, int(a / (2 * kPi) * 16));
    far[std::size_t(k)] = std::max(far[std::size_t(k)], d.norm());
  }
  return *std::max_element(far.begin(), far.end()) / *std::min_element(far.begin(), far.end());
}

// --- floating bodies ---------------------------------------------------------

/// A 2 m × 1 m tank with 0.6 m of still water (spacing 0.01) and a dynamic crate, 0.6 m × 0.2 m
/// of density `density` kg/m², its centre at height `y`, solver `solver`.
inline SceneDef crateScene(const std::string& solver, double density, double y) {
  SceneDef s = tank(solver, 2.0, 1.0, 0.01);
  s.blocks.push_back(block({0, 0}, {2.0, 0.6}));
  BodyDef crate;
  crate.type = BodyDef::Type::Dynamic;
  crate.position = Vec2d(1.0, y);
  ShapeDef box = boxShape({0, 0}, {0.3, 0.1});
  box.density = density;
  crate.fixtures.push_back(box);
  s.bodies.push_back(crate);
  return s;
}

/// A 2 m × 1 m tank (spacing 0.02, no gravity) holding water [0, 2] × [0, 0.6] moving at
/// `velocity`, and a 0.4 m × 0.12 m box centred at (1, 0.3): static, or kinematic at rest (the
/// same box sampled as a moving body). Water within 0.2 + 2 spacings of its centre in x is beside it.
inline SceneDef boxInWater(const std::string& solver, bool kinematic, const Vec2d& velocity = Vec2d(0, 0)) {
  SceneDef s = tank(solver, 2.0, 1.0, 0.02);
  s.gravity = Vec2d(0, 0);
  s.blocks.push_back(block({0, 0}, {2.0, 0.6}, velocity));
  BodyDef box;
  box.type = kinematic ? BodyDef::Type::Kinematic : BodyDef::Type::Static;
  box.position = Vec2d(1.0, 0.3);
  box.fixtures.push_back(boxShape({0, 0}, {0.2, 0.06}));
  s.bodies.push_back(box);
  return s;
}

/// The world's first dynamic body (null: none).
inline const b2Body* dynamicBody(const World& w) {
  for (const b2Body* b = w.box2d().GetBodyList(); b; b = b->GetNext())
    if (b->GetType() == b2_dynamicBody) return b;
  return nullptr;
}

/// The water's surface height in [x0, x1]: over columns three spacings wide (so that a
/// column always holds a surface particle), the mean of the highest particle's centre,
/// plus half a spacing.
inline double crateSurface(const World& w, double x0, double x1) {
  const double dx = double(w.spacing()), bin = 3 * dx;
  const int n = int(std::floor((x1 - x0) / bin));
  std::vector<double> top(std::size_t(n), -1e300);
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const Vec2d q = w.worldPosition(i);
    const int k = int(std::floor((q.x() - x0) / bin));
    if (k >= 0 && k < n) top[std::size_t(k)] = std::max(top[std::size_t(k)], q.y());
  }
  double sum = 0;
  for (double t : top) sum += t;
  return sum / n + 0.5 * dx;
}

/// The lowest point of a body of polygons (world coordinates).
inline double bottomOf(const b2Body* b) {
  double lo = 1e300;
  for (const b2Fixture* f = b->GetFixtureList(); f; f = f->GetNext()) {
    const auto* poly = static_cast<const b2PolygonShape*>(f->GetShape());
    for (int i = 0; i < poly->m_count; ++i) lo = std::min(lo, double(b2Mul(b->GetTransform(), poly->m_vertices[i]).y));
  }
  return lo;
}

/// Particles deeper than 0.1 spacing inside any moving body (as the fluid meets it:
/// World::movingColliders()), those with y below `floorBand` not counted.
inline std::size_t insideMovingCount(const World& w, double floorBand = -1e300) {
  std::size_t n = 0;
  const std::vector<Collider> shapes = w.movingColliders();
  for (std::size_t i = 0; i < w.particleCount(); ++i) {
    const Vec2 x = w.particles().x[i];
    if (w.worldPosition(i).y() < floorBand) continue;
    for (const Collider& c : shapes) {
      Real depth = 1e30f;
      if (c.kind == Collider::Kind::Circle)
        depth = c.radius - (x - c.center).norm();
      else
        for (std::size_t f = 0; f < c.vertices.size(); ++f)
          depth = std::min(depth, -c.normals[f].dot(x - c.vertices[f]));
      if (depth > Real(0.1) * w.spacing()) ++n;
    }
  }
  return n;
}

}  // namespace sph2d::test
