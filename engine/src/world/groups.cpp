// groups.cpp — particle groups (sph2d/groups.hpp): made from a region of new particles, each
// particle holding its group, its place in the rest shape and the stiffness (fields, so that
// reordering, removal and save/load keep them); the groups stage matches each group's shape
// (Müller, Heidelberger, Teschner & Gross 2005) after the solver and the collisions: the
// best-fit rotation of the rest shape about the centre of mass (2D: the angle of
// Σ m r q̃ᵀ's rotational part), each particle a share `stiffness` of the way to its place there
// and its velocity with it; a rigid group (stiffness 1) takes the rigid motion of its
// particles' momentum and angular momentum (both kept). Sums in double, in slot order: the
// same bits for any thread count.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "world/world_impl.hpp"

namespace sph2d {

void World::Impl::groupSums(std::vector<GroupSums>& sums) const {
  const std::vector<std::uint32_t>& group = *P.findU32(ParticleStore::kGroup);
  const std::vector<Real>& qx = *P.find(ParticleStore::kGroupQx);
  const std::vector<Real>& qy = *P.find(ParticleStore::kGroupQy);
  const std::vector<Real>* ratio = P.find(ParticleStore::kRestRatio);
  std::uint32_t count = 0;
  for (const std::uint32_t g : group) count = std::max(count, g);
  sums.assign(count, GroupSums{});
  auto massOf = [&](std::size_t i) { return double(mass) * (ratio ? double((*ratio)[i]) : 1.0); };
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (!group[i]) continue;
    GroupSums& s = sums[group[i] - 1];
    const double m = massOf(i);
    s.m += m;
    s.mx += m * double(P.x[i].x());
    s.my += m * double(P.x[i].y());
    s.mvx += m * double(P.v[i].x());
    s.mvy += m * double(P.v[i].y());
    s.mqx += m * double(qx[i]);
    s.mqy += m * double(qy[i]);
    ++s.n;
  }
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (!group[i]) continue;
    GroupSums& s = sums[group[i] - 1];
    const double m = massOf(i);
    const double rx = double(P.x[i].x()) - s.mx / s.m, ry = double(P.x[i].y()) - s.my / s.m;
    const double ux = double(qx[i]) - s.mqx / s.m, uy = double(qy[i]) - s.mqy / s.m;
    const double vx = double(P.v[i].x()) - s.mvx / s.m, vy = double(P.v[i].y()) - s.mvy / s.m;
    s.a00 += m * rx * ux;
    s.a01 += m * rx * uy;
    s.a10 += m * ry * ux;
    s.a11 += m * ry * uy;
    s.L += m * (rx * vy - ry * vx);
    s.I += m * (rx * rx + ry * ry);
  }
}

void World::Impl::matchGroups(StepContext& c) {
  const Real dt = c.dt;
  std::vector<GroupSums>& sums = groupScratch;
  groupSums(sums);
  const std::vector<std::uint32_t>& group = *P.findU32(ParticleStore::kGroup);
  const std::vector<Real>& qx = *P.find(ParticleStore::kGroupQx);
  const std::vector<Real>& qy = *P.find(ParticleStore::kGroupQy);
  const std::vector<Real>& stiffness = *P.find(ParticleStore::kGroupStiffness);
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (!group[i]) continue;
    const GroupSums& s = sums[group[i] - 1];
    const double cx = s.mx / s.m, cy = s.my / s.m;
    const double theta = std::atan2(s.a10 - s.a01, s.a00 + s.a11), cs = std::cos(theta), sn = std::sin(theta);
    const double ux = double(qx[i]) - s.mqx / s.m, uy = double(qy[i]) - s.mqy / s.m;
    const double gx = cx + cs * ux - sn * uy, gy = cy + sn * ux + cs * uy;  // its place in the matched shape
    const double k = double(stiffness[i]);
    if (k >= 1) {  // rigid: the place, and the rigid motion of the group's momentum
      const double omega = s.I > 0 ? s.L / s.I : 0;
      P.x[i] = Vec2(Real(gx), Real(gy));
      P.v[i] = Vec2(Real(s.mvx / s.m - omega * (gy - cy)), Real(s.mvy / s.m + omega * (gx - cx)));
    } else {  // elastic: a share of the way, the velocity with it
      const Vec2 d(Real(k * (gx - double(P.x[i].x()))), Real(k * (gy - double(P.x[i].y()))));
      P.x[i] += d;
      P.v[i] += d / dt;
    }
  }
  if (c.boundary.colliders.empty()) return;
  // The static solids: an elastic group's particles leave them one by one (as the collide
  // stage moves fluid); a rigid group as one, by the largest push each way along each axis,
  // its velocity into the solid stopped (a contact without bounce).
  std::vector<double>& push = groupPush;  // per group: +x, −x, +y, −y
  push.assign(4 * sums.size(), 0.0);
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (!group[i] || c.boundary.clearOf(P.x[i], P.xPrev[i], c.clearance)) continue;
    if (stiffness[i] < 1) {
      c.boundary.resolve(P.x[i], P.v[i], P.xPrev[i], c.clearance);
      continue;
    }
    Vec2 x = P.x[i], v = P.v[i];
    if (!c.boundary.resolve(x, v, P.xPrev[i], c.clearance)) continue;
    const double dxp = double(x.x()) - double(P.x[i].x()), dyp = double(x.y()) - double(P.x[i].y());
    double* p = &push[4 * (group[i] - 1)];
    p[0] = std::max(p[0], dxp);
    p[1] = std::min(p[1], dxp);
    p[2] = std::max(p[2], dyp);
    p[3] = std::min(p[3], dyp);
  }
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (!group[i] || stiffness[i] < 1) continue;
    const double* p = &push[4 * (group[i] - 1)];
    const double sx = p[0] + p[1], sy = p[2] + p[3];
    if (sx == 0 && sy == 0) continue;
    const GroupSums& s = sums[group[i] - 1];
    const double vx = s.mvx / s.m, vy = s.mvy / s.m;
    const double stopX = (sx > 0 && vx < 0) || (sx < 0 && vx > 0) ? -vx : 0;
    const double stopY = (sy > 0 && vy < 0) || (sy < 0 && vy > 0) ? -vy : 0;
    P.x[i] += Vec2(Real(sx), Real(sy));
    P.v[i] += Vec2(Real(stopX), Real(stopY));
  }
}

