// foam.cpp — foam, spray and bubbles (sph2d/foam.hpp has the method, world/foam.hpp the class).
#include "world/foam.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/constants.hpp"
#include "particles/particle_store.hpp"

namespace sph2d {
namespace {

// A diffuse particle's kind by the liquid particles within R of it, as shares of a full
// neighbourhood's count (π R²/dx² on a square lattice): the paper's 6 and 20 of a 3D
// neighbourhood of about 30 (spray where the liquid is a few drops, bubbles deep inside).
constexpr Real kSprayShare = Real(0.2), kBubbleShare = Real(0.6);
// A liquid particle is on the surface when its neighbours' directions, W̃-weighted, are lopsided
// by more than this share of their weight (0 in the bulk, about 0.4 on a flat surface).
constexpr Real kSurfaceShare = Real(0.25);
// The wave crest counts only where the surface moves outward: v̂·n̂ at least this (the paper's).
constexpr Real kCrestDirection = Real(0.6);

/// Uniform in [0, 1) from a key: splitmix64's finaliser (the same bits on every machine).
Real uniform(std::uint64_t key) {
  key += 0x9E3779B97F4A7C15ull;
  key = (key ^ (key >> 30)) * 0xBF58476D1CE4E5B9ull;
  key = (key ^ (key >> 27)) * 0x94D049BB133111EBull;
  key ^= key >> 31;
  return Real(double(key >> 11) * (1.0 / 9007199254740992.0));
}

/// (min(I, hi) − min(I, lo)) / (hi − lo): 0 below lo, 1 above hi (in double: the scene's
/// bounds differ in double, not always in float).
double clampedPotential(double v, const Vec2d& range) {
  const double lo = range.x(), hi = range.y();
  return (std::min(v, hi) - std::min(v, lo)) / (hi - lo);
}

}  // namespace

bool FoamSystem::liquid(const std::vector<std::uint32_t>* group, const std::vector<std::uint32_t>* material,
                        std::size_t i) const {
  if (group && (*group)[i]) return false;
  const std::uint32_t m = material ? (*material)[i] : 0u;  // one material: no field, material 0
  return !(m < granular_.size() && granular_[m]);
}

void FoamSystem::clear() {
  x_.clear();
  v_.clear();
  age_.clear();
  life_.clear();
  kind_.clear();
}

void FoamSystem::step(StepContext& c) {
  advance(c);
  shed(c);
}

void FoamSystem::advance(StepContext& c) {
  const std::size_t n = x_.size();
  if (n == 0) return;
  const ParticleStore& P = c.P;
  const Real R = c.R, R2 = R * R, invR = Real(1) / R, dt = c.dt;
  const Real full = Real(kPi<double> * double(R2) / double(c.dx * c.dx));
  const Vec2 g = c.gravity;
  const Real buoyancy = Real(def_.buoyancy), dragStep = std::min(Real(1), Real(def_.drag) * dt);
  const std::vector<std::uint32_t>* group = P.findU32(ParticleStore::kGroup);
  const std::vector<std::uint32_t>* material = P.findU32(ParticleStore::kMaterial);
  alive_.assign(n, 0);
  // Each diffuse particle from the liquid around it alone (a gather): any thread count.
  c.pool.parallelFor(n, kBlock, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      const Vec2 p = x_[k];
      Real w = 0, count = 0;
      Vec2 vf = Vec2::Zero();
      c.grid.forCandidates(p, [&](std::uint32_t j) {
        if (!liquid(group, material, j)) return;  // grains and groups are no water to be in
        Real dx = p.x() - P.x[j].x(), dy = p.y() - P.x[j].y();
        c.periodic.nearest(dx, dy);
        const Real r2 = dx * dx + dy * dy;
        if (r2 >= R2) return;
        const Real wt = Real(1) - std::sqrt(r2) * invR;
        w += wt;
        vf += wt * P.v[j];
        count += 1;
      });
      if (w > 0) vf /= w;
      DiffuseKind kind = count < kSprayShare * full    ? DiffuseKind::Spray
                         : count > kBubbleShare * full ? DiffuseKind::Bubble
                                                       : DiffuseKind::Foam;
      Vec2 v = v_[k];
      if (kind == DiffuseKind::Spray)
        v += g * dt;  // ballistic
      else if (kind == DiffuseKind::Foam)
        v = vf;  // carried by the liquid
      else
        v += -buoyancy * g * dt + (vf - v) * dragStep;  // pushed up, dragged along
      Vec2 x = p + v * dt;
      Real age = age_[k] + dt;
      bool alive = age < life_[k] && allFinite(x) && allFinite(v);
      if (alive && !c.boundary.clearOf(x, p, c.clearance)) {
        Vec2 vc = v;
        alive = !c.boundary.resolve(x, vc, p, c.clearance);  // it met a solid: gone
      }
      if (alive) c.periodic.wrap(x);
      x_[k] = x;
      v_[k] = v;
      age_[k] = age;
      kind_[k] = kind;
      alive_[k] = alive ? 1 : 0;
    }
  });
  // The living keep their order.
  std::size_t m = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (!alive_[k]) continue;
    if (m != k) {
      x_[m] = x_[k];
      v_[m] = v_[k];
      age_[m] = age_[k];
      life_[m] = life_[k];
      kind_[m] = kind_[k];
    }
    ++m;
  }
  x_.resize(m);
  v_.resize(m);
  age_.resize(m);
  life_.resize(m);
  kind_.resize(m);
}

