// pbf — Position Based Fluids (Macklin & Müller 2013, "Position Based Fluids",
// ACM TOG 32(4)): the substep around the density solve. The Pbf object, its
// stage list, the solve loop (Jacobi iterations with Chebyshev weights, Wang
// 2015; then the local iterations and the step-limit controller), the
// prediction, the final density and pressure, and the velocity with XSPH
// (Monaghan 1989). The method and its design choices: pbf.hpp; the
// constraint and correction passes: pbf_constraint.cpp; the parameters and
// the registrations of pbf and game, and the calibration of D0: pbf_params.cpp.
#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "core/state_io.hpp"
#include "solvers/pbf/pbf.hpp"
#include "step/stages.hpp"

namespace sph2d {

Pbf::Pbf(const SolverDef& d)
    : name_(d.type == "game" ? "game" : "pbf"),
      iterations_(int(std::lround(d.param("iterations")))),
      maxIterations_(int(std::lround(d.param("max_iterations")))),
      chebPlainAbove_(Real(d.param("chebyshev_plain_above"))),
      tolerance_(Real(d.param("tolerance"))),
      toleranceMax_(Real(d.param("tolerance_max"))),
      relaxation_(Real(d.param("relaxation"))),
      chebyshev_(Real(d.param("chebyshev"))),
      tensileK_(Real(d.param("tensile_k"))),
      tensileN_(int(std::lround(d.param("tensile_n")))),
      tensileDq_(Real(d.param("tensile_dq"))),
      xsph_(Real(d.param("xsph"))),
      maxDt_(Real(d.param("max_dt"))),
      maxMove_(Real(d.param("max_move"))),
      toVelocity_(Real(d.param("correction_to_velocity"))),
      pushoutSpeed_(Real(d.param("pushout_speed"))),
      maxApproach_(Real(d.param("max_approach"))),
      adaptiveDt_(d.param("adaptive_dt") != 0),
      quantile_(Real(d.param("speed_quantile"))),
      moveCap_(Real(d.param("move_cap"))),
      localIterations_(int(std::lround(d.param("local_iterations")))),
      resolveEach_(d.param("resolve_each") != 0) {
  if (d.param("grid_cell") > 0)
    projection_ = std::make_unique<GridProjection>(
        Real(d.param("grid_cell")), Real(d.param("grid_fluid_fraction")), Real(d.param("grid_compression_rate")),
        Real(d.param("grid_tolerance")), int(std::lround(d.param("grid_max_iterations"))),
        GridShift{Real(d.param("grid_shift")), Real(d.param("grid_shift_above")), Real(d.param("grid_shift_tolerance")),
                  Real(d.param("grid_fill"))});
  if (projection_) projection_->pic_ = Real(d.param("grid_pic"));
  if (projection_) projection_->surface_ = d.param("grid_surface") > 0;
  if (projection_) projection_->flipClamp_ = d.param("grid_flip_clamp") > 0;
  if (projection_) projection_->conserve_ = d.param("grid_conserve") > 0;
}

void Pbf::prepare(StepContext& c) {
  calibrate(c);
  c.P.field("pbf.lambda");
  // Every field before any stage takes a reference to one (a new field may move the others).
  if (pushoutSpeed_ > 0 && toVelocity_ > 0) c.P.field("pbf.carried");
  if (maxApproach_ > 0) c.P.field("pbf.approach");
  if (c.P.size() == 0) return;
  stageGrid(c, false);
  stageNeighbours(c);
  finalDensity(c, Real(0));
}

Real Pbf::maxTimeStep(const StepContext& c, Real vmax, Real amax) const {
  (void)amax;
  Real dt = std::min(maxDt_, dtLimit_);
  if (quantile_ > 0 && c.P.size() > 0) vmax = std::max(robustSpeed(c), c.sourceSpeed);  // an emitter's jet is no spray
  if (vmax > 0) dt = std::min(dt, maxMove_ * c.R / vmax);
  if (maxApproach_ > 0 && c.P.size() > 0) {
    // The fastest approach of two neighbours as the last substep ended (velocity()).
    const std::vector<Real>* ap = c.P.find("pbf.approach");
    const Real w = ap ? c.pool.reduce(
                            c.P.size(), kStreamBlock, Real(0),
                            [&](std::size_t b, std::size_t e) {
                              Real m = 0;
                              for (std::size_t i = b; i < e; ++i) m = std::max(m, (*ap)[i]);
                              return m;
                            },
                            [](Real a, Real b2) { return std::max(a, b2); })
                      : Real(0);
    if (w > 0) dt = std::min(dt, maxApproach_ * c.R / w);
  }
  // The hydrostatic pressure's own stiffness, as dfsph's (docs/SOLVERS.md): without the grid
  // projection the Jacobi iterations carry a deep column's pressure, and a substep in which a
  // wave of speed sqrt(|g| D) runs past a support leaves the floor rows crushed and then
  // flings them (the 1 m tank at 12,800 particles erupted at max_move 2, 123 m/s at frame 60).
  const Real gh = projection_ ? Real(0) : hydrostaticGravity(c).norm();
  if (gh > 0 && c.P.size() > 0) {
    Real dMax = 0;
    columnDepths(c, depthScratch_, [&](std::size_t, Real depth) { dMax = std::max(dMax, depth); });
    if (dMax > 0) dt = std::min(dt, kPressureCfl * c.R / std::sqrt(gh * dMax));
  }
  return dt;
}

Real Pbf::robustSpeed(const StepContext& c) const {
  const ParticleStore& P = c.P;
  const std::size_t n = P.size();
  const std::size_t skip = std::min(n - 1, std::size_t(double(quantile_) * double(n)));
  const std::size_t k = skip + 1;  // the answer is the k-th largest squared speed
  // Each block selects its k largest (in parallel); the k largest of all are among them,
  // so the k-th largest of the blocks' is the answer: the value a selection over every
  // particle finds, for any thread count.
  std::vector<Real>& s = speedScratch_;
  s.resize(n);
  c.pool.parallelFor(n, kStreamBlock, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) s[i] = P.v[i].squaredNorm();
    const std::size_t kb = std::min(k, e - b);
    std::nth_element(s.begin() + std::ptrdiff_t(b), s.begin() + std::ptrdiff_t(e - kb), s.begin() + std::ptrdiff_t(e));
  });
  std::vector<Real>& top = speedTop_;
  top.clear();
  for (std::size_t b = 0; b < n; b += kStreamBlock) {
    const std::size_t e = std::min(n, b + kStreamBlock);
    top.insert(top.end(), s.begin() + std::ptrdiff_t(e - std::min(k, e - b)), s.begin() + std::ptrdiff_t(e));
  }
  std::nth_element(top.begin(), top.end() - std::ptrdiff_t(k), top.end());
  return std::sqrt(top[top.size() - k]);
}

