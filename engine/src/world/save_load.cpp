// save_load.cpp — World::save and World::load: the World's changing state as one
// byte stream (state_io.hpp), after LiquidFun's and Box2D's notion that a game
// snapshots its physics between frames.
//
// What is saved is everything a step reads that the scene does not fix: the
// particles with every field (fixed and optional, in their slot order), the clock
// and counters, the emitters' random streams and counts and where a game moved
// them, gravity, the user forces, which effects are switched on, and what the
// solver carries between substeps (Solver::saveState). Grids, neighbour lists and
// caches are rebuilt by the next substep. A fingerprint of the scene's solver,
// spacing, emitters and effects makes a save load only into a World of its scene.
//
// load() reads the whole input into temporaries and checks it (magic, version,
// fingerprint, every count against the budget or the scene, field names and sizes,
// unique ids below the next id) before it changes anything.
//
// What no save holds is the b2World's state that Box2D 2.4 keeps private: each contact's
// and joint's impulses of the last step, from which it warm-starts the next (and a rebuilt
// b2World, never stepped, would scale restored ones by 0 in its first step: its previous
// step length is private too), each body's sleep timer, and the order of its contacts
// (creation order, which a rebuilt world's broad phase decides afresh). save() reports the
// first two when they are live (SaveReport); docs/EMBEDDING.md gives the remedy.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <istream>
#include <iterator>
#include <ostream>
#include <sstream>

#include <box2d/box2d.h>

#include "core/state_io.hpp"
#include "particles/material_fields.hpp"
#include "sph2d/hash.hpp"
#include "world/world_impl.hpp"

