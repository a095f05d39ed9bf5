// The coarse-grid pressure projection (grid_projection.hpp).
#include "solvers/game/grid_projection.hpp"
#include "bodies/moving_solid.hpp"
#include "core/state_io.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace sph2d {

GridProjection::GridProjection(Real cellInSpacings, Real fluidFraction, Real compressionRate, Real tolerance,
                               int maxIterations, GridShift shift)
    : cellRatio_(cellInSpacings),
      fluidFraction_(fluidFraction),
      rate_(compressionRate),
      tol_(tolerance),
      maxIt_(maxIterations),
      shiftDef_(shift) {}

void GridProjection::layout(const StepContext& c) {
  const ParticleStore& P = c.P;
  const std::size_t n = P.size();
  struct Box {
    Real x0, y0, x1, y1;
  };
  const Real inf = std::numeric_limits<Real>::infinity();
  const Box init{inf, inf, -inf, -inf};
  const Box b = c.pool.reduce(
      n, kStreamBlock, init,
      [&](std::size_t s, std::size_t e) {
        Box r = init;
        for (std::size_t i = s; i < e; ++i) {
          r.x0 = std::min(r.x0, P.x[i].x());
          r.y0 = std::min(r.y0, P.x[i].y());
          r.x1 = std::max(r.x1, P.x[i].x());
          r.y1 = std::max(r.y1, P.x[i].y());
        }
        return r;
      },
      [](Box a, Box q) { return Box{std::min(a.x0, q.x0), std::min(a.y0, q.y0), std::max(a.x1, q.x1), std::max(a.y1, q.y1)}; });
  h_ = cellRatio_ * c.dx;
  // Spray far from the bulk must not make the grid huge: above the budget the cells grow.
  const double budget = std::max(16.0 * double(n), 4096.0);
  for (;;) {
    invH_ = Real(1) / h_;
    I0_ = long(std::floor(b.x0 * invH_)) - 1;
    J0_ = long(std::floor(b.y0 * invH_)) - 1;
    nx_ = int(long(std::floor(b.x1 * invH_)) + 1 - I0_ + 1);
    ny_ = int(long(std::floor(b.y1 * invH_)) + 1 - J0_ + 1);
    if (double(nx_) * double(ny_) <= budget) break;
    h_ *= Real(std::sqrt(double(nx_) * double(ny_) / budget) * 1.01);
  }
}

void GridProjection::resetCells() {
  // The cells' fields and the faces' flags (classify and assemble write them).
  const std::size_t cells = std::size_t(nx_) * std::size_t(ny_);
  type_.assign(cells, kAir);
  w_.assign(cells, 0);
  comp_.assign(cells, 0);
  if (surface_) top_.assign(cells, -std::numeric_limits<Real>::infinity());
  index_.assign(cells, -1);
  uOpen_.assign(std::size_t(nx_ + 1) * std::size_t(ny_), 0);
  fluidU_.assign(uOpen_.size(), 0);
  vOpen_.assign(std::size_t(nx_) * std::size_t(ny_ + 1), 0);
  fluidV_.assign(vOpen_.size(), 0);
}

void GridProjection::resetFaces(int axis) {
  // One axis's face velocities, weights and changes.
  const std::size_t faces = axis == 0 ? std::size_t(nx_ + 1) * std::size_t(ny_) : std::size_t(nx_) * std::size_t(ny_ + 1);
  for (std::vector<Real>* f : axis == 0 ? std::array<std::vector<Real>*, 4>{&u_, &uw_, &du_, &uNew_}
                                        : std::array<std::vector<Real>*, 4>{&v_, &vw_, &dv_, &vNew_})
    f->assign(faces, 0);
}

std::uint8_t GridProjection::cacheEntry(const StepContext& c, long I, long J) {
  const bool inside = I >= cI0_ && J >= cJ0_ && I < cI0_ + cnx_ && J < cJ0_ + cny_;
  std::uint8_t* slot = inside ? &cache_[std::size_t(J - cJ0_) * cnx_ + std::size_t(I - cI0_)] : nullptr;
  if (slot && (*slot & 1)) return *slot;
  const Vec2 ctr((Real(I) + Real(0.5)) * h_, (Real(J) + Real(0.5)) * h_);
  std::uint8_t e = 1;
  if (c.boundary.insideDepth(ctr) > 0) e |= 2;
  if (c.boundary.blocks(ctr - Vec2(h_, 0), ctr)) e |= 4;
  if (c.boundary.blocks(ctr - Vec2(0, h_), ctr)) e |= 8;
  if (slot) *slot = e;
  return e;
}

