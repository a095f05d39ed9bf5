// body_samples.hpp (internal) — boundary samples of the moving Box2D bodies, for the SPH
// solvers that take them (Solver::movingSamples).
//
// Akinci et al. 2012, "Versatile rigid-fluid coupling for incompressible SPH": a rigid body
// is sampled with boundary particles of volume Ψ_b that the fluid sees as frozen fluid of
// mass ρ0Ψ_b (in its density, in the pressure and viscosity terms of the walls), moving with
// the body; the force each sample exerts on a particle is given back to the body (−F at the
// sample: a force and a torque about its centre of mass), so the fluid pushes the body and
// the body the fluid by one symmetric exchange (momentum kept by construction).
//
// Each body's shapes are sampled once, in the body frame, with the static solids' sampler
// (sampleColliders: layers at depths dx/2, 3dx/2, ... down to the support R, each sample
// with the area it stands for), with a grid over them in the body frame; the cache keeps
// them while the body's shapes stay the same. Each substep, the `body_samples` stage places
// them at the body's pose at the substep's start (moving_solid.hpp: the path within the
// step) with the velocity of the body's material point there, v + ω × r. The neighbours
// stage lists, per particle, the samples within R (body by body, each body's in its grid's
// order: the lists depend on the positions only). The solver adds, per particle and body,
// the force the body's samples exert on it into `perBlock` (its block's partial, in
// particle order); the `body_forces` stage, after the integration (the substep's length
// is then known), sums the partials in block order and gives each dynamic body the
// opposite impulse over the substep at the substep's start, so the body's path over the
// substep takes it (symplectic Euler, like the fluid's). No atomics: the same bits for any
// thread count.
//
// These samples enter neither the static walls' sums (World::wallImpulse: what the fluid
// exchanges with a body is the body's momentum) nor the static grid; the `bodies` stage
// (moving_bodies.cpp) still puts back a particle that entered a body, as a safety net.
#pragma once

#include <box2d/box2d.h>

#include <cstdint>
#include <vector>

#include "bodies/moving_solid.hpp"
#include "boundary/boundary_set.hpp"
#include "core/constants.hpp"
#include "particles/neighbour_grid.hpp"

namespace sph2d {

/// The moving bodies' boundary samples of one substep.
struct BodySamples {
  /// One body's samples in its own frame (sampled once, kept while its shapes stay).
  struct Sampled {
    const b2Body* body = nullptr;
    std::vector<Collider> shapes;  ///< the shapes they were made from (body coordinates)
    std::vector<Vec2> local;       ///< sample positions, body coordinates
    std::vector<Real> volume;      ///< Ψ_b [m²]
    Grid grid;                     ///< over `local`, cells of at least R
    bool used = false;             ///< scratch: found again at this placement
  };
  std::vector<Sampled> cache;
  /// One body as placed this substep: its samples are first .. first + count of the arrays below.
  struct Placed {
    std::uint32_t first = 0, count = 0;
    const Sampled* sampled = nullptr;
    double c = 1, s = 0;      ///< the rotation at the substep's start
    Vec2d origin{0, 0};       ///< the body origin there (local frame)
    Vec2 com = Vec2::Zero();  ///< its centre of mass there
    Real reach2 = 0;          ///< (the samples' reach from com + R)²: a particle farther sees none
    bool dynamic = false;     ///< the fluid's force on it is gathered
  };
  std::vector<Placed> placed;       ///< per moving body, in MovingSolids order (empty: none placed)
  std::vector<Vec2> x;              ///< sample positions (local frame) at the substep's start
  std::vector<Vec2> v;              ///< sample velocities v + ω × r
  std::vector<Vec2> arm;            ///< sample position − the body's centre of mass
  std::vector<Real> volume;         ///< Ψ_b [m²]
  std::vector<std::uint32_t> body;  ///< the sample's body (index into placed)

  /// What the fluid of one block felt from one body's samples: Σ m a and Σ arm × m a.
  struct Reaction {
    std::uint32_t body;
    Vec2d force;
    double torque;
  };
  std::vector<std::vector<Reaction>> perBlock;  ///< per block of kBlock particles, bodies in first-met order

 private:
  std::vector<Vec2d> force_;           ///< react()'s scratch per body: Σ of the blocks' forces
  std::vector<double> torque_;         ///< … and torques
  std::vector<std::uint8_t> touched_;  ///< … and whether any block met the body

 public:
  /// Calls f(k, first, last) for each body k's run [first, last) of a particle's list of moving
  /// samples ml[0, count) (nbr.movingOf: the neighbours stage lists each body's samples together),
  /// in list order.
  template <class F>
  void forEachBody(const std::uint32_t* ml, std::uint32_t count, F&& f) const {
    for (std::uint32_t q = 0; q < count;) {
      const std::uint32_t k = body[ml[q]], first = q;
      while (q < count && body[ml[q]] == k) ++q;
      f(k, ml + first, ml + q);
    }
  }

  /// The velocity of sample s's body at x (the body turning at ω): v_s + ω × (x − x_s).
  Vec2d velocityAt(std::uint32_t s, double omega, const Vec2& at) const {
    const Vec2 d = at - x[s];
    return v[s].cast<double>() + Vec2d(-double(d.y()), double(d.x())) * omega;
  }

  /// The torque arm × f about a body's centre of mass (2D cross product).
  static Real torque(const Vec2& arm, const Vec2& f) { return arm.x() * f.y() - arm.y() * f.x(); }

  /// True between the `body_samples` and `body_forces` stages of a substep: the samples
  /// are placed, and the neighbour lists hold them.
  bool active() const { return !placed.empty(); }

  /// Adds what momentum mass·acceleration `ma` (double; StepContext::momentumMass) with torque arm sum `torque` one
  /// block's particle felt from body k's samples to the block's partial. Call from the block's own job.
  void addReaction(std::size_t block, std::uint32_t k, const Vec2d& ma, double torque) {
    std::vector<Reaction>& r = perBlock[block];
    for (Reaction& e : r)
      if (e.body == k) {
        e.force += ma;
        e.torque += torque;
        return;
      }
    r.push_back({k, ma, torque});
  }

  /// The `body_samples` stage: samples (once, at spacing dx to depth R) and places every moving
  /// body's samples at its pose at `time` (the substep's start), and sizes the blocks' partials
  /// for `particles` particles.
  void place(double time, Real dx, Real R, std::size_t particles, ThreadPool& pool, const MovingSolids& solids);
  /// The `body_forces` stage: each dynamic body takes minus the fluid's force from its samples
  /// (partials summed in block order) over the substep dt, at its start `time`; then the
  /// samples are put away (active() is false until the next placement).
  void react(double time, double dt, MovingSolids& solids);
};

}  // namespace sph2d