std::vector<Stage> Pbf::stages(bool effects) {
  std::vector<Stage> s;
  if (effects) {  // the effects read neighbours of the current positions
    s.push_back(plainStage("grid", [](StepContext& c) { stageGrid(c, false); }));
    s.push_back(plainStage("neighbours", [](StepContext& c) { stageNeighbours(c); }));
  }
  s.push_back(plainStage("external", [](StepContext& c) {
    ParticleStore& P = c.P;
    c.pool.parallelFor(P.size(), kStreamBlock, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) P.a[i] = c.gravity;
    });
  }));
  s.push_back(Stage::effects());
  if (projection_) {
    s.push_back(plainStage("predict_velocity", [](StepContext& c) {
      c.pool.parallelFor(c.P.size(), kStreamBlock, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
          c.P.v[i] = c.P.v[i] + c.P.a[i] * c.dt;
          c.P.a[i] = Vec2::Zero();  // in v now; predict adds nothing more
        }
      });
    }));
    s.push_back(Stage{"grid_projection", [this](StepContext& c) { return projection_->project(c); }});
    s.push_back(Stage::velocities([this](StepContext& c) { return pressureNow(c); }));
  }
  s.push_back(Stage{"predict", [this](StepContext& c) { return predict(c, c.P.field("pbf.lambda")); }});
  s.push_back(plainStage("predicted_grid", [](StepContext& c) { stageGrid(c, reorderThisStep(c)); }));
  s.push_back(plainStage("predicted_neighbours", [](StepContext& c) { stageNeighbours(c); }));
  s.push_back(Stage{"density_solve", [this](StepContext& c) { return solve(c); }});
  s.push_back(Stage{"density", [this](StepContext& c) { return finalDensity(c, c.dt); }});
  s.push_back(Stage{"velocity", [this](StepContext& c) { return velocity(c); }});
  return s;
}