void GridProjection::classify(const StepContext& c) {
  // The cache covers the grid plus one cell (the right and top faces of the last cells).
  const std::uint64_t version = c.boundaryVersion ^ std::uint64_t(std::lround(double(h_) * 1e9));
  const bool covers = cacheValid_ && I0_ >= cI0_ && J0_ >= cJ0_ && I0_ + nx_ + 1 <= cI0_ + cnx_ &&
                      J0_ + ny_ + 1 <= cJ0_ + cny_;
  if (!cacheValid_ || version != cacheVersion_) {
    cacheValid_ = true;
    cacheVersion_ = version;
    cI0_ = I0_ - nx_ / 2;
    cJ0_ = J0_ - ny_ / 2;
    cnx_ = 2 * nx_ + 2;
    cny_ = 2 * ny_ + 2;
    cache_.assign(std::size_t(cnx_) * cny_, 0);
  } else if (!covers) {  // grow to the union (with room), keeping what is known
    const long nI0 = std::min(cI0_, I0_ - nx_ / 2), nJ0 = std::min(cJ0_, J0_ - ny_ / 2);
    const long nI1 = std::max(cI0_ + cnx_, I0_ + nx_ + 1 + nx_ / 2), nJ1 = std::max(cJ0_ + cny_, J0_ + ny_ + 1 + ny_ / 2);
    std::vector<std::uint8_t> grown(std::size_t(nI1 - nI0) * std::size_t(nJ1 - nJ0), 0);
    for (int j = 0; j < cny_; ++j)
      for (int i = 0; i < cnx_; ++i)
        grown[std::size_t(cJ0_ + j - nJ0) * std::size_t(nI1 - nI0) + std::size_t(cI0_ + i - nI0)] =
            cache_[std::size_t(j) * cnx_ + i];
    cache_.swap(grown);
    cI0_ = nI0;
    cJ0_ = nJ0;
    cnx_ = int(nI1 - nI0);
    cny_ = int(nJ1 - nJ0);
  }
  // Cell (i, j) of the grid (−1 ≤ i ≤ nx, −1 ≤ j ≤ ny) from the cache, computed when not yet known.
  std::uint8_t* const base = cache_.data() + std::size_t(J0_ - cJ0_) * std::size_t(cnx_) + std::size_t(I0_ - cI0_);
  auto entry = [&](int i, int j) {
    const std::uint8_t e = base[std::ptrdiff_t(j) * cnx_ + i];
    return (e & 1) ? e : cacheEntry(c, I0_ + i, J0_ + j);
  };
  const Real full = cellRatio_ * cellRatio_;  // particle weight of a full cell
  for (int j = 1; j + 1 < ny_; ++j)  // border cells stay air (solid neighbours are marked below)
    for (int i = 1; i + 1 < nx_; ++i) {
      const std::size_t k = std::size_t(j) * nx_ + i;
      if (!(w_[k] > 0)) continue;  // empty cells stay air
      const std::uint8_t e = entry(i, j);
      type_[k] = (e & 2) ? kSolid : (w_[k] >= fluidFraction_ * full ? kFluid : kAir);
    }
  markBodies(c);
  // Faces of fluid cells: open unless blocked; the neighbour's solidity from the cache.
  for (int j = 0; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) {
      const std::size_t k = std::size_t(j) * nx_ + i;
      if (type_[k] != kFluid) continue;
      const std::uint8_t e = entry(i, j);
      const std::uint8_t eR = entry(i + 1, j);
      const std::uint8_t eT = entry(i, j + 1);
      uOpen_[std::size_t(j) * (nx_ + 1) + i] = !(e & 4);
      uOpen_[std::size_t(j) * (nx_ + 1) + i + 1] = !(eR & 4);
      vOpen_[std::size_t(j) * nx_ + i] = !(e & 8);
      vOpen_[std::size_t(j + 1) * nx_ + i] = !(eT & 8);
      if (i > 0 && (entry(i - 1, j) & 2)) type_[k - 1] = kSolid;
      if (i + 1 < nx_ && (eR & 2)) type_[k + 1] = kSolid;
      if (j > 0 && (entry(i, j - 1) & 2)) type_[k - nx_] = kSolid;
      if (j + 1 < ny_ && (eT & 2)) type_[k + nx_] = kSolid;
    }
}

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
    // The body's cells, anchored indices [bI0, bI0 + bn) × [bJ0, bJ0 + bm), over its whole
    // reach (the grid may hold only part of it): a cell is the body's when its centre lies
    // at least half a cell inside, so the fluid cells around have their centres (where
    // the pressure is) on its surface.
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
        if (d >= 0.5 * h) {
          in[std::size_t(J * bn + I)] = 1;
          if (inGrid && type_[k] != kSolid && type_[k] != kBody) {
            type_[k] = kBody;
            bodyOf_[k] = std::int32_t(b);
          }
        } else if (d > 0 && inGrid && type_[k] == kAir && w_[k] > 0 && i > 0 && j > 0 && i + 1 < nx_ && j + 1 < ny_) {
          // Covered less deeply, the cell holds fluid only beside the body: any particle
          // weight makes it fluid (by its fill alone it would be air, and the pressure
          // would vanish against the body); border cells stay air, as everywhere.
          type_[k] = kFluid;
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
  forUnknowns([&](std::size_t a, int i, int j) {
    const int k = cells_[a];
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
      if (e == coupling_.size()) coupling_.push_back(Coupling{std::int32_t(a), body, {0, 0, 0}});
      double g[3];
      st.coupling(normals[q], faces[q], g);
      for (int r = 0; r < 3; ++r) coupling_[e].g[r] += g[r];
    }
  });
}

namespace {
/// Adds the bilinear weights at (fx, fy), in the units of a field `stride` wide, to
/// `weight`, and `value` times them to `sum` when given (fx, fy ≥ 0: the grid has a
/// margin, so truncation is floor).
inline void splat(Real* sum, std::vector<Real>& weight, int stride, Real fx, Real fy, Real value) {
  const int i0 = int(fx), j0 = int(fy);
  const Real tx = fx - Real(i0), ty = fy - Real(j0);
  const Real wq[4] = {(1 - tx) * (1 - ty), tx * (1 - ty), (1 - tx) * ty, tx * ty};
  const std::size_t k = std::size_t(j0) * std::size_t(stride) + std::size_t(i0);
  const std::size_t ks[4] = {k, k + 1, k + std::size_t(stride), k + std::size_t(stride) + 1};
  for (int q = 0; q < 4; ++q) {
    if (sum) sum[ks[q]] += wq[q] * value;
    weight[ks[q]] += wq[q];
  }
}
}  // namespace

void GridProjection::splatCells(const StepContext& c) {
  // Serial in slot order (the same bits for any thread count).
  const ParticleStore& P = c.P;
  const Real rho0 = c.rho0;
  // The cells' SPH compression is read only by the compression source.
  Real* comp = rate_ > 0 ? comp_.data() : nullptr;
  for (std::size_t p = 0; p < P.size(); ++p) {
    const Real px = P.x[p].x() * invH_ - Real(I0_), py = P.x[p].y() * invH_ - Real(J0_);
    splat(comp, w_, nx_, px - Real(0.5), py - Real(0.5), P.rho[p] / rho0 - Real(1));  // cell centres
    if (surface_) {  // the highest particle of each cell (the ghost surface's height)
      const std::size_t k = std::size_t(int(py)) * std::size_t(nx_) + std::size_t(int(px));
      top_[k] = std::max(top_[k], P.x[p].y());
    }
  }
}

void GridProjection::splatFaces(const StepContext& c, int axis) {
  // Serial in slot order (the same bits for any thread count); then the mean velocity.
  const ParticleStore& P = c.P;
  std::vector<Real>& f = axis == 0 ? u_ : v_;
  std::vector<Real>& fw = axis == 0 ? uw_ : vw_;
  for (std::size_t p = 0; p < P.size(); ++p) {
    const Real px = P.x[p].x() * invH_ - Real(I0_), py = P.x[p].y() * invH_ - Real(J0_);
    if (axis == 0) splat(f.data(), fw, nx_ + 1, px, py - Real(0.5), P.v[p].x());  // u faces at (i, j + 1/2)
    else splat(f.data(), fw, nx_, px - Real(0.5), py, P.v[p].y());                 // v faces at (i + 1/2, j)
  }
  for (std::size_t k = 0; k < f.size(); ++k)
    if (fw[k] > 0) f[k] /= fw[k];
}

