#include "sph2d/world.hpp"

#include <box2d/box2d.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <sstream>

#include "effects/effect.hpp"
#include "solvers/solver.hpp"
#include "sph2d/hash.hpp"
#include "stages.hpp"

namespace sph2d {

SimulationError::SimulationError(const std::string& what, std::string stage_, std::uint32_t particleId_,
                                 std::uint64_t step_, double time_)
    : std::runtime_error(what), stage(std::move(stage_)), particleId(particleId_), step(step_), time(time_) {}

namespace {

b2Vec2 bv(const Vec2d& v) { return b2Vec2(float(v.x()), float(v.y())); }

void addBody(b2World& world, const BodyDef& def) {
  b2BodyDef bd;
  bd.type = b2_staticBody;
  bd.position = bv(def.position);
  bd.angle = float(def.angle);
  b2Body* body = world.CreateBody(&bd);
  for (const ShapeDef& s : def.fixtures) {
    b2FixtureDef fd;
    fd.friction = float(s.friction);
    fd.restitution = float(s.restitution);
    b2PolygonShape poly;
    b2CircleShape circle;
    b2EdgeShape edge;
    b2ChainShape chain;
    std::vector<b2Vec2> pts;
    for (const Vec2d& v : s.vertices) pts.push_back(bv(v));
    switch (s.type) {
      case ShapeDef::Type::Box:
        poly.SetAsBox(float(s.halfSize.x()), float(s.halfSize.y()), bv(s.center), float(s.angle));
        fd.shape = &poly;
        break;
      case ShapeDef::Type::Polygon:
        poly.Set(pts.data(), int(pts.size()));
        fd.shape = &poly;
        break;
      case ShapeDef::Type::Circle:
        circle.m_p = bv(s.center);
        circle.m_radius = float(s.radius);
        fd.shape = &circle;
        break;
      case ShapeDef::Type::Edge:
        edge.SetTwoSided(pts[0], pts[1]);
        fd.shape = &edge;
        break;
      case ShapeDef::Type::Chain:
        if (s.loop) {
          chain.CreateLoop(pts.data(), int(pts.size()));
        } else {
          const b2Vec2 prev = pts[0] + (pts[0] - pts[1]);
          const b2Vec2 next = pts.back() + (pts.back() - pts[pts.size() - 2]);
          chain.CreateChain(pts.data(), int(pts.size()), prev, next);
        }
        fd.shape = &chain;
        break;
    }
    body->CreateFixture(&fd);
  }
}

/// Σ W over a square lattice of spacing dx around one point (the point included).
double latticeSum(const Solver& solver, double R, double dx) {
  const int n = int(std::ceil(R / dx)) + 1;
  double s = 0;
  for (int j = -n; j <= n; ++j)
    for (int i = -n; i <= n; ++i) s += solver.densityKernel(std::sqrt(double(i * i + j * j)) * dx, R);
  return s;
}

}  // namespace

struct World::Impl final : StageRunner {
  SceneDef scene;
  ThreadPool pool;
  std::unique_ptr<b2World> ownWorld;
  b2World* b2 = nullptr;
  Vec2d origin{0, 0};
  Particles P;
  Grid grid;
  NeighbourLists nbr;
  BoundarySet boundary;
  Scratch scratch;
  std::unique_ptr<Solver> solver;
  EffectList effects;
  Real dx = 0, R = 0, mass = 0;
  PeriodicBox periodic;  ///< the scene's periodic box in the local frame
  double time = 0;
  std::uint64_t frames = 0, steps = 0;
  int lastSubsteps = 0;
  Real lastAccel = 0;
  std::uint32_t nextId = 0;
  std::vector<StageTiming> timing;  ///< in the order stages first ran
  std::vector<std::string> warnings;

  // The particle system of seed 001: emitters, lifetimes, sinks, budget.
  struct EmitterState {
    EmitterDef def;
    std::uint64_t rng = 0;      ///< SplitMix64 state, seeded per emitter
    std::uint64_t emitted = 0;
    bool warnedBudget = false;
  };
  std::vector<EmitterState> emitters;
  std::size_t budget = 0;
  std::uint64_t removed = 0;
  std::vector<UserForce> userForces;
  bool userForceEffect = false;
  std::vector<unsigned char> dead;  ///< scratch: removal flags

