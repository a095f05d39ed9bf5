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
#include <sstream>
#include <stdexcept>

#include "world/world_impl.hpp"

namespace sph2d {
namespace {

/// An elastic group's internal damping [1/s]: the rate at which its particles' velocity
/// relative to the group's rigid motion decays (a jelly's own viscosity).
constexpr double kElasticDamping = 4;

/// The farthest a plastic particle's place in the rest shape moves in one substep [spacings].
/// A hard landing strains a stiff jelly far past its yield within a substep or two; taken at
/// once, places crossed and nearly met, and the match packed their particles together each
/// substep: a stiffness 0.9 block dropped 0.5 m blew up in the grid projection, and dented ones
/// crept along the floor (docs/notes/plastic-jelly-creep.md). At half a spacing a substep the
/// yield is a flow, fast against the motion of a resting jelly and slow against an impact's.
constexpr double kMaxPlasticMove = 0.5;

/// The largest yield or break strain a group takes.
constexpr double kMaxStrain = 10;

/// Union–find over slots: the root of a, halving the path.
std::size_t findRoot(std::vector<std::size_t>& parent, std::size_t a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

}  // namespace

void World::Impl::groupSums(std::vector<GroupSums>& sums) const {
  const std::vector<std::uint32_t>& group = *P.findU32(ParticleStore::kGroup);
  const std::vector<Real>& qx = *P.find(ParticleStore::kGroupQx);
  const std::vector<Real>& qy = *P.find(ParticleStore::kGroupQy);
  const std::vector<Real>* ratio = P.find(ParticleStore::kRestRatio);
  std::uint32_t count = 0;
  for (const std::uint32_t g : group) count = std::max(count, g);
  sums.assign(count, GroupSums{});
  auto massOf = [&](std::size_t i) { return double(momentumMass) * (ratio ? double((*ratio)[i]) : 1.0); };
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

void World::Impl::groupsBeforeCollide(const StepContext& c) {
  const std::vector<std::uint32_t>& group = *P.findU32(ParticleStore::kGroup);
  const std::vector<Real>& stiffness = *P.find(ParticleStore::kGroupStiffness);
  groupBefore.resize(P.size());
  c.pool.parallelFor(P.size(), kStreamBlock, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i)
      if (group[i] && stiffness[i] < 1) groupBefore[i] = {P.x[i], P.v[i]};
  });
}

void World::Impl::matchGroups(StepContext& c, bool full) {
  const Real dt = c.dt;
  std::vector<GroupSums>& sums = groupScratch;
  groupSums(sums);
  const std::vector<std::uint32_t>& group = *P.findU32(ParticleStore::kGroup);
  const std::vector<Real>& qx = *P.find(ParticleStore::kGroupQx);
  const std::vector<Real>& qy = *P.find(ParticleStore::kGroupQy);
  const std::vector<Real>& stiffness = *P.find(ParticleStore::kGroupStiffness);
  const std::vector<Real>* yield = P.find(ParticleStore::kGroupYield);
  const Real damp = Real(std::exp(-kElasticDamping * double(dt)));
  // The solver's own corrections of this substep (none in a drift: they are the last full one's).
  const std::vector<Vec2>* own = full && solver->groupCorrections() ? solver->groupMoves() : nullptr;
  if (own && own->size() != P.size()) own = nullptr;
  std::vector<Real>* qxw = P.find(ParticleStore::kGroupQx);  // the rest shape, which plasticity moves
  std::vector<Real>* qyw = P.find(ParticleStore::kGroupQy);
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
      if (full && yield && (*yield)[i] > 0) {
        // Plastic: beyond the yield strain its place in the rest shape takes the excess (rotated
        // back into the rest frame), so the shape it springs back to is the deformed one.
        const double ex = double(P.x[i].x()) - gx, ey = double(P.x[i].y()) - gy, e = std::sqrt(ex * ex + ey * ey);
        const double limit = double((*yield)[i]) * std::max(std::sqrt(ux * ux + uy * uy), double(dx));
        if (e > limit) {
          const double f = std::min(1 - limit / e, kMaxPlasticMove * double(dx) / e), rx = f * (cs * ex + sn * ey),
                       ry = f * (-sn * ex + cs * ey);
          (*qxw)[i] += Real(rx);
          (*qyw)[i] += Real(ry);
        }
      }
      const double pull = full ? k : 0.0;  // a drift: no pull (matchGroups' comment)
      const Vec2 d(Real(pull * (gx - double(P.x[i].x()))), Real(pull * (gy - double(P.x[i].y()))));
      P.x[i] += d;
      // Its velocity takes the shape's pull, d/dt, and the solver's corrections of its position
      // this substep, which a liquid's velocity leaves out: left out, a jelly at rest kept −dt·g
      // of velocity and never read as still. Not the collisions' pushes: they set the velocity
      // themselves (with a body's reaction). The game solver says which moves are its own
      // corrections (not those of its pairs with the liquid: Solver::groupMoves, pbf_groups.cpp).
      if (own)
        P.v[i] += (*own)[i] / dt;
      else if (groupBefore.size() == P.size())
        P.v[i] += (groupBefore[i].x - P.xPrev[i]) / dt - groupBefore[i].v;
      P.v[i] += d / dt;
      // Internal friction: the velocity relative to the group's rigid motion decays at
      // kElasticDamping per second (the rigid motion itself, momentum and spin, is kept).
      const double omega = s.I > 0 ? s.L / s.I : 0;
      const double rx = double(P.x[i].x()) - cx, ry = double(P.x[i].y()) - cy;
      const Vec2 rigid(Real(s.mvx / s.m - omega * ry), Real(s.mvy / s.m + omega * rx));
      P.v[i] = rigid + (P.v[i] - rigid) * damp;
    }
  }
  if (P.find(ParticleStore::kGroupBreak)) breakGroups(c);
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
  if (!(def.yieldStrain >= 0 && def.yieldStrain <= kMaxStrain) ||
      !(def.breakStrain >= 0 && def.breakStrain <= kMaxStrain))
    throw std::invalid_argument("createGroup: yieldStrain and breakStrain must be in 0.." + std::to_string(kMaxStrain) +
                                " (0: none), got " + std::to_string(def.yieldStrain) + " and " +
                                std::to_string(def.breakStrain));
  if (def.stiffness >= 1 && (def.yieldStrain > 0 || def.breakStrain > 0))
    throw std::invalid_argument("createGroup: a rigid group (stiffness 1) neither yields nor breaks");
  Impl& w = *impl_;
  // A pair of rest neighbours (1.5 spacings apart at most) stretched by the break strain must
  // still be within the support R, where the neighbour lists see it.
  const double maxBreak = double(w.R) / (1.5 * double(w.dx)) - 1;
  if (def.breakStrain > maxBreak) {
    std::ostringstream o;
    o.precision(3);
    o << "createGroup: breakStrain must be at most " << maxBreak
      << " for this solver (its support over 1.5 spacings, less 1), got " << def.breakStrain;
    throw std::invalid_argument(o.str());
  }
  const IdRange added = w.fillNamed(def.region, "createGroup");
  if (added.size() == 0)
    throw std::invalid_argument(
        "createGroup: the region makes no particle (outside the fluid's space, "
        "inside solids or past the budget)");
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
  // Yield and break strains: fields only once a group has one (0 in the others: none).
  for (const auto& [name, value] : {std::pair<const char*, double>{ParticleStore::kGroupYield, def.yieldStrain},
                                    {ParticleStore::kGroupBreak, def.breakStrain}}) {
    if (value <= 0 && !w.P.find(name)) continue;
    std::vector<Real>& f = w.P.field(name);
    for (const std::size_t i : slots) f[i] = Real(value);
  }
  if (def.color) {  // drawn in its own colour: the particles' colour field (made now if new)
    std::vector<std::uint32_t>& c = w.P.fieldU32(ParticleStore::kColor);
    for (const std::size_t i : slots) c[i] = def.color & 0xFFFFFFu;
  }
  w.refreshView();
  w.buildStages();  // the groups stage, and the elastic groups' record before the collisions
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