void GridProjection::assemble() {
  const int nu = nx_ + 1;
  // The faces next to a fluid cell (their change is known; the others are extrapolated).
  auto isFluid = [&](int i, int j) { return type_[std::size_t(j) * nx_ + i] == kFluid; };
  for (int j = 0; j < ny_; ++j)
    for (int i = 1; i < nx_; ++i) fluidU_[std::size_t(j) * nu + i] = isFluid(i - 1, j) || isFluid(i, j);
  for (int j = 1; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) fluidV_[std::size_t(j) * nx_ + i] = isFluid(i, j - 1) || isFluid(i, j);
  // The unknowns in cell order, and each row's first (rowStart_[ny] = m): the loops over
  // unknowns go row by row (no division to find a cell's row).
  cells_.clear();
  rowStart_.resize(std::size_t(ny_) + 1);
  for (int j = 0; j < ny_; ++j) {
    rowStart_[std::size_t(j)] = std::int32_t(cells_.size());
    for (int i = 0; i < nx_; ++i) {
      const std::size_t k = std::size_t(j) * nx_ + i;
      if (type_[k] != kFluid) continue;
      index_[k] = std::int32_t(cells_.size());
      cells_.push_back(std::int32_t(k));
    }
  }
  const std::size_t m = cells_.size();
  rowStart_[std::size_t(ny_)] = std::int32_t(m);
  diag_.assign(m, 0);
  if (surface_) thetaUp_.assign(type_.size(), Real(1));
  adj_.assign(4 * m, -1);
  vented_.assign(m, 0);
  forUnknowns([&](std::size_t a, int i, int j) {
    const int k = cells_[a];
    const bool open[4] = {uOpen_[std::size_t(j) * nu + i] != 0, uOpen_[std::size_t(j) * nu + i + 1] != 0,
                          vOpen_[std::size_t(j) * nx_ + i] != 0, vOpen_[std::size_t(j + 1) * nx_ + i] != 0};
    const int nb[4] = {k - 1, k + 1, k - nx_, k + nx_};
    Real dg = 0;
    for (int q = 0; q < 4; ++q) {
      const std::uint8_t t = type_[std::size_t(nb[q])];
      if (q == 3 && open[q] && t == kAir && surface_) {
        // Ghost fluid (Gibou, Fedkiw, Cheng & Kang 2002): κ = 0 on the surface, a fraction θ
        // of the way to the air cell's centre: half a spacing above the highest particle of
        // the two cells (the fill would say it too, but beside a wall or over a compressed
        // layer its reading differs by a tenth of a cell, and that difference drives a flow).
        const double ya = (double(J0_ + j) + 0.5) * double(h_);
        const Real ytop = std::max(top_[std::size_t(k)], top_[std::size_t(nb[q])]);
        const Real theta = std::clamp(Real((double(ytop) + 0.5 * double(dx_) - ya) * double(invH_)), kMinSurfaceFraction, Real(1));
        dg += Real(1) / theta;
        thetaUp_[std::size_t(k)] = theta;
        vented_[a] = 1;
      } else if (open[q] && t != kSolid && t != kBody) {
        dg += 1;
        if (t == kAir) vented_[a] = 1;
      }
      adj_[4 * a + q] = open[q] ? index_[std::size_t(nb[q])] : -1;  // −1: air, solid or closed
    }
    diag_[a] = dg;
  });
  assembleCoupling();
  groundPockets();
  nbrPad_.resize(adj_.size());
  for (std::size_t e = 0; e < adj_.size(); ++e) nbrPad_[e] = adj_[e] >= 0 ? adj_[e] : std::int32_t(m);
  // MIC(0) (Bridson, "Fluid Simulation for Computer Graphics", 2nd ed., fig. 5.7):
  // the incomplete Cholesky factor of the 5-point Laplacian, in cell order.
  const Real tau = Real(0.97), sigma = Real(0.25);
  precon_.assign(m, 0);
  for (std::size_t a = 0; a < m; ++a) {
    if (!(diag_[a] > 0)) continue;
    Real e = diag_[a];
    const std::int32_t l = adj_[4 * a + 0], d = adj_[4 * a + 2];
    if (l >= 0) {  // A(left, a) = −1; the left cell's "plus j" entry: its up neighbour
      const Real pl = precon_[std::size_t(l)];
      const Real aUpL = adj_[4 * std::size_t(l) + 3] >= 0 ? Real(-1) : Real(0);
      e -= pl * pl + tau * (-1) * aUpL * pl * pl;
    }
    if (d >= 0) {
      const Real pd = precon_[std::size_t(d)];
      const Real aRightD = adj_[4 * std::size_t(d) + 1] >= 0 ? Real(-1) : Real(0);
      e -= pd * pd + tau * (-1) * aRightD * pd * pd;
    }
    if (e < sigma * diag_[a]) e = diag_[a];
    precon_[a] = Real(1) / std::sqrt(e);
  }
  precon2_.resize(m);
  for (std::size_t a = 0; a < m; ++a) precon2_[a] = precon_[a] * precon_[a];
}

void GridProjection::groundPockets() {
  // A pocket: fluid cells joined by open faces with no open face to air (no κ = 0 anywhere)
  // and no dynamic body to push. Its rows are a pure Neumann Laplacian: singular, κ only up
  // to a constant, solvable only when its right-hand side sums to zero. Fluid cut off by a
  // wall from the rest (the cells between the teeth of an acute chain, or a sealed tank
  // filled to the lid) makes one; conjugate gradients on it divide by a vanishing d·Ad and
  // return infinities (a 50 m/s jet into a zigzag funnel stopped with a NaN shift). Each
  // pocket's last cell is grounded (diagonal + 1, so the system is definite), and
  // balance() takes the pocket's mean out of each right-hand side: then the grounded row's
  // κ is 0 and every row's equation holds as before. A sealed pocket cannot change its
  // volume; the mean compression it cannot shed stays with the particle solve.
  const std::size_t m = cells_.size();
  std::vector<std::int32_t>& root = pocketOf_;
  root.resize(m);
  auto find = [&](std::int32_t a) {
    while (root[std::size_t(a)] != a) a = root[std::size_t(a)] = root[std::size_t(root[std::size_t(a)])];
    return a;
  };
  for (std::size_t a = 0; a < m; ++a) {
    root[a] = std::int32_t(a);
    for (int q : {0, 2}) {  // left and down: already labelled
      const std::int32_t b = adj_[4 * a + std::size_t(q)];
      if (b < 0) continue;
      const std::int32_t ra = find(std::int32_t(a)), rb = find(b);
      if (ra != rb) root[std::size_t(std::max(ra, rb))] = std::min(ra, rb);  // the lower index is the root
    }
  }
  for (const Coupling& e : coupling_) vented_[std::size_t(find(e.unknown))] = 1;  // a body can move: not sealed
  for (std::size_t a = 0; a < m; ++a) {
    const std::int32_t r = find(std::int32_t(a));
    if (vented_[a]) vented_[std::size_t(r)] = 1;
    root[a] = r;
  }
  // Pocket numbers in order of their roots; −1 for cells of a vented region.
  pocketCells_.clear();
  pocketLast_.clear();
  for (std::size_t a = 0; a < m; ++a) {
    const std::int32_t r = root[a];
    if (vented_[std::size_t(r)]) {
      root[a] = -1;
      continue;
    }
    std::int32_t id;
    if (std::size_t(r) == a) {
      id = std::int32_t(pocketCells_.size());
      pocketCells_.push_back(0);
      pocketLast_.push_back(0);
    } else {
      id = root[std::size_t(r)];  // the root, visited first, holds its pocket's number
    }
    root[a] = id;
    ++pocketCells_[std::size_t(id)];
    pocketLast_[std::size_t(id)] = std::int32_t(a);
  }
  for (const std::int32_t a : pocketLast_) diag_[std::size_t(a)] += 1;
}