std::size_t Pbf::solve(StepContext& c) {
  const std::size_t n = c.P.size();
  if (n == 0) return kNone;
  if (!(d0_ > 0)) calibrate(c);
  std::vector<Real>& lambda = c.P.field("pbf.lambda");
  // A density contrast: each particle's inverse mass ratio 1/r_i (pbf.hpp).
  if (const std::vector<Real>* ratio = c.P.find(ParticleStore::kRestRatio)) {
    invRatio_.resize(n);
    c.pool.parallelFor(n, kStreamBlock, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) invRatio_[i] = Real(1) / (*ratio)[i];
    });
  } else {
    invRatio_.clear();
  }
  dLambda_.resize(n);
  lOld_.resize(n);
  startElastic(c);
  wallGrad_.resize(n);
  const int maxIt = std::max(iterations_, maxIterations_);
  int used = 0;
  // pushout_speed (pbf.hpp): first what becomes velocity, then the rest with positions only.
  const bool split = pushoutSpeed_ > 0 && toVelocity_ > 0;
  againstStart_ = split;
  velocityFromSnapshot_ = false;
  std::size_t badIt = iterate(c, lambda, maxIt, used);
  if (badIt != kNone) return badIt;
  // The first solve's figures, for the step-limit controller (below).
  bool convergedFirst = converged();
  Real meanFirst = meanCompression_, maxFirst = maxCompression_;
  const int usedFirst = used;
  if (split) {
    againstStart_ = false;
    if (!(plainMean_ <= tolerance_ && plainMax_ <= toleranceMax_)) {
      // The rest (the compression the substep started with) is pushed out with positions only.
      xVel_.assign(c.P.x.begin(), c.P.x.end());
      wallMoveVel_[0] = wallMove_[0];
      wallMoveVel_[1] = wallMove_[1];
      velocityFromSnapshot_ = true;
      int more = 0;
      badIt = iterate(c, lambda, maxIt, more);
      if (badIt != kNone) return badIt;
      used += more;
    }
    meanCompression_ = plainMean_;  // what the substep leaves
    maxCompression_ = plainMax_;
  }
  // Local iterations: only the particles near a compression above tolerance_max
  // (and their neighbours) take further Jacobi steps; the rest keep their place.
  int local = 0;
  if (localIterations_ > 0 && endedOnCorrection_) {
    // The full passes ended with a correction: where it left the particles decides (a last
    // Chebyshev step can overshoot into a compression the pass before it did not show).
    const std::size_t bad = constraint(c, lambda);
    if (bad != kNone) return bad;
  }
  if (localIterations_ > 0 && maxCompression_ > toleranceMax_) {
    const std::size_t bad = localPhase(c, lambda, local);
    if (bad != kNone) return bad;
  }
  if (!ownVel_.empty()) ownMoves(c);
  stats_.pressureIterations = used + local;  // corrections applied
  stats_.densityError = double(meanCompression_);
  if (!split) {  // the last pass's (the local iterations may have gone on)
    convergedFirst = converged();
    meanFirst = meanCompression_;
    maxFirst = maxCompression_;
  }
  if (tolerance_ > 0 && adaptiveDt_) {
    // The compression left after N iterations grows as dt²/N²: when max_iterations
    // did not reach the tolerance, the next substeps are shorter; when half of them
    // sufficed, the limit grows back towards max_dt. (pushout_speed: the first solve's, the
    // one a shorter substep helps; the rest of the older compression moves positions only.)
    if (!convergedFirst) {
      const Real ratio = std::min(tolerance_ / meanFirst, toleranceMax_ / maxFirst);
      dtLimit_ = c.dt * std::min(Real(0.9), std::max(Real(0.5), Real(0.9) * std::sqrt(ratio)));
      dtLimit_ = std::max(dtLimit_, maxDt_ / Real(32));  // a jam it cannot resolve must not stall the run
    } else if (2 * (split ? usedFirst : used) <= maxIt) {
      dtLimit_ = std::min(maxDt_, dtLimit_ * Real(1.2));
    }
  }
  return kNone;
}

