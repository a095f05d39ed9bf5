// contacts.cpp — the `contacts` stage: which particles touch which fixture during a step
// (World::setContactTracking), LiquidFun's particle-body contacts gathered at the end of
// every substep rather than only read at the step's end, so that a splash that hit a
// fixture and left it within one step is still reported. A particle touches a fixture when
// its centre lies within one spacing of the surface the fluid meets there, or inside it (as
// World::idsTouching measures now): a static collider, or a moving body's shape at
// its pose at the substep's end. Each block lists its contacts in slot order and the
// blocks are joined in block order: the same list for any thread count.
#include <algorithm>
#include <cmath>

#include "core/constants.hpp"
#include "world/contacts.hpp"
#include "world/world_impl.hpp"

namespace sph2d {

void ContactTracker::record(StepContext& c, const ParticleStore& P, const BoundarySet& boundary,
                            const MovingSolids& moving, Real reach) {
  const std::size_t n = P.size(), blocks = (n + kBlock - 1) / kBlock;
  blocks_.resize(blocks);
  const double tau = c.time - moving.time0 + double(c.dt);  // the moving bodies at the substep's end
  std::vector<Pose>& placed = poses_;                       // kept: no allocation in the step
  placed.resize(moving.bodies.size());
  for (std::size_t k = 0; k < placed.size(); ++k) {
    moving.bodies[k].pose(tau, placed[k].theta, placed[k].o);
    placed[k].centre = moving.bodies[k].centreAt(tau);
  }
  c.pool.parallelFor(n, kBlock, [&](std::size_t b, std::size_t e) {
    auto& out = blocks_[b / kBlock];
    out.clear();
    for (std::size_t i = b; i < e; ++i) {
      const Vec2 x = P.x[i];
      if (!boundary.clearOf(x, x, reach))
        boundary.forCollidersNear(x, reach, [&](std::uint32_t k) {
          if (colliderSeparation(boundary.colliders[k], x) <= reach)
            out.emplace_back(std::uintptr_t(boundary.colliderFixture[k]), P.id[i]);
        });
      for (std::size_t k = 0; k < placed.size(); ++k) {
        const MovingSolid& m = moving.bodies[k];
        const Vec2d p(x.x(), x.y());
        const double r = m.radius + double(reach);
        if ((p - placed[k].centre).squaredNorm() > r * r) continue;
        const double cs = std::cos(placed[k].theta), sn = std::sin(placed[k].theta);
        const Vec2d d = p - placed[k].o, q(cs * d.x() + sn * d.y(), -sn * d.x() + cs * d.y());  // body frame
        for (std::size_t s = 0; s < m.shapes.size(); ++s) {
          Vec2d normal;
          if (outsideCollider(m.shapes[s], q, q, normal) <= double(reach))
            out.emplace_back(std::uintptr_t(m.fixtures[s]), P.id[i]);
        }
      }
    }
  });
  for (std::size_t k = 0; k < blocks; ++k) record_.insert(record_.end(), blocks_[k].begin(), blocks_[k].end());
}

void ContactTracker::finishStep() {
  if (!on_) return;
  std::sort(record_.begin(), record_.end());  // by fixture, then id: each fixture's ids together
  record_.erase(std::unique(record_.begin(), record_.end()), record_.end());
}

void World::setContactTracking(bool on) {
  if (impl_->contacts.setOn(on)) impl_->buildStages();
}

bool World::contactTracking() const { return impl_->contacts.on(); }

}  // namespace sph2d