void World::Impl::splitParts(std::uint32_t g, const std::vector<std::size_t>& slots,
                             const std::function<Vec2d(std::size_t)>& place, double reach,
                             const std::function<bool(std::size_t, std::size_t)>& linked,
                             std::vector<std::uint32_t>* made) {
  std::vector<std::uint32_t>& group = *P.findU32(ParticleStore::kGroup);
  std::vector<std::size_t> parent(slots.size());
  for (std::size_t a = 0; a < slots.size(); ++a) parent[a] = a;
  // The candidates: the particles in cells of `reach` at `place`, sorted by cell; each asks the
  // cells around its own for partners of a higher index (each pair once). The parts do not
  // depend on the order of the unions (each root is its part's lowest index).
  struct Entry {
    std::int64_t cy, cx;
    std::size_t a;
    bool operator<(const Entry& o) const { return cy != o.cy ? cy < o.cy : cx != o.cx ? cx < o.cx : a < o.a; }
  };
  std::vector<Entry> cells(slots.size());
  for (std::size_t a = 0; a < slots.size(); ++a) {
    const Vec2d p = place(slots[a]);
    cells[a] = Entry{std::int64_t(std::floor(p.y() / reach)), std::int64_t(std::floor(p.x() / reach)), a};
  }
  std::vector<Entry> sorted = cells;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t a = 0; a < slots.size(); ++a)
    for (std::int64_t dy = -1; dy <= 1; ++dy)
      for (std::int64_t dxc = -1; dxc <= 1; ++dxc) {
        const Entry lo{cells[a].cy + dy, cells[a].cx + dxc, a + 1};
        for (auto it = std::lower_bound(sorted.begin(), sorted.end(), lo);
             it != sorted.end() && it->cy == lo.cy && it->cx == lo.cx; ++it) {
          const std::size_t b = it->a;
          if (!linked(slots[a], slots[b])) continue;
          const std::size_t ra = findRoot(parent, a), rb = findRoot(parent, b);
          if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
        }
      }
  // The parts in order of their lowest slot; the largest (the first of equals) keeps g.
  std::vector<std::size_t> size(slots.size(), 0), roots;
  for (std::size_t a = 0; a < slots.size(); ++a) {
    const std::size_t r = findRoot(parent, a);
    if (size[r]++ == 0) roots.push_back(r);
  }
  if (roots.size() < 2) return;
  std::size_t keep = roots.front();
  for (const std::size_t r : roots)
    if (size[r] > size[keep]) keep = r;
  std::uint32_t next = 0;
  for (const std::uint32_t v : group) next = std::max(next, v);
  std::vector<std::uint32_t> partIndex(slots.size(), g + 1);
  for (const std::size_t r : roots) {
    if (r == keep) continue;
    if (size[r] < kMinGroup) {
      partIndex[r] = 0;  // too few to hold a shape: free fluid
      continue;
    }
    partIndex[r] = ++next;
    if (made) made->push_back(next - 1);
  }
  for (std::size_t a = 0; a < slots.size(); ++a) group[slots[a]] = partIndex[findRoot(parent, a)];
  if (size[keep] < kMinGroup)
    for (std::size_t a = 0; a < slots.size(); ++a)
      if (findRoot(parent, a) == keep) group[slots[a]] = 0;
}

