// MovingSolid's resting contacts (bodies/resting_contacts.cpp): the velocity nearest the given
// one that enters no contact, and the response the contacts leave.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "bodies/moving_solid.hpp"

using namespace sph2d;

namespace {

/// A contact row (n, r × n): normal n from the body into the fixture, r from the centre of mass.
std::array<double, 3> row(double nx, double ny, double rx, double ry) { return {nx, ny, rx * ny - ry * nx}; }

/// A box of half sizes a × b and unit mass resting on the floor on its two bottom corners.
MovingSolid boxOnFloor(double a, double b) {
  MovingSolid m;
  m.invMass = 1;
  m.invInertia = 3 / (a * a + b * b);
  m.rests = {row(0, -1, -a, -b), row(0, -1, a, -b)};
  return m;
}

double dot(const std::array<double, 3>& a, const double* q) { return a[0] * q[0] + a[1] * q[1] + a[2] * q[2]; }

}  // namespace

TEST_CASE("resting contacts: a box on the floor keeps what leaves the floor and loses what enters it") {
  const MovingSolid m = boxOnFloor(0.3, 0.1);
  double fall[3] = {0.2, -0.16, 0};  // sliding and falling: the fall goes, the slide stays
  m.restrict(fall);
  CHECK(fall[0] == doctest::Approx(0.2));
  CHECK(std::fabs(fall[1]) < 1e-12);
  CHECK(std::fabs(fall[2]) < 1e-12);
  double lift[3] = {0.1, 0.3, 0.2};  // lifting off and turning: left as it is
  m.restrict(lift);
  CHECK(lift[0] == 0.1);
  CHECK(lift[1] == 0.3);
  CHECK(lift[2] == 0.2);
}

TEST_CASE("resting contacts: a tall box falling and spinning pivots on one corner, not held by the other") {
  // Holding both corners (the contacts' first guess) would pull on one: the nearest velocity
  // that enters neither floor point pivots on the corner it turns onto and lifts the other.
  const MovingSolid m = boxOnFloor(0.1, 0.5);
  double q[3] = {0, -0.1, 0.5};
  m.restrict(q);
  CHECK(dot(m.rests[0], q) <= 1e-12);
  CHECK(dot(m.rests[1], q) <= 1e-12);
  CHECK(q[2] > 0.3);  // still turning
  // Exactly one corner is held, the other leaves the floor.
  const bool leftHeld = std::fabs(dot(m.rests[0], q)) < 1e-12, rightHeld = std::fabs(dot(m.rests[1], q)) < 1e-12;
  CHECK(leftHeld != rightHeld);
}

TEST_CASE("resting contacts: over random boxes and velocities no contact pulls (the quadratic program's conditions)") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int n = 0; n < 20000; ++n) {
    const MovingSolid m = boxOnFloor(0.05 + 0.5 * (U(rng) + 1), 0.05 + 0.5 * (U(rng) + 1));
    double q[3] = {U(rng), U(rng), 3 * U(rng)};
    const double q0[3] = {q[0], q[1], q[2]};
    m.restrict(q);
    // Feasible: enters neither point. Optimal: q0 − q = M⁻¹ Aᵀ λ with λ ≥ 0, λ_k = 0 where the
    // point leaves (solved for the two multipliers from the x- and ω-free parts).
    REQUIRE(dot(m.rests[0], q) <= 1e-9);
    REQUIRE(dot(m.rests[1], q) <= 1e-9);
    const double dy = (q0[1] - q[1]) / m.invMass, dw = (q0[2] - q[2]) / m.invInertia;
    CHECK(std::fabs(q0[0] - q[0]) < 1e-12);  // frictionless: the slide is untouched
    // dy = −(λ0 + λ1), dw = λ0 r0 + λ1 r1 with r_k = the rows' third entries.
    const double r0 = m.rests[0][2], r1 = m.rests[1][2];
    const double l1 = (dw + dy * r0) / (r1 - r0), l0 = -dy - l1;
    CHECK(l0 >= -1e-9);
    CHECK(l1 >= -1e-9);
    if (dot(m.rests[0], q) < -1e-9) CHECK(std::fabs(l0) < 1e-9);
    if (dot(m.rests[1], q) < -1e-9) CHECK(std::fabs(l1) < 1e-9);
  }
}

TEST_CASE("resting contacts: the response left is symmetric, and zero for a body they hold still") {
  MovingSolid m = boxOnFloor(0.3, 0.1);
  double W[3][3];
  m.restingResponse(W);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) CHECK(W[r][c] == doctest::Approx(W[c][r]).epsilon(1e-12));
  CHECK(W[0][0] == doctest::Approx(1));  // free along the floor
  CHECK(std::fabs(W[1][1]) < 1e-12);     // held against it, and from turning into it
  CHECK(std::fabs(W[2][2]) < 1e-12);
  // In a corner (the floor and a wall on the left), unable to turn: held still.
  m.invInertia = 0;
  m.rests = {row(0, -1, -0.3, -0.1), row(-1, 0, -0.3, -0.1)};
  m.restingResponse(W);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) CHECK(W[r][c] == 0);
  // Moving off the floor faster than a resting body does: free to rise.
  m = boxOnFloor(0.3, 0.1);
  m.v = Vec2d(0, 0.05);
  m.restingResponse(W);
  CHECK(W[1][1] == doctest::Approx(1));
}