std::size_t Pbf::iterate(StepContext& c, std::vector<Real>& lambda, int maxIt, int& used) {
  const Real rho2 = chebyshev_ * chebyshev_;
  Real omega = 1;
  bool plain = false;
  endedOnCorrection_ = true;
  for (int k = 0; k < maxIt; ++k, ++used) {
    const std::size_t bad = constraint(c, lambda);
    if (bad != kNone) return bad;
    if (k >= iterations_ && (localIterations_ > 0 ? meanCompression_ <= tolerance_ : converged())) {
      endedOnCorrection_ = false;
      break;
    }
    // Chebyshev weights (Wang 2015): ω1 = 1, ω2 = 2/(2 − ρ²), ω_{k+1} = 4/(4 − ρ²ω_k); none
    // in a substep whose first pass finds a compression above chebyshev_plain_above.
    if (k == 0) plain = chebPlainAbove_ > 0 && maxCompression_ > chebPlainAbove_;  // an impact (pbf.hpp)
    plainSubstep_ = plain;
    omega = plain || k == 0 ? Real(1) : k == 1 ? Real(2) / (Real(2) - rho2) : Real(4) / (Real(4) - rho2 * omega);
    const std::size_t badC = correct(c, lambda, omega);
    if (badC != kNone) return badC;
  }
  return kNone;
}

std::size_t Pbf::predict(StepContext& c, std::vector<Real>& lambda) {
  ParticleStore& P = c.P;
  const Real dt = c.dt, vmax2 = c.maxSpeed * c.maxSpeed, moveMax2 = vmax2 * dt * dt;
  // The grid projection's compression shift of this substep (positions only).
  const std::vector<Vec2>* shift =
      projection_ && projection_->shift().size() == P.size() ? &projection_->shift() : nullptr;
  const Real capSpeed = moveCap_ > 0 ? moveCap_ * maxMove_ * c.R / dt : Real(0), capSpeed2 = capSpeed * capSpeed;
  // With correction_to_velocity > 0 the sweep's push becomes velocity: the walls' share (pbf.hpp, wallMove_).
  const bool countWall = c.wall && toVelocity_ > 0;
  const std::size_t blocks = (P.size() + kBlock - 1) / kBlock;
  if (countWall) wallBlock_.assign(2 * blocks, Vec2d(0, 0));
  // pushout_speed: the compression each particle starts with (ρ of its positions: the last
  // substep's final density; ρ0 for a particle added since), less what the pushout speed
  // may remove as velocity in this substep.
  std::vector<Real>* carried = pushoutSpeed_ > 0 && toVelocity_ > 0 ? P.find("pbf.carried") : nullptr;
  const Real pushout = Real(2) * pushoutSpeed_ * dt / c.dx;
  const std::vector<Real>* ratioField = P.find(ParticleStore::kRestRatio);  // m_i = r_i m with a density contrast
  const Real* ratio = ratioField ? ratioField->data() : nullptr;
  markElastic(c);
  const bool elastic = !ownVel_.empty();
  const std::size_t first = firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
    std::size_t bad = kNone;
    Vec2d push(0, 0);
    for (std::size_t i = b; i < e; ++i) {
      Vec2 v = P.v[i] + P.a[i] * dt;
      if (capSpeed2 > 0) {
        const Real s2 = v.squaredNorm();
        if (s2 > capSpeed2) v *= std::sqrt(capSpeed2 / s2);
      }
      const Vec2 x0 = P.x[i];
      Vec2 x = x0 + v * dt;
      if (shift && !(elastic && ownVel_[i])) x += (*shift)[i];
      Vec2 vd = v;  // resolve()'s velocity response is not used: v follows from the positions
      const Vec2 xFree = x;
      // clearOf: resolve would find no collider near the move (most particles; exact).
      if (!c.boundary.clearOf(x, x0, c.clearance) && c.boundary.resolve(x, vd, x0, c.clearance) && countWall)
        push += (x.cast<double>() - xFree.cast<double>()) * (ratio ? double(ratio[i]) : 1.0);
      P.xPrev[i] = x0;
      P.v[i] = v;
      P.x[i] = x;
      lambda[i] = 0;
      if (carried)
        (*carried)[i] =
            std::max(Real(0), (ratio ? P.rho[i] / (c.rho0 * ratio[i]) : P.rho[i] / c.rho0) - Real(1) - pushout);
      // A move longer than the speed limit allows over the substep is a runaway too (the
      // shift and the sweep move positions without a velocity the speed check would see).
      if (bad == kNone &&
          (!allFinite(x) || !allFinite(v) || v.squaredNorm() > vmax2 || (x - x0).squaredNorm() > moveMax2))
        bad = i;
    }
    if (countWall) wallBlock_[2 * (b / kBlock) + 1] = push;
    return bad;
  });
  for (Vec2d& m : wallMove_) m = Vec2d(0, 0);
  if (countWall) addWallMoves(blocks, Real(1), false);
  return first;
}

