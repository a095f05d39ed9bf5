// resting_contacts.cpp — a dynamic body against the static fixtures it rests on, within a
// step (moving_solid.hpp: MovingSolid::rests). Box2D holds such a body with its contacts only
// when it next steps it; within the fluid's step nothing did, and a cup of water on the floor
// sank under its water's weight in the grid's coupled pressure solve (the body gave way, its
// water followed, Box2D then put the body back and the water kept the fall: 0.6-1.05 m/s of
// downward flow that never stopped, 5-9 cm low, in cups of 120-3000 kg/m²). Here the contacts
// act as Box2D's resting contacts would: inelastic and without friction, a constraint
// J q ≤ 0 per contact point on the generalized velocity q = (v, ω).
//
// Both functions project in the metric of the body's mass (inner product ⟨a, b⟩ = a M⁻¹ bᵀ):
// the rows are made ⟨·,·⟩-orthogonal by Gram–Schmidt (a row that depends on the earlier ones,
// such as a third point along one face, drops out), and each orthogonal row e takes
// M⁻¹eᵀ (e·q) / ⟨e, e⟩ off the velocity. restrict() solves the small quadratic program (the
// velocity nearest q that enters no contact, so that a contact the body would pull on, as a
// tall box pivoting on one corner, lets go); restingResponse() holds every contact the body
// is not moving off, for the coupled solve's linear system.
#include "bodies/moving_solid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace sph2d {
namespace {

/// A contact point moving off its fixture faster than this [m/s] is leaving it, not resting:
/// a tenth of Box2D's sleep tolerance (b2_linearSleepTolerance), well above the velocity Box2D
/// leaves a resting body with.
constexpr double kLeaving = 0.1 * b2_linearSleepTolerance;

/// restrict() tries every set of up to this many contacts (2^10 small projections at most; a
/// body on the floor has two, in a corner three or four).
constexpr std::size_t kMaxRestingSets = 10;

/// Up to three ⟨·,·⟩-orthogonal rows spanning those of `rows` whose bit is set in `use` (bit k
/// for row k; rows past the mask's width are in it when its top bit is set), in order.
int orthogonalRows(const std::vector<std::array<double, 3>>& rows, std::uint64_t use, const double m[3], double e[3][3],
                   double ee[3]) {
  int n = 0;
  for (std::size_t k = 0; k < rows.size() && n < 3; ++k) {
    if (!((k < 64 ? use >> k : use >> 63) & 1)) continue;
    double a[3] = {rows[k][0], rows[k][1], rows[k][2]};
    const double norm0 = a[0] * a[0] * m[0] + a[1] * a[1] * m[1] + a[2] * a[2] * m[2];
    for (int j = 0; j < n; ++j) {
      const double d = (a[0] * e[j][0] * m[0] + a[1] * e[j][1] * m[1] + a[2] * e[j][2] * m[2]) / ee[j];
      for (int r = 0; r < 3; ++r) a[r] -= d * e[j][r];
    }
    const double norm = a[0] * a[0] * m[0] + a[1] * a[1] * m[1] + a[2] * a[2] * m[2];
    if (!(norm > 1e-9 * norm0) || !(norm0 > 0)) continue;  // in the span of the earlier rows
    for (int r = 0; r < 3; ++r) e[n][r] = a[r];
    ee[n++] = norm;
  }
  return n;
}

/// p without its parts along the `rows` ⟨·,·⟩-orthogonal rows e (orthogonalRows): p −= M⁻¹eᵀ
/// (e·p)/⟨e, e⟩, row by row.
void projectOut(const double m[3], const double e[3][3], const double ee[3], int rows, double p[3]) {
  for (int j = 0; j < rows; ++j) {
    const double d = (e[j][0] * p[0] + e[j][1] * p[1] + e[j][2] * p[2]) / ee[j];
    for (int r = 0; r < 3; ++r) p[r] -= m[r] * e[j][r] * d;
  }
}

}  // namespace

void MovingSolid::restrict(double q[3]) const {
  const double m[3] = {invMass, invMass, invInertia};
  auto entering = [&](const std::array<double, 3>& a, const double* u) {
    const double an = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    const double un = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    return a[0] * u[0] + a[1] * u[1] + a[2] * u[2] > 1e-12 * an * un;
  };
  bool any = false;
  for (const auto& a : rests) any = any || entering(a, q);
  if (!any) return;
  // The velocity nearest q (in the mass metric) that enters no contact: the projection of q onto
  // the contacts held at the optimum, which among the projections onto every set of contacts is
  // the nearest that enters none (few contacts: every set is tried, in a fixed order).
  const double free[3] = {q[0], q[1], q[2]};
  const std::size_t n = std::min<std::size_t>(rests.size(), kMaxRestingSets);
  double best[3] = {0, 0, 0}, bestCost = -1;
  for (std::uint64_t set = 1; set < (std::uint64_t(1) << n); ++set) {
    double e[3][3], ee[3], p[3] = {free[0], free[1], free[2]};
    projectOut(m, e, ee, orthogonalRows(rests, set, m, e, ee), p);
    bool ok = true;
    for (const auto& a : rests) ok = ok && !entering(a, p);
    if (!ok) continue;
    double cost = 0;
    for (int r = 0; r < 3; ++r)
      if (m[r] > 0) cost += (p[r] - free[r]) * (p[r] - free[r]) / m[r];
    if (bestCost < 0 || cost < bestCost) {
      bestCost = cost;
      for (int r = 0; r < 3; ++r) best[r] = p[r];
    }
  }
  if (bestCost < 0) {  // none (more contacts than were tried): hold every contact
    double e[3][3], ee[3];
    for (int r = 0; r < 3; ++r) best[r] = free[r];
    projectOut(m, e, ee, orthogonalRows(rests, ~std::uint64_t(0), m, e, ee), best);
  }
  for (int r = 0; r < 3; ++r) q[r] = best[r];
}

void MovingSolid::restingResponse(double W[3][3]) const {
  const double m[3] = {invMass, invMass, invInertia};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) W[r][c] = r == c ? m[r] : 0.0;
  // The contacts it rests on, not those it leaves: a body that water lifts off the floor
  // (Box2D gave it the lift at the last step) is free to rise in the coupled solve.
  std::uint64_t resting = 0;
  for (std::size_t k = 0; k < rests.size(); ++k) {
    const auto& a = rests[k];
    if (a[0] * v.x() + a[1] * v.y() + a[2] * omega > -kLeaving)
      resting |= std::uint64_t(1) << std::min<std::size_t>(k, 63);
  }
  double e[3][3], ee[3];
  const int n = orthogonalRows(rests, resting, m, e, ee);
  for (int j = 0; j < n; ++j)
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) W[r][c] -= m[r] * e[j][r] * m[c] * e[j][c] / ee[j];
}

}  // namespace sph2d