void GridProjection::balance(std::vector<Real>& rhs) const {
  if (pocketLast_.empty()) return;
  std::vector<double> sum(pocketLast_.size(), 0.0);  // the two solves balance side by side: no shared scratch
  for (std::size_t a = 0; a < cells_.size(); ++a)
    if (pocketOf_[a] >= 0) sum[std::size_t(pocketOf_[a])] += double(rhs[a]);
  for (std::size_t a = 0; a < cells_.size(); ++a)
    if (pocketOf_[a] >= 0) {
      const std::size_t id = std::size_t(pocketOf_[a]);
      rhs[a] -= Real(sum[id] / double(pocketCells_[id]));
    }
}

void GridProjection::precondition(const std::vector<Real>& r, std::vector<Real>& z, std::vector<Real>& y) const {
  // z = (L Lᵀ)⁻¹ r with L = MIC(0)'s factor (p = precon_ = 1/diag(L), p2 = p²). Each
  // substitution is a chain from one cell to the next along a row (a left neighbour is
  // always the unknown before, a right one the unknown after), fed by the row below
  // (forward) or above (backward). Each cell's arithmetic is fixed; only the schedule is
  // free: two rows run side by side, the second a cell or more behind the first, so two
  // chains are in flight (the chain is one multiply and one add per cell, and with one
  // row at a time the core waits on it). Each cursor carries its row's last value in a
  // register. The same bits as one cell after the other.
  const std::size_t m = cells_.size();
  const Real* p = precon_.data();
  const Real* p2 = precon2_.data();
  const std::int32_t* A = adj_.data();
  const std::int32_t* rows = rowStart_.data();
  const Real* R = r.data();
  y.resize(m);
  Real* Y = y.data();
  Real* Z = z.data();
  // Forward: q = L⁻¹ r, kept as z (= q) and y = q·p (what the right and up cells read).
  auto forward = [&](std::int32_t a, Real& yPrev) {
    const std::int32_t l = A[4 * a + 0], d = A[4 * a + 2];
    const Real t = R[a] + (d >= 0 ? Y[d] : Real(0));
    const Real yl = l < 0 ? Real(0) : yPrev;
    Z[a] = (t + yl) * p[a];
    yPrev = Y[a] = t * p2[a] + yl * p2[a];
  };
  for (int j = 0; j < ny_; j += 2) {
    // Row j (cursor a) and row j + 1 (cursor b): b's cell waits for the cell below it.
    std::int32_t a = rows[j], b = rows[j + 1];
    const std::int32_t ae = rows[j + 1], be = rows[std::min(j + 2, ny_)];
    Real ya = 0, yb = 0;
    while (a < ae) {
      forward(a++, ya);
      if (b < be && A[4 * b + 2] < a) forward(b++, yb);  // below: done (or none, −1)
    }
    while (b < be) forward(b++, yb);
  }
  // Backward: z = L⁻ᵀ q, from the top row down.
  auto backward = [&](std::int32_t a, Real& zNext) {
    const std::int32_t rt = A[4 * a + 1], u = A[4 * a + 3];
    const Real s = Z[a] * p[a] + (u >= 0 ? Z[u] : Real(0)) * p2[a];
    const Real zr = rt < 0 ? Real(0) : zNext;
    zNext = Z[a] = s + zr * p2[a];
  };
  for (int j = ny_ - 1; j >= 0; j -= 2) {
    // Row j (cursor a, descending) and row j − 1 (cursor b): b's cell waits for the cell above.
    std::int32_t a = rows[j + 1] - 1, b = rows[j] - 1;
    const std::int32_t as = rows[j], bs = rows[std::max(j - 1, 0)];
    Real za = 0, zb = 0;
    while (a >= as) {
      backward(a--, za);
      if (b >= bs && (A[4 * b + 3] < 0 || A[4 * b + 3] > a)) backward(b--, zb);  // above: done, or none
    }
    while (b >= bs) backward(b--, zb);
  }
  (void)m;
}

double GridProjection::dot(const std::vector<Real>& a, const std::vector<Real>& b) const {
  double s = 0;  // in cell order
  for (std::size_t k = 0; k < cells_.size(); ++k) s += double(a[k]) * double(b[k]);
  return s;
}

double GridProjection::applyDot(const std::vector<Real>& in, std::vector<Real>& out) const {
  // apply(in, out, false), and in·out summed in cell order as it goes. `in` holds m + 1
  // values, the last 0: a missing neighbour (nbrPad_ = m) subtracts that 0, as exact as
  // subtracting none (s − 0 = s), and the loop has no branch to mispredict.
  const std::size_t m = cells_.size();
  const std::int32_t* A = nbrPad_.data();
  const Real* I = in.data();
  const Real* D = diag_.data();
  Real* O = out.data();
  double dsum = 0;
  for (std::size_t a = 0; a < m; ++a) {
    Real s = D[a] * I[a];
    s -= I[A[4 * a + 0]];
    s -= I[A[4 * a + 1]];
    s -= I[A[4 * a + 2]];
    s -= I[A[4 * a + 3]];
    O[a] = s;
    dsum += double(I[a]) * double(s);
  }
  return dsum;
}

