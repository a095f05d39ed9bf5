// pbf_local.cpp — the local phase of a Position Based Fluids substep (pbf.hpp): after
// the full passes, further Jacobi passes over the particles still compressed above
// tolerance_max and their neighbours (an active list), until none is or local_iterations
// are spent. A phase that starts on a deep pile takes the full passes' Chebyshev weights
// (Wang 2015): a pile at a wall as deep as a substep's run into it (a slab thrown at a wall
// at 5.6 m/s, a dozen spacings a substep) took 500 plain passes, so the hundred allowed left
// it at 62 % for a frame; weighted, 28. Each particle starts its weighted steps from the
// iterate the last pass left it (a particle new to the list from where it is).
#include <algorithm>

#include "bodies/moving_solid.hpp"
#include "solvers/pbf/pbf.hpp"

namespace sph2d {

std::size_t Pbf::localPhase(StepContext& c, std::vector<Real>& lambda, int& local) {
  const std::size_t n = c.P.size();
  active_.reset(n);
  moved_.reset(n);
  startLocalPhase(c);
  Real omega = 1;
  const Real thr = Real(0.5) * toleranceMax_;
  const Real limit = c.rho0 * (Real(1) + thr);
  bool first = true;  // every ρ and Δλ is the last full pass's
  while (local < localIterations_) {
    for (; local < localIterations_ && maxCompression_ > toleranceMax_; ++local) {
      // Active: compressed above half the tolerance, or next to such a particle.
      // After a full scan only the last list's ρ changed, and every particle off
      // that list kept the ρ it had when it was found at or below the threshold
      // (or was summed again in the halo pass), so the compressed ones are on the
      // list: they and their neighbours (the lists are symmetric) are the new
      // active set, the same set a full scan finds.
      if (first) {
        // A block of kBlock slots owns its words of the set (64 slots each).
        static_assert(kBlock % 64 == 0, "a job block covers whole words of a SlotSet");
        c.pool.parallelFor(n, kBlock, [&](std::size_t b, std::size_t e) {
          for (std::size_t w0 = b; w0 < e; w0 += 64) {
            std::uint64_t bits = 0;
            for (std::size_t i = w0; i < std::min(e, w0 + 64); ++i) {
              bool a = c.P.rho[i] > limit;
              const std::uint32_t* nb = c.nbr.of(i);
              for (std::uint32_t k = 0; k < c.nbr.count[i] && !a; ++k) a = c.P.rho[nb[k]] > limit;
              if (a)
                bits |= std::uint64_t(1) << (i - w0);
              else
                dLambda_[i] = 0;  // only the listed particles take their step of the full pass
            }
            active_.setWord(w0 / 64, bits);
          }
        });
        active_.summarise();
        first = false;
      } else {
        neighbourhood(c, lastList_, &limit, active_);
        // Off the new list, only the last list's Δλ can be non-zero: those are cleared.
        for (const std::uint32_t i : lastList_)
          if (!active_.has(i)) dLambda_[i] = 0;
      }
      active_.list(activeList_);
      active_.clear();
      if (localChebyshev_) {
        // The full passes' weights (Wang 2015), from the phase's first pass on.
        const Real rho2 = chebyshev_ * chebyshev_;
        omega = local == 0 ? Real(1) : local == 1 ? Real(2) / (Real(2) - rho2) : Real(4) / (Real(4) - rho2 * omega);
        ++localPass_;
      }
      std::size_t bad = correct(c, lambda, omega, &activeList_);
      if (bad != kNone) return bad;
      // Every particle moved in this phase: its neighbours' ρ changed too.
      for (const std::uint32_t i : activeList_) moved_.add(i);
      bad = constraint(c, lambda, &activeList_);
      if (bad != kNone) return bad;
      lastList_.swap(activeList_);
    }
    if (local == 0) break;
    // The particles moved in this phase, and their neighbours, have their density
    // summed again (the rest kept ρ and W of the last full pass). A neighbour off the
    // lists may have been pushed above the tolerance: then the iterations go on from
    // this halo, whose ρ are all fresh.
    moved_.list(movedList_);
    neighbourhood(c, movedList_, nullptr, active_);
    active_.list(activeList_);
    active_.clear();
    const std::size_t bad = constraint(c, lambda, &activeList_);
    if (bad != kNone) return bad;
    lastList_.swap(activeList_);
    rhoCurrent_ = true;  // every ρ (and W) is that of the current positions again
    if (maxCompression_ <= toleranceMax_) break;
  }
  return kNone;
}

namespace {
/// The local passes take Chebyshev's weights when the phase starts with a particle compressed
/// beyond this many times tolerance_max: a pile deeper than a few plain passes undo (a slab's
/// run into a wall: 20 to 60 %). Below it plain passes end in a few (the dam break's phases:
/// 1 to 15), and the weights would only overshoot them: with weights in every phase, the 20k
/// dam break took 12.0 → 15.1 local and full passes a frame and its 100k 29 → 39, and a sand
/// pile under water stood 8 % lower.
constexpr Real kDeepPile = 2;
}  // namespace

void Pbf::startLocalPhase(const StepContext& c) {
  // Chebyshev's weights need each particle's previous iterate; the walls' share of the moves
  // (countWall) is summed with one weight for every particle, which a local pass's
  // particles, some of them new to it, do not share: those passes stay plain.
  localChebyshev_ =
      chebyshev_ > 0 && !plainSubstep_ && !(c.wall && toVelocity_ > 0) && maxCompression_ > kDeepPile * toleranceMax_;
  if (!localChebyshev_) return;
  // The moving bodies are no part of this solve (the grid and the `bodies` stage keep the water
  // out of them): an extrapolated step beside one ran particles into it, and a sinking crate
  // took 18 of them to the floor with it. Particles within a body's reach over the substep (and
  // two supports) step plainly.
  localBodies_.clear();
  if (c.solids) {
    const double tau = c.time - c.solids->time0 + 0.5 * double(c.dt);
    for (const MovingSolid& b : c.solids->bodies) {
      const Vec2d o = b.centreAt(tau);
      const double r = b.radius + 2 * double(c.R) + double(c.clearance) +
                       (b.v.norm() + std::fabs(b.omega) * b.radius) * double(c.dt);
      localBodies_.push_back({Vec2(Real(o.x()), Real(o.y())), Real(r * r)});
    }
  }
  const std::size_t n = c.P.size();
  // Passes are numbered on from the last phase's, and a phase starts two numbers on, so that no
  // mark of an earlier phase reads as the pass just before (a wrap clears the marks).
  if (localMoved_.size() != n || localPass_ > 0xffff0000u) {
    localMoved_.assign(n, 0);
    localPass_ = 0;
  }
  localPass_ += 2;
}

void Pbf::neighbourhood(const StepContext& c, const std::vector<std::uint32_t>& list, const Real* limit,
                        SlotSet& out) const {
  // Serial over the list (a local iteration's few particles); a set, so the result
  // does not depend on the order the list was built in.
  for (const std::uint32_t i : list) {
    if (limit && !(c.P.rho[i] > *limit)) continue;
    out.add(i);
    const std::uint32_t* nb = c.nbr.of(i);
    for (std::uint32_t k = 0; k < c.nbr.count[i]; ++k) out.add(nb[k]);
  }
}

}  // namespace sph2d
