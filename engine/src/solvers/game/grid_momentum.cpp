// The coarse-grid projection's momentum balance (grid_projection.hpp): what the transfer gave
// the particles of a fluid region that no wall holds, against what the dynamic bodies it
// touches took.
//
// On a grid of uniform face mass the pressure's changes telescope: within a region of fluid
// cells they sum to the impulse of its closed faces (walls, bodies). The particles take each
// face's change in proportion to their weight on it, and a face a surface or a meeting of two
// blobs fills in part carries less than a full face's mass: the sum no longer telescopes,
// and a blob in free flight, or water meeting a rigid group, a jelly or a dynamic body,
// gained or lost momentum where nothing outside pushed it (docs/notes/free-blob-momentum.md;
// the variable-density projection that would weigh each face by its mass made a resting tank
// flow). A region that meets no wall and no kinematic body has a conservation law: its
// particles' change of momentum plus the dynamic bodies' impulse is zero. For each such
// cluster (regions joined through the dynamic bodies they touch) the transfer's imbalance is
// taken out as one velocity change of the cluster's particles and bodies, the smallest change
// of kinetic energy that restores the balance. Pressure is instantaneous through a connected
// incompressible region, so the correction reaches no further than the pressure did. A
// region a wall holds is left as it is: the wall takes whatever the particles do not; so is a
// cluster with a dynamic body that Box2D holds (a joint, or a static fixture it rests on: a cup resting on
// the floor passed the pressure's push on its bottom to the water it held, 3.3 cm lower). So is
// a cluster with no interior cell (four fluid neighbours): spray of a few particles, all
// surface, whose grid pressure stands for no resolved flow; balanced, clusters of one to six
// particles took shifts of up to 10 m/s in an 80 m/s jet's spray.
#include "bodies/moving_solid.hpp"
#include "solvers/game/grid_projection.hpp"

#include <algorithm>
#include <cmath>

