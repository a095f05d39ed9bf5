// The World's particle system (the particle-system seed: emitters,
// lifetimes, forces, integration): fluid blocks and drops on the lattice of
// the spacing, seeded emitters, lifetimes, sinks and the particle budget.
// Removal keeps the order of the remaining particles (Particles::compact), and
// emitters draw from their own SplitMix64 stream, so a run is deterministic.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "world_impl.hpp"

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
/// `keep` (optional) selects lattice points by world position (addDrop's disc).
std::size_t World::Impl::fillBlock(const FluidBlockDef& b, bool hydrostaticStart,
                                   const std::function<bool(const Vec2d&)>& keep) {
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

void World::Impl::removeFlagged() { removed += P.compact(dead); }

/// Removes the k particles with the smallest ids (the oldest).
void World::Impl::removeOldest(std::size_t k) {
  if (k == 0 || P.size() == 0) return;
  k = std::min(k, P.size());
  std::vector<std::uint32_t> ids(P.id);
  std::nth_element(ids.begin(), ids.begin() + std::ptrdiff_t(k - 1), ids.end());  // ids are unique: no ties
  const std::uint32_t cut = ids[k - 1];
  dead.assign(P.size(), 0);
  for (std::size_t i = 0; i < P.size(); ++i) dead[i] = P.id[i] <= cut;
  removeFlagged();
}

void World::Impl::emit(Real dt) {
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

void World::Impl::lifetimes(Real dt) {
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

void World::Impl::sinks() {
  dead.assign(P.size(), 0);
  bool any = false;
  for (std::size_t i = 0; i < P.size(); ++i) {
    const Vec2d w = Vec2d(P.x[i].x(), P.x[i].y()) + origin;
    for (const RegionDef& r : scene.effects.sinks) dead[i] = dead[i] || r.contains(w);
    any = any || dead[i];
  }
  if (any) removeFlagged();
}

}  // namespace sph2d