void World::Impl::breakGroups(const StepContext& c) {
  const std::vector<std::uint32_t>& group = *P.findU32(ParticleStore::kGroup);
  const std::vector<Real>& qx = *P.find(ParticleStore::kGroupQx);
  const std::vector<Real>& qy = *P.find(ParticleStore::kGroupQy);
  const std::vector<Real>& strain = *P.find(ParticleStore::kGroupBreak);
  if (c.nbr.count.size() != P.size()) return;  // no neighbour lists of these particles (a drift)
  const double adjacent2 = 1.5 * 1.5 * double(dx) * double(dx);
  auto restDist2 = [&](std::size_t i, std::size_t j) {
    const double ax = double(qx[i]) - double(qx[j]), ay = double(qy[i]) - double(qy[j]);
    return ax * ax + ay * ay;
  };
  // Rest neighbours: at most 1.5 spacings apart in the rest shape (not two particles a join
  // left on one point).
  const double tooClose2 = 0.25 * 0.25 * double(dx) * double(dx);
  auto restAdjacent = [&](std::size_t i, std::size_t j) {
    const double r2 = restDist2(i, j);
    return r2 <= adjacent2 && r2 > tooClose2;
  };
  auto stretched = [&](std::size_t i, std::size_t j) {  // current / rest − 1 beyond the strain
    double d2x = double(P.x[i].x()) - double(P.x[j].x()), d2y = double(P.x[i].y()) - double(P.x[j].y());
    const double ratio = std::sqrt((d2x * d2x + d2y * d2y) / restDist2(i, j));
    return ratio - 1 > double(strain[i]);
  };
  // The breakable groups with a broken pair: rest neighbours in each other's neighbour list
  // (within R: createGroup holds the break strain below R / 1.5 spacings − 1, so a pair
  // stretched that far is still in the list), now stretched beyond the strain. (A pair torn
  // past R within one substep is not seen until another is stretched.)
  std::vector<std::uint32_t> broken;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (!group[i] || !(strain[i] > 0)) continue;
    if (std::find(broken.begin(), broken.end(), group[i]) != broken.end()) continue;
    const std::uint32_t* nb = c.nbr.of(i);
    bool cut = false;
    for (std::uint32_t k = 0; k < c.nbr.count[i] && !cut; ++k) {
      const std::uint32_t j = nb[k];
      if (group[j] == group[i] && restAdjacent(i, j)) cut = stretched(i, j);
    }
    if (cut) broken.push_back(group[i]);
  }
  std::sort(broken.begin(), broken.end());
  for (const std::uint32_t g : broken) {
    std::vector<std::size_t> slots;
    for (std::size_t i = 0; i < P.size(); ++i)
      if (group[i] == g) slots.push_back(i);
    splitParts(
        g - 1, slots, [&](std::size_t i) { return Vec2d(double(qx[i]), double(qy[i])); }, 1.5 * double(dx),
        [&](std::size_t i, std::size_t j) { return restAdjacent(i, j) && !stretched(i, j); });
  }
}

