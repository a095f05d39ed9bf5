// moving_solid.hpp (internal) — the kinematic and dynamic Box2D bodies as a step's
// stages see them (moving_bodies.cpp captures them; the `bodies` stage and the grid
// projection read and push them).
//
// A body is captured at the start of each World::step with its pose and velocity.
// Within the step its centre of mass moves along a piecewise-linear path: with
// velocity v (and angular velocity ω) until something changes them — gravity at
// each substep's start, the grid projection's pressure and the particles' contacts
// for a dynamic body (never for a kinematic one, which moves exactly as Box2D moves
// it over the step). A change at time τ keeps the pose continuous (the offsets
// `drift` and `turn` absorb it), so pose(τ) = com0 + drift + v·τ. What the fluid
// gives a dynamic body during the step is summed in `impulse` and `angularImpulse`
// (about the centre of mass) and handed to Box2D at the step's end, which then
// integrates the body (gravity, contacts with other bodies) as it always does.
#pragma once

#include <box2d/box2d.h>

#include <array>
#include <cmath>
#include <vector>

#include "sph2d/boundary.hpp"
#include "sph2d/math.hpp"

namespace sph2d {

/// One non-static body of the b2World during a step.
struct MovingSolid {
  b2Body* body = nullptr;
  std::vector<Collider>
      shapes;  ///< polygons (with Box2D's skin) and circles in body coordinates: where the fluid meets the body
  std::vector<const void*> fixtures;  ///< the b2Fixture of each of `shapes`
  std::vector<Collider> cores;  ///< the fixtures as Box2D weighs them (polygons without the skin), body coordinates
  Vec2d com0{0, 0};             ///< centre of mass at the step's start (World's local frame)
  Vec2d localCenter{0, 0};      ///< centre of mass in body coordinates
  double angle0 = 0;            ///< angle at the step's start [rad]
  Vec2d v{0, 0};                ///< velocity of the centre of mass now [m/s]
  double omega = 0;             ///< angular velocity now [rad/s]
  Vec2d drift{0, 0};            ///< position offset that keeps the path continuous across velocity changes
  double turn = 0;              ///< angle offset, likewise
  double radius = 0;            ///< the shapes' reach from the centre of mass [m]
  double area = 0;              ///< the area of its shapes' union [m²]
  Vec2d centroid{0, 0};         ///< the union's centroid, body coordinates from the centre of mass
  double invMass = 0;           ///< 1/mass: 0 for a kinematic body (the fluid does not move it)
  double invInertia = 0;        ///< 1/(rotational inertia about the centre of mass), 0 when it cannot turn
  /// Box2D holds it beyond the fluid: a joint, or a static fixture its shapes touch at the
  /// step's start (World::Impl::holdBody, from the poses, so that a loaded World holds it as
  /// the saved one did). What the fluid gives it, Box2D may take away.
  bool held = false;
  /// Where it rests on static fixtures at the step's start (World::Impl::holdBody): one row
  /// (n, r × n) per contact point, n from the body into the fixture, r from the centre of mass.
  /// Within the step it does not move into them, as Box2D's resting contacts hold it: gravity
  /// and the fluid's pushes go through changeVelocityResting(), and the grid projection's
  /// coupled solve takes the response they leave (restingResponse()). What the fluid gives it
  /// still goes whole to Box2D (`impulse`), which settles it against the contacts.
  std::vector<std::array<double, 3>> rests;
  Vec2d gravity{0, 0};        ///< the b2World's gravity times the body's gravity scale (dynamic only)
  double sweptTheta = 0;      ///< the pose the particles last saw it at (the last substep's end; the
  Vec2d sweptOrigin{0, 0};    ///< capture, or the last step's end when Box2D then moved it elsewhere)
  Vec2d impulse{0, 0};        ///< the fluid's linear impulse on it during this step [kg m/s]
  double angularImpulse = 0;  ///< … and angular impulse about the centre of mass [kg m²/s]

