// The coarse-grid projection's moving bodies (grid_projection.hpp): their cells and faces on
// the grid, the body across a face, and a dynamic body's row of the coupled pressure system.
#include "bodies/moving_solid.hpp"
#include "core/state_io.hpp"
#include "solvers/game/grid_projection.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace sph2d {
namespace {

// How deep a cell's centre lies inside a moving body for the cell to be the body's [cells]. At
// half a cell, a cell whose centre lay less deep was fluid or air by the particles in it: along
// a resting cup's bottom the layer of water found air cells inside the body beside it and ran
// along the bottom at up to 3 m/s, for ever, at three of five bottom thicknesses (0.08-0.12 m,
// cells of 0.04 m). At any depth at all, the cells a moving face had just covered turned the
// body's with the water still in them: a dam break's front squeezed a particle by 15 % against
// a crate (the density solve's tolerance is 10 %). A tenth of a cell: neither.
constexpr double kBodyDepth = 0.1;

}  // namespace

void GridProjection::markBodies(const StepContext& c) {
  bodies_.clear();
  if (!c.solids) {
    bodyOf_.clear();
    return;
  }
  const MovingSolids& S = *c.solids;
  const double tau = c.time - S.time0, h = double(h_);
  bodyOf_.assign(type_.size(), -1);
  std::vector<std::uint8_t>& in = bodyCells_;  // the body's cells over its bounding box (one cell of margin)
  for (std::size_t b = 0; b < S.bodies.size(); ++b) {
    const MovingSolid& m = S.bodies[b];
    BodyState st;
    st.centre = m.centreAt(tau);
    st.v = m.v;
    st.omega = m.omega;
    st.invMass = m.invMass;
    st.invInertia = m.invInertia;
    st.held = m.held;
    if (m.dynamic()) m.restingResponse(st.W);
    // W's entries below rounding of its largest possible (1/m, 1/I) are zero: a body its contacts
    // hold still has W = 0 exactly, not a residue of either sign.
    const double scale = 1e-12 * std::max(m.invMass, m.invInertia);
    for (int r = 0; r < 3; ++r)
      for (int q = 0; q < 3; ++q) {
        if (std::fabs(st.W[r][q]) <= scale) st.W[r][q] = 0;
        st.movable = st.movable || st.W[r][q] != 0;
      }
    // The body's cells, anchored indices [bI0, bI0 + bn) × [bJ0, bJ0 + bm), over its whole
    // reach (the grid may hold only part of it): a cell is the body's when its centre lies
    // more than kBodyDepth of a cell inside it (the faces' correction below keeps Archimedes'
    // force whatever the cells).
    // Beyond the grid: no cell of it (a far body costs nothing).
    if (st.centre.x() + m.radius < double(I0_) * h || st.centre.x() - m.radius > double(I0_ + nx_) * h ||
        st.centre.y() + m.radius < double(J0_) * h || st.centre.y() - m.radius > double(J0_ + ny_) * h) {
      bodies_.push_back(st);
      continue;
    }
    long bI0 = long(std::floor((st.centre.x() - m.radius) / h - 0.5)) - 1;
    long bJ0 = long(std::floor((st.centre.y() - m.radius) / h - 0.5)) - 1;
    long bn = long(std::ceil((st.centre.x() + m.radius) / h - 0.5)) + 2 - bI0;
    long bm = long(std::ceil((st.centre.y() + m.radius) / h - 0.5)) + 2 - bJ0;
    // The face correction needs the whole body; one too large to scan every substep is
    // scanned over the grid only, T left the identity.
    const bool whole = double(bn) * double(bm) <= std::max(double(1 << 20), 4.0 * double(type_.size()));
    if (!whole) {
      const long cI0 = std::max(bI0, I0_ - 1), cJ0 = std::max(bJ0, J0_ - 1);
      bn = std::min(bI0 + bn, I0_ + nx_ + 1) - cI0;
      bm = std::min(bJ0 + bm, J0_ + ny_ + 1) - cJ0;
      bI0 = cI0;
      bJ0 = cJ0;
    }
    in.assign(std::size_t(bn * bm), 0);
    for (long J = 1; J + 1 < bm; ++J)
      for (long I = 1; I + 1 < bn; ++I) {
        const Vec2d ctr((double(bI0 + I) + 0.5) * h, (double(bJ0 + J) + 0.5) * h);
        const double d = m.depth(tau, ctr);
        const long i = bI0 + I - I0_, j = bJ0 + J - J0_;
        const bool inGrid = i >= 0 && j >= 0 && i < nx_ && j < ny_;
        const std::size_t k = inGrid ? std::size_t(j) * nx_ + std::size_t(i) : 0;
        if (d > kBodyDepth * h) {
          in[std::size_t(J * bn + I)] = 1;
          if (inGrid && type_[k] != kSolid && type_[k] != kBody) {
            type_[k] = kBody;
            bodyOf_[k] = std::int32_t(b);
          }
        }
      }
    // The faces' moments: for a pressure κ linear in x, the faces' impulse Σ κ(x_c) h g
    // (x_c the fluid cell's centre across the face) is K·∇κ with K = Σ h g x_cᵀ (3 × 2);
    // the body's own surface gives (−A·I, t*ᵀ) (A its area, t* the torque below). The faces
    // miss that by about a cell along each side: T = [C 0; τᵀ 1] with C K_F = −A I and
    // τᵀ K_F + k_θᵀ = t*ᵀ corrects every face's g (and the flux it carries), so a body
    // floats by Archimedes at any cell size.
    double KF[2][2] = {{0, 0}, {0, 0}}, kt[2] = {0, 0};
    const long di[4] = {-1, 1, 0, 0}, dj[4] = {0, 0, -1, 1};
    for (long J = 1; J + 1 < bm; ++J)
      for (long I = 1; I + 1 < bn; ++I) {
        if (!in[std::size_t(J * bn + I)]) continue;
        const Vec2d ctr((double(bI0 + I) + 0.5) * h, (double(bJ0 + J) + 0.5) * h);
        for (int q = 0; q < 4; ++q) {
          if (in[std::size_t((J + dj[q]) * bn + I + di[q])]) continue;
          const Vec2d n(-double(di[q]), -double(dj[q]));  // from the fluid cell into the body
          const Vec2d xc = ctr - h * n - st.centre, rf = ctr - 0.5 * h * n - st.centre;
          const double rn = rf.x() * n.y() - rf.y() * n.x();
          for (int r = 0; r < 2; ++r) {
            KF[0][r] += h * n.x() * xc[r];
            KF[1][r] += h * n.y() * xc[r];
            kt[r] += h * rn * xc[r];
          }
        }
      }
    // The true torque of a linear κ about the centre of mass: A (c_y ∂x κ − c_x ∂y κ), c the
    // centroid's offset (zero for a uniform body; a heavy keel puts it above: the righting
    // moment).
    const double th = m.angleAt(tau), cs = std::cos(th), sn = std::sin(th);
    const Vec2d cw(cs * m.centroid.x() - sn * m.centroid.y(), sn * m.centroid.x() + cs * m.centroid.y());
    const double tstar[2] = {m.area * cw.y(), -m.area * cw.x()};
    const double det = KF[0][0] * KF[1][1] - KF[0][1] * KF[1][0];
    if (whole && std::fabs(det) > 1e-30) {
      const double inv[2][2] = {{KF[1][1] / det, -KF[0][1] / det}, {-KF[1][0] / det, KF[0][0] / det}};
      for (int r = 0; r < 2; ++r)
        for (int q = 0; q < 2; ++q) {
          st.T[r][q] = -m.area * inv[r][q];
          st.T[2][q] += (tstar[r] - kt[r]) * inv[r][q];
        }
    }
    bodies_.push_back(st);
  }
}