void Pbf::addWallMoves(std::size_t blocks, Real omega, bool rotate) {
  Vec2d part[2] = {Vec2d(0, 0), Vec2d(0, 0)};
  for (std::size_t k = 0; k < blocks; ++k) {
    part[0] += wallBlock_[2 * k];
    part[1] += wallBlock_[2 * k + 1];
  }
  for (int q = 0; q < 2; ++q) {
    // Chebyshev (omega ≠ 1): x = x_old + (x_k + d − x_old)·ω, then the sweep's push.
    const Vec2d combined =
        omega != Real(1) ? Vec2d(wallMovePrev_[q] +
                                 (wallMove_[q] + (q == 0 ? part[0] : Vec2d(0, 0)) - wallMovePrev_[q]) * double(omega))
                         : Vec2d(wallMove_[q] + (q == 0 ? part[0] : Vec2d(0, 0)));
    const Vec2d next = combined + (q == 1 ? part[1] : Vec2d(0, 0));
    if (rotate) wallMovePrev_[q] = wallMove_[q];
    wallMove_[q] = next;
  }
}

std::size_t Pbf::finalDensity(StepContext& c, Real dt) {
  ParticleStore& P = c.P;
  // A density contrast: the density is r_i times the number density the solve sums (pbf.hpp).
  const std::vector<Real>* ratioField = P.find(ParticleStore::kRestRatio);
  const Real* ratio = ratioField ? ratioField->data() : nullptr;
  if (rhoCurrent_) {  // the last constraint pass already summed ρ (and cached W) at these positions
    const std::vector<Real>* lam = P.find("pbf.lambda");
    const Real pK = dt > 0 ? -c.rho0 / (dt * dt) : Real(0);
    // kBlock, not kStreamBlock: the grid's κ sampled per particle is no streaming pass,
    // and five blocks of 20k would leave one thread a block behind the other.
    c.pool.parallelFor(P.size(), kBlock, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        if (ratio) P.rho[i] *= ratio[i];
        const Real p = pressure(c, lam, pK, i);
        P.invRho[i] = Real(1) / P.rho[i];
        P.p[i] = p;
        P.pOverRho[i] = p * P.invRho[i];
      }
    });
    return kNone;
  }
  const BoundarySet& B = c.boundary;
  const Spiky<Real> S(c.R);
  const Real invR = Real(1) / c.R, wK = S.c * c.R * c.R * c.R;
  const std::vector<Real>* lam = P.find("pbf.lambda");
  const Real pK = dt > 0 ? -c.rho0 / (dt * dt) : Real(0);
  gCache_.resize(c.nbr.perBlock.size());
  return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
    std::vector<Real>& cache = gCache_[b / kBlock];
    const std::size_t need = c.nbr.perBlock[b / kBlock].size();
    if (cache.size() < need) cache.resize(need);
    std::size_t bad = kNone;
    const Vec2* X = P.x.data();
    for (std::size_t i = b; i < e; ++i) {
      const std::uint32_t cnt = c.nbr.count[i];
      const std::uint32_t* nb = c.nbr.of(i);
      Real* wc = cache.data() + c.nbr.start[i];
      const Real xix = X[i].x(), xiy = X[i].y();
      Real w = 1;
      for (std::uint32_t k = 0; k < cnt; ++k) {
        Real dx = xix - X[nb[k]].x(), dy = xiy - X[nb[k]].y();
        c.periodic.nearest(dx, dy);
        const Real a = std::max(Real(0), Real(1) - std::sqrt(dx * dx + dy * dy) * invR);
        wc[k] = a * a * a;
        w += wc[k];
      }
      Real rho = c.mass * wK * w;
      const std::uint32_t bc = c.nbr.boundaryCount[i];
      if (bc) {
        const std::uint32_t* bl = c.nbr.boundaryOf(i);
        Real bw = 0;
        for (std::uint32_t k = 0; k < bc; ++k) {
          const std::uint32_t s = bl[k];
          const Real a = std::max(Real(0), Real(1) - std::sqrt((P.x[i] - B.samples[s]).squaredNorm()) * invR);
          bw += B.volume[s] * a * a * a;
        }
        rho += c.rho0 * wK * bw;
      }
      if (ratio) rho *= ratio[i];
      const Real p = pressure(c, lam, pK, i);
      P.rho[i] = rho;
      P.invRho[i] = Real(1) / rho;
      P.p[i] = p;
      P.pOverRho[i] = p * P.invRho[i];
      if (bad == kNone && !std::isfinite(rho)) bad = i;
    }
    return bad;
  });
}