  explicit Impl(const SceneDef& s, const WorldOptions& o) : scene(s), pool(o.threads) {}

  StepContext context(Real dt) {
    StepContext c{P, grid, nbr, boundary, pool, scratch, scene.solver};
    c.R = R;
    c.dx = dx;
    c.dt = dt;
    c.mass = mass;
    c.rho0 = Real(scene.solver.restDensity);
    c.gravity = Vec2(Real(scene.gravity.x()), Real(scene.gravity.y()));
    c.clearance = Real(0.25) * dx;
    c.maxSpeed = Real(scene.solver.maxSpeed);
    c.step = steps;
    c.time = time;
    c.origin = origin;
    c.periodic = periodic;
    return c;
  }

  std::uint64_t boundarySignature = 0;

  /// XXH64 of the static fixtures' identities and transforms: changes when the game edits its level.
  std::uint64_t staticSignature() const {
    Xxh64 h;
    for (b2Body* body = b2->GetBodyList(); body; body = body->GetNext()) {
      if (body->GetType() != b2_staticBody) continue;
      const b2Transform& xf = body->GetTransform();
      h.update(&xf, sizeof xf);
      for (b2Fixture* f = body->GetFixtureList(); f; f = f->GetNext()) {
        const void* ptr = f;
        h.update(&ptr, sizeof ptr);
        const int type = int(f->GetType());
        h.update(&type, sizeof type);
      }
    }
    return h.digest();
  }

  void rebuildBoundary() {
    boundary.collect(*b2, origin);
    boundary.sample(dx, R, pool);
    boundary.buildBins(Real(4) * R);
    boundarySignature = staticSignature();
  }

  /// Fills a block on the lattice of the spacing; particles inside solids are
  /// dropped with one warning. With `hydrostaticStart`, rows are placed closer
  /// with depth so the block starts at the density the solver holds at rest,
  /// ρ = ρ0(1 + f g z) with the solver's factor f (2/c² for muller2003, whose
  /// symmetric force recovers ∇p/2; 1/c0² for wcsph). Started uncompressed, a
  /// column would ring in its acoustic mode with a speed amplitude of about g·H/c.
  /// `keep` (optional) selects lattice points by world position (addDrop's disc).
  std::size_t fillBlock(const FluidBlockDef& b, bool hydrostaticStart,
                        const std::function<bool(const Vec2d&)>& keep = nullptr) {
    const SolverDef& sd = scene.solver;
    const double hydroFactor = solver->hydrostaticFactor();
    const bool hydrostatic = hydrostaticStart && hydroFactor > 0 && scene.gravity.x() == 0 && scene.gravity.y() < 0;
    const double gz = -scene.gravity.y();
    const Real rho0 = Real(sd.restDensity);
    const long nx = long(std::floor((b.max.x() - b.min.x()) / sd.spacing + 1e-9));
    const long ny = long(std::floor((b.max.y() - b.min.y()) / sd.spacing + 1e-9));
    std::vector<double> rowY(std::size_t(std::max(ny, 0L)));
    double prevScale = 1;
    for (long j = 0; j < ny; ++j) {
      const double depth = (double(ny - j) - 0.5) * sd.spacing;
      const double scale = hydrostatic ? 1.0 / (1.0 + hydroFactor * gz * depth) : 1.0;
      rowY[std::size_t(j)] = j == 0 ? b.min.y() + 0.5 * sd.spacing * scale
                                    : rowY[std::size_t(j - 1)] + 0.5 * sd.spacing * (prevScale + scale);
      prevScale = scale;
    }
    std::size_t added = 0, dropped = 0;
    Vec2d dlo(0, 0), dhi(0, 0);
    for (long j = 0; j < ny; ++j)
      for (long i = 0; i < nx; ++i) {
        const Vec2d pw(b.min.x() + (double(i) + 0.5) * sd.spacing, rowY[std::size_t(j)]);
        if (keep && !keep(pw)) continue;
        const Vec2 p = Vec2(Real(pw.x() - origin.x()), Real(pw.y() - origin.y()));
        if (boundary.insideDepth(p) > 0) {
          dlo = dropped ? dlo.cwiseMin(pw) : pw;
          dhi = dropped ? dhi.cwiseMax(pw) : pw;
          ++dropped;
          continue;
        }
        Vec2d vel = b.velocity;
        if (b.field.type == VelocityFieldDef::Type::TaylorGreen) {
          const double k = 2 * 3.14159265358979323846 / b.field.wavelength, U = b.field.amplitude;
          const Vec2d q = pw - b.field.origin;
          vel += Vec2d(-U * std::cos(k * q.x()) * std::sin(k * q.y()), U * std::sin(k * q.x()) * std::cos(k * q.y()));
        }
        P.push(p, Vec2(Real(vel.x()), Real(vel.y())), nextId++, rho0);
        ++added;
      }
    if (dropped) {
      std::ostringstream o;
      o << "dropped " << dropped << " particles that the scene placed inside solids, in the box [" << dlo.x() << ", "
        << dlo.y() << "] – [" << dhi.x() << ", " << dhi.y() << "]";
      warnings.push_back(o.str());
    }
    return added;
  }

