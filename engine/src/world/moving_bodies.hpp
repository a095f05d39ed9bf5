// moving_bodies.hpp (internal) — the moving bodies subsystem's data: the kinematic and dynamic
// bodies of the b2World as the fluid meets them this step, their boundary samples (for the
// solvers that take them), and the scratch of the `bodies` stage. Its stages (capture, body
// gravity and walls, the bodies stage, moving the scene's own bodies) are the World's, in
// moving_bodies.cpp and moving_collision.cpp, as they meet the particles, the b2World and the
// solver.
#pragma once

#include <cstdint>
#include <vector>

#include "bodies/body_samples.hpp"
#include "bodies/moving_solid.hpp"

namespace sph2d {

struct MovingBodies {
  /// The bodies captured at the start of each step with their pose and velocity; the `bodies`
  /// stage pushes the fluid out of them and, for a dynamic body, takes the contacts' impulse;
  /// the grid projection of the game solver sees them as moving solids.
  MovingSolids solids;
  /// Their boundary samples (body_samples.hpp), when the solver takes them.
  BodySamples samples;

  // The `bodies` stage's scratch (kept: no allocation in the step).
  std::vector<std::int32_t> hitBody;  ///< the dynamic body particle i met (−1: none)
  std::vector<Vec2d> hitNormal;       ///< … and the body's outward normal there
  /// Per body: its pose at the substep's start and end.
  struct Pose {
    double theta0, theta1, c0, s0, c1, s1;  ///< the rotations at the substep's start and end
    Vec2d o0, o1, com1;
    double reach2;  ///< beyond this from com1, a particle's whole path misses the body (squared)
  };
  std::vector<Pose> poses;
  std::vector<int> contactCount;      ///< per body: its approaching contacts
  std::vector<Vec2d> contactImpulse;  ///< … the contacts' impulse on it
  std::vector<double> contactTorque;  ///< … and their angular impulse
  struct Response {
    double w[3][3];
  };
  std::vector<Response> contactResponse;  ///< each body's response left by its resting contacts
};

}  // namespace sph2d