void GridProjection::apply(const std::vector<Real>& in, std::vector<Real>& out, bool coupled) const {
  const std::size_t m = cells_.size();
  const std::int32_t* A = adj_.data();
  for (std::size_t a = 0; a < m; ++a) {
    Real s = diag_[a] * in[a];
    for (int q = 0; q < 4; ++q)
      if (A[4 * a + q] >= 0) s -= in[std::size_t(A[4 * a + q])];
    out[a] = s;
  }
  if (!coupled || coupling_.empty()) return;
  // The dynamic bodies' response (Batty, Bertails & Bridson 2007, "A fast variational
  // framework for accurate solid-fluid coupling", on a voxelized body): the pressure's
  // impulse Gᵀκ moves a body by M⁻¹Gᵀκ, which changes the flux through its faces by G·that.
  bodySum_.assign(3 * bodies_.size(), 0.0);
  for (const Coupling& e : coupling_)
    for (int q = 0; q < 3; ++q) bodySum_[3 * std::size_t(e.body) + std::size_t(q)] += e.g[q] * double(in[std::size_t(e.unknown)]);
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    bodySum_[3 * b + 0] *= couplingScale_ * bodies_[b].invMass;
    bodySum_[3 * b + 1] *= couplingScale_ * bodies_[b].invMass;
    bodySum_[3 * b + 2] *= couplingScale_ * bodies_[b].invInertia;
  }
  for (const Coupling& e : coupling_) {
    const double* t = &bodySum_[3 * std::size_t(e.body)];
    out[std::size_t(e.unknown)] += Real(e.g[0] * t[0] + e.g[1] * t[1] + e.g[2] * t[2]);
  }
}

int GridProjection::pcg(std::vector<Real>& x, const std::vector<Real>& b, Real tol, Real& res, CgWork& w,
                        bool coupled) const {
  // Conjugate gradients with the MIC(0) preconditioner; sums in cell order.
  const std::size_t m = cells_.size();
  std::vector<Real>&r_ = w.r, &z_ = w.z, &d_ = w.d, &q_ = w.q;
  r_.resize(m);
  z_.resize(m);
  d_.assign(m + 1, 0);  // d[m] = 0 stays: applyDot's missing neighbour
  q_.resize(m);
  apply(x, q_, coupled);
  for (std::size_t a = 0; a < m; ++a) r_[a] = b[a] - q_[a];
  auto worst = [&] {
    Real mx = 0;
    for (std::size_t a = 0; a < m; ++a) mx = std::max(mx, std::fabs(r_[a]));
    return mx;
  };
  double rz = 0;
  precondition(r_, z_, w.y);
  for (std::size_t a = 0; a < m; ++a) {
    d_[a] = z_[a];
    rz += double(r_[a]) * double(z_[a]);
  }
  int it = 0;
  res = worst();
  while (it < maxIt_ && res > tol && rz > 0) {
    // q = A d and d·q (in one pass when no body adds to q afterwards), the update of r
    // with the largest |r| in one pass: the same sums in the same order.
    const double dq = coupled ? (apply(d_, q_, true), dot(d_, q_)) : applyDot(d_, q_);
    if (!(dq > 0)) break;
    const Real alpha = Real(rz / dq);
    Real mx = 0;
    for (std::size_t a = 0; a < m; ++a) {
      r_[a] -= alpha * q_[a];
      mx = std::max(mx, std::fabs(r_[a]));
    }
    precondition(r_, z_, w.y);
    // r·z in cell order, and x's update beside it (d is still this iteration's: the same
    // x; the sum is a chain of additions, and the update fills the core's idle slots).
    double rzNew = 0;
    for (std::size_t a = 0; a < m; ++a) {
      rzNew += double(r_[a]) * double(z_[a]);
      x[a] += alpha * d_[a];
    }
    const Real beta = Real(rzNew / rz);
    rz = rzNew;
    for (std::size_t a = 0; a < m; ++a) d_[a] = z_[a] + beta * d_[a];
    ++it;
    res = mx;
  }
  return it;
}

void GridProjection::pressureSystem(const StepContext& c) {
  const Real dt = c.dt;
  const int nu = nx_ + 1;
  const std::size_t m = cells_.size();
  rhs_.assign(m, 0);
  std::vector<Real>& x = x_;
  x.assign(m, 0);
  // Warm start from the last substep's κ of the same anchored cells (none when the cells
  // grew to hold spray: the same index is then another place).
  const bool sameCells = h_ == pH_;
  if (sameCells)
    forUnknowns([&](std::size_t a, int i, int j) {
      const long I = I0_ + i - pI0_, J = J0_ + j - pJ0_;
      if (I >= 0 && J >= 0 && I < pnx_ && J < pny_) x[a] = prevKappa_[std::size_t(J) * pnx_ + std::size_t(I)];
    });
  // A face against a moving body's cell carries the body's velocity there.
  auto uf = [&](int i, int j) {
    const std::size_t k = std::size_t(j) * nx_ + std::size_t(i);
    const int b = i > 0 && i < nx_ ? bodyAcross(k - 1, k) : -1;
    if (b >= 0) return bodyFaceVelocity(b, 0, i, j);
    return uOpen_[std::size_t(j) * nu + i] ? u_[std::size_t(j) * nu + i] : Real(0);
  };
  auto vf = [&](int i, int j) {
    const std::size_t k = std::size_t(j) * nx_ + std::size_t(i);
    const int b = j > 0 && j < ny_ ? bodyAcross(k - std::size_t(nx_), k) : -1;
    if (b >= 0) return bodyFaceVelocity(b, 1, i, j);
    return vOpen_[std::size_t(j) * nx_ + i] ? v_[std::size_t(j) * nx_ + i] : Real(0);
  };
  forUnknowns([&](std::size_t a, int i, int j) {
    const int k = cells_[a];
    const Real div = (uf(i + 1, j) - uf(i, j) + vf(i, j + 1) - vf(i, j)) * invH_;
    const Real comp = std::max(Real(0), comp_[std::size_t(k)] / w_[std::size_t(k)]);
    const Real src = div - rate_ * comp / dt;  // a compressed cell is to expand by rate·comp over the substep
    rhs_[a] = -(h_ * h_ / dt) * src;
  });
  balance(rhs_);
}