  static std::uint64_t splitmix(std::uint64_t& state) {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  static double uniform(std::uint64_t& state) { return double(splitmix(state) >> 11) * (1.0 / 9007199254740992.0); }

  /// Removes the flagged particles, keeping the order of the rest (stable, serial: deterministic).
  void removeFlagged() {
    std::size_t out = 0;
    const std::size_t n = P.size();
    for (std::size_t i = 0; i < n; ++i) {
      if (dead[i]) continue;
      if (out != i) {
        P.x[out] = P.x[i];
        P.v[out] = P.v[i];
        P.a[out] = P.a[i];
        P.xPrev[out] = P.xPrev[i];
        P.rho[out] = P.rho[i];
        P.p[out] = P.p[i];
        P.invRho[out] = P.invRho[i];
        P.pOverRho[out] = P.pOverRho[i];
        P.id[out] = P.id[i];
        for (auto& f : P.extra) f.second[out] = f.second[i];
      }
      ++out;
    }
    removed += n - out;
    P.x.resize(out);
    P.v.resize(out);
    P.a.resize(out);
    P.xPrev.resize(out);
    P.rho.resize(out);
    P.p.resize(out);
    P.invRho.resize(out);
    P.pOverRho.resize(out);
    P.id.resize(out);
    for (auto& f : P.extra) f.second.resize(out);
  }

  /// Removes the k particles with the smallest ids (the oldest).
  void removeOldest(std::size_t k) {
    if (k == 0 || P.size() == 0) return;
    k = std::min(k, P.size());
    std::vector<std::uint32_t> ids(P.id);
    std::nth_element(ids.begin(), ids.begin() + std::ptrdiff_t(k - 1), ids.end());  // ids are unique: no ties
    const std::uint32_t cut = ids[k - 1];
    dead.assign(P.size(), 0);
    for (std::size_t i = 0; i < P.size(); ++i) dead[i] = P.id[i] <= cut;
    removeFlagged();
  }

  void emit(Real dt) {
    const Real rho0 = Real(scene.solver.restDensity);
    for (std::size_t e = 0; e < emitters.size(); ++e) {
      EmitterState& s = emitters[e];
      const EmitterDef& d = s.def;
      if (!d.enabled || d.rate <= 0) continue;
      const double tEnd = std::min(time + double(dt), d.stop);
      if (tEnd <= d.start) continue;
      // Emission k happens at start + k/rate; count those before tEnd.
      const auto total = std::uint64_t(std::max(0.0, std::ceil(d.rate * (tEnd - d.start) - 1e-9)));
      const Vec2d dir = d.direction;
      const Vec2d across(-dir.y(), dir.x());
      for (; s.emitted < total; ++s.emitted) {
        if (P.size() >= budget) {
          if (scene.effects.budgetPolicy == BudgetPolicy::RecycleOldest) {
            removeOldest(P.size() - budget + 1);
          } else {
            if (!s.warnedBudget) {
              std::ostringstream o;
              o << "particle budget " << budget << " reached at t = " << time << " s: emitter " << e
                << " pauses until particles leave (policy stop_emitting)";
              warnings.push_back(o.str());
              s.warnedBudget = true;
            }
            s.emitted = total;  // the missed particles are not owed later
            break;
          }
        }
        const double te = d.start + double(s.emitted) / d.rate;
        // Rows across the nozzle: slot k % perRow, evenly spaced (randomly
        // placed particles would overlap and blow the stream apart), with a
        // small random offset of ±0.1 spacing.
        const std::uint64_t perRow = std::max<std::uint64_t>(1, std::uint64_t(std::llround(d.width / double(dx))));
        const double slot = (double(s.emitted % perRow) + 0.5) / double(perRow) - 0.5;
        const double u1 = uniform(s.rng), u2 = uniform(s.rng), u3 = uniform(s.rng);
        const double ang = (u2 - 0.5) * d.spread;
        const Vec2d vdir(dir.x() * std::cos(ang) - dir.y() * std::sin(ang), dir.x() * std::sin(ang) + dir.y() * std::cos(ang));
        const double speed = d.speed * (1.0 + d.jitter * (2.0 * u3 - 1.0));
        const Vec2d vel = vdir * speed;
        // Placed where a particle emitted at te would be at the substep start,
        // so that the stream is continuous after this substep's integration.
        const Vec2d pw = d.position + across * (slot * d.width + (u1 - 0.5) * 0.2 * double(dx)) + vel * (time - te);
        P.push(Vec2(Real(pw.x() - origin.x()), Real(pw.y() - origin.y())), Vec2(Real(vel.x()), Real(vel.y())), nextId++, rho0);
      }
    }
  }

  void lifetimes(Real dt) {
    std::vector<Real>& age = P.field("age");
    const Real maxAge = Real(scene.effects.maxAge);
    dead.assign(P.size(), 0);
    bool any = false;
    for (std::size_t i = 0; i < P.size(); ++i) {
      age[i] += dt;
      dead[i] = age[i] > maxAge;
      any = any || dead[i];
    }
    if (any) removeFlagged();
  }

  void sinks() {
    dead.assign(P.size(), 0);
    bool any = false;
    for (std::size_t i = 0; i < P.size(); ++i) {
      const Vec2d w = Vec2d(P.x[i].x(), P.x[i].y()) + origin;
      for (const RegionDef& r : scene.effects.sinks) dead[i] = dead[i] || r.contains(w);
      any = any || dead[i];
    }
    if (any) removeFlagged();
  }

  StageTiming& timingOf(const char* name) {
    for (auto& t : timing)
      if (t.name == name) return t;
    timing.push_back(StageTiming{name, 0, 0});
    return timing.back();
  }

  void run(const char* name, const std::function<void()>& f) override {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    StageTiming& t = timingOf(name);
    t.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++t.calls;
  }

  void checked(const char* name, const std::function<std::size_t()>& f) override {
    std::size_t bad = kNone;
    run(name, [&] { bad = f(); });
    if (bad != kNone) fail(name, bad);
  }

  [[noreturn]] void fail(const char* stage, std::size_t slot) {
    std::ostringstream o;
    o.precision(9);
    const Vec2d w = Vec2d(P.x[slot].x(), P.x[slot].y()) + origin;
    o << "simulation stopped: non-finite or runaway value after stage '" << stage << "' at substep " << steps
      << " (t = " << time << " s): particle id " << P.id[slot] << " position (" << w.x() << ", " << w.y()
      << ") velocity (" << P.v[slot].x() << ", " << P.v[slot].y() << ") density " << P.rho[slot] << " pressure "
      << P.p[slot] << " (speed limit solver.max_speed = " << scene.solver.maxSpeed << " m/s)";
    throw SimulationError(o.str(), stage, P.id[slot], steps, time);
  }

  Real stableDt() {
    const Real vmax = maxSpeedOf(P, pool);
    const StepContext c = context(0);
    Real dt = solver->maxTimeStep(c, vmax, lastAccel);
    for (const auto& e : effects)
      if (e->enabled) dt = std::min(dt, e->maxTimeStep(c));
    return dt;
  }

  void substep(Real dt) {
    if (!emitters.empty()) run("emit", [&] { emit(dt); });
    StepContext c = context(dt);
    solver->substep(c, *this, effects);
    lastAccel = maxAccelOf(P, pool);
    run("collide", [&] { stageCollide(c); });
    if (periodic.any()) run("wrap", [&] { stageWrap(c); });
    if (scene.effects.lifetime) run("lifetimes", [&] { lifetimes(dt); });
    if (!scene.effects.sinks.empty()) run("sinks", [&] { sinks(); });
    time += double(dt);
    ++steps;
  }

  void advance(double frameDt) {
    double remaining = frameDt;
    int n = 0;
    const int cap = scene.solver.maxSubsteps;
    // A leftover below a millionth of the frame (float rounding of dt) is not a substep.
    while (remaining > 1e-6 * frameDt) {
      if (n == cap) {
        std::ostringstream o;
        o << "frame " << frames << ": substep cap solver.max_substeps = " << cap << " reached; simulated "
          << (frameDt - remaining) << " s of " << frameDt << " s (the frame runs slow instead of unstable)";
        warnings.push_back(o.str());
        break;
      }
      const Real limit = stableDt();
      const double k = std::ceil(remaining / double(limit) - 1e-9);
      const double dt = k <= 1 ? remaining : remaining / k;
      substep(Real(dt));
      remaining -= double(Real(dt));
      ++n;
    }
    lastSubsteps = n;
  }
};

World::World(const SceneDef& sceneIn, const WorldOptions& options) : impl_(std::make_unique<Impl>(sceneIn, options)) {
  impl_->ownWorld = std::make_unique<b2World>(bv(sceneIn.gravity));
  impl_->b2 = impl_->ownWorld.get();
  for (const BodyDef& b : sceneIn.bodies) addBody(*impl_->b2, b);
  init();
}

World::World(const SceneDef& sceneIn, b2World& gameWorld, const WorldOptions& options)
    : impl_(std::make_unique<Impl>(sceneIn, options)) {
  impl_->b2 = &gameWorld;
  if (!sceneIn.bodies.empty())
    impl_->warnings.push_back("the scene's " + std::to_string(sceneIn.bodies.size()) +
                              " boundary bodies are ignored: the fluid uses the game's b2World");
  init();
}

void World::init() {
  Impl& w = *impl_;
  // A scene built in code may leave solver parameters out: give them their defaults.
  for (const SolverParam& sp : solverParams(w.scene.solver.type))
    if (!w.scene.solver.params.count(sp.key)) w.scene.solver.params[sp.key] = sp.def;
  const SceneDef& scene = w.scene;
  const SolverDef& sd = scene.solver;
  w.solver = makeSolver(sd);
  w.effects = makeEffects(scene);
  for (const EmitterDef& e : scene.effects.emitters) {
    Impl::EmitterState st;
    st.def = e;
    st.rng = e.seed;
    w.emitters.push_back(st);
  }
  w.budget = scene.effects.budget > 0 ? scene.effects.budget : scene.maxParticles;
  if (scene.effects.lifetime) w.P.field("age");

  // Local frame: the centre of the scene's box, rounded to 64 m, so that
  // scenes far from the origin keep float precision.
  bool any = false;
  Vec2d lo(0, 0), hi(0, 0);
  auto grow = [&](const Vec2d& p) {
    lo = any ? lo.cwiseMin(p) : p;
    hi = any ? hi.cwiseMax(p) : p;
    any = true;
  };
  for (const auto& b : scene.blocks) {
    grow(b.min);
    grow(b.max);
  }
  for (const auto& b : scene.bodies) grow(b.position);
  if (!w.ownWorld)
    for (b2Body* body = w.b2->GetBodyList(); body; body = body->GetNext())
      if (body->GetType() == b2_staticBody) grow(Vec2d(body->GetPosition().x, body->GetPosition().y));
  if (any) {
    const Vec2d c = (lo + hi) * 0.5;
    w.origin = Vec2d(std::round(c.x() / 64.0) * 64.0, std::round(c.y() / 64.0) * 64.0);
  }

  w.dx = Real(sd.spacing);
  w.R = Real(sd.supportRatio * sd.spacing);
  // Mass so that a full square lattice at spacing dx has exactly ρ0.
  w.mass = Real(sd.restDensity / latticeSum(*w.solver, double(w.R), sd.spacing));

  if (scene.periodic.any()) {
    const PeriodicDef& pd = scene.periodic;
    for (int axis = 0; axis < 2; ++axis) {
      if (!(axis == 0 ? pd.x : pd.y)) continue;
      const double L = pd.max[axis] - pd.min[axis];
      if (!(L >= 3 * double(w.R)))
        throw SceneError(scene.path.empty() ? "scene" : scene.path, 0, 0, axis == 0 ? "periodic.x" : "periodic.y",
                         "the period is " + std::to_string(L) + " m; it must be at least 3 support radii (" +
                             std::to_string(3 * double(w.R)) + " m)");
    }
    w.periodic.x = pd.x;
    w.periodic.y = pd.y;
    w.periodic.lo = Vec2(Real(pd.min.x() - w.origin.x()), Real(pd.min.y() - w.origin.y()));
    w.periodic.lx = pd.x ? Real(pd.max.x() - pd.min.x()) : Real(0);
    w.periodic.ly = pd.y ? Real(pd.max.y() - pd.min.y()) : Real(0);
  }
  w.rebuildBoundary();
  // Fluid blocks on a square lattice; particles inside solids are dropped.
  for (const FluidBlockDef& b : scene.blocks) w.fillBlock(b, true);
  // An effect whose explicit step limit is below the smallest substep the
  // solver can take cannot be followed: refuse the scene, naming the limit.
  {
    const StepContext lc = w.context(0);
    const double minDt = w.solver->minTimeStep(lc);
    for (const auto& e : w.effects) {
      const double lim = double(e->maxTimeStep(lc));
      if (lim < minDt) {
        std::ostringstream o;
        o << "the " << e->name() << " effect needs substeps of at most " << lim << " s, but the " << w.solver->name()
          << " solver cannot go below " << minDt << " s; lower " << e->limitKey() << " or use wcsph or muller2003";
        throw SceneError(scene.path.empty() ? "scene" : scene.path, 0, 0, e->limitKey(), o.str());
      }
    }
  }
  // First density/pressure so that the initial state is complete for readers.
  StepContext c = w.context(0);
  w.solver->prepare(c);
}

World::~World() = default;

void World::stepFrame() { step(1.0 / impl_->scene.fps); }

void World::step(double dt) {
  // A game may edit its level between frames: re-read the static fixtures when they changed.
  if (impl_->staticSignature() != impl_->boundarySignature) refreshBoundaries();
  impl_->advance(dt);
  ++impl_->frames;
}

void World::refreshBoundaries() {
  Impl& w = *impl_;
  w.rebuildBoundary();
  // Particles a new solid buries are dropped (pushing them out would be an explosion).
  w.dead.assign(w.P.size(), 0);
  std::size_t n = 0;
  for (std::size_t i = 0; i < w.P.size(); ++i) {
    w.dead[i] = w.boundary.insideDepth(w.P.x[i]) > 0;
    n += w.dead[i];
  }
  if (n) {
    w.removeFlagged();
    w.warnings.push_back("dropped " + std::to_string(n) + " particles now inside solids (the level changed at frame " +
                         std::to_string(w.frames) + ")");
  }
}

void World::setGravity(const Vec2d& g) { impl_->scene.gravity = g; }

std::size_t World::addBlock(const FluidBlockDef& block) { return impl_->fillBlock(block, false); }

std::size_t World::addDrop(const Vec2d& center, double radius, const Vec2d& velocity) {
  // A square patch of 2k × 2k lattice points centred on `center` (k spacings each
  // side covers the radius); the extra half spacing makes the count exact in floats.
  const double dx = impl_->scene.solver.spacing;
  const double half = std::ceil(radius / dx - 1e-9) * dx;
  FluidBlockDef b;
  b.min = center - Vec2d(half, half);
  b.max = center + Vec2d(half + 0.5 * dx, half + 0.5 * dx);
  b.velocity = velocity;
  return impl_->fillBlock(b, false, [&](const Vec2d& p) { return (p - center).squaredNorm() <= radius * radius; });
}

void World::moveEmitter(std::size_t index, const Vec2d& position, const Vec2d& direction) {
  EmitterDef& d = impl_->emitters.at(index).def;
  if (!(direction.norm() > 0)) throw std::invalid_argument("moveEmitter: the direction must not be zero");
  d.position = position;
  d.direction = direction.normalized();
}

const EmitterDef& World::emitter(std::size_t index) const { return impl_->emitters.at(index).def; }

std::size_t World::removeParticlesInBox(const Vec2d& lo, const Vec2d& hi) {
  Impl& w = *impl_;
  const RegionDef r{lo, hi};
  w.dead.assign(w.P.size(), 0);
  std::size_t n = 0;
  for (std::size_t i = 0; i < w.P.size(); ++i) {
    w.dead[i] = r.contains(worldPosition(i));
    n += w.dead[i];
  }
  if (n) w.removeFlagged();
  return n;
}

std::vector<std::size_t> World::particlesInRadius(const Vec2d& c, double radius) const {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < impl_->P.size(); ++i)
    if ((worldPosition(i) - c).squaredNorm() <= radius * radius) out.push_back(i);
  return out;
}

std::vector<std::size_t> World::particlesInBox(const Vec2d& lo, const Vec2d& hi) const {
  std::vector<std::size_t> out;
  const RegionDef r{lo, hi};
  for (std::size_t i = 0; i < impl_->P.size(); ++i)
    if (r.contains(worldPosition(i))) out.push_back(i);
  return out;
}

World::FieldSample World::sampleAt(const Vec2d& point) const {
  const Impl& w = *impl_;
  const WendlandC2<double> W(double(w.R));
  FieldSample s;
  double rho = 0;
  Vec2d vel(0, 0);
  for (std::size_t i = 0; i < w.P.size(); ++i) {
    const double r = (worldPosition(i) - point).norm();
    if (r >= W.R) continue;
    const double wv = W.value(r) * double(w.mass) / double(w.P.rho[i]);  // V_j W
    s.weight += wv;
    rho += wv * double(w.P.rho[i]);
    vel += wv * Vec2d(w.P.v[i].x(), w.P.v[i].y());
  }
  if (s.weight > 0) {
    s.density = rho / s.weight;
    s.velocity = vel / s.weight;
  }
  return s;
}

const Particles& World::particles() const { return impl_->P; }
std::size_t World::particleCount() const { return impl_->P.size(); }
Vec2d World::origin() const { return impl_->origin; }
Vec2d World::worldPosition(std::size_t i) const {
  return Vec2d(impl_->P.x[i].x(), impl_->P.x[i].y()) + impl_->origin;
}
const std::vector<Collider>& World::colliders() const { return impl_->boundary.colliders; }
const std::vector<Vec2>& World::boundarySamples() const { return impl_->boundary.samples; }
b2World& World::box2d() { return *impl_->b2; }
const SceneDef& World::scene() const { return impl_->scene; }
double World::time() const { return impl_->time; }
std::uint64_t World::frame() const { return impl_->frames; }
std::uint64_t World::substeps() const { return impl_->steps; }
int World::lastFrameSubsteps() const { return impl_->lastSubsteps; }
double World::stableTimeStep() const { return double(impl_->stableDt()); }
Real World::particleMass() const { return impl_->mass; }
Real World::support() const { return impl_->R; }
Real World::spacing() const { return impl_->dx; }
int World::threads() const { return impl_->pool.size(); }

std::uint64_t World::stateHash() const {
  const Particles& P = impl_->P;
  std::vector<std::uint32_t> slotOf(impl_->nextId, 0xffffffffu);
  for (std::size_t i = 0; i < P.size(); ++i) slotOf[P.id[i]] = std::uint32_t(i);
  Xxh64 h;
  h.update(impl_->origin.data(), sizeof(double) * 2);
  for (std::uint32_t id = 0; id < impl_->nextId; ++id) {
    const std::uint32_t s = slotOf[id];
    if (s == 0xffffffffu) continue;
    h.update(&id, sizeof id);
    h.update(P.x[s].data(), sizeof(Real) * 2);
    h.update(P.v[s].data(), sizeof(Real) * 2);
  }
  return h.digest();
}

DensityStats World::densityStats() const {
  const Particles& P = impl_->P;
  DensityStats s;
  if (P.size() == 0) return s;
  const double rho0 = impl_->scene.solver.restDensity;
  double sumErr = 0, sumRho = 0, maxErr = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    const double e = std::max(0.0, (double(P.rho[i]) - rho0) / rho0);
    sumErr += e;
    sumRho += P.rho[i];
    maxErr = std::max(maxErr, e);
  }
  s.meanError = sumErr / double(P.size());
  s.maxError = maxErr;
  s.meanDensity = sumRho / double(P.size());
  return s;
}

