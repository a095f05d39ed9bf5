// The World: construction from a scene and the public API. The work is in
// stepper.cpp (the substep), particle_sources.cpp, box2d_bridge.cpp and
// queries.cpp (world_impl.hpp lists them).
#include "sph2d/world.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <type_traits>

#include "world/world_impl.hpp"

namespace sph2d {

Interrupted::Interrupted(const std::string& what, std::string stage_)
    : std::runtime_error(what), stage(std::move(stage_)) {}

SimulationError::SimulationError(const std::string& what, std::string stage_, std::uint32_t particleId_,
                                 std::uint64_t step_, double time_)
    : std::runtime_error(what), stage(std::move(stage_)), particleId(particleId_), step(step_), time(time_) {}

namespace {

/// Σ W over a square lattice of spacing dx around one point (the point included).
double latticeSum(const Solver& solver, double R, double dx) {
  const int n = int(std::ceil(R / dx)) + 1;
  double s = 0;
  for (int j = -n; j <= n; ++j)
    for (int i = -n; i <= n; ++i) s += solver.densityKernel(std::sqrt(double(i * i + j * j)) * dx, R);
  return s;
}

}  // namespace

World::World(const SceneDef& sceneIn, const WorldOptions& options) : impl_(std::make_unique<Impl>(sceneIn, options)) {
  impl_->ownWorld = makeSceneWorld(sceneIn);
  impl_->b2 = impl_->ownWorld.get();
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

/// A weakly compressible solver (wcsph, muller2003) compresses a flow by about (v/c0)²;
/// below c0 = 10 v the density error passes ~1 % and a fast jet gains energy (a 50 m/s jet
/// at c0 = 500 spread to 22–98 m/s, +5.5 % energy in 0.07 s). One warning names the
/// fastest speed the scene sets and the key to raise.
void World::Impl::warnLowSoundSpeed() {
  const SolverDef& sd = scene.solver;
  const bool wcsph = sd.type == "wcsph", muller = sd.type == "muller2003";
  if (!wcsph && !muller) return;
  const double expected = wcsph ? sd.param("expected_speed") : 0.0;
  const double c0 = expected > 0 ? 10 * expected : sd.soundSpeed;
  double fastest = 0;
  std::string where;
  auto consider = [&](double v, const std::string& key) {
    if (v > fastest) {
      fastest = v;
      where = key;
    }
  };
  for (std::size_t k = 0; k < scene.blocks.size(); ++k) {
    const FluidBlockDef& b = scene.blocks[k];
    double field = b.field.type == VelocityFieldDef::Type::TaylorGreen ? std::fabs(b.field.amplitude) : 0.0;
    if (b.field.type == VelocityFieldDef::Type::Strain)  // |s| times the farthest corner from the origin
      for (const Vec2d& c : {b.min, b.max, Vec2d(b.min.x(), b.max.y()), Vec2d(b.max.x(), b.min.y())})
        field = std::max(field, std::fabs(b.field.rate) * (c - b.field.origin).norm());
    if (b.field.type == VelocityFieldDef::Type::Linear)  // |A x| is largest at a corner of the box (convex)
      for (const Vec2d& c : {b.min, b.max, Vec2d(b.min.x(), b.max.y()), Vec2d(b.max.x(), b.min.y())})
        field = std::max(field, b.field.at(c).norm());
    consider(b.velocity.norm() + field, "fluid[" + std::to_string(k) + "].velocity");
  }
  for (std::size_t k = 0; k < scene.effects.emitters.size(); ++k) {
    const EmitterDef& e = scene.effects.emitters[k];
    consider(e.speed * (1 + e.jitter), "effects.emitters[" + std::to_string(k) + "].speed");
  }
  for (std::size_t k = 0; k < scene.events.size(); ++k) {
    const EventDef& e = scene.events[k];
    if (e.type == EventDef::Type::Block)
      consider(e.block.velocity.norm(), "events[" + std::to_string(k) + "].velocity");
    if (e.type == EventDef::Type::Drop) consider(e.velocity.norm(), "events[" + std::to_string(k) + "].velocity");
  }
  if (!(c0 < 10 * fastest)) return;  // 10 x is the usual choice (Monaghan 1994), kept by the validation cases
  std::ostringstream o;
  o << "the sound speed " << c0 << " m/s is below 10 x the fastest speed the scene sets (" << fastest << " m/s at "
    << where << "): " << sd.type << " would compress the flow by about " << 100 * (fastest / c0) * (fastest / c0)
    << " % and can gain energy; raise "
    << (wcsph ? (expected > 0 ? "solver.expected_speed" : "solver.sound_speed (or set solver.expected_speed)")
              : "solver.sound_speed")
    << " to at least " << (wcsph && expected > 0 ? fastest : 10 * fastest) << " m/s";
  warnings.push_back(o.str());
}

/// muller2003's pressure force is not the gradient of an energy (poly6 density, spiky
/// gradient): with nothing to dissipate what it feeds in, a flow heats up. Monaghan's
/// elliptical drop (u = −100x, v = 100y, ν = 0; tests/engine/solvers/test_elliptic_drop.cpp)
/// ended with 2.3 × the exact kinetic energy at 40 spacings a radius and was stopped by
/// the guard at 80; with effects.shifting it stays within 2 %. One warning names the key and
/// the remedy (docs/SOLVERS.md has what was measured).
void World::Impl::warnInviscidMuller() {
  const SolverDef& sd = scene.solver;
  if (sd.type != "muller2003" || sd.viscosity > 0) return;
  warnings.push_back(
      "solver.viscosity is 0 with muller2003: its pressure force is not the gradient of an energy, so a flow without "
      "viscosity gains kinetic energy (a strained drop: 2.3 x the exact); set solver.viscosity (about 0.005 m^2/s at "
      "dx = 0.02 m), or keep the particles evenly spread with effects.shifting (strength 2)");
}

/// Moving bodies are not wrapped across a periodic seam (Box2D's bodies know no period, and a
/// particle meets a body's samples and skin only directly, not through the nearest image).
/// One warning names the scene's first moving body and the seam (or, with a game's b2World,
/// says it has one when the World is built).
void World::Impl::warnMovingBodiesInPeriodic() {
  if (!scene.periodic.any()) return;
  const char* what =
      "moving bodies do not wrap at the periodic seam, and water across the seam does not meet them: keep them "
      "more than a support radius from it";
  for (std::size_t k = 0; k < scene.bodies.size(); ++k) {
    if (scene.bodies[k].type == BodyDef::Type::Static) continue;
    std::ostringstream o;
    o << "boundaries[" << k << "] is " << (scene.bodies[k].type == BodyDef::Type::Kinematic ? "kinematic" : "dynamic")
      << " in a periodic scene (seam at ";
    if (scene.periodic.x) o << "x = " << scene.periodic.min.x() << " and " << scene.periodic.max.x();
    if (scene.periodic.x && scene.periodic.y) o << "; ";
    if (scene.periodic.y) o << "y = " << scene.periodic.min.y() << " and " << scene.periodic.max.y();
    o << "): " << what;
    warnings.push_back(o.str());
    return;
  }
  if (ownWorld) return;
  for (const b2Body* b = b2->GetBodyList(); b; b = b->GetNext())  // a game's b2World, as it is now
    if (b->GetType() != b2_staticBody) {
      warnings.push_back(std::string("the game's b2World has a ") +
                         (b->GetType() == b2_kinematicBody ? "kinematic" : "dynamic") +
                         " body and the scene a periodic axis: " + what);
      return;
    }
}

void World::init() {
  Impl& w = *impl_;
  // The stop flag is read through the set-up too (sampling long solids, filling the blocks,
  // the first density pass): an interrupted constructor throws, and nothing is built.
  World::Impl::StopScope scope(w.pool, w.stop);
  std::string phase = "solver";
  try {
    initPhases(phase);
  } catch (const Interrupted&) {
    throw Interrupted("the World's construction was stopped by the stop flag (" + phase + "); nothing is built",
                      "construction: " + phase);
  }
}

void World::initPhases(std::string& phase) {
  Impl& w = *impl_;
  if (w.stopSet()) throw Interrupted("stopped by the stop flag", "");
  // A scene built in code may leave solver parameters out: give them their defaults.
  fillSolverDefaults(w.scene.solver);
  const SceneDef& scene = w.scene;
  const SolverDef& sd = scene.solver;
  // A combination of parameters the solver cannot run (its own check) is refused by key.
  const auto problem = solverParamProblem(sd);
  if (!problem.first.empty())
    throw SceneError(scene.path.empty() ? "scene" : scene.path, 0, 0, problem.first, problem.second);
  w.solver = makeSolver(sd);
  w.initMaterials();
  w.effects = makeEffects(scene);
  if (scene.effects.foam) w.foam = std::make_unique<FoamSystem>(scene.effects.foamDef, w.granularMaterials());
  for (std::size_t k = 0; k < scene.effects.emitters.size(); ++k)
    w.checkSceneMaterial(scene.effects.emitters[k].material, "effects.emitters[" + std::to_string(k) + "].material");
  for (std::size_t k = 0; k < scene.blocks.size(); ++k)
    w.checkSceneMaterial(scene.blocks[k].material, "fluid[" + std::to_string(k) + "].material");
  for (const EmitterDef& e : scene.effects.emitters) {
    ParticleSources::Emitter st;
    st.def = e;
    st.rng = e.seed;
    w.sources.emitters.push_back(st);
  }
  w.sources.budget = scene.effects.budget > 0 ? scene.effects.budget : scene.maxParticles;
  if (scene.effects.lifetime) w.P.field("age");
  w.warnLowSoundSpeed();
  w.warnInviscidMuller();
  w.warnMovingBodiesInPeriodic();

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
  for (const auto& g : scene.groups) {
    grow(g.region.min);
    grow(g.region.max);
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
  // The density sums' mass, so that a full square lattice at spacing dx has exactly ρ0; the
  // mass of momentum, ρ0 over the area dx² each particle fills at rest (StepContext).
  w.mass = Real(sd.restDensity / latticeSum(*w.solver, double(w.R), sd.spacing));
  w.momentumMass = Real(sd.restDensity * sd.spacing * sd.spacing);

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
  phase = "boundary samples";
  w.readBoundary();
  w.statics.recordPoses(*w.b2);
  w.captureBodies();
  // Fluid blocks on a square lattice; particles inside solids (moving ones too) are dropped.
  for (std::size_t k = 0; k < scene.blocks.size(); ++k) {
    phase = "fluid[" + std::to_string(k) + "]";
    w.fillBlock(scene.blocks[k], true);
  }
  phase = "first density";
  // The blocks were filled particle by particle: give back what the arrays' doubling kept
  // spare (up to 40 % of their bytes: 20,100 particles held room for 32,768).
  w.P.forEachField([](const char*, auto& field) { field.shrink_to_fit(); });
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
  w.buildStages();
  w.refreshView();
  for (std::size_t k = 0; k < scene.groups.size(); ++k) {
    w.checkSceneMaterial(scene.groups[k].region.material, "groups[" + std::to_string(k) + "].material");
    try {
      createGroup(scene.groups[k]);
    } catch (const std::invalid_argument& e) {
      std::string why = e.what();
      why.erase(0, std::string("createGroup: ").size());
      throw SceneError(scene.path.empty() ? "scene" : scene.path, 0, 0, "groups[" + std::to_string(k) + "]", why);
    }
  }
}

World::~World() = default;

void World::stepFrame() { step(1.0 / impl_->scene.fps); }

void World::Impl::beforeStep(const char* call) {
  if (!abandonedIn.empty())
    throw Interrupted(std::string(call) + ": the World was interrupted in stage '" + abandonedIn +
                          "' and does not step again; load() a saved state or build a new World",
                      abandonedIn);
  if (stopSet())  // set before the step began: nothing has changed
    throw Interrupted(std::string(call) + ": the stop flag is set; the step was not started", call);
}

void World::Impl::abandon(const Interrupted& e) {
  abandonedIn = e.stage.empty() ? std::string("step") : e.stage;
  refreshView();         // the arrays may have moved; every field has one length
  index.noteEdit();      // the particles moved without a step's count: the search grid is stale
  contacts.beginStep();  // an unfinished record (unsorted) is no record
  std::ostringstream o;
  o.precision(9);
  o << "stopped by the stop flag in stage '" << abandonedIn << "' of substep " << steps << " (frame " << frames
    << ", t = " << time << " s): the step is abandoned and the World does not step again (World::interrupted())";
  throw Interrupted(o.str(), abandonedIn);
}

void World::step(double dt) {
  Impl& w = *impl_;
  w.beforeStep("step");
  World::Impl::StopScope scope(w.pool, w.stop);
  try {
    // A game may edit its level between frames: a static body it slid moves through this step
    // as a kinematic one; other changes are re-read (the particles a new solid covers dropped).
    w.readStatics(dt);
    w.contacts.beginStep();  // the contacts stage's record is this step's
    w.captureBodies();       // the moving bodies' pose and velocity for this step
    const double t0 = w.time;
    const bool everySubstep = w.bodiesEverySubstep();  // then advance() stepped the bodies
    w.advance(dt);
    if (!everySubstep) w.moveOwnBodies(w.time - t0);
    w.contacts.finishStep();
    ++w.frames;
    w.refreshView();
  } catch (const Interrupted& e) {
    try {
      w.abandon(e);  // marks the World abandoned and throws what to report
    } catch (const Interrupted&) {
      w.deliverRemovalsAfterFailure();  // what left the World before it stopped has left
      throw;
    }
  } catch (...) {
    w.deliverRemovalsAfterFailure();
    throw;
  }
  w.deliverRemovals();
  if (w.contactListener) w.deliverParticleContacts();
}

void World::setStopFlag(const std::atomic<bool>* stop) { impl_->stop = stop; }

bool World::interrupted() const { return !impl_->abandonedIn.empty(); }

void World::setGravity(const Vec2d& g) {
  impl_->scene.gravity = g;
  // The scene's own b2World falls the same way (its dynamic bodies); a game sets its own.
  if (impl_->ownWorld) impl_->ownWorld->SetGravity(b2Vec2(float(g.x()), float(g.y())));
}

IdRange World::Impl::fillNamed(const FluidBlockDef& b, const char* call) {
  try {
    return fillBlock(b, false, call);
  } catch (const Interrupted&) {
    throw Interrupted(std::string(call) + ": stopped by the stop flag; nothing was added", call);
  }
}

IdRange World::addBlock(const FluidBlockDef& block) { return impl_->fillNamed(block, "addBlock"); }

IdRange World::addDrop(const Vec2d& center, double radius, const Vec2d& velocity, std::uint32_t material) {
  FluidBlockDef b = circleRegion(center, radius, impl_->scene.solver.spacing);
  b.velocity = velocity;
  b.material = material;
  return impl_->fillNamed(b, "addDrop");
}

void World::moveEmitter(std::size_t index, const Vec2d& position, const Vec2d& direction) {
  EmitterDef& d = impl_->sources.emitters.at(index).def;
  if (!(direction.norm() > 0)) throw std::invalid_argument("moveEmitter: the direction must not be zero");
  d.position = position;
  d.direction = direction.normalized();
}

const EmitterDef& World::emitter(std::size_t index) const { return impl_->sources.emitters.at(index).def; }

std::size_t World::addEmitter(const EmitterDef& def) {
  Impl& w = *impl_;
  const std::string problem = ParticleSources::problem(def);
  if (!problem.empty()) throw std::invalid_argument("addEmitter: " + problem);
  w.checkMaterial(def.material, "addEmitter");
  if (w.sources.emitters.size() >= ParticleSources::kMaxEmitters)
    throw std::invalid_argument("addEmitter: the world has " + std::to_string(ParticleSources::kMaxEmitters) +
                                " emitters, the most it holds");
  ParticleSources::Emitter st;
  st.def = def;
  st.def.direction = def.direction.normalized();
  st.def.start = std::max(def.start, w.time);  // nothing is owed for the time before
  st.def.stop = std::max(st.def.stop, st.def.start);
  st.rng = def.seed;
  w.sources.emitters.push_back(st);
  if (w.sources.emitters.size() == 1) w.buildStages();  // the `emit` stage exists only with emitters
  return w.sources.emitters.size() - 1;
}

void World::removeEmitter(std::size_t index) {
  Impl& w = *impl_;
  if (index >= w.sources.emitters.size())
    throw std::out_of_range("removeEmitter: no emitter " + std::to_string(index) + " (the world has " +
                            std::to_string(w.sources.emitters.size()) + ")");
  w.sources.emitters.erase(w.sources.emitters.begin() + std::ptrdiff_t(index));
  // Emitter tags follow the indices: the removed one's particles have none now, later ones move down.
  if (std::vector<std::uint32_t>* tag = w.P.findU32(ParticleStore::kEmitter)) {
    const std::uint32_t removed = std::uint32_t(index) + 1;
    for (std::uint32_t& t : *tag) t = t == removed ? 0u : t > removed ? t - 1 : t;
  }
  if (w.sources.emitters.empty()) w.buildStages();
}

std::vector<std::uint32_t> World::removeParticlesInBox(const Vec2d& lo, const Vec2d& hi) {
  Impl& w = *impl_;
  const RegionDef r{lo, hi};
  w.sources.dead.assign(w.P.size(), 0);
  std::size_t n = 0;
  for (std::size_t i = 0; i < w.P.size(); ++i) {
    w.sources.dead[i] = r.contains(worldPosition(i));
    n += w.sources.dead[i];
  }
  std::vector<std::uint32_t> ids;
  if (n) w.removeFlagged(RemovalReason::game, &ids);
  w.deliverRemovals();
  return ids;
}

namespace {

/// The views of `S`'s public arrays as they are now (the optional ones empty when absent).
Particles viewOf(const ParticleStore& S) {
  auto opt = [](const auto* vec) {
    using T = typename std::remove_pointer_t<decltype(vec)>::value_type;
    return vec ? ArrayView<T>(*vec) : ArrayView<T>();
  };
  Particles V;
  V.x = S.x;
  V.v = S.v;
  V.rho = S.rho;
  V.p = S.p;
  V.id = S.id;
  V.age = opt(S.find("age"));
  V.color = opt(S.findU32(ParticleStore::kColor));
  V.userData = opt(S.findU32(ParticleStore::kUserData));
  V.emitter = opt(S.findU32(ParticleStore::kEmitter));
  V.material = opt(S.findU32(ParticleStore::kMaterial));
  V.mixedColor = opt(S.findU32(ParticleStore::kMixedColor));
  V.group = opt(S.findU32(ParticleStore::kGroup));
  return V;
}

}  // namespace

bool World::Impl::viewCurrent() const {
  const Particles now = viewOf(P);
  auto same = [](const auto& a, const auto& b) { return a.data() == b.data() && a.size() == b.size(); };
  return same(view.x, now.x) && same(view.v, now.v) && same(view.rho, now.rho) && same(view.p, now.p) &&
         same(view.id, now.id) && same(view.age, now.age) && same(view.color, now.color) &&
         same(view.userData, now.userData) && same(view.emitter, now.emitter) && same(view.material, now.material) &&
         same(view.mixedColor, now.mixedColor) && same(view.group, now.group);
}

void World::Impl::refreshView() const { view = viewOf(P); }

DiffuseParticles World::diffuse() const { return impl_->foam ? impl_->foam->view() : DiffuseParticles{}; }

const Particles& World::particles() const {
  // Every change of the particles refreshes the view; this is the net for one that did not, and
  // writes only then (so threads that only read a World may call it side by side).
  if (!impl_->viewCurrent()) impl_->refreshView();
  return impl_->view;
}
std::size_t World::particleCount() const { return impl_->P.size(); }
Vec2d World::origin() const { return impl_->origin; }
Vec2d World::worldPosition(std::size_t i) const { return Vec2d(impl_->P.x[i].x(), impl_->P.x[i].y()) + impl_->origin; }
const std::vector<Collider>& World::colliders() const { return impl_->boundary.colliders; }
const std::vector<Vec2>& World::boundarySamples() const { return impl_->boundary.samples; }
b2World& World::box2d() { return *impl_->b2; }
const b2World& World::box2d() const { return *impl_->b2; }
const SceneDef& World::scene() const { return impl_->scene; }
double World::time() const { return impl_->time; }
std::uint64_t World::frame() const { return impl_->frames; }
double World::stableTimeStep() const { return double(impl_->stableDt()); }
Real World::particleMass() const { return impl_->momentumMass; }
Real World::support() const { return impl_->R; }
Real World::spacing() const { return impl_->dx; }
int World::threads() const { return impl_->pool.size(); }

void World::setUserForces(const std::vector<UserForce>& forces) {
  impl_->userForces = forces;
  if (!impl_->userForceEffect && !forces.empty()) {
    impl_->effects.push_back(makeUserForceEffect(&impl_->userForces));
    impl_->userForceEffect = true;
    impl_->buildStages();
  }
}

void World::setEmitterEnabled(std::size_t index, bool enabled) {
  impl_->sources.emitters.at(index).def.enabled = enabled;
}

namespace {

/// The scene's effect called `name`; std::invalid_argument naming the scene's effects if none.
template <class Effects>
auto& effectNamed(Effects& effects, const std::string& name) {
  std::string names;
  for (auto& e : effects) {
    if (name == e->name()) return *e;
    names += (names.empty() ? "" : ", ") + std::string(e->name());
  }
  throw std::invalid_argument("the scene does not enable the effect '" + name +
                              "'; its effects: " + (names.empty() ? std::string("none") : names));
}

}  // namespace

void World::setEffectEnabled(const std::string& name, bool enabled) {
  auto& e = effectNamed(impl_->effects, name);
  if (e.enabled == enabled) return;
  e.enabled = enabled;
  impl_->buildStages();
}

bool World::effectEnabled(const std::string& name) const { return effectNamed(impl_->effects, name).enabled; }

Vec2d World::gravity() const { return impl_->scene.gravity; }

const std::vector<UserForce>& World::userForces() const { return impl_->userForces; }

bool World::emitterEnabled(std::size_t index) const { return impl_->sources.emitters.at(index).def.enabled; }

std::size_t World::emitterCount() const { return impl_->sources.emitters.size(); }

std::uint64_t World::emittedCount(std::size_t index) const { return impl_->sources.emitters.at(index).emitted; }

void bench::stepSubstep(World& world) {
  World::Impl& w = *world.impl_;
  w.beforeStep("stepSubstep");
  World::Impl::StopScope scope(w.pool, w.stop);
  try {
    w.readStatics(0);  // the level's edits (a moved static body is re-read where it is: no step to slide it over)
    w.contacts.beginStep();
    w.captureBodies();
    w.moveOwnBodies(double(w.substep(w.stableDt())));
    w.contacts.finishStep();
    w.refreshView();
  } catch (const Interrupted& e) {
    w.abandon(e);
  }
}

std::vector<std::string> World::takeWarnings() {
  std::vector<std::string> out;
  out.swap(impl_->warnings);
  return out;
}

}  // namespace sph2d
