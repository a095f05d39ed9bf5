// The viscosity effect's implicit step (viscosity_implicit.hpp). Units: masses in particle
// masses m (s_i = r_i, the rest ratio, or 1), velocities in m/s; the coefficients are the
// explicit effect's (viscosity.cpp) without its pair cap.
#include "effects/viscosity_implicit.hpp"

#include <algorithm>
#include <cmath>

#include "bodies/body_samples.hpp"
#include "bodies/moving_solid.hpp"

namespace sph2d {
namespace {

double sumParts(ThreadPool& pool, std::size_t n, const std::function<double(std::size_t, std::size_t)>& fn) {
  return pool.reduce<double>(n, kBlock, 0.0, fn, [](double a, double b) { return a + b; });
}

/// ω × arm per unit ω.
Vec2d perp(const Vec2& arm) { return Vec2d(-double(arm.y()), double(arm.x())); }

}  // namespace

double flatFaceLaplacian(const ViscosityKernel<Real>& W, double dx, double distance) {
  const double R = double(W.R);
  const int steps = 64;  // along the face: Simpson's rule over the layer's chord of the support
  double g = 0;
  for (double y = std::max(0.0, distance) + 0.5 * dx; y < R; y += dx) {
    const double half = std::sqrt(R * R - y * y), h = 2 * half / steps;
    double layer = 0;
    for (int k = 0; k <= steps; ++k) {
      const double a = -half + k * h, f = double(W.laplacianR2(Real(a * a + y * y)));
      layer += f * (k == 0 || k == steps ? 1 : k % 2 ? 4 : 2);
    }
    g += layer * h / 3 * dx;  // samples dx apart along the face, each of volume dx²
  }
  return g;
}

double ImplicitViscosity::dot(StepContext& c, const Vec& a, const Vec& b) {
  double s = sumParts(c.pool, a.p.size(), [&](std::size_t lo, std::size_t hi) {
    double d = 0;
    for (std::size_t i = lo; i < hi; ++i) d += a.p[i].dot(b.p[i]);
    return d;
  });
  for (std::size_t k = 0; k < a.b.size(); ++k) s += a.b[k].v.dot(b.b[k].v) + a.b[k].w * b.b[k].w;
  return s;
}

void ImplicitViscosity::precondition(StepContext& c, const Vec& r, Vec& z) {
  c.pool.parallelFor(r.p.size(), kBlock, [&](std::size_t lo, std::size_t hi) {
    for (std::size_t i = lo; i < hi; ++i) z.p[i] = r.p[i] / diag_[i];
  });
  for (std::size_t k = 0; k < r.b.size(); ++k) {
    z.b[k].v = r.b[k].v / bodyDiag_[k].v.x();
    z.b[k].w = r.b[k].w / bodyDiag_[k].w;
  }
}

double ImplicitViscosity::multiply(StepContext& c, const Vec& x, Vec& out) {
  const std::size_t nb = x.b.size();
  double dotP = sumParts(c.pool, x.p.size(), [&](std::size_t lo, std::size_t hi) {
    const std::size_t blk = lo / kBlock;
    const Real* S = coef_[blk].data();
    const std::vector<Link>& L = links_[blk];
    std::vector<BodyVel>& part = partial_[blk];
    std::fill(part.begin(), part.end(), BodyVel{});
    std::size_t q = 0;
    double dot = 0;
    for (std::size_t i = lo; i < hi; ++i) {
      Vec2d s = x.p[i] * diag_[i];
      if (!coupled_[i]) {  // no pair and no body: its row is its diagonal alone
        out.p[i] = s;
        dot += x.p[i].dot(s);
        continue;
      }
      const std::uint32_t* nbr = c.nbr.of(i);
      const Real* Si = S + c.nbr.start[i];
      for (std::uint32_t k = 0; k < c.nbr.count[i]; ++k) s -= x.p[nbr[k]] * double(Si[k]);
      for (; q < L.size() && L[q].particle == i; ++q) {
        const Link& l = L[q];
        s -= x.b[l.body].v * l.E + l.P * x.b[l.body].w;
        part[l.body].v += x.p[i] * l.E;
        part[l.body].w += l.P.dot(x.p[i]);
      }
      out.p[i] = s;
      dot += x.p[i].dot(s);
    }
    return dot;
  });
  for (std::size_t k = 0; k < nb; ++k) {
    BodyVel o;
    o.v = x.b[k].v * bodyDiag_[k].v.x() + bodyP_[k] * x.b[k].w;
    o.w = bodyP_[k].dot(x.b[k].v) + bodyDiag_[k].w * x.b[k].w;
    for (const std::vector<BodyVel>& part : partial_) {
      o.v -= part[k].v;
      o.w -= part[k].w;
    }
    out.b[k] = o;
    dotP += x.b[k].v.dot(o.v) + x.b[k].w * o.w;
  }
  return dotP;
}

std::size_t ImplicitViscosity::apply(StepContext& c, const ViscosityTerm& t, const ViscosityWeights& w, bool count,
                                     std::vector<Vec2d>& wallBlock) {
  ParticleStore& P = c.P;
  const std::size_t n = P.size();
  const Real dt = c.dt;
  const Vec2* X = P.x.data();
  const Real* IR = P.invRho.data();
  const BoundarySet& B = c.boundary;
  BodySamples* moving = t.noSlip && c.bodySamples && c.bodySamples->active() ? c.bodySamples : nullptr;
  const ShapeContacts* shapes = !moving && c.solids && w.shapes && !w.shapes->list.empty() ? w.shapes : nullptr;
  // The dynamic bodies' unknowns: every placed body has a row (a kinematic one's stays at 0).
  const std::size_t nb = moving && c.solids ? std::min(moving->placed.size(), c.solids->bodies.size())
                         : shapes           ? c.solids->bodies.size()
                                            : 0;
  auto isDynamic = [&](std::uint32_t k) {
    return k < nb && (moving ? moving->placed[k].dynamic : c.solids->bodies[k].dynamic());
  };
  const double tau = c.solids ? double(c.time) - c.solids->time0 : 0.0;
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  coef_.resize(blocks);
  links_.resize(blocks);
  partial_.resize(blocks);
  for (std::vector<BodyVel>& part : partial_) part.resize(nb);
  diag_.resize(n);
  coupled_.resize(n);
  for (Vec* v : {&b_, &x_, &r_, &z_, &d_, &q_}) {
    v->p.resize(n);
    v->b.assign(nb, BodyVel{});
  }
  std::vector<double>& wallG = wallG_;
  wallG.resize(t.walls ? n : 0);

  // The system: pair coefficients, diagonal, right-hand side, and x = v* to start from.
  c.pool.parallelFor(n, kBlock, [&](std::size_t lo, std::size_t hi) {
    std::vector<Real>& S = coef_[lo / kBlock];
    std::vector<Link>& L = links_[lo / kBlock];
    S.resize(c.nbr.perBlock[lo / kBlock].size());
    L.clear();
    for (std::size_t i = lo; i < hi; ++i) {
      const Real si = w.ratio ? w.ratio[i] : Real(1);
      const Real reli = w.rel ? w.rel[i] : Real(1);
      const std::uint32_t* nbr = c.nbr.of(i);
      Real* Si = S.data() + c.nbr.start[i];
      double rowSum = 0;
      for (std::uint32_t k = 0; k < c.nbr.count[i]; ++k) {
        const std::uint32_t j = nbr[k];
        Real dx = X[i].x() - X[j].x(), dy = X[i].y() - X[j].y();
        c.periodic.nearest(dx, dy);
        // Symmetric to the bit: every factor is a commutative product or sum of i's and j's.
        Real g = t.muMass * t.W.laplacianR2(dx * dx + dy * dy) * (IR[i] * IR[j]);
        if (w.ratio) g *= si * w.ratio[j];
        if (w.rel) g *= (reli + w.rel[j]) * Real(0.5);
        if (w.member && !(w.member[i] && w.member[j])) g = 0;
        Si[k] = dt * g;
        rowSum += double(Si[k]);
      }
      const double vK = double(t.wallFactor) * double(IR[i] * si) * (w.nuRel ? double(w.nuRel[i]) : 1.0);
      const double e = double(dt) * double(si) * vK;  // e_is per Σ Ψ_s ∇²W_is
      double gi = 0;  // Σ_b Ψ_b ∇²W_ib over the walls' and the moving bodies' samples
      Vec2d h(0, 0);  // Σ_s Ψ_s ∇²W_is v_s over the samples whose velocity is given
      if (t.walls) {
        const std::uint32_t* bl = c.nbr.boundaryOf(i);
        for (std::uint32_t k = 0; k < c.nbr.boundaryCount[i]; ++k) {
          const std::uint32_t s = bl[k];
          gi += double(B.volume[s] * t.W.laplacianR2((X[i] - B.samples[s]).squaredNorm()));
        }
        wallG[i] = vK * gi;
      }
      if (moving && c.nbr.movingCount[i] > 0)
        moving->forEachBody(c.nbr.movingOf(i), c.nbr.movingCount[i],
                            [&](std::uint32_t body, const std::uint32_t* run, const std::uint32_t* runEnd) {
                              // The body's velocity at the particle, v_s + ω × (x_i − x_s) (BodySamples::velocityAt).
                              const bool dyn = isDynamic(body);
                              const double omega = c.solids ? c.solids->bodies[body].omega : 0.0;
                              const std::uint32_t first = *run;
                              const Vec2 arm = moving->arm[first] + (X[i] - moving->x[first]);  // x_i − com
                              double sum = 0;
                              for (const std::uint32_t* p = run; p != runEnd; ++p) {
                                const std::uint32_t s = *p;
                                const double q =
                                    double(moving->volume[s] * t.W.laplacianR2((X[i] - moving->x[s]).squaredNorm()));
                                sum += q;
                                if (!dyn) h += moving->velocityAt(s, omega, X[i]) * q;
                              }
                              gi += sum;
                              if (!dyn) return;
                              Link l{std::uint32_t(i), body, e * sum, Vec2d(0, 0), 0};
                              if (c.solids->bodies[body].invInertia > 0) {
                                l.P = perp(arm) * l.E;
                                l.A = double(arm.squaredNorm()) * l.E;
                              } else {  // it cannot turn: its spin is given
                                h += perp(arm) * (omega * sum);
                              }
                              L.push_back(l);
                            });
      if (shapes)  // a body's face as its samples would be (ShapeContacts)
        for (std::uint32_t k = shapes->start[i]; k < shapes->start[i + 1]; ++k) {
          const ShapeContacts::Contact& ct = shapes->list[k];
          const MovingSolid& m = c.solids->bodies[ct.body];
          gi += ct.g;
          const Vec2d xi = X[i].cast<double>(), arm = xi - m.centreAt(tau);
          if (!isDynamic(ct.body)) {
            h += m.velocityAt(tau, xi) * ct.g;
            continue;
          }
          Link l{std::uint32_t(i), ct.body, e * ct.g, Vec2d(0, 0), 0};
          if (m.invInertia > 0) {
            l.P = Vec2d(-arm.y(), arm.x()) * l.E;
            l.A = arm.squaredNorm() * l.E;
          } else {
            h += Vec2d(-arm.y(), arm.x()) * (m.omega * ct.g);
          }
          L.push_back(l);
        }
      diag_[i] = double(si) * (1.0 + double(dt) * vK * gi) + rowSum;
      coupled_[i] = rowSum != 0 || (!L.empty() && L.back().particle == i);
      const Vec2d vStar = (P.v[i] + P.a[i] * dt).cast<double>();
      b_.p[i] = vStar * double(si) + h * e;
      x_.p[i] = vStar;
    }
  });
  // The bodies' rows, from their links (blocks in order). Through ShapeContacts, a body no
  // particle touches has the row of a given velocity (its m·v would loosen the stop norm).
  bodyDiag_.assign(nb, BodyVel{});
  bodyP_.assign(nb, Vec2d(0, 0));
  linked_.assign(nb, shapes ? 0 : 1);
  if (shapes)
    for (const std::vector<Link>& L : links_)
      for (const Link& l : L) linked_[l.body] = 1;
  for (std::size_t k = 0; k < nb; ++k) {
    if (!isDynamic(std::uint32_t(k)) || !linked_[k]) {
      bodyDiag_[k].v = Vec2d(1, 1);
      bodyDiag_[k].w = 1;
      continue;
    }
    const MovingSolid& m = c.solids->bodies[k];
    const double mass = 1.0 / (m.invMass * double(c.momentumMass));
    const double inertia = m.invInertia > 0 ? 1.0 / (m.invInertia * double(c.momentumMass)) : 1.0;
    bodyDiag_[k].v = Vec2d(mass, mass);
    bodyDiag_[k].w = inertia;
    b_.b[k].v = m.v * mass;
    b_.b[k].w = m.invInertia > 0 ? m.omega * inertia : m.omega;
    x_.b[k].v = m.v;
    x_.b[k].w = m.omega;
  }
  for (const std::vector<Link>& L : links_)
    for (const Link& l : L) {
      bodyDiag_[l.body].v += Vec2d(l.E, l.E);
      bodyDiag_[l.body].w += l.A;
      bodyP_[l.body] += l.P;
    }
  const double bb = dot(c, b_, b_);

  // Conjugate gradients, preconditioned by the diagonal.
  multiply(c, x_, q_);
  for (std::size_t i = 0; i < n; ++i) r_.p[i] = b_.p[i] - q_.p[i];
  for (std::size_t k = 0; k < nb; ++k) {
    r_.b[k].v = b_.b[k].v - q_.b[k].v;
    r_.b[k].w = b_.b[k].w - q_.b[k].w;
  }
  precondition(c, r_, z_);
  d_ = z_;
  double rz = dot(c, r_, z_);
  const double stop2 = kTolerance * kTolerance * bb;
  iterations_ = 0;
  while (iterations_ < kMaxIterations && rz > 0) {
    const double dq = multiply(c, d_, q_);
    if (!(dq > 0)) break;
    const double alpha = rz / dq;
    c.pool.parallelFor(n, kBlock, [&](std::size_t lo, std::size_t hi) {
      for (std::size_t i = lo; i < hi; ++i) {
        x_.p[i] += d_.p[i] * alpha;
        r_.p[i] -= q_.p[i] * alpha;
      }
    });
    for (std::size_t k = 0; k < nb; ++k) {
      x_.b[k].v += d_.b[k].v * alpha;
      x_.b[k].w += d_.b[k].w * alpha;
      r_.b[k].v -= q_.b[k].v * alpha;
      r_.b[k].w -= q_.b[k].w * alpha;
    }
    ++iterations_;
    if (dot(c, r_, r_) <= stop2) break;
    precondition(c, r_, z_);
    const double rzNew = dot(c, r_, z_);
    const double beta = rzNew / rz;
    rz = rzNew;
    c.pool.parallelFor(n, kBlock, [&](std::size_t lo, std::size_t hi) {
      for (std::size_t i = lo; i < hi; ++i) d_.p[i] = z_.p[i] + d_.p[i] * beta;
    });
    for (std::size_t k = 0; k < nb; ++k) {
      d_.b[k].v = z_.b[k].v + d_.b[k].v * beta;
      d_.b[k].w = z_.b[k].w + d_.b[k].w * beta;
    }
  }

  // a_i += (v'_i − v*_i)/dt; the walls' force on the fluid and the moving bodies' reactions
  // from v' (a dynamic body's samples at its solved velocity and spin).
  const std::size_t firstBadSlot = firstBad(c.pool, n, [&](std::size_t lo, std::size_t hi) {
    std::size_t bad = kNone;
    Vec2d wallAcc(0, 0);
    std::vector<BodyVel>& react = partial_[lo / kBlock];  // the shapes' reactions, this block's
    std::fill(react.begin(), react.end(), BodyVel{});
    for (std::size_t i = lo; i < hi; ++i) {
      const Real si = w.ratio ? w.ratio[i] : Real(1);
      const Vec2d vStar = (P.v[i] + P.a[i] * dt).cast<double>();
      const Vec2 acc = ((x_.p[i] - vStar) / double(dt)).cast<Real>();
      P.a[i] += acc;
      if (!allFinite(acc) && bad == kNone) bad = i;
      if (t.walls && count) wallAcc -= x_.p[i] * (wallG[i] * double(si));
      if (shapes && shapes->start[i] < shapes->start[i + 1]) {
        const double vK = double(t.wallFactor) * double(IR[i] * si) * (w.nuRel ? double(w.nuRel[i]) : 1.0);
        const double mass = double(c.momentumMass) * double(si);
        for (std::uint32_t k = shapes->start[i]; k < shapes->start[i + 1]; ++k) {
          const ShapeContacts::Contact& ct = shapes->list[k];
          if (!isDynamic(ct.body)) continue;
          const BodyVel& u = x_.b[ct.body];
          const Vec2d arm = X[i].cast<double>() - c.solids->bodies[ct.body].centreAt(tau);
          const Vec2d lv = (x_.p[i] - (u.v + Vec2d(-arm.y(), arm.x()) * u.w)) * ct.g;
          react[ct.body].v += lv * (vK * mass);  // the particle's pull on the body
          react[ct.body].w += (arm.x() * lv.y() - arm.y() * lv.x()) * vK * mass;
        }
      }
      if (!moving || c.nbr.movingCount[i] == 0) continue;
      const Vec2 xi = X[i];
      const Vec2 vi = x_.p[i].cast<Real>();
      const Real vK = t.wallFactor * IR[i] * si * (w.nuRel ? w.nuRel[i] : Real(1));
      moving->forEachBody(c.nbr.movingOf(i), c.nbr.movingCount[i],
                          [&](std::uint32_t body, const std::uint32_t* run, const std::uint32_t* runEnd) {
                            if (!isDynamic(body)) return;
                            const BodyVel& u = x_.b[body];
                            const Vec2 arm = moving->arm[*run] + (xi - moving->x[*run]);  // x_i − com
                            Real sum = 0;
                            for (const std::uint32_t* p = run; p != runEnd; ++p)
                              sum += moving->volume[*p] * t.W.laplacianR2((xi - moving->x[*p]).squaredNorm());
                            const Vec2 lv = (vi - (u.v + perp(arm) * u.w).cast<Real>()) * sum;
                            const Real tv = BodySamples::torque(arm, lv);
                            const double mass = double(c.momentumMass) * double(si);
                            moving->addReaction(lo / kBlock, body, (-lv * vK).cast<double>() * mass,
                                                -double(tv) * double(vK) * mass);
                          });
    }
    if (count) wallBlock[lo / kBlock] = wallAcc;
    return bad;
  });
  if (shapes)  // the bodies take the reactions, block by block in order
    for (std::size_t k = 0; k < nb; ++k) {
      if (!isDynamic(std::uint32_t(k)) || !linked_[k]) continue;
      BodyVel J;
      for (const std::vector<BodyVel>& part : partial_) {
        J.v += part[k].v;
        J.w += part[k].w;
      }
      c.solids->bodies[k].push(tau, J.v * double(dt), J.w * double(dt));  // the particles' pull over the substep
    }
  return firstBadSlot;
}

}  // namespace sph2d