double World::kineticEnergy() const {
  const Particles& P = impl_->P;
  double e = 0;
  for (std::size_t i = 0; i < P.size(); ++i) e += 0.5 * double(impl_->mass) * double(P.v[i].squaredNorm());
  return e;
}

std::vector<StageTiming> World::timings() const { return impl_->timing; }

void World::resetTimings() {
  for (auto& t : impl_->timing) {
    t.seconds = 0;
    t.calls = 0;
  }
}

std::size_t World::neighbourPairs() const { return impl_->nbr.pairs(); }

void World::setUserForces(const std::vector<UserForce>& forces) {
  impl_->userForces = forces;
  if (!impl_->userForceEffect && !forces.empty()) {
    impl_->effects.push_back(makeUserForceEffect(&impl_->userForces));
    impl_->userForceEffect = true;
  }
}

void World::setEmitterEnabled(std::size_t index, bool enabled) { impl_->emitters.at(index).def.enabled = enabled; }

void World::setEffectEnabled(const std::string& name, bool enabled) {
  std::string names;
  for (const auto& e : impl_->effects) {
    if (name == e->name()) {
      e->enabled = enabled;
      return;
    }
    names += (names.empty() ? "" : ", ") + std::string(e->name());
  }
  throw std::invalid_argument("the scene does not enable the effect '" + name + "'; its effects: " +
                              (names.empty() ? std::string("none") : names));
}