std::size_t Pbf::velocity(StepContext& c) {
  ParticleStore& P = c.P;
  const Real invDt = Real(1) / c.dt, vmax2 = c.maxSpeed * c.maxSpeed;
  // pushout_speed: the positions the first solve left (what came after moved positions only).
  const Vec2* X = velocityFromSnapshot_ && xVel_.size() == P.size() ? xVel_.data() : P.x.data();
  const Vec2* XF = P.x.data();  // the final positions: the pairs' directions
  std::vector<Real>* approach = maxApproach_ > 0 ? P.find("pbf.approach") : nullptr;
  const Vec2* X0 = P.xPrev.data();
  const Real* IR = P.invRho.data();
  const Spiky<Real> S(c.R);
  const Real cm = xsph_ * c.mass * S.c * c.R * c.R * c.R;
  // A density contrast: XSPH weighs neighbour j by its volume m_j/ρ_j times sqrt(r_j/r_i), so
  // that m_i times the pair's weight is symmetric in the masses (m_i = r_i m; what is left is
  // the volumes' asymmetry of XSPH with one material): per particle
  // sqrt(r_j) m_j/ρ_j for its neighbours and 1/sqrt(r_i) for its own sum, no division per pair.
  const std::vector<Real>* ratioField = cm > 0 ? P.find(ParticleStore::kRestRatio) : nullptr;
  const Real* ratio = ratioField ? ratioField->data() : nullptr;
  if (ratio) {
    xsphNeighbour_.resize(P.size());
    xsphOwn_.resize(P.size());
    c.pool.parallelFor(P.size(), kStreamBlock, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        const Real root = std::sqrt(ratio[i]);
        xsphNeighbour_[i] = IR[i] * ratio[i] * root;
        xsphOwn_[i] = Real(1) / root;
      }
    });
  }
  const Real* XN = ratio ? xsphNeighbour_.data() : nullptr;
  vNew_.resize(P.size());
  const Real kc = toVelocity_;
  const Vec2* V0 = P.v.data();
  // The velocity of particle j: from its move (PBF), or its predicted velocity
  // plus a share kc of the correction's (kc < 1: corrections move positions only).
  auto vel = [&](std::size_t j) -> Vec2 {
    if (kc == Real(0)) return V0[j];  // corrections moved positions only
    const Vec2 moved = (X[j] - X0[j]) * invDt;
    return kc == Real(1) ? moved : Vec2(V0[j] + (moved - V0[j]) * kc);
  };
  // The block's loop, compiled once with a density contrast and once without.
  auto block = [&](auto contrastTag, std::size_t b, std::size_t e) {
    constexpr bool kContrast = decltype(contrastTag)::value;
    const Real* cache = cm > 0 ? gCache_[b / kBlock].data() : nullptr;
    std::size_t bad = kNone;
    for (std::size_t i = b; i < e; ++i) {
      const Vec2 vi = vel(i);
      if (approach) {
        // max_approach: the fastest a neighbour closes on i, −(v_i − v_j)·x_ij/|x_ij| (pbf.hpp).
        const std::uint32_t* nb = c.nbr.of(i);
        const std::uint32_t cnt = c.nbr.count[i];
        Real w2 = 0;  // the largest (v_ij·x_ij)²/|x_ij|² of an approaching pair
        for (std::uint32_t k = 0; k < cnt; ++k) {
          const std::uint32_t j = nb[k];
          Real dx = XF[i].x() - XF[j].x(), dy = XF[i].y() - XF[j].y();
          c.periodic.nearest(dx, dy);
          const Vec2 vj = vel(j);
          const Real vd = (vi.x() - vj.x()) * dx + (vi.y() - vj.y()) * dy;
          const Real r2 = dx * dx + dy * dy;
          if (vd < 0 && r2 > 0) w2 = std::max(w2, vd * vd / r2);
        }
        (*approach)[i] = std::sqrt(w2);
      }
      Vec2 v = vi;
      if (cm > 0) {
        const std::uint32_t* nb = c.nbr.of(i);
        const std::uint32_t cnt = c.nbr.count[i];
        const Real* wc = cache + c.nbr.start[i];
        Real sx = 0, sy = 0;
        for (std::uint32_t k = 0; k < cnt; ++k) {
          const std::uint32_t j = nb[k];
          const Real f = wc[k] * (kContrast ? XN[j] : IR[j]);
          if (kc == Real(1)) {
            sx += f * ((X[j].x() - X0[j].x()) * invDt - vi.x());
            sy += f * ((X[j].y() - X0[j].y()) * invDt - vi.y());
          } else {
            const Vec2 vj = vel(j);
            sx += f * (vj.x() - vi.x());
            sy += f * (vj.y() - vi.y());
          }
        }
        if constexpr (kContrast) {
          sx *= xsphOwn_[i];
          sy *= xsphOwn_[i];
        }
        v += Vec2(sx, sy) * cm;
      }
      vNew_[i] = v;
      if (bad == kNone && (!allFinite(v) || v.squaredNorm() > vmax2)) bad = i;
    }
    return bad;
  };
  const std::size_t first = firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
    return ratio ? block(std::true_type{}, b, e) : block(std::false_type{}, b, e);
  });
  P.v.swap(vNew_);
  // The walls' share of the move becomes velocity as the move does: kc·D/dt (XSPH then mixes
  // velocities among the particles, which keeps their sum up to the density ratio).
  if (c.wall && kc > 0) {
    const Vec2d* moved = velocityFromSnapshot_ ? wallMoveVel_ : wallMove_;  // pushout_speed: the first solve's
    c.wall->sum.samples += moved[0] * (double(c.momentumMass) * double(kc) / double(c.dt));
    c.wall->sum.collision += moved[1] * (double(c.momentumMass) * double(kc) / double(c.dt));
  }
  return first;
}

void Pbf::saveState(StateOut& out) const {
  out.put(dtLimit_);
  out.put(std::uint8_t(projection_ ? 1 : 0));
  if (projection_) projection_->saveState(out);
}

void Pbf::loadState(StateIn& in) {
  const Real limit = in.get<Real>("the solver's step limit");
  const bool grid = in.get<std::uint8_t>("the solver's grid flag") != 0;
  if (grid != bool(projection_) || !(limit > 0))
    throw SaveError("the saved state is malformed: its solver state is not this solver's");
  if (projection_) projection_->loadState(in, std::size_t(1) << 26);  // reads all, then assigns
  dtLimit_ = limit;
}

}  // namespace sph2d