void GridProjection::shiftSystem(const StepContext& c) {
  // The compression shift's right-hand side: −∇²φ = rate·(comp − above)/dt² per fluid cell,
  // comp = the cell's particle weight over a full cell's, − 1 (a count, as Kugelstadt et al.:
  // the SPH density of a disordered packing reads high, and removing that lifted the water:
  // 1.5 % energy gain at 40k, 2.8 % at 80k). The particles move by −dt²∇φ in
  // transferToParticles, their velocities unchanged.
  const Real dt = c.dt;
  const std::size_t m = cells_.size();
  const Real invFull = Real(1) / (cellRatio_ * cellRatio_);
  rhsS_.resize(m);
  xs_.assign(m, 0);
  const std::size_t nx = std::size_t(nx_);
  for (std::size_t a = 0; a < m; ++a) {
    const std::size_t k = std::size_t(cells_[a]);
    const Real excess = w_[k] * invFull - Real(1);
    const Real comp = std::max(Real(0), excess - shiftDef_.above);
    Real src = shiftDef_.rate * comp;
    if (shiftDef_.fill > 0 && excess < -shiftDef_.above) {
      const std::size_t i = k % nx, j = k / nx;
      const bool interior = i > 0 && j > 0 && i + 1 < nx && j + 1 < std::size_t(ny_) && type_[k - 1] == kFluid &&
                            type_[k + 1] == kFluid && type_[k - nx] == kFluid && type_[k + nx] == kFluid;
      if (interior) src = shiftDef_.fill * (excess + shiftDef_.above);  // negative: the cell draws particles in
    }
    rhsS_[a] = (h_ * h_ / dt) * src / dt;
  }
  balance(rhsS_);
}

void GridProjection::solve(const StepContext& c) {
  const Real dt = c.dt;
  const std::size_t m = cells_.size();
  stats_ = GridProjectionStats{};
  stats_.fluidCells = int(m);
  kappa_.assign(type_.size(), 0);  // air and solid cells hold 0
  const bool shifting = shiftDef_.on();
  if (m == 0) {
    if (shifting) shiftMoves(c);  // none: no fluid cell
    return;
  }
  // The two solves share the matrix and nothing else: with two threads they run side by
  // side, each with its right-hand side first and in cell order on one thread (the same
  // bits for any thread count); the shift's, the shorter, goes on to its face moves. The
  // residual stands for a density change of |r| dt²/h² over the substep.
  std::vector<Real>& x = x_;  // the unknowns, in cell order (kept: no allocation in the step)
  Real res = 0, resS = 0;
  int itS = 0;
  const Real scale = h_ * h_ / (dt * dt);
  couplingScale_ = double(c.rho0) * double(h_) * double(h_);
  const bool coupled = !coupling_.empty();
  c.pool.parallelFor(shifting ? 2 : 1, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      if (k == 0) {
        pressureSystem(c);
        stats_.iterations = pcg(x, rhs_, tol_ * scale, res, cgMain_, coupled);
      } else {
        shiftSystem(c);
        itS = pcg(xs_, rhsS_, shiftDef_.tolerance * scale, resS, cgShift_, false);
        kappaS_.assign(type_.size(), 0);
        for (std::size_t a = 0; a < m; ++a) kappaS_[std::size_t(cells_[a])] = xs_[a];
        shiftMoves(c);
      }
    }
  });
  if (coupled) {
    // Each dynamic body takes the pressure's impulse J = ρ0 h dt Σ κ G (force p·h per face,
    // along n into the body, and its torque about the centre of mass) at the substep's start.
    std::vector<double>& J = bodyImpulse_;
    J.assign(3 * bodies_.size(), 0.0);
    for (const Coupling& e : coupling_)
      for (int q = 0; q < 3; ++q) J[3 * std::size_t(e.body) + std::size_t(q)] += e.g[q] * double(x[std::size_t(e.unknown)]);
    const double f = double(c.rho0) * double(h_) * double(dt);
    const double tau0 = c.time - c.solids->time0;
    for (std::size_t b = 0; b < bodies_.size(); ++b) {
      if (!(bodies_[b].invMass > 0)) continue;
      const Vec2d Jl(f * J[3 * b], f * J[3 * b + 1]);
      const double L = f * J[3 * b + 2];
      c.solids->bodies[b].push(tau0, Jl, L);
      bodies_[b].v = c.solids->bodies[b].v;
      bodies_[b].omega = c.solids->bodies[b].omega;
    }
  }
  stats_.iterations += itS;
  stats_.pockets = int(pocketLast_.size());
  stats_.residual = double(res * dt * dt * invH_ * invH_);
  for (std::size_t a = 0; a < m; ++a) kappa_[std::size_t(cells_[a])] = x[a];
  pH_ = h_;
  pI0_ = I0_;
  pJ0_ = J0_;
  pnx_ = nx_;
  pny_ = ny_;
  prevKappa_ = kappa_;
}

GridProjection::FaceWeights GridProjection::faceWeights(Real px, Real py) const {
  // Bilinear over the MAC faces: u at (i, j + 1/2), v at (i + 1/2, j), in cell units of the
  // grid (px, py ≥ 0: the grid has a margin, so truncation is floor).
  FaceWeights w;
  {
    const Real fx = px, fy = py - Real(0.5);
    const int i0 = int(fx), j0 = int(fy);
    const Real tx = fx - Real(i0), ty = fy - Real(j0);
    w.ku = std::size_t(j0) * std::size_t(nx_ + 1) + std::size_t(i0);
    w.u[0] = (1 - tx) * (1 - ty);
    w.u[1] = tx * (1 - ty);
    w.u[2] = (1 - tx) * ty;
    w.u[3] = tx * ty;
  }
  {
    const Real fx = px - Real(0.5), fy = py;
    const int i0 = int(fx), j0 = int(fy);
    const Real tx = fx - Real(i0), ty = fy - Real(j0);
    w.kv = std::size_t(j0) * std::size_t(nx_) + std::size_t(i0);
    w.v[0] = (1 - tx) * (1 - ty);
    w.v[1] = tx * (1 - ty);
    w.v[2] = (1 - tx) * ty;
    w.v[3] = tx * ty;
  }
  return w;
}

Vec2 GridProjection::sampleFaces(const std::vector<Real>& u, const std::vector<Real>& v, const FaceWeights& w) const {
  const std::size_t nu = std::size_t(nx_ + 1), k = w.ku, kv = w.kv, nv = std::size_t(nx_);
  const Real ux = w.u[0] * u[k] + w.u[1] * u[k + 1] + w.u[2] * u[k + nu] + w.u[3] * u[k + nu + 1];
  const Real uy = w.v[0] * v[kv] + w.v[1] * v[kv + 1] + w.v[2] * v[kv + nv] + w.v[3] * v[kv + nv + 1];
  return Vec2(ux, uy);
}