std::vector<std::string> World::effects() const {
  std::vector<std::string> out;
  for (const auto& e : impl_->effects) out.push_back(e->name());
  return out;
}

std::size_t World::emitterCount() const { return impl_->emitters.size(); }

std::uint64_t World::emittedCount(std::size_t index) const { return impl_->emitters.at(index).emitted; }

std::uint64_t World::removedCount() const { return impl_->removed; }

std::vector<std::string> World::particleFields() const {
  std::vector<std::string> f = {"x", "v", "a", "xPrev", "rho", "p", "invRho", "pOverRho", "id"};
  for (const auto& e : impl_->P.extra) f.push_back(e.first);
  return f;
}

std::vector<std::string> World::stages() const {
  std::vector<std::string> s;
  for (const auto& t : impl_->timing) s.push_back(t.name);
  return s;
}

std::size_t World::memoryBytes() const {
  const Impl& w = *impl_;
  auto cap = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  std::size_t b = w.P.bytes();
  b += cap(w.grid.cellStart) + cap(w.grid.sorted) + cap(w.grid.cellOf) + cap(w.grid.scratch_);
  b += cap(w.nbr.start) + cap(w.nbr.count);
  for (const auto& v : w.nbr.perBlock) b += cap(v);
  b += cap(w.scratch.v) + cap(w.scratch.r) + cap(w.scratch.u);
  b += cap(w.boundary.samples) + cap(w.boundary.volume) + cap(w.boundary.sideNormal) + cap(w.boundary.sideOffset);
  return b;
}

void World::substep() { impl_->substep(impl_->stableDt()); }

std::vector<std::string> World::takeWarnings() {
  std::vector<std::string> out;
  out.swap(impl_->warnings);
  return out;
}

}  // namespace sph2d