bool World::destroyGroup(std::uint32_t g, bool withParticles) {
  Impl& w = *impl_;
  std::vector<std::uint32_t>* group = w.P.findU32(ParticleStore::kGroup);
  if (!group) return false;
  std::size_t n = 0;
  if (withParticles) w.sources.dead.assign(w.P.size(), 0);
  for (std::size_t i = 0; i < w.P.size(); ++i) {
    if ((*group)[i] != g + 1) continue;
    ++n;
    if (withParticles)
      w.sources.dead[i] = 1;
    else
      (*group)[i] = 0;
  }
  if (n == 0) return false;
  if (withParticles) {
    w.removeFlagged(RemovalReason::game);
    w.deliverRemovals();
  }
  return true;
}

bool World::joinGroups(std::uint32_t into, std::uint32_t from) {
  Impl& w = *impl_;
  std::vector<std::uint32_t>* group = w.P.findU32(ParticleStore::kGroup);
  if (!group || into == from) return false;
  std::vector<std::size_t> slots;
  std::size_t inInto = 0;
  for (std::size_t i = 0; i < w.P.size(); ++i)
    if ((*group)[i] == into + 1 || (*group)[i] == from + 1) {
      slots.push_back(i);
      inInto += (*group)[i] == into + 1;
    }
  if (inInto == 0 || inInto == slots.size()) return false;
  // One group of `into`'s kind whose rest shape is the two as they are now.
  std::size_t first = slots.front();
  for (const std::size_t i : slots)
    if ((*group)[i] == into + 1) {
      first = i;
      break;
    }
  std::vector<Real>& qx = w.P.field(ParticleStore::kGroupQx);
  std::vector<Real>& qy = w.P.field(ParticleStore::kGroupQy);
  std::vector<Real>& k = w.P.field(ParticleStore::kGroupStiffness);
  std::vector<Real>* yield = w.P.find(ParticleStore::kGroupYield);
  std::vector<Real>* brk = w.P.find(ParticleStore::kGroupBreak);
  for (const std::size_t i : slots) {
    (*group)[i] = into + 1;
    qx[i] = w.P.x[i].x();
    qy[i] = w.P.x[i].y();
    k[i] = k[first];
    if (yield) (*yield)[i] = (*yield)[first];
    if (brk) (*brk)[i] = (*brk)[first];
  }
  return true;
}

std::vector<std::uint32_t> World::splitGroup(std::uint32_t g) {
  Impl& w = *impl_;
  std::vector<std::uint32_t> made;
  if (!w.P.findU32(ParticleStore::kGroup)) return made;
  const std::vector<std::uint32_t>& group = *w.P.findU32(ParticleStore::kGroup);
  std::vector<std::size_t> slots;
  for (std::size_t i = 0; i < w.P.size(); ++i)
    if (group[i] == g + 1) slots.push_back(i);
  const double near2 = 1.5 * 1.5 * double(w.dx) * double(w.dx);
  w.splitParts(
      g, slots, [&](std::size_t i) { return w.P.x[i].cast<double>(); }, 1.5 * double(w.dx),
      [&](std::size_t i, std::size_t j) { return (w.P.x[i] - w.P.x[j]).cast<double>().squaredNorm() <= near2; }, &made);
  return made;
}

std::uint32_t World::groupCount() const {
  const std::vector<std::uint32_t>* group = impl_->P.findU32(ParticleStore::kGroup);
  std::uint32_t n = 0;
  if (group)
    for (const std::uint32_t g : *group) n = std::max(n, g);
  return n;
}

}  // namespace sph2d
