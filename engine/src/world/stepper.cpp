// The World's stepper: the substep as one explicit list of stages, the
// time-step policy and the guard.
//
// The list is built once from the solver's stages (solvers/solver.hpp), the
// scene's enabled effects at the solver's effects marker, and the World's own
// stages around them: emit first; then, after the solver, the largest
// acceleration (for the next substep's force limit), the swept collision with
// the Box2D solids, the periodic wrap, lifetimes and sinks. A stage exists
// only when the scene needs it. The list is rebuilt when a user force is
// first set or an effect is switched on or off. One fold: when the first
// enabled effect is the Laplacian viscosity and the solver computes it in its
// own pressure-force pair loop (muller2003: one pass over the neighbours
// instead of two, the same terms; its sums in eight partial sums, the effect's
// pass in list order, so they differ by rounding), that stage is "pressure_force+viscosity" and
// the effect has no stage of its own (Solver::foldViscosity).
//
// The time-step policy is the World's alone: the solver and the enabled
// effects report their limits; a frame is split into equal substeps no longer
// than the least of them, at most solver.max_substeps a frame (beyond that the
// frame advances less time and a warning names it); what remains of a frame
// below kFrameLeftover of it is float rounding and is dropped. A stage may
// shorten its substep (c.dt; the explicit solvers' force_limit, when this
// substep's forces allow less than the last one's did): the clock advances by
// the substep taken, and the frame's next substep starts from there. A step()
// shorter than kMinStepOfLast of the last substep (a caller stepping "up to
// time t") is a drift: the particles move with their velocity under gravity,
// collide, and the particle system runs, but no solver stage: the density
// solves divide by dt, and a sliver would turn the compression the last
// substep left into a huge velocity. The drift is a second, short stage list.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "world/world_impl.hpp"