std::uint32_t World::createGroup(const GroupDef& def, IdRange* ids) {
  if (!(def.stiffness > 0 && def.stiffness <= 1))
    throw std::invalid_argument("createGroup: stiffness must be in (0, 1] (1: rigid), got " +
                                std::to_string(def.stiffness));
  Impl& w = *impl_;
  const IdRange added = w.fillNamed(def.region, "createGroup");
  if (added.size() == 0)
    throw std::invalid_argument(
        "createGroup: the region makes no particle (outside the fluid's space, "
        "inside solids or past the budget)");
  const bool had = w.P.findU32(ParticleStore::kGroup) != nullptr;
  std::vector<std::uint32_t>& group = w.P.fieldU32(ParticleStore::kGroup);
  std::vector<Real>& qx = w.P.field(ParticleStore::kGroupQx);
  std::vector<Real>& qy = w.P.field(ParticleStore::kGroupQy);
  std::vector<Real>& k = w.P.field(ParticleStore::kGroupStiffness);
  std::uint32_t index = 0;  // the next group: one past the highest a particle holds
  for (const std::uint32_t g : group) index = std::max(index, g);
  const std::vector<std::uint32_t> newIds = added.ids();
  std::vector<std::size_t> slots;
  w.index.forEachId(w.P, newIds, [&](std::size_t, std::size_t i) {
    slots.push_back(i);
    return true;
  });
  std::sort(slots.begin(), slots.end());
  double cx = 0, cy = 0;  // the rest shape about its centre (the new particles: one material)
  for (const std::size_t i : slots) cx += double(w.P.x[i].x()), cy += double(w.P.x[i].y());
  cx /= double(slots.size());
  cy /= double(slots.size());
  for (const std::size_t i : slots) {
    group[i] = index + 1;
    qx[i] = Real(double(w.P.x[i].x()) - cx);
    qy[i] = Real(double(w.P.x[i].y()) - cy);
    k[i] = Real(def.stiffness);
  }
  w.refreshView();
  if (!had) w.buildStages();
  if (ids) *ids = added;
  return index;
}

bool World::groupState(std::uint32_t g, GroupState& state) const {
  const Impl& w = *impl_;
  if (!w.P.findU32(ParticleStore::kGroup)) return false;
  std::vector<Impl::GroupSums> sums;
  w.groupSums(sums);
  if (g >= sums.size() || sums[g].n == 0) return false;
  const Impl::GroupSums& s = sums[g];
  state.centre = Vec2d(s.mx / s.m, s.my / s.m) + w.origin;
  state.angle = std::atan2(s.a10 - s.a01, s.a00 + s.a11);
  state.velocity = Vec2d(s.mvx / s.m, s.mvy / s.m);
  state.angularVelocity = s.I > 0 ? s.L / s.I : 0;
  state.mass = s.m;
  state.particles = s.n;
  return true;
}

bool World::applyGroupImpulse(std::uint32_t g, const Vec2d& linear, double angular) {
  Impl& w = *impl_;
  if (!w.P.findU32(ParticleStore::kGroup)) return false;
  std::vector<Impl::GroupSums> sums;
  w.groupSums(sums);
  if (g >= sums.size() || sums[g].n == 0) return false;
  const Impl::GroupSums& s = sums[g];
  const std::vector<std::uint32_t>& group = *w.P.findU32(ParticleStore::kGroup);
  const double cx = s.mx / s.m, cy = s.my / s.m, dw = s.I > 0 ? angular / s.I : 0;
  for (std::size_t i = 0; i < w.P.size(); ++i) {
    if (group[i] != g + 1) continue;
    const double rx = double(w.P.x[i].x()) - cx, ry = double(w.P.x[i].y()) - cy;
    w.P.v[i] += Vec2(Real(linear.x() / s.m - dw * ry), Real(linear.y() / s.m + dw * rx));
  }
  return true;
}

}  // namespace sph2d
