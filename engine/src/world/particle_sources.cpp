// The World's particle system (the particle-system seed: emitters,
// lifetimes, forces, integration): fluid blocks and drops on the lattice of
// the spacing, seeded emitters, lifetimes, sinks and the particle budget.
// Removal keeps the order of the remaining particles (ParticleStore::compact), and
// emitters draw from their own SplitMix64 stream, so a run is deterministic.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "world/world_impl.hpp"

namespace sph2d {

namespace {

std::uint64_t splitmix(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}
double uniform(std::uint64_t& state) { return double(splitmix(state) >> 11) * (1.0 / 9007199254740992.0); }

}  // namespace

/// Fills a block on the lattice of the spacing; particles inside solids are
/// dropped with one warning. With `hydrostaticStart`, rows are placed closer
/// with depth so the block starts at the density the solver holds at rest,
/// ρ = ρ0(1 + f g z) with the solver's factor f (2/c² for muller2003, whose
/// symmetric force recovers ∇p/2; 1/c0² for wcsph). Started uncompressed, a
/// column would ring in its acoustic mode with a speed amplitude of about g·H/c.
/// A circle region (a drop) keeps only the lattice points within its radius, a polygon those inside it.
/// The particle budget holds: once the world holds `budget` particles the rest of
/// the block is refused with one warning, and no work or memory grows with the
/// block's size beyond the particles added (rows are computed as they are
/// filled, a drop's rows only over its chord). The stop flag is read at every row and every
/// 4096 lattice points: when it is set the particles this call added are taken back (the
/// World is as before it) and Interrupted is thrown (empty stage: the caller names it).
IdRange World::Impl::fillBlock(const FluidBlockDef& b, bool hydrostaticStart, const char* call) {
  checkMaterial(b.material, call);
  IdRange ids;
  ids.first = nextId;  // every particle below takes the next id: the ones added are consecutive
  const std::size_t before = P.size();
  const std::uint32_t idBefore = nextId;
  std::uint32_t visited = 0;  // lattice points since the stop flag was last read
  auto checkStop = [&] {
    if (!stopSet()) return;
    P.truncate(before);
    nextId = idBefore;
    refreshView();
    throw Interrupted("stopped by the stop flag", "");
  };
  const bool disc = b.shape == FluidBlockDef::Shape::Circle;  // a circle or a drop: row chords
  std::vector<double> crossings;                              // a polygon's edges across the current row
  const SolverDef& sd = scene.solver;
  const double hydroFactor = solver->hydrostaticFactor();
  const bool hydrostatic = hydrostaticStart && hydroFactor > 0 && scene.gravity.x() == 0 && scene.gravity.y() < 0;
  const double gz = -scene.gravity.y();
  const Real rho0 = Real(sd.restDensity);
  const double nxd = std::floor((b.max.x() - b.min.x()) / sd.spacing + 1e-9);
  const double nyd = std::floor((b.max.y() - b.min.y()) / sd.spacing + 1e-9);
  if (!(nxd >= 1 && nyd >= 1)) return ids;  // empty (or NaN)
  // Lattice indices stay far inside a long: a block wider than 2^52 spacings is cut there
  // (it could never be filled within a budget anyway).
  const double cap = 4503599627370496.0;
  const long nx = long(std::min(nxd, cap)), ny = long(std::min(nyd, cap));
  std::size_t added = 0, dropped = 0;
  bool refused = false;
  Vec2d dlo(0, 0), dhi(0, 0);
  double y = 0, prevScale = 1;
  for (long j = 0; j < ny && !refused; ++j) {
    checkStop();
    const double depth = (double(ny - j) - 0.5) * sd.spacing;
    const double scale = hydrostatic ? 1.0 / (1.0 + hydroFactor * gz * depth) : 1.0;
    y = j == 0 ? b.min.y() + 0.5 * sd.spacing * scale : y + 0.5 * sd.spacing * (prevScale + scale);
    prevScale = scale;
    long i0 = 0, i1 = nx;          // the row's lattice points [i0, i1)
    b.rowCrossings(y, crossings);  // a polygon's edges across this row (none otherwise)
    if (disc) {
      const double dy = y - b.center.y(), r2 = b.radius * b.radius;
      if (dy * dy > r2) continue;
      // The chord, one spacing wider each side; the exact test below decides.
      const double half = std::sqrt(r2 - dy * dy) + sd.spacing;
      i0 = long(std::max(0.0, std::floor((b.center.x() - half - b.min.x()) / sd.spacing - 0.5)));
      i1 = long(std::min(double(nx), std::ceil((b.center.x() + half - b.min.x()) / sd.spacing + 0.5)));
    }
    for (long i = i0; i < i1; ++i) {
      if (++visited == 4096) {
        visited = 0;
        checkStop();
      }
      const Vec2d pw(b.min.x() + (double(i) + 0.5) * sd.spacing, y);
      if (disc && !((pw - b.center).squaredNorm() <= b.radius * b.radius)) continue;
      if (b.shape == FluidBlockDef::Shape::Polygon && !FluidBlockDef::insideRow(crossings, pw.x())) continue;
      const Vec2 p = Vec2(Real(pw.x() - origin.x()), Real(pw.y() - origin.y()));
      if (nearMovingSamples(p) && !insideMoving(p)) continue;  // on a moving body's samples: left out, no warning
      if (onStaticSurface(p)) continue;  // within the clearance of a static solid: left out, no warning
      if (boundary.insideDepth(p) > 0 || insideMoving(p)) {
        dlo = dropped ? dlo.cwiseMin(pw) : pw;
        dhi = dropped ? dhi.cwiseMax(pw) : pw;
        ++dropped;
        continue;
      }
      if (P.size() >= sources.budget) {
        refused = true;
        break;
      }
      const Vec2d vel = b.velocityAt(pw);
      P.push(p, Vec2(Real(vel.x()), Real(vel.y())), nextId++, rho0);
      ++added;
    }
  }
  if (dropped) {
    std::ostringstream o;
    o << "dropped " << dropped << " particles that the scene placed inside solids, in the box [" << dlo.x() << ", "
      << dlo.y() << "] – [" << dhi.x() << ", " << dhi.y() << "]";
    warnings.push_back(o.str());
  }
  if (refused) {
    const double lattice = disc ? 3.14159265358979323846 * b.radius * b.radius / (sd.spacing * sd.spacing) : nxd * nyd;
    std::ostringstream o;
    o << "particle budget of " << sources.budget << " (" << budgetKey() << ") reached: added " << added << " of the "
      << (disc ? "drop" : "block") << "'s about " << lattice << " and refused the rest (raise " << budgetKey()
      << " or add less)";
    warnings.push_back(o.str());
  }
  setMaterial(before, b.material);
  index.noteEdit();
  refreshView();
  ids.count = added;
  return ids;
}

bool World::Impl::onStaticSurface(const Vec2& p) const {
  if (boundary.insideDepth(p) > 0) return false;  // inside: dropped, with the warning
  Vec2 q = p, v(0, 0);
  return boundary.resolve(q, v, p, Real(0.4) * dx);  // true when it would be pushed off a surface
}

const char* World::Impl::budgetKey() const {
  return scene.effects.budget > 0 ? "effects.budget.max_particles" : "max_particles";
}

void World::Impl::removeFlagged(RemovalReason reason, std::vector<std::uint32_t>* ids) {
  if (destructionListener) {  // slot order, then the removal's ids increasing
    const std::size_t first = removals.size();
    for (std::size_t i = 0; i < P.size(); ++i)
      if (sources.dead[i]) removals.push_back(Removal{P.id[i], reason});
    std::sort(removals.begin() + std::ptrdiff_t(first), removals.end(),
              [](const Removal& a, const Removal& b) { return a.id < b.id; });
  }
  if (ids) {
    ids->clear();
    for (std::size_t i = 0; i < P.size(); ++i)
      if (sources.dead[i]) ids->push_back(P.id[i]);
    std::sort(ids->begin(), ids->end());
  }
  sources.removed += P.compact(sources.dead);
  index.noteEdit();
  refreshView();
}

/// Removes the k particles with the smallest ids (the oldest).
void World::Impl::removeOldest(std::size_t k) {
  if (k == 0 || P.size() == 0) return;
  k = std::min(k, P.size());
  std::vector<std::uint32_t> ids(P.id);
  std::nth_element(ids.begin(), ids.begin() + std::ptrdiff_t(k - 1), ids.end());  // ids are unique: no ties
  const std::uint32_t cut = ids[k - 1];
  sources.dead.assign(P.size(), 0);
  for (std::size_t i = 0; i < P.size(); ++i) sources.dead[i] = P.id[i] <= cut;
  removeFlagged(RemovalReason::budget);
}

std::string ParticleSources::problem(const EmitterDef& d) {
  auto finite = [](const Vec2d& v) { return std::isfinite(v.x()) && std::isfinite(v.y()); };
  auto in = [](double v, double lo, double hi) { return v >= lo && v <= hi; };  // false for NaN
  std::ostringstream o;
  using E = EmitterDef;  // the scene format's ranges
  if (!finite(d.position))
    o << "position must be finite";
  else if (!finite(d.direction) || !(d.direction.norm() > 1e-12))
    o << "direction must be finite and not zero";
  else if (!in(d.width, 0, E::kMaxWidth))
    o << "width must be in 0.." << E::kMaxWidth << " m, got " << d.width;
  else if (!in(d.rate, 0, E::kMaxRate))
    o << "rate must be in 0.." << E::kMaxRate << " per s, got " << d.rate;
  else if (!in(d.speed, 0, E::kMaxSpeed))
    o << "speed must be in 0.." << E::kMaxSpeed << " m/s, got " << d.speed;
  else if (!in(d.spread, 0, E::kMaxSpread))
    o << "spread must be in 0.." << E::kMaxSpread << " rad, got " << d.spread;
  else if (!in(d.jitter, 0, E::kMaxJitter))
    o << "jitter must be in 0.." << E::kMaxJitter << ", got " << d.jitter;
  else if (!in(d.start, 0, E::kMaxStart))
    o << "start must be in 0.." << E::kMaxStart << " s, got " << d.start;
  else if (!in(d.stop, 0, E::kMaxStop))
    o << "stop must be in 0.." << E::kMaxStop << " s, got " << d.stop;
  else if (d.stop < d.start)
    o << "stop must not be before start";
  else if (d.seed > E::kMaxSeed)
    o << "seed must be at most 2^53";
  return o.str();
}

void World::Impl::emit(Real dt) {
  const Real rho0 = Real(scene.solver.restDensity);
  // With emitter tracking on, each particle made here takes 1 + its emitter's index. (A field in
  // a deque: removeOldest below compacts it, and the pointer stays good.)
  std::vector<std::uint32_t>* tag = P.findU32(ParticleStore::kEmitter);
  std::vector<std::uint32_t>* material = P.findU32(ParticleStore::kMaterial);  // with more than one
  for (std::size_t e = 0; e < sources.emitters.size(); ++e) {
    ParticleSources::Emitter& s = sources.emitters[e];
    const EmitterDef& d = s.def;
    if (!d.enabled || d.rate <= 0) continue;
    const double tEnd = std::min(time + double(dt), d.stop);
    if (tEnd <= d.start) continue;
    // Emission k happens at start + k/rate; count those before tEnd.
    const auto total = std::uint64_t(std::max(0.0, std::ceil(d.rate * (tEnd - d.start) - 1e-9)));
    const Vec2d dir = d.direction;
    const Vec2d across(-dir.y(), dir.x());
    for (; s.emitted < total; ++s.emitted) {
      const double te = d.start + double(s.emitted) / d.rate;
      // Rows across the nozzle: slot k % perRow, evenly spaced. No random offset across: a
      // pair placed nearer than the spacing is a compression that stores ½c²(Δρ/ρ0)² of
      // energy per unit mass, released as speed; with ±0.1 spacing a stiff fluid's free jet
      // (wcsph, c0 = 500 m/s, 50 m/s) gained 39 % of its energy and single particles 3.2
      // times their specific energy (docs/STABILITY.md). `spread` and `jitter` randomise.
      const std::uint64_t perRow = std::max<std::uint64_t>(1, std::uint64_t(std::llround(d.width / double(dx))));
      const double slot = (double(s.emitted % perRow) + 0.5) / double(perRow) - 0.5;
      const std::uint64_t rngBefore = s.rng;
      const double uSpread = uniform(s.rng), uSpeed = uniform(s.rng);
      const double ang = (uSpread - 0.5) * d.spread;
      const Vec2d vdir(dir.x() * std::cos(ang) - dir.y() * std::sin(ang),
                       dir.x() * std::sin(ang) + dir.y() * std::cos(ang));
      const double speed = d.speed * (1.0 + d.jitter * (2.0 * uSpeed - 1.0));
      const Vec2d vel = vdir * speed;
      // Placed where a particle emitted at te would be at the substep start,
      // so that the stream is continuous after this substep's integration: upstream of
      // the nozzle by up to speed × substep for a particle due within the substep (the
      // substep is short enough for the emitters' speed: World::Impl::sourceSpeed), and
      // downstream for one that is late. A particle due within the substep whose way back
      // to that point crosses a solid waits for a later substep (its point upstream is then
      // nearer); one that is late starts at the nozzle. All of them at the nozzle would stack
      // one substep's particles on one point, and their pressure shot them out faster than
      // the jet (a 50 m/s jet 0.3 m under a lid: 5.8 times its specific energy, dfsph).
      const Vec2d nozzle = d.position + across * (slot * d.width);
      Vec2d pw = nozzle + vel * (time - te);
      const Vec2 a = Vec2(Real(nozzle.x() - origin.x()), Real(nozzle.y() - origin.y()));
      const Vec2 b = Vec2(Real(pw.x() - origin.x()), Real(pw.y() - origin.y()));
      if (!(pw == nozzle) && boundary.blocks(a, b)) {
        if (te > time) {
          s.rng = rngBefore;  // drawn again, the same, when it is emitted
          break;
        }
        pw = nozzle;
      }
      if (P.size() >= sources.budget) {
        if (scene.effects.budgetPolicy == BudgetPolicy::RecycleOldest) {
          removeOldest(P.size() - sources.budget + 1);
        } else {
          if (!s.warnedBudget) {
            std::ostringstream o;
            o << "particle budget " << sources.budget << " reached at t = " << time << " s: emitter " << e
              << " pauses until particles leave (policy stop_emitting)";
            warnings.push_back(o.str());
            s.warnedBudget = true;
          }
          s.emitted = total;  // the missed particles are not owed later
          break;
        }
      }
      P.push(Vec2(Real(pw.x() - origin.x()), Real(pw.y() - origin.y())), Vec2(Real(vel.x()), Real(vel.y())), nextId++,
             rho0);
      if (tag) tag->back() = std::uint32_t(e + 1);
      if (material) {
        material->back() = d.material;
        initMaterialFields(P.size() - 1);
      }
    }
  }
}

void World::Impl::lifetimes(Real dt) {
  std::vector<Real>& age = P.field("age");
  const Real maxAge = Real(scene.effects.maxAge);
  sources.dead.assign(P.size(), 0);
  bool any = false;
  for (std::size_t i = 0; i < P.size(); ++i) {
    age[i] += dt;
    sources.dead[i] = age[i] > maxAge;
    any = any || sources.dead[i];
  }
  if (any) removeFlagged(RemovalReason::lifetime);
}

void World::Impl::sinks() {
  sources.dead.assign(P.size(), 0);
  bool any = false;
  for (std::size_t i = 0; i < P.size(); ++i) {
    const Vec2d w = Vec2d(P.x[i].x(), P.x[i].y()) + origin;
    for (const RegionDef& r : scene.effects.sinks) sources.dead[i] = sources.dead[i] || r.contains(w);
    any = any || sources.dead[i];
  }
  if (any) removeFlagged(RemovalReason::sink);
}

void World::Impl::particleLifetimes(double t1) {
  const std::vector<double>& end = *P.findD(ParticleStore::kLifeEnd);
  sources.dead.assign(P.size(), 0);
  bool any = false;
  for (std::size_t i = 0; i < P.size(); ++i) {
    sources.dead[i] = end[i] > 0 && end[i] <= t1;  // 0: none of its own
    any = any || sources.dead[i];
  }
  if (any) removeFlagged(RemovalReason::lifetime);
}

void World::Impl::deliverRemovals() {
  if (removals.empty() || !destructionListener) return;
  std::vector<Removal> batch;
  batch.swap(removals);
  // A copy: the listener may replace or clear itself while it runs.
  const DestructionListener listener = destructionListener;
  listener(batch);
}

}  // namespace sph2d