namespace sph2d {
namespace {

constexpr char kMagic[8] = {'S', 'P', 'H', '2', 'D', 'S', 'A', 'V'};
constexpr std::uint64_t kMaxEmitters = ParticleSources::kMaxEmitters;  // a save holding more is not one of ours
// 2: every emitter's whole definition (emitters added at run time); 3: bodies' swept poses;
// 4: the swept poses of a game's b2World's bodies too; 5: the scene's own b2World's warm-starting
// and sleeping switches and each of its moving bodies' awake state; 6: each emitter's material.
// Versions 4 and 5 load as well (what they lack as the loading World has it; emitters of the
// first material).
constexpr std::uint32_t kVersion = 6;
constexpr std::uint32_t kOldestVersion = 4;
constexpr std::size_t kMaxFields = 64, kMaxName = 128;
constexpr const char* kUserForce = "user_force";  ///< the effect setUserForces adds

/// What a save must match: the solver and its spacing, the emitters, the effects, and the
/// materials when there is more than one (a World of one fluid has the fingerprint it had
/// before materials existed).
std::uint64_t fingerprint(const SceneDef& scene, const Solver& solver, const EffectList& effects,
                          const std::vector<MaterialDef>& materials) {
  Xxh64 h;
  auto str = [&](const std::string& s) {
    const std::uint64_t n = s.size();
    h.update(&n, sizeof n);
    h.update(s.data(), s.size());
  };
  str(solver.name());
  const double keys[] = {scene.solver.spacing, scene.solver.supportRatio, scene.solver.restDensity};
  h.update(keys, sizeof keys);
  const std::uint64_t emitters = scene.effects.emitters.size();  // the scene's: a game adds and removes others
  h.update(&emitters, sizeof emitters);
  for (const auto& e : effects)
    if (std::string(e->name()) != kUserForce) str(e->name());  // a game adds it at run time
  if (materials.size() > 1)
    for (const MaterialDef& m : materials) {
      str(m.name);
      h.update(&m.density, sizeof m.density);
    }
  return h.digest();
}

void putVec(StateOut& o, const Vec2d& v) {
  o.put(v.x());
  o.put(v.y());
}

Vec2d getVec(StateIn& in, const char* what) {
  const double x = in.get<double>(what), y = in.get<double>(what);
  return Vec2d(x, y);
}

/// The state of `world` that no save can hold and that is live now (SaveReport).
SaveReport unsaved(b2World& world) {
  SaveReport r;
  auto dynamic = [](b2Body* b) { return b->GetType() == b2_dynamicBody; };
  if (world.GetWarmStarting()) {
    for (b2Contact* c = world.GetContactList(); c; c = c->GetNext())
      if (c->IsTouching() && !c->GetFixtureA()->IsSensor() && !c->GetFixtureB()->IsSensor() &&
          (dynamic(c->GetFixtureA()->GetBody()) || dynamic(c->GetFixtureB()->GetBody())))
        ++r.warmStartedContacts;
    for (b2Joint* j = world.GetJointList(); j; j = j->GetNext())
      if (dynamic(j->GetBodyA()) || dynamic(j->GetBodyB())) ++r.warmStartedJoints;
  }
  if (world.GetAllowSleeping()) {
    // Box2D's island adds the step to a body's timer while the body is slower than both
    // tolerances after the step, and zeroes it otherwise.
    const float linTol2 = b2_linearSleepTolerance * b2_linearSleepTolerance;
    const float angTol2 = b2_angularSleepTolerance * b2_angularSleepTolerance;
    for (b2Body* b = world.GetBodyList(); b; b = b->GetNext())
      if (b->GetType() != b2_staticBody && b->IsAwake() && b->IsEnabled() && b->IsSleepingAllowed() &&
          b2Dot(b->GetLinearVelocity(), b->GetLinearVelocity()) <= linTol2 &&
          b->GetAngularVelocity() * b->GetAngularVelocity() <= angTol2)
        ++r.sleepTimers;
  }
  if (r.complete()) return r;
  std::ostringstream o;
  o << "save: the b2World holds state no save can: ";
  if (r.warmStartedContacts || r.warmStartedJoints) {
    o << r.warmStartedContacts << " touching contact" << (r.warmStartedContacts == 1 ? "" : "s");
    if (r.warmStartedJoints) o << " and " << r.warmStartedJoints << " joint" << (r.warmStartedJoints == 1 ? "" : "s");
    o << " of dynamic bodies warm-start from impulses Box2D keeps private";
    if (r.sleepTimers) o << ", and ";
  }
  if (r.sleepTimers)
    o << r.sleepTimers << " bod" << (r.sleepTimers == 1 ? "y" : "ies") << " at rest "
      << (r.sleepTimers == 1 ? "has a" : "have") << " sleep timer" << (r.sleepTimers == 1 ? "" : "s") << " running";
  o << "; a World loaded from this save steps on close to this one, not bit for bit. For replays that match bit for bit, call ";
  if (r.warmStartedContacts || r.warmStartedJoints) o << "SetWarmStarting(false)" << (r.sleepTimers ? " and " : "");
  if (r.sleepTimers) o << "SetAllowSleeping(false)";
  o << " on the b2World from its creation, and on the one rebuilt for the load (docs/EMBEDDING.md, Saving and loading)";
  r.warning = o.str();
  return r;
}

}  // namespace

SaveReport World::save(std::ostream& out) const {
  Impl& w = *impl_;
  StateOut o;
  for (const char c : kMagic) o.put(c);
  o.put(kVersion);
  o.put(fingerprint(w.scene, *w.solver, w.effects, w.materials));
  o.put(w.time);
  o.put(w.frames);
  o.put(w.steps);
  o.put(std::int32_t(w.lastSubsteps));
  o.put(w.lastAccel);
  o.put(w.lastDt);
  o.put(w.nextId);
  o.put(w.iterations);
  o.put(w.sources.removed);
  putVec(o, w.scene.gravity);
  o.put(std::uint64_t(w.sources.emitters.size()));
  for (const ParticleSources::Emitter& e : w.sources.emitters) {
    o.put(e.rng);
    o.put(e.emitted);
    o.put(std::uint8_t(e.warnedBudget));
    putVec(o, e.def.position);
    putVec(o, e.def.direction);
    o.put(std::uint8_t(e.def.enabled));
    const double shape[] = {e.def.width, e.def.rate, e.def.speed, e.def.spread, e.def.jitter, e.def.start, e.def.stop};
    for (const double v : shape) o.put(v);
    o.put(e.def.seed);
    o.put(e.def.material);
  }
  o.put(std::uint8_t(w.userForceEffect));
  o.put(std::uint64_t(w.userForces.size()));
  for (const UserForce& f : w.userForces) {
    putVec(o, f.point);
    o.put(f.radius);
    o.put(f.strength);
  }
  std::uint64_t sceneEffects = 0;
  for (const auto& e : w.effects) sceneEffects += std::string(e->name()) != kUserForce;
  o.put(sceneEffects);
  for (const auto& e : w.effects) {
    if (std::string(e->name()) == kUserForce) continue;
    o.putString(e->name());
    o.put(std::uint8_t(e->enabled));
  }
  o.put(std::uint64_t(w.P.size()));
  std::uint64_t fields = 0;
  w.P.forEachField([&](const char*, const auto&) { ++fields; });
  o.put(fields);
  w.P.forEachField([&](const char* name, const auto& f) {
    o.putString(name);
    o.put(std::uint32_t(sizeof(f[0])));
    o.putBytes(f.data(), f.size() * sizeof(f[0]));
  });
  // The moving bodies of the b2World the fluid meets, in its body list's order: the scene's
  // own with their pose and velocity; a game's without (the game saves its own b2World and
  // rebuilds it with its bodies in the same order), but with where the particles last saw
  // them, which the World holds.
  std::uint64_t bodies = 0;
  if (w.b2)
    for (b2Body* b = w.b2->GetBodyList(); b; b = b->GetNext()) bodies += b->GetType() != b2_staticBody;
  o.put(bodies);
  o.put(std::uint8_t(w.ownWorld != nullptr));
  if (w.ownWorld && bodies) {  // the switches the scene's own world steps its bodies with (a game keeps its own)
    o.put(std::uint8_t(w.ownWorld->GetWarmStarting()));
    o.put(std::uint8_t(w.ownWorld->GetAllowSleeping()));
  }
  if (w.b2)
    for (b2Body* b = w.b2->GetBodyList(); b; b = b->GetNext()) {
      if (b->GetType() == b2_staticBody) continue;
      if (w.ownWorld) {
        o.put(b->GetPosition());
        o.put(b->GetAngle());
        o.put(b->GetLinearVelocity());
        o.put(b->GetAngularVelocity());
        o.put(std::uint8_t(b->IsAwake()));
      }
      // The pose the particles last saw a dynamic body at (moving_solid.hpp), if any.
      const MovingSolids::LastPose* last = nullptr;
      for (const MovingSolids::LastPose& l : w.moving.solids.last)
        if (l.body == b) last = &l;
      o.put(std::uint8_t(last != nullptr));
      o.put(last ? last->theta : 0.0);
      o.put(last ? last->origin.x() : 0.0);
      o.put(last ? last->origin.y() : 0.0);
    }
  w.solver->saveState(o);
  out.write(reinterpret_cast<const char*>(o.bytes.data()), std::streamsize(o.bytes.size()));
  if (!out) throw SaveError("World::save: the stream refused the state (" + std::to_string(o.bytes.size()) + " bytes)");
  SaveReport report = w.b2 ? unsaved(*w.b2) : SaveReport{};
  if (!report.complete() && !w.warnedSave) {
    w.warnings.push_back(report.warning);
    w.warnedSave = true;
  }
  return report;
}

void World::load(std::istream& input) {
  Impl& w = *impl_;
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(input)), std::istreambuf_iterator<char>());
  StateIn in(bytes.data(), bytes.size());
  for (const char c : kMagic)
    if (in.get<char>("the header") != c) throw SaveError("not an sph2d saved state (its first bytes are not SPH2DSAV)");
  const std::uint32_t version = in.get<std::uint32_t>("the header");
  if (version < kOldestVersion || version > kVersion)
    throw SaveError("the saved state has version " + std::to_string(version) + "; this sph2d reads versions " +
                    std::to_string(kOldestVersion) + " to " + std::to_string(kVersion));
  if (in.get<std::uint64_t>("the header") != fingerprint(w.scene, *w.solver, w.effects, w.materials))
    throw SaveError(
        "the saved state belongs to another scene (its solver, spacing, materials, emitters or effects differ)");
  const double time = in.get<double>("the clock");
  const std::uint64_t frames = in.get<std::uint64_t>("the clock"), steps = in.get<std::uint64_t>("the clock");
  const std::int32_t lastSubsteps = in.get<std::int32_t>("the clock");
  const Real lastAccel = in.get<Real>("the clock");
  const double lastDt = in.get<double>("the clock");
  const std::uint32_t nextId = in.get<std::uint32_t>("the counters");
  const std::uint64_t iterations = in.get<std::uint64_t>("the counters"),
                      removed = in.get<std::uint64_t>("the counters");
  const Vec2d gravity = getVec(in, "gravity");
  if (!std::isfinite(time) || !std::isfinite(lastDt) || !std::isfinite(gravity.x()) || !std::isfinite(gravity.y()))
    throw SaveError("the saved state is malformed: its clock or gravity is not finite");
  const std::uint64_t emitterCount = in.get<std::uint64_t>("the emitters");
  if (emitterCount > kMaxEmitters)
    throw SaveError("the saved state is malformed: " + std::to_string(emitterCount) + " emitters (at most " +
                    std::to_string(kMaxEmitters) + ")");
  std::vector<ParticleSources::Emitter> emitters(static_cast<std::size_t>(emitterCount));
  for (ParticleSources::Emitter& e : emitters) {
    e.rng = in.get<std::uint64_t>("an emitter");
    e.emitted = in.get<std::uint64_t>("an emitter");
    e.warnedBudget = in.get<std::uint8_t>("an emitter") != 0;
    e.def.position = getVec(in, "an emitter");
    e.def.direction = getVec(in, "an emitter");
    e.def.enabled = in.get<std::uint8_t>("an emitter") != 0;
    double* shape[] = {&e.def.width,  &e.def.rate,  &e.def.speed, &e.def.spread,
                       &e.def.jitter, &e.def.start, &e.def.stop};
    for (double* v : shape) *v = in.get<double>("an emitter");
    e.def.seed = in.get<std::uint64_t>("an emitter");
    if (version >= 6) e.def.material = in.get<std::uint32_t>("an emitter");
    if (e.def.material >= w.materials.size())
      throw SaveError("the saved state is malformed: an emitter's material " + std::to_string(e.def.material) +
                      " (the World has " + std::to_string(w.materials.size()) + ")");
    const std::string problem = ParticleSources::problem(e.def);
    if (!problem.empty() || !(std::abs(e.def.direction.norm() - 1) < 1e-6))
      throw SaveError("the saved state is malformed: an emitter's " +
                      (problem.empty() ? std::string("direction") : problem));
  }
  const bool userForceEffect = in.get<std::uint8_t>("the user forces") != 0;
  const std::uint64_t forces = in.get<std::uint64_t>("the user forces");
  if (forces > 4096)
    throw SaveError("the saved state is malformed: " + std::to_string(forces) + " user forces (at most 4096)");
  std::vector<UserForce> userForces(static_cast<std::size_t>(forces));
  for (UserForce& f : userForces) {
    f.point = getVec(in, "a user force");
    f.radius = in.get<double>("a user force");
    f.strength = in.get<double>("a user force");
  }
  std::vector<std::string> effectNames;
  for (const auto& e : w.effects)
    if (std::string(e->name()) != kUserForce) effectNames.push_back(e->name());
  if (in.get<std::uint64_t>("the effects") != effectNames.size())
    throw SaveError("the saved state is malformed: its effect count is not the World's");
  std::vector<bool> enabled;
  for (const std::string& name : effectNames) {
    if (in.getString(kMaxName, "an effect's name") != name)
      throw SaveError("the saved state is malformed: the effects differ (expected " + name + ")");
    enabled.push_back(in.get<std::uint8_t>("an effect") != 0);
  }
  const std::uint64_t n = in.get<std::uint64_t>("the particle count");
  if (n > w.sources.budget)
    throw SaveError("the saved state holds " + std::to_string(n) + " particles, beyond the scene's budget of " +
                    std::to_string(w.sources.budget) + " (" + w.budgetKey() + ")");
  const std::uint64_t fieldCount = in.get<std::uint64_t>("the field count");
  if (fieldCount > kMaxFields)
    throw SaveError("the saved state is malformed: " + std::to_string(fieldCount) + " particle fields");
  struct Field {
    std::string name;
    std::uint32_t element = 0;
    std::vector<std::uint8_t> data;
  };
  std::vector<Field> saved(static_cast<std::size_t>(fieldCount));
  for (Field& f : saved) {
    f.name = in.getString(kMaxName, "a field's name");
    f.element = in.get<std::uint32_t>("a field");
    if (f.element != 4 && f.element != 8)
      throw SaveError("the saved state is malformed: field " + f.name + "'s element size");
    in.getVector(f.data, std::size_t(n) * f.element, "a field's values");
    if (f.data.size() != std::size_t(n) * f.element)
      throw SaveError("the saved state is malformed: field " + f.name + " does not hold one value per particle");
  }
  auto find = [&](const std::string& name) -> const Field* {
    for (const Field& f : saved)
      if (f.name == name) return &f;
    return nullptr;
  };
  // Every field of this World (fixed and optional) must be in the save, with its element size.
  std::string missing;
  w.P.forEachField([&](const char* name, const auto& vec) {
    const Field* f = find(name);
    // A colour, tag, group or lifetime set after the save: zeros ("none") on load.
    if (!f && (ParticleStore::integerField(name) || ParticleStore::gameRealField(name) ||
               std::string(name) == ParticleStore::kLifeEnd))
      return;
    if (!f || f->element != sizeof(vec[0])) missing += (missing.empty() ? "" : ", ") + std::string(name);
  });
  if (!missing.empty()) throw SaveError("the saved state is malformed: it lacks the particle fields " + missing);
  for (const Field& f : saved) {
    bool fixed = false;
    w.P.forEachField([&](const char* name, const auto&) { fixed = fixed || f.name == name; });
    const std::size_t element = f.name == ParticleStore::kLifeEnd ? sizeof(double) : sizeof(Real);
    if (!fixed && f.element != element)
      throw SaveError("the saved state is malformed: field " + f.name + "'s element size");
  }
  std::vector<std::uint32_t> ids(static_cast<std::size_t>(n));
  if (n) std::memcpy(ids.data(), find("id")->data.data(), ids.size() * sizeof(std::uint32_t));
  std::sort(ids.begin(), ids.end());
  if (std::adjacent_find(ids.begin(), ids.end()) != ids.end() || (!ids.empty() && ids.back() >= nextId))
    throw SaveError("the saved state is malformed: particle ids repeat or reach the next id");
  for (std::size_t k = 0; k < w.materials.size(); ++k)  // with mixing: concentrations, each in 0..1
    if (const Field* cf = find(ParticleStore::concentration(k))) {
      std::vector<double> c(static_cast<std::size_t>(n));
      if (n && cf->element == sizeof(double)) std::memcpy(c.data(), cf->data.data(), c.size() * sizeof(double));
      for (const double v : c)
        if (!(v >= -1e-3 && v <= 1.001))
          throw SaveError("the saved state is malformed: a concentration of " + std::to_string(v) + " (field " +
                          ParticleStore::concentration(k) + ")");
    }
  if (const Field* mf = find(ParticleStore::kMaterial)) {
    if (w.materials.size() < 2)
      throw SaveError("the saved state is malformed: it holds each particle's material, and the World has one");
    std::vector<std::uint32_t> mat(static_cast<std::size_t>(n));
    if (n) std::memcpy(mat.data(), mf->data.data(), mat.size() * sizeof(std::uint32_t));
    for (const std::uint32_t m : mat)
      if (m >= w.materials.size())
        throw SaveError("the saved state is malformed: a particle of material " + std::to_string(m) +
                        " (the World has " + std::to_string(w.materials.size()) + ")");
  }
  std::vector<b2Body*> movable;
  if (w.b2)
    for (b2Body* b = w.b2->GetBodyList(); b; b = b->GetNext())
      if (b->GetType() != b2_staticBody) movable.push_back(b);
  const std::uint64_t savedBodies = in.get<std::uint64_t>("the bodies");
  const std::uint8_t savedOwn = in.get<std::uint8_t>("the bodies");
  if (savedOwn != std::uint8_t(w.ownWorld != nullptr))
    throw SaveError(savedOwn ? "the saved state holds the scene's own bodies, but this World meets a game's b2World"
                             : "the saved state was taken with a game's b2World, but this World has the scene's own");
  if (savedBodies != movable.size())
    throw SaveError("the saved state has " + std::to_string(savedBodies) + " moving bodies, but " +
                    (w.ownWorld ? "the scene has " : "the game's b2World has ") + std::to_string(movable.size()));
  // The scene's own world's switches (version 5, with moving bodies): as the loading World has them otherwise.
  bool warmStarting = w.ownWorld ? w.ownWorld->GetWarmStarting() : true;
  bool allowSleeping = w.ownWorld ? w.ownWorld->GetAllowSleeping() : true;
  if (savedOwn && savedBodies && version >= 5) {
    const std::uint8_t warm = in.get<std::uint8_t>("the bodies"), sleep = in.get<std::uint8_t>("the bodies");
    if (warm > 1 || sleep > 1) throw SaveError("the saved state is malformed: the b2World's switches");
    warmStarting = warm != 0;
    allowSleeping = sleep != 0;
  }
  struct BodyState {
    b2Vec2 p = b2Vec2(0, 0), v = b2Vec2(0, 0);  // a game's bodies: not in the save
    float angle = 0, omega = 0;
    std::uint8_t awake = 1;  // version 5 (version 4: left as the loading World has it)
    std::uint8_t hasLast = 0;
    double lastTheta = 0, lastX = 0, lastY = 0;
  };
  std::vector<BodyState> bodyStates(movable.size());
  for (BodyState& b : bodyStates) {
    if (savedOwn) {
      b.p = in.get<b2Vec2>("a body");
      b.angle = in.get<float>("a body");
      b.v = in.get<b2Vec2>("a body");
      b.omega = in.get<float>("a body");
      if (version >= 5) b.awake = in.get<std::uint8_t>("a body");
    }
    b.hasLast = in.get<std::uint8_t>("a body");
    b.lastTheta = in.get<double>("a body");
    b.lastX = in.get<double>("a body");
    b.lastY = in.get<double>("a body");
    if (!b.p.IsValid() || !b.v.IsValid() || !std::isfinite(b.angle) || !std::isfinite(b.omega) || b.hasLast > 1 ||
        b.awake > 1 || !std::isfinite(b.lastTheta) || !std::isfinite(b.lastX) || !std::isfinite(b.lastY))
      throw SaveError("the saved state is malformed: a body's pose or velocity is not finite");
  }
  // The solver's state is the stream's tail. Its own loadState reads all before it assigns;
  // if it throws, or bytes are left over, the solver gets its previous state back.
  StateOut backup;
  w.solver->saveState(backup);
  try {
    w.solver->loadState(in);
    if (!in.done()) throw SaveError("the saved state is malformed: bytes follow the solver's state");
  } catch (...) {
    StateIn restore(backup.bytes.data(), backup.bytes.size());
    w.solver->loadState(restore);
    throw;
  }
  // Commit.
  for (const Field& f : saved) {
    bool fixed = false;
    w.P.forEachField([&](const char* name, auto& vec) {
      if (f.name != name) return;
      fixed = true;
      vec.resize(static_cast<std::size_t>(n));
      if (n) std::memcpy(static_cast<void*>(vec.data()), f.data.data(), f.data.size());
    });
    if (!fixed && ParticleStore::integerField(f.name)) {  // colour or user data the save holds and this World lacks
      std::vector<std::uint32_t>& vec = w.P.fieldU32(f.name);
      vec.resize(static_cast<std::size_t>(n));
      if (n) std::memcpy(vec.data(), f.data.data(), f.data.size());
    } else if (!fixed && f.name == ParticleStore::kLifeEnd) {  // lifetimes the save holds and this World lacks
      std::vector<double>& vec = w.P.fieldD(f.name);
      vec.resize(static_cast<std::size_t>(n));
      if (n) std::memcpy(vec.data(), f.data.data(), f.data.size());
    } else if (!fixed) {
      std::vector<Real>& vec = w.P.field(f.name);
      vec.resize(static_cast<std::size_t>(n));
      if (n) std::memcpy(vec.data(), f.data.data(), f.data.size());
    }
  }
  for (auto& e : w.P.extraU32)  // integer fields the save lacks: none set at the time of the save
    if (!find(e.first)) e.second.assign(static_cast<std::size_t>(n), 0u);
  for (auto& e : w.P.extra)  // the groups' fields the save lacks: no group at the time of the save
    if (ParticleStore::gameRealField(e.first) && !find(e.first)) e.second.assign(static_cast<std::size_t>(n), Real(0));
  if (std::vector<double>* end = w.P.findD(ParticleStore::kLifeEnd))  // no lifetime at the time of the save
    if (!find(ParticleStore::kLifeEnd)) end->assign(static_cast<std::size_t>(n), 0.0);
  w.fillRestRatio(0);                             // from the materials (checked above), not the file
  deriveFromConcentrations(w.P, w.materials, 0);  // with mixing: from the concentrations (checked above)
  if (savedOwn) {
    w.ownWorld->SetWarmStarting(warmStarting);
    w.ownWorld->SetAllowSleeping(allowSleeping);  // (false wakes every body: before the bodies' own state)
  }
  for (std::size_t k = 0; k < movable.size() && savedOwn; ++k) {
    movable[k]->SetTransform(bodyStates[k].p, bodyStates[k].angle);
    movable[k]->SetLinearVelocity(bodyStates[k].v);
    movable[k]->SetAngularVelocity(bodyStates[k].omega);
    if (version >= 5) movable[k]->SetAwake(bodyStates[k].awake != 0);  // asleep: at rest, as Box2D put it to sleep
  }
  w.moving.solids.last.clear();  // the loaded state's, not those of the World's own last step
  for (std::size_t k = 0; k < movable.size(); ++k)
    if (bodyStates[k].hasLast)
      w.moving.solids.last.push_back(
          {movable[k], bodyStates[k].lastTheta, Vec2d(bodyStates[k].lastX, bodyStates[k].lastY)});
  w.time = time;
  w.frames = frames;
  w.steps = steps;
  w.lastSubsteps = lastSubsteps;
  w.lastAccel = lastAccel;
  w.lastDt = lastDt;
  w.nextId = nextId;
  w.iterations = iterations;
  w.wall = WallAccount{};  // World::wallImpulse() counts from the load on
  w.sources.removed = removed;
  w.scene.gravity = gravity;
  if (w.ownWorld) w.ownWorld->SetGravity(b2Vec2(float(gravity.x()), float(gravity.y())));
  w.sources.emitters = std::move(emitters);
  // The user-force effect exactly when the saved World had it (setUserForces adds it on the
  // first non-empty list); then the scene's effects as they were switched.
  if (userForceEffect && !w.userForceEffect) {
    w.effects.push_back(makeUserForceEffect(&w.userForces));
    w.userForceEffect = true;
  } else if (!userForceEffect && w.userForceEffect) {
    w.effects.erase(std::remove_if(w.effects.begin(), w.effects.end(),
                                   [](const auto& e) { return std::string(e->name()) == kUserForce; }),
                    w.effects.end());
    w.userForceEffect = false;
  }
  w.userForces = std::move(userForces);
  for (std::size_t k = 0; k < effectNames.size(); ++k)
    for (auto& e : w.effects)
      if (effectNames[k] == e->name()) e->enabled = enabled[k];
  w.buildStages();
  w.index.clear();
  w.lastContacts.clear();  // the particle contact listener's `began` is of the loaded state on
  w.contacts.beginStep();  // the contacts of the state before the load are not this state's
  if (w.foam) w.foam->clear();  // foam is not saved: the loaded state's grows again
  w.refreshView();
  w.abandonedIn.clear();  // an interrupted World is this state now, and steps again
}

}  // namespace sph2d