int GridProjection::bodyAcross(std::size_t k1, std::size_t k2) const {
  if (bodies_.empty()) return -1;
  return type_[k1] == kBody ? bodyOf_[k1] : type_[k2] == kBody ? bodyOf_[k2] : -1;
}

void GridProjection::BodyState::coupling(const Vec2d& n, const Vec2d& face, double g[3]) const {
  const Vec2d r = face - centre;
  const double raw[3] = {n.x(), n.y(), r.x() * n.y() - r.y() * n.x()};
  for (int a = 0; a < 3; ++a) g[a] = T[a][0] * raw[0] + T[a][1] * raw[1] + T[a][2] * raw[2];
}

Real GridProjection::bodyFaceVelocity(int body, int axis, int i, int j) const {
  const BodyState& b = bodies_[std::size_t(body)];
  const double h = double(h_);
  const Vec2d face = axis == 0 ? Vec2d(double(I0_ + i) * h, (double(J0_ + j) + 0.5) * h)
                               : Vec2d((double(I0_ + i) + 0.5) * h, double(J0_ + j) * h);
  double g[3];
  b.coupling(axis == 0 ? Vec2d(1, 0) : Vec2d(0, 1), face, g);
  return Real(g[0] * b.v.x() + g[1] * b.v.y() + g[2] * b.omega);
}

void GridProjection::assembleCoupling() {
  coupling_.clear();
  if (bodies_.empty()) return;
  const double h = double(h_);
  pcg_.forUnknowns([&](std::size_t a, int i, int j) {
    const int k = pcg_.cells()[a];
    const int nb[4] = {k - 1, k + 1, k - nx_, k + nx_};
    const Vec2d normals[4] = {Vec2d(-1, 0), Vec2d(1, 0), Vec2d(0, -1), Vec2d(0, 1)};
    const Vec2d faces[4] = {Vec2d(double(I0_ + i) * h, (double(J0_ + j) + 0.5) * h),
                            Vec2d(double(I0_ + i + 1) * h, (double(J0_ + j) + 0.5) * h),
                            Vec2d((double(I0_ + i) + 0.5) * h, double(J0_ + j) * h),
                            Vec2d((double(I0_ + i) + 0.5) * h, double(J0_ + j + 1) * h)};
    const std::size_t first = coupling_.size();
    for (int q = 0; q < 4; ++q) {
      if (type_[std::size_t(nb[q])] != kBody) continue;
      const std::int32_t body = bodyOf_[std::size_t(nb[q])];
      const BodyState& st = bodies_[std::size_t(body)];
      if (!(st.invMass > 0)) continue;  // kinematic: a moving wall only
      std::size_t e = first;
      while (e < coupling_.size() && coupling_[e].body != body) ++e;
      if (e == coupling_.size()) {
        // A body its resting contacts hold still (W = 0) still takes the pressure's impulse
        // (handed to Box2D), but does not open the region.
        coupling_.push_back(Coupling{std::int32_t(a), body, {0, 0, 0}});
        if (st.movable) pcg_.vent(a);  // the body can move: the region is not sealed
      }
      double g[3];
      st.coupling(normals[q], faces[q], g);
      for (int r = 0; r < 3; ++r) coupling_[e].g[r] += g[r];
    }
  });
}

}  // namespace sph2d