void GridProjection::extrapolate(std::vector<Real>& d, int w, int h, const std::vector<std::uint8_t>& known) {
  // One layer: an unknown face next to known ones (along either axis) takes their
  // mean, so a particle between a fluid cell and a solid or air cell gets the
  // fluid's full velocity change (Bridson's extrapolation, ch. 4.1). Reads only
  // the known faces: the result does not depend on the visiting order.
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const std::size_t f = std::size_t(j) * w + i;
      if (known[f]) continue;
      Real sum = 0;
      int n = 0;
      if (i > 0 && known[f - 1]) sum += d[f - 1], ++n;
      if (i + 1 < w && known[f + 1]) sum += d[f + 1], ++n;
      if (j > 0 && known[f - std::size_t(w)]) sum += d[f - std::size_t(w)], ++n;
      if (j + 1 < h && known[f + std::size_t(w)]) sum += d[f + std::size_t(w)], ++n;
      if (n > 0) d[f] = sum / Real(n);
    }
}

void GridProjection::shiftMoves(const StepContext& c) {
  // The shift's face moves: −dt²∇φ across open faces between fluid and air cells (none
  // through a wall or a moving body), extrapolated one layer as the velocity change is.
  const Real dt = c.dt;
  const int nu = nx_ + 1;
  const Real k2 = -dt * dt * invH_;
  auto phi = [&](int i, int j) {  // φ in a fluid cell, 0 elsewhere (air holds 0)
    return type_[std::size_t(j) * nx_ + i] == kFluid ? kappaS_[std::size_t(j) * nx_ + i] : Real(0);
  };
  su_.assign(u_.size(), 0);
  sv_.assign(v_.size(), 0);
  for (int j = 0; j < ny_; ++j)
    for (int i = 1; i < nx_; ++i) {
      const std::size_t f = std::size_t(j) * nu + i;
      if (!fluidU_[f]) continue;
      const std::size_t kl = std::size_t(j) * nx_ + i - 1, kr = kl + 1;
      const bool solidSide = type_[kl] == kSolid || type_[kr] == kSolid;
      if (uOpen_[f] && !solidSide && bodyAcross(kl, kr) < 0) su_[f] = k2 * (phi(i, j) - phi(i - 1, j));
    }
  extrapolate(su_, nu, ny_, fluidU_);
  for (int j = 1; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) {
      const std::size_t f = std::size_t(j) * nx_ + i;
      if (!fluidV_[f]) continue;
      const std::size_t kd = std::size_t(j - 1) * nx_ + i, ku = kd + std::size_t(nx_);
      const bool solidSide = type_[kd] == kSolid || type_[ku] == kSolid;
      // Under the ghost surface the gradient spans θ of a cell (the matrix's 1/θ).
      const Real span = surface_ && type_[ku] == kAir ? thetaUp_[kd] : Real(1);
      if (vOpen_[f] && !solidSide && bodyAcross(kd, ku) < 0) sv_[f] = k2 * (phi(i, j) - phi(i, j - 1)) / span;
    }
  extrapolate(sv_, nx_, ny_ + 1, fluidV_);
}

std::size_t GridProjection::transferToParticles(StepContext& c) {
  const Real dt = c.dt;
  const int nu = nx_ + 1;
  // κ in a fluid cell, 0 elsewhere (air holds 0; solid faces are not read).
  auto kap = [&](int i, int j) {
    return type_[std::size_t(j) * nx_ + i] == kFluid ? kappa_[std::size_t(j) * nx_ + i] : Real(0);
  };
  const bool shifting = shiftDef_.on();
  // The static solids' impulse on the fluid (World::wallImpulse, WallImpulse::grid), per axis in
  // face order within its task: on each face closed by a static solid (a solid cell beside it, or
  // a wall across it) next to a fluid cell, the cell's pressure ρ0κ over the face's length h for
  // dt, pushing away from the face; and the normal velocity the face removes, −u_f, times the
  // particle mass on the face (m × its splat weight). Between fluid cells the pressure gradient
  // telescopes to these end terms on a grid of uniform mass ρ0h² a face; a moving body's faces
  // are not static (the body takes their impulse).
  const bool countWall = c.wall != nullptr;
  const double wallP = double(c.mass) / (double(c.dx) * double(c.dx)) * double(h_) * double(dt), wallM = double(c.mass);
  double wallAxis[2] = {0, 0};
  // The u faces and the v faces are independent: two tasks, each serial. Open faces
  // next to fluid take the pressure gradient; closed faces next to fluid lose their
  // normal velocity (the wall).
  c.pool.parallelFor(2, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t task = b; task < e; ++task) {
      if (task == 0) {
        for (int j = 0; j < ny_; ++j)
          for (int i = 1; i < nx_; ++i) {
            const std::size_t f = std::size_t(j) * nu + i;
            if (!fluidU_[f]) continue;
            const std::size_t kl = std::size_t(j) * nx_ + i - 1, kr = kl + 1;
            const bool solidSide = type_[kl] == kSolid || type_[kr] == kSolid;
            const int body = solidSide ? -1 : bodyAcross(kl, kr);
            du_[f] = body >= 0                    ? bodyFaceVelocity(body, 0, i, j) - u_[f]  // a moving body's face
                     : uOpen_[f] && !solidSide ? -dt * (kap(i, j) - kap(i - 1, j)) * invH_
                                               : -u_[f];
            if (countWall && body < 0 && !(uOpen_[f] && !solidSide))
              wallAxis[0] += wallP * (double(kap(i, j)) - double(kap(i - 1, j))) + wallM * double(uw_[f]) * double(du_[f]);
          }
        extrapolate(du_, nu, ny_, fluidU_);
        if (pic_ > 0)  // the projected face velocities (closed faces: 0)
          for (std::size_t f = 0; f < u_.size(); ++f) uNew_[f] = u_[f] + du_[f];
      } else {
        for (int j = 1; j < ny_; ++j)
          for (int i = 0; i < nx_; ++i) {
            const std::size_t f = std::size_t(j) * nx_ + i;
            if (!fluidV_[f]) continue;
            const std::size_t kd = std::size_t(j - 1) * nx_ + i, ku = kd + std::size_t(nx_);
            const bool solidSide = type_[kd] == kSolid || type_[ku] == kSolid;
            const int body = solidSide ? -1 : bodyAcross(kd, ku);
            // Under the ghost surface the gradient spans θ of a cell (the matrix's 1/θ).
            const Real span = surface_ && type_[ku] == kAir ? thetaUp_[kd] : Real(1);
            dv_[f] = body >= 0                    ? bodyFaceVelocity(body, 1, i, j) - v_[f]
                     : vOpen_[f] && !solidSide ? -dt * (kap(i, j) - kap(i, j - 1)) * invH_ / span
                                               : -v_[f];
            if (countWall && body < 0 && !(vOpen_[f] && !solidSide))
              wallAxis[1] += wallP * (double(kap(i, j)) - double(kap(i, j - 1))) + wallM * double(vw_[f]) * double(dv_[f]);
          }
        extrapolate(dv_, nx_, ny_ + 1, fluidV_);
        if (pic_ > 0)
          for (std::size_t f = 0; f < v_.size(); ++f) vNew_[f] = v_[f] + dv_[f];
      }
    }
  });
  if (countWall) c.wall->sum.grid += Vec2d(wallAxis[0], wallAxis[1]);
  ParticleStore& P = c.P;
  const Real vmax2 = c.maxSpeed * c.maxSpeed;
  if (shifting) shift_.resize(P.size());
  else shift_.clear();
  return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
    std::size_t bad = kNone;
    for (std::size_t p = b; p < e; ++p) {
      const Real px = P.x[p].x() * invH_ - Real(I0_), py = P.x[p].y() * invH_ - Real(J0_);
      const FaceWeights w = faceWeights(px, py);  // the same for every face field
      const Vec2 v0 = P.v[p];
      Vec2 vp = v0 + sampleFaces(du_, dv_, w);  // FLIP: the change of the grid velocity
      if (pic_ > 0) {
        // PIC share: towards the projected grid velocity itself (smooths particle noise).
        const Vec2 ug = sampleFaces(uNew_, vNew_, w);
        vp += (ug - vp) * pic_;
      }
      if (flipClamp_) vp = clampToFaces(vp, v0, w);
      P.v[p] = vp;
      if (shifting) shift_[p] = sampleFaces(su_, sv_, w);
      if (bad == kNone && (!allFinite(P.v[p]) || P.v[p].squaredNorm() > vmax2)) bad = p;
    }
    return bad;
  });
}