namespace sph2d {

StepContext World::Impl::context(Real dt) {
  StepContext c{P, grid, nbr, boundary, pool, scratch, scene.solver};
  c.R = R;
  c.dx = dx;
  c.dt = dt;
  c.mass = mass;
  c.momentumMass = momentumMass;
  c.rho0 = Real(scene.solver.restDensity);
  c.gravity = Vec2(Real(scene.gravity.x()), Real(scene.gravity.y()));
  c.clearance = kClearance * dx;
  c.maxSpeed = Real(scene.solver.maxSpeed);
  c.step = steps;
  c.time = time;
  c.origin = origin;
  c.periodic = periodic;
  c.boundaryVersion = statics.version();
  c.solids = moving.solids.bodies.empty() ? nullptr : &moving.solids;
  if (bodySamplesOn()) c.bodySamples = &moving.samples;
  if (materials.size() > 1) c.materials = &materials;
  return c;
}

void World::Impl::buildStages() {
  stages.clear();
  if (!sources.emitters.empty()) stages.add(plainStage("emit", [this](StepContext& c) { emit(c.dt); }));
  if (moving.solids.anyDynamic()) {
    stages.add(plainStage("body_gravity", [this](StepContext& c) { bodyGravity(c); }));
    stages.add(plainStage("body_walls", [this](StepContext& c) { bodyWalls(c); }));
  }
  if (bodySamplesOn()) {
    // A particle a body's Box2D step moved onto would read as a compression the solve must
    // remove within one substep (kicks of 50 m/s and more under a crate): put back first.
    stages.add(plainStage("body_jump", [this](StepContext& c) { collideMoving(c, true); }));
    stages.add(plainStage("body_samples", [this](StepContext& c) {
      moving.samples.place(c.time, c.dx, c.R, c.P.size(), c.pool, moving.solids);
    }));
  }
  bool anyEffect = false;
  Effect* first = nullptr;  // the first enabled effect: the solver may fold it into its pressure force
  for (const auto& e : effects) {
    if (e->enabled && !first) first = e.get();
    anyEffect = anyEffect || e->enabled;
  }
  Effect* folded = first && first->foldable() && solver->foldViscosity(first) ? first : nullptr;
  if (!folded) solver->foldViscosity(nullptr);
  for (const auto& e : effects) e->folded = e.get() == folded;
  bool marker = false, late = false, lateMarker = false;
  for (const auto& e : effects) late = late || (e->enabled && e->afterPressure());
  for (Stage& s : solver->stages(anyEffect)) {
    if (!s.effectsMarker && !s.velocityMarker) {
      stages.add(std::move(s));
      continue;
    }
    marker = marker || s.effectsMarker;
    lateMarker = lateMarker || s.velocityMarker;
    if (s.velocityMarker && late && s.run) stages.add(Stage{s.name, s.run});
    for (const auto& e : effects) {
      if (!e->enabled || e.get() == folded || e->afterPressure() != s.velocityMarker) continue;
      Effect* fx = e.get();
      stages.add(Stage{fx->name(), [fx](StepContext& c) { return fx->apply(c); }});
    }
  }
  if (!marker) throw std::logic_error(std::string("solver ") + solver->name() + " has no effects marker in its stages");
  if (late && !lateMarker)
    throw std::logic_error(std::string("solver ") + solver->name() + " has no velocity marker for its effects");
  stages.add(plainStage("max_acceleration", [this](StepContext& c) {
    lastAccel = c.accelMeasured >= 0 ? c.accelMeasured
                                     : maxAccelOf(c.P, c.pool);  // the explicit solvers' force_limit measured it
  }));
  if (bodySamplesOn())
    stages.add(plainStage("body_forces",
                          [this](StepContext& c) { moving.samples.react(c.time, double(c.dt), moving.solids); }));
  addParticleSystemStages(stages, true);

  drift.clear();
  if (!sources.emitters.empty()) drift.add(plainStage("emit", [this](StepContext& c) { emit(c.dt); }));
  drift.add(Stage{"drift", [](StepContext& c) { return stageDrift(c); }});
  addParticleSystemStages(drift, false);
}

void World::Impl::addParticleSystemStages(StageList& list, bool full) {
  const std::vector<Real>* k = P.find(ParticleStore::kGroupStiffness);
  if (k && !solver->groupCorrections() && std::any_of(k->begin(), k->end(), [](Real s) { return s > 0 && s < 1; }))
    list.add(plainStage("groups_before_collide", [this](StepContext& c) { groupsBeforeCollide(c); }));
  else
    groupBefore.clear();
  list.add(plainStage("collide", [](StepContext& c) { stageCollide(c); }));
  if (!moving.solids.bodies.empty()) list.add(plainStage("bodies", [this](StepContext& c) { collideMoving(c); }));
  if (P.findU32(ParticleStore::kGroup))
    list.add(plainStage("groups", [this, full](StepContext& c) { matchGroups(c, full); }));
  // Foam reads the liquid's neighbour lists: before any slot is removed or wrapped.
  if (foam && full) list.add(plainStage("foam", [this](StepContext& c) { foam->step(c); }));
  if (periodic.any()) list.add(plainStage("wrap", [](StepContext& c) { stageWrap(c); }));
  if (scene.effects.lifetime) list.add(plainStage("lifetimes", [this](StepContext& c) { lifetimes(c.dt); }));
  if (!scene.effects.sinks.empty()) list.add(plainStage("sinks", [this](StepContext&) { sinks(); }));
  if (P.findD(ParticleStore::kLifeEnd))
    list.add(
        plainStage("particle_lifetimes", [this](StepContext& c) { particleLifetimes(double(c.time) + double(c.dt)); }));
  if (contacts.on())
    list.add(plainStage("contacts", [this](StepContext& c) { contacts.record(c, P, boundary, moving.solids, dx); }));
}

Real World::Impl::sourceSpeed() const {
  // An emitter adds particles at its speed within the substep, upstream of its nozzle by up
  // to that speed × the substep (particle_sources.cpp): the substep must be short enough for
  // them too. An empty world's first substep would otherwise be a whole frame, and a 50 m/s
  // jet's first particles were placed 0.4 m behind the nozzle (stacked on it where a wall
  // was nearer).
  double v = 0;
  const double horizon = time + 1.0 / double(scene.fps);
  for (const ParticleSources::Emitter& s : sources.emitters) {
    const EmitterDef& d = s.def;
    if (d.enabled && d.rate > 0 && time < d.stop && d.start <= horizon) v = std::max(v, d.speed * (1.0 + d.jitter));
  }
  return Real(v);
}

Real World::Impl::stableDt() {
  StepContext c = context(0);
  c.sourceSpeed = sourceSpeed();
  const Real vmax = std::max(maxSpeedOf(P, pool), c.sourceSpeed);
  Real dt = solver->maxTimeStep(c, vmax, lastAccel);
  for (const auto& e : effects)
    if (e->enabled) dt = std::min(dt, e->maxTimeStep(c));
  return dt;
}

void World::Impl::fail(const std::string& stage, std::size_t slot) {
  std::ostringstream o;
  o.precision(9);
  const Vec2d w = Vec2d(P.x[slot].x(), P.x[slot].y()) + origin;
  o << "simulation stopped: non-finite or runaway value after stage '" << stage << "' at substep " << steps
    << " (t = " << time << " s): particle id " << P.id[slot] << " position (" << w.x() << ", " << w.y()
    << ") velocity (" << P.v[slot].x() << ", " << P.v[slot].y() << ") density " << P.rho[slot] << " pressure "
    << P.p[slot] << " (speed limit solver.max_speed = " << scene.solver.maxSpeed << " m/s)";
  throw SimulationError(o.str(), stage, P.id[slot], steps, time);
}

Real World::Impl::substep(Real dt, bool driftOnly) {
  StepContext c = context(dt);
  c.wall = &wall;
  wall.force = Vec2d(0, 0);
  (driftOnly ? drift : stages)
      .run(
          c, [this](const std::string& stage, std::size_t slot) { fail(stage, slot); }, stop);
  dt = c.dt;
  wall.sum.samples += wall.force * double(dt);  // the explicit solvers' wall force, over the substep taken
  wall.force = Vec2d(0, 0);
  if (!driftOnly) {
    const SolverStats st = solver->stats();
    iterations += std::uint64_t(st.pressureIterations) + std::uint64_t(st.divergenceIterations);
  }
  time += double(dt);
  ++steps;
  return dt;
}

void World::Impl::bodiesFollow(Real taken) {
  if (!bodiesEverySubstep()) return;
  moveOwnBodies(double(taken));  // Box2D takes the substep too
  captureBodies();               // and the next substep starts from its poses
}

void World::Impl::advance(double frameDt) {
  double remaining = frameDt;
  if (remaining < kMinStepOfLast * lastDt) {  // a sliver: drift only (see the top of this file)
    bodiesFollow(substep(Real(remaining), true));
    lastSubsteps = 1;
    return;
  }
  const double total = remaining;
  int n = 0;
  const int cap = scene.solver.maxSubsteps;
  while (remaining > kFrameLeftover * total) {
    if (n == cap) {
      std::ostringstream o;
      o << "frame " << frames << ": substep cap solver.max_substeps = " << cap << " reached; simulated "
        << (total - remaining) << " s of " << total << " s (the frame runs slow instead of unstable)";
      warnings.push_back(o.str());
      break;
    }
    const Real limit = stableDt();
    const double k = std::ceil(remaining / double(limit) - 1e-9);
    const double dt = k <= 1 ? remaining : remaining / k;
    const Real taken = substep(Real(dt));
    bodiesFollow(taken);
    lastDt = double(taken);
    remaining -= double(taken);
    ++n;
  }
  lastSubsteps = n;
}

}  // namespace sph2d