  /// True for a body the fluid pushes (dynamic, with mass).
  bool dynamic() const { return invMass > 0; }
  /// Angle τ seconds into the step.
  double angleAt(double tau) const { return angle0 + turn + omega * tau; }
  /// Centre of mass τ seconds into the step (local frame).
  Vec2d centreAt(double tau) const { return com0 + drift + v * tau; }
  /// The pose τ seconds into the step: rotation θ, body origin o (local frame).
  void pose(double tau, double& theta, Vec2d& o) const {
    theta = angleAt(tau);
    const double c = std::cos(theta), s = std::sin(theta);
    o = centreAt(tau) - Vec2d(c * localCenter.x() - s * localCenter.y(), s * localCenter.x() + c * localCenter.y());
  }
  /// Velocity of the body's material point at local position p, τ seconds into the step.
  Vec2d velocityAt(double tau, const Vec2d& p) const {
    const Vec2d r = p - centreAt(tau);
    return v + omega * Vec2d(-r.y(), r.x());
  }
  /// How deep local point p lies inside its shapes τ seconds into the step (the largest
  /// over the shapes; ≤ 0 outside all of them; a cheap −∞ beyond its reach).
  double depth(double tau, const Vec2d& p) const;
  /// True when local point p lies inside one of its shapes τ seconds into the step.
  bool contains(double tau, const Vec2d& p) const { return depth(tau, p) > 0; }
  /// Changes the velocity by (dv, dω) at time τ, the pose staying continuous.
  void changeVelocity(double tau, const Vec2d& dv, double dOmega) {
    drift -= dv * tau;
    turn -= dOmega * tau;
    v += dv;
    omega += dOmega;
  }
  /// Changes the velocity by (dv, dω) at time τ as the resting contacts allow: the new
  /// velocity without its part into the contacts it would move into (restrict()).
  void changeVelocityResting(double tau, const Vec2d& dv, double dOmega) {
    if (rests.empty()) return changeVelocity(tau, dv, dOmega);
    double q[3] = {v.x() + dv.x(), v.y() + dv.y(), omega + dOmega};
    restrict(q);
    changeVelocity(tau, Vec2d(q[0], q[1]) - v, q[2] - omega);
  }
  /// Gives the body the fluid's impulse (J about the centre of mass, L) at time τ.
  void push(double tau, const Vec2d& J, double L) {
    impulse += J;
    angularImpulse += L;
    changeVelocityResting(tau, J * invMass, L * invInertia);
  }
  /// The generalized velocity q = (v, ω) made the nearest, in the metric of the body's mass
  /// (the least change of kinetic energy), that moves into none of the resting contacts: held
  /// still at the contacts it would enter, free from those it leaves (a contact it would pull
  /// on lets go).
  void restrict(double q[3]) const;
  /// The response to an impulse (J, L) that the resting contacts leave, W = M⁻¹ − M⁻¹Aᵀ(A M⁻¹
  /// Aᵀ)⁺A M⁻¹ over those it is not moving off (A their rows): row-major 3 × 3, symmetric.
  /// Without contacts, diag(1/m, 1/m, 1/I).
  void restingResponse(double W[3][3]) const;
};

/// The moving bodies of one step.
struct MovingSolids {
  std::vector<MovingSolid> bodies;
  double time0 = 0;  ///< World time of the capture (τ = time − time0)
  /// The pose each body had at the end of the last step (what the particles were kept out
  /// of): Box2D's own step may put it elsewhere (a contact's impulse moves it further, a
  /// game moves it), and the first substep sweeps the particles from this pose, so that the
  /// jump cannot carry the body over a particle.
  struct LastPose {
    const b2Body* body;
    double theta;
    Vec2d origin;
  };
  std::vector<LastPose> last;
  /// True when some body is dynamic.
  bool anyDynamic() const {
    for (const MovingSolid& b : bodies)
      if (b.dynamic()) return true;
    return false;
  }
};

/// Signed distance of body-frame point b outside collider k (negative inside) and the
/// outward normal it is measured along; for a polygon, the face the particle entered by
/// when its start a was outside (else the least deep face). moving_bodies.cpp.
double outsideCollider(const Collider& k, const Vec2d& a, const Vec2d& b, Vec2d& normal);

/// True when the segment from body-frame point a to b enters collider k (a outside it):
/// then `t` is where along the segment (0..1) and `normal` the face's outward normal.
/// moving_bodies.cpp.
bool sweptEntry(const Collider& k, const Vec2d& a, const Vec2d& b, double& t, Vec2d& normal);

/// The index of the body whose shapes contain local point p at time τ of the step
/// (the first in order), or −1.
int solidAt(const MovingSolids& s, double tau, const Vec2d& p);

}  // namespace sph2d