namespace sph2d {

namespace {
constexpr std::uint8_t kHeld = 1;      ///< a cell of the region meets a wall or a kinematic body
constexpr std::uint8_t kResolved = 2;  ///< the region has an interior cell (below)
/// An interior cell: its four neighbours are fluid and it holds at least this share of a full
/// cell's particle weight. A cell is fluid from 0.15 of it (the game preset), so a plus of five
/// fluid cells can stand on a handful of spray particles; half a full cell is water, not spray.
constexpr Real kResolvedFill = Real(0.5);
}  // namespace

bool GridProjection::momentumClusters() {
  // Each region's closed faces: a static solid, a face a wall blocks, a kinematic body
  // (the transfer's walls); a dynamic body joins the regions it touches into one cluster.
  const std::vector<std::int32_t>& regionOf = pcg_.regionOf();
  const std::size_t R = pcg_.regions(), B = bodies_.size();
  std::vector<std::int32_t>& root = clusterRoot_;
  root.resize(R + B);
  for (std::size_t r = 0; r < R + B; ++r) root[r] = std::int32_t(r);
  // Per region (then per body, then per cluster root): kHeld, kResolved.
  std::vector<std::uint8_t>& walled = clusterWalled_;
  walled.assign(R + B, 0);
  auto find = [&](std::int32_t a) {
    while (root[std::size_t(a)] != a) a = root[std::size_t(a)] = root[std::size_t(root[std::size_t(a)])];
    return a;
  };
  const int nu = nx_ + 1;
  pcg_.forUnknowns([&](std::size_t a, int i, int j) {
    const std::size_t k = std::size_t(j) * nx_ + std::size_t(i);
    const std::size_t nb[4] = {k - 1, k + 1, k - std::size_t(nx_), k + std::size_t(nx_)};
    const bool open[4] = {uOpen_[std::size_t(j) * nu + i] != 0, uOpen_[std::size_t(j) * nu + i + 1] != 0,
                          vOpen_[k] != 0, vOpen_[k + std::size_t(nx_)] != 0};
    bool held = false, interior = true;
    for (int q = 0; q < 4; ++q) {
      const std::uint8_t t = type_[nb[q]];
      if (t == kSolid)
        held = true;
      else if (t == kBody)
        held = held || !(bodies_[std::size_t(bodyOf_[nb[q]])].invMass > 0);
      else
        held = held || !open[q];
      interior = interior && t == kFluid && open[q];
    }
    interior = interior && w_[k] >= kResolvedFill * cellRatio_ * cellRatio_;
    if (held) walled[std::size_t(regionOf[a])] |= kHeld;
    if (interior) walled[std::size_t(regionOf[a])] |= kResolved;
  });
  for (std::size_t b = 0; b < B; ++b)
    if (bodies_[b].held) walled[R + b] |= kHeld;
  for (const Coupling& e : coupling_) {
    const std::int32_t ra = find(regionOf[std::size_t(e.unknown)]), rb = find(std::int32_t(R) + e.body);
    if (ra != rb) root[std::size_t(std::max(ra, rb))] = std::min(ra, rb);
  }
  // Compact cluster numbers in order of their roots; −1 for one a wall holds or one with no
  // interior cell.
  for (std::size_t r = 0; r < R + B; ++r) walled[std::size_t(find(std::int32_t(r)))] |= walled[r];
  std::vector<std::int32_t>& id = clusterOf_;
  id.assign(R + B, -1);
  std::size_t clusters = 0;
  for (std::size_t r = 0; r < R + B; ++r) {
    const std::int32_t top = find(std::int32_t(r));
    if (walled[std::size_t(top)] != kResolved) continue;
    if (std::size_t(top) == r)
      id[r] = std::int32_t(clusters++);
    else
      id[r] = id[std::size_t(top)];
  }
  clusters_ = clusters;
  if (clusters == 0) return false;
  cellCluster_.assign(type_.size(), kNoFluid);
  pcg_.forUnknowns(
      [&](std::size_t a, int, int) { cellCluster_[std::size_t(pcg_.cells()[a])] = id[std::size_t(regionOf[a])]; });
  return true;
}

std::int32_t GridProjection::clusterAt(Real px, Real py) const {
  // The particle's own cell's cluster when that cell is fluid; else that of the nearest fluid
  // cell within two cells (the faces it samples reach fluid cells up to two away through the
  // one layer of extrapolation), in a fixed order; else none (its faces hold no change).
  const int i = int(px), j = int(py);
  if (i < 0 || j < 0 || i >= nx_ || j >= ny_) return -1;
  const std::int32_t own = cellCluster_[std::size_t(j) * nx_ + std::size_t(i)];
  if (own != kNoFluid) return own;
  std::int32_t best = -1;
  Real bestD = 0;
  bool found = false;
  for (int dj = -2; dj <= 2; ++dj)
    for (int di = -2; di <= 2; ++di) {
      const int ii = i + di, jj = j + dj;
      if (ii < 0 || jj < 0 || ii >= nx_ || jj >= ny_) continue;
      const std::int32_t cl = cellCluster_[std::size_t(jj) * nx_ + std::size_t(ii)];
      if (cl == kNoFluid) continue;
      const Real ex = Real(ii) + Real(0.5) - px, ey = Real(jj) + Real(0.5) - py, d = ex * ex + ey * ey;
      if (!found || d < bestD) {
        found = true;
        bestD = d;
        best = cl;
      }
    }
  return best;
}

std::size_t GridProjection::balanceMomentum(StepContext& c) {
  // Σ m Δv of each cluster's particles (slot order) and its dynamic bodies' impulse from this
  // projection, over the cluster's mass: one velocity change for all of them takes it out.
  ParticleStore& P = c.P;
  const std::vector<Real>* ratio = P.find(ParticleStore::kRestRatio);
  std::vector<double>& sum = clusterSum_;  // per cluster: Σ m Δv (x, y) and Σ m
  sum.assign(3 * clusters_, 0.0);
  const double mp = double(c.momentumMass);
  for (std::size_t p = 0; p < P.size(); ++p) {
    const std::int32_t cl = partCluster_[p];
    if (cl < 0) continue;
    const double m = mp * (ratio ? double((*ratio)[p]) : 1.0);
    double* s = &sum[3 * std::size_t(cl)];
    s[0] += m * double(partDelta_[p].x());
    s[1] += m * double(partDelta_[p].y());
    s[2] += m;
  }
  const std::size_t R = pcg_.regions();
  const double f = double(c.rho0) * double(h_) * double(c.dt);
  const bool pushed = !coupling_.empty();
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const std::int32_t cl = clusterOf_[R + b];
    if (cl < 0 || !(bodies_[b].invMass > 0) || !pushed) continue;
    double* s = &sum[3 * std::size_t(cl)];
    s[0] += f * bodyImpulse_[3 * b];
    s[1] += f * bodyImpulse_[3 * b + 1];
    s[2] += 1.0 / bodies_[b].invMass;
  }
  clusterShift_.assign(clusters_, Vec2::Zero());
  for (std::size_t k = 0; k < clusters_; ++k)
    if (sum[3 * k + 2] > 0)
      clusterShift_[k] = Vec2(Real(-sum[3 * k] / sum[3 * k + 2]), Real(-sum[3 * k + 1] / sum[3 * k + 2]));
  const Real vmax2 = c.maxSpeed * c.maxSpeed;
  const std::size_t bad = firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
    std::size_t first = kNone;
    for (std::size_t p = b; p < e; ++p) {
      if (partCluster_[p] < 0) continue;
      P.v[p] += clusterShift_[std::size_t(partCluster_[p])];
      if (first == kNone && (!allFinite(P.v[p]) || P.v[p].squaredNorm() > vmax2)) first = p;
    }
    return first;
  });
  if (!pushed) return bad;
  const double tau0 = c.time - c.solids->time0;
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const std::int32_t cl = clusterOf_[R + b];
    if (cl < 0 || !(bodies_[b].invMass > 0)) continue;
    const Vec2d d = clusterShift_[std::size_t(cl)].cast<double>();
    c.solids->bodies[b].push(tau0, d / bodies_[b].invMass, 0.0);
    bodies_[b].v = c.solids->bodies[b].v;
  }
  return bad;
}

}  // namespace sph2d
