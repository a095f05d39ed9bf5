// What readers ask of a World's state: searches by region, field samples,
// the state hash, density and energy statistics, memory, and the names of
// the fields, effects and stages.
#include <cmath>

#include "sph2d/hash.hpp"
#include "world_impl.hpp"

namespace sph2d {

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

std::size_t World::neighbourPairs() const { return impl_->nbr.pairs(); }

std::vector<std::string> World::particleFields() const {
  std::vector<std::string> f;
  impl_->P.forEachField([&](const char* name, const auto&) { f.push_back(name); });
  return f;
}

std::vector<std::string> World::effects() const {
  std::vector<std::string> out;
  for (const auto& e : impl_->effects) out.push_back(e->name());
  return out;
}

std::vector<std::string> World::stages() const {
  std::vector<std::string> s;
  for (const Stage& st : impl_->stages.stages()) s.push_back(st.name);
  return s;
}

std::vector<StageTiming> World::timings() const { return impl_->stages.timings(); }

void World::resetTimings() { impl_->stages.resetTimings(); }

SolverStats World::solverStats() const { return impl_->solver->stats(); }

std::uint64_t World::solverIterations() const { return impl_->iterations; }

std::size_t World::memoryBytes() const {
  const Impl& w = *impl_;
  auto cap = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  std::size_t b = w.P.bytes();
  b += cap(w.grid.cellStart) + cap(w.grid.sorted) + cap(w.grid.cellOf) + cap(w.grid.scratch_);
  b += cap(w.nbr.start) + cap(w.nbr.count) + cap(w.nbr.boundaryStart) + cap(w.nbr.boundaryCount);
  for (const auto& v : w.nbr.perBlock) b += cap(v);
  for (const auto& v : w.nbr.boundaryPerBlock) b += cap(v);
  b += cap(w.scratch.v) + cap(w.scratch.r) + cap(w.scratch.u);
  b += cap(w.boundary.samples) + cap(w.boundary.volume) + cap(w.boundary.sideNormal) + cap(w.boundary.sideOffset);
  b += cap(w.idIndex);  // only once a game looked a particle up by id
  return b;
}

}  // namespace sph2d