Vec2 GridProjection::clampToFaces(const Vec2& vp, const Vec2& v0, const FaceWeights& w) const {
  // The particle no faster than it was, or than the projected velocity (u + Δu) of the faces
  // it samples can make it (the largest |u| and |v| of its stencil together): the transfer
  // makes no new extreme of speed. Only the speed is limited, not the direction (a clamp per
  // axis made a resting tank creep sideways, 4 mm in 333 s).
  const std::size_t nu = std::size_t(nx_ + 1), nv = std::size_t(nx_);
  const std::size_t ku[4] = {w.ku, w.ku + 1, w.ku + nu, w.ku + nu + 1};
  const std::size_t kv[4] = {w.kv, w.kv + 1, w.kv + nv, w.kv + nv + 1};
  Real u2 = 0, v2 = 0;
  for (int q = 0; q < 4; ++q) {
    const Real u = u_[ku[q]] + du_[ku[q]], v = v_[kv[q]] + dv_[kv[q]];
    u2 = std::max(u2, u * u);
    v2 = std::max(v2, v * v);
  }
  const Real limit2 = std::max(v0.squaredNorm(), u2 + v2), s2 = vp.squaredNorm();
  return s2 > limit2 ? Vec2(vp * std::sqrt(limit2 / s2)) : vp;
}

Real GridProjection::kappaAt(const Vec2& x) const {
  if (nx_ < 2 || ny_ < 2 || kappa_.size() != std::size_t(nx_) * std::size_t(ny_)) return 0;
  const Real fx = x.x() * invH_ - Real(I0_) - Real(0.5), fy = x.y() * invH_ - Real(J0_) - Real(0.5);
  if (!(fx >= 0 && fy >= 0 && fx < Real(nx_ - 1) && fy < Real(ny_ - 1))) return 0;  // also NaN
  const int i0 = int(fx), j0 = int(fy);
  const Real tx = fx - Real(i0), ty = fy - Real(j0);
  const std::size_t k = std::size_t(j0) * nx_ + i0;
  const std::size_t ks[4] = {k, k + 1, k + nx_, k + nx_ + 1};
  const Real wq[4] = {(1 - tx) * (1 - ty), tx * (1 - ty), (1 - tx) * ty, tx * ty};
  Real sum = 0, wsum = 0;
  for (int q = 0; q < 4; ++q) {
    if (type_[ks[q]] == kSolid || type_[ks[q]] == kBody) continue;
    wsum += wq[q];
    if (type_[ks[q]] == kFluid) sum += wq[q] * kappa_[ks[q]];
  }
  return wsum > 0 ? sum / wsum : Real(0);
}

std::size_t GridProjection::project(StepContext& c) {
  if (c.P.size() == 0 || !(c.dt > 0)) return kNone;
  dx_ = c.dx;
  layout(c);
  // The cells' particle weights decide the cell types and the matrix; the face
  // velocities are read only by the solve. Three tasks, each serial: the cells with the
  // classification and the matrix (the longest), the u faces, the v faces.
  c.pool.parallelFor(3, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t task = b; task < e; ++task) {
      if (task == 0) {
        resetCells();
        splatCells(c);
        classify(c);
        assemble();
      } else {
        resetFaces(int(task) - 1);
        splatFaces(c, int(task) - 1);
      }
    }
  });
  solve(c);
  return transferToParticles(c);
}

void GridProjection::saveState(StateOut& out) const {
  out.put(pH_);
  out.put(std::int64_t(pI0_));
  out.put(std::int64_t(pJ0_));
  out.put(std::int32_t(pnx_));
  out.put(std::int32_t(pny_));
  out.putVector(prevKappa_);
}

void GridProjection::loadState(StateIn& in, std::size_t maxCells) {
  const Real h = in.get<Real>("the grid's cell size");
  const std::int64_t i0 = in.get<std::int64_t>("the grid's origin"), j0 = in.get<std::int64_t>("the grid's origin");
  const std::int32_t nx = in.get<std::int32_t>("the grid's size"), ny = in.get<std::int32_t>("the grid's size");
  std::vector<Real> k;
  in.getVector(k, maxCells, "the grid's pressure");
  if (!(h >= 0) || nx < 0 || ny < 0 || std::uint64_t(nx) * std::uint64_t(ny) != k.size())
    throw SaveError("the saved state is malformed: the grid's pressure does not fit its size");
  pH_ = h;
  pI0_ = long(i0);
  pJ0_ = long(j0);
  pnx_ = nx;
  pny_ = ny;
  prevKappa_ = std::move(k);
}

}  // namespace sph2d