void FoamSystem::shed(StepContext& c) {
  const ParticleStore& P = c.P;
  const std::size_t n = P.size();
  if (n == 0 || !(def_.rate > 0)) return;
  const Real R = c.R, R2 = R * R, invR = Real(1) / R, dt = c.dt;
  const std::vector<std::uint32_t>* group = P.findU32(ParticleStore::kGroup);
  const std::vector<std::uint32_t>* material = P.findU32(ParticleStore::kMaterial);
  auto pairs = [&](std::size_t i, auto&& f) {
    const std::uint32_t* nb = c.nbr.of(i);
    for (std::uint32_t k = 0; k < c.nbr.count[i]; ++k) {
      const std::uint32_t j = nb[k];
      if (!liquid(group, material, j)) continue;  // grains and groups are not the liquid's surface or flow
      Real dx = P.x[i].x() - P.x[j].x(), dy = P.x[i].y() - P.x[j].y();
      c.periodic.nearest(dx, dy);
      const Real r2 = dx * dx + dy * dy;
      if (r2 >= R2 || r2 <= 0) continue;
      const Real r = std::sqrt(r2);
      f(j, Vec2(dx, dy) / r, Real(1) - r * invR);
    }
  };
  // The surface normals: the W̃-weighted mean direction away from the neighbours, where lopsided.
  normal_.resize(n);
  c.pool.parallelFor(n, kBlock, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      Vec2 s = Vec2::Zero();
      Real w = 0;
      pairs(i, [&](std::uint32_t, const Vec2& xhat, Real wt) {
        s += wt * xhat;
        w += wt;
      });
      const Real len = s.norm();
      normal_[i] = w > 0 && len > kSurfaceShare * w ? Vec2(s / len) : Vec2(Vec2::Zero());
    }
  });
  // How many each sheds: the potentials, the expected count, rounded by a hash of id and time.
  std::uint64_t timeBits = 0;
  static_assert(sizeof(c.time) == sizeof(timeBits), "the time is a double");
  std::memcpy(&timeBits, &c.time, sizeof timeBits);
  count_.resize(n);
  const FoamDef& d = def_;
  c.pool.parallelFor(n, kBlock, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      count_[i] = 0;
      if (!liquid(group, material, i)) continue;
      const Vec2 vi = P.v[i];
      const double energy = clampedPotential(0.5 * double(vi.squaredNorm()), d.energy);
      if (energy <= 0) continue;
      const Vec2 ni = normal_[i];
      const Real speed = vi.norm();
      const bool outward = ni.squaredNorm() > 0 && speed > 0 && vi.dot(ni) >= kCrestDirection * speed;
      Real trapped = 0, crest = 0;
      pairs(i, [&](std::uint32_t j, const Vec2& xhat, Real wt) {
        const Vec2 vij = vi - P.v[j];
        const Real vn = vij.norm();
        if (vn > 0) trapped += vn * (Real(1) - vij.dot(xhat) / vn) * wt;
        // κ̃ over the surface particles behind i's surface (0 along a flat one, the more its
        // normals fan out the larger); particles inside have no normal and do not count.
        if (outward && xhat.dot(ni) > 0 && normal_[j].squaredNorm() > 0) crest += (Real(1) - ni.dot(normal_[j])) * wt;
      });
      double expected =
          energy * d.rate * (clampedPotential(trapped, d.trappedAir) + clampedPotential(crest, d.waveCrest)) * dt;
      if (!std::isfinite(expected)) expected = 0;
      const std::uint64_t key = (std::uint64_t(P.id[i]) << 32) ^ timeBits;
      count_[i] = std::uint32_t(std::min(1e6, std::floor(expected + double(uniform(key)))));
    }
  });
  // Where each one's go, in slot order. Beyond the largest number every count is scaled down
  // alike (the room shared over the whole liquid, not given to its first slots).
  std::uint64_t wanted = 0;
  for (std::size_t i = 0; i < n; ++i) wanted += count_[i];
  const std::uint64_t room = def_.maxParticles > x_.size() ? def_.maxParticles - x_.size() : 0;
  if (wanted > room) {  // rounded by each particle's hash (counts are mostly 0 or 1), then clamped
    const double share = double(room) / double(wanted);
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint64_t key = ((std::uint64_t(P.id[i]) << 32) ^ timeBits) ^ 5;
      count_[i] = std::uint32_t(std::floor(double(count_[i]) * share + double(uniform(key))));
    }
  }
  offset_.resize(n);
  std::uint64_t total = x_.size();
  for (std::size_t i = 0; i < n; ++i) {
    offset_[i] = total;
    count_[i] = std::uint32_t(std::min<std::uint64_t>(count_[i], room - std::min(room, total - x_.size())));
    total += count_[i];
  }
  if (total == x_.size()) return;
  x_.resize(total);
  v_.resize(total);
  age_.resize(total);
  life_.resize(total);
  kind_.resize(total);
  const Real half = Real(0.5) * c.dx;
  const Real lo = Real(d.lifetime.x()), span = Real(d.lifetime.y() - d.lifetime.x());
  c.pool.parallelFor(n, kBlock, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      for (std::uint32_t k = 0; k < count_[i]; ++k) {
        const std::uint64_t key = (std::uint64_t(P.id[i]) << 32) ^ timeBits ^ (std::uint64_t(k + 1) * 0x9E3779B1ull);
        const Real a = Real(2 * kPi<double>) * uniform(key ^ 1), r = half * std::sqrt(uniform(key ^ 2));
        const std::size_t s = std::size_t(offset_[i]) + k;
        // Within half a spacing of it, somewhere along its path in the substep.
        Vec2 at = P.x[i] - P.v[i] * (dt * uniform(key ^ 3)) + r * Vec2(std::cos(a), std::sin(a));
        c.periodic.wrap(at);
        x_[s] = at;
        v_[s] = P.v[i];
        age_[s] = 0;
        life_[s] = lo + span * uniform(key ^ 4);
        kind_[s] = DiffuseKind::Foam;
      }
    }
  });
}

}  // namespace sph2d
