// Granular materials (sand, powder: a material of "kind": "granular"), as a viscoplastic
// continuum with the Coulomb yield of the μ(I) rheology at rest (Jop, Forterre & Pouliquen
// 2006, "A constitutive law for dense granular flows", Nature 441; its quasi-static limit,
// μ(I) = μs): the shear stress of a grain is bounded by
//   |τ| ≤ c + μs·p,   μs = tan(friction_angle),
// c the cohesion and p the pressure; below the bound the material does not deform. As in
// their Navier–Stokes form (Lagrée, Staron & Popinet 2011, "The granular column collapse as
// a continuum", JFM 686, who reproduce the 2D collapses of Lajeunesse et al. 2005 with it),
// the bound is a viscosity:
//   η_i = min((c + μs p_i) / |γ̇_i|, η_max),   |γ̇| = sqrt(2 D':D'),
// D' the deviatoric strain rate; η_max stands for "rigid" (the regularisation of a yield
// stress). A layer on a slope then flows where tan θ exceeds μs and stands where it does
// not: a pile stands at the friction angle.
//
// The stage runs where the game solver's velocities are final (after its grid pressure
// projection, before the move: Stage::velocities(), whose "pressure_now" stage brings P.p to
// this substep's), so the friction meets the pressure's push in the same substep; at the
// forces' place the projection would add a slump each substep that the friction removes only
// after the particles moved, and a pile would creep at about g·dt. The friction is the
// Laplacian viscosity's backward Euler (viscosity_implicit.hpp) with each grain's own η: a pair
// of grains takes the mean, a pair of a grain and a liquid none (the liquid's viscosity is the
// viscosity effect's). The static walls' samples take part with a wall viscosity of the
// grain's own, bounded so that the wall's force on a sliding grain is at most the bound over
// its share of the wall (Coulomb friction at the floor, the material's μs). A moving body's
// face takes part alike (the game solver places no samples in bodies: ShapeContacts gives each
// grain within a support of a body's shape the samples' sum of a flat face at its distance),
// no-slip against the body's velocity there under the same Coulomb bound, and a dynamic body
// is an unknown of the solve that takes the reaction: sand holds a body up by its friction,
// not only by its pressure, and a body that pushes sand is pushed back.
//
// η is lagged, a Picard iteration across substeps: each substep solves with the η the last
// one left (fields granular.nu and granular.wall_nu, η/ρ; 0 for a grain not measured yet,
// which starts rigid), then measures the strain rate of the solved velocities (the corrected
// SPH gradient, over granular neighbours) and sets η for the next from it. The solve is a
// momentum balance, so the stress it leaves, η|γ̇|, is the stress that holds the grains; where
// it exceeds the bound, η falls to the bound over |γ̇| and the grains yield.
//
// Measured (tests/engine/effects/test_granular.cpp): slowly poured piles stand within 1.5° of
// the friction angle from 20° to 40°; the 2D column collapses run out as Lajeunesse et al.'s
// law at 20 to 60 particles per column height, and further at finer spacings (a rate-independent
// Coulomb material is ill-posed, Barker, Schaeffer, Bohórquez & Gray 2015, JFM 779: its shear
// bands take the spacing's width; docs/notes/granular-resolution.md); a box 2.5 times as dense
// presses into a bed by less the larger φ and stops, where it sinks through φ = 0 to the floor
// (test_granular_bodies.cpp). Sand under water reads
// the total pressure, not the effective (no pore pressure): it stands steeper than in air.
#include <algorithm>
#include <cmath>
#include <limits>

#include "bodies/moving_solid.hpp"
#include "effects/effect.hpp"
#include "effects/viscosity_implicit.hpp"

namespace sph2d {
namespace {

/// η_max as a kinematic viscosity, in units of sqrt(g R³): "rigid". A layer H deep at rest on a
/// slope creeps at about g H² sin θ/(2 η_max/ρ), that is sqrt(gH)·(H/R)^1.5·sin θ/(2 kRigid):
/// 0.2 % of its free-fall speed at H = 50 R (at dx = 0.005 m, R = 0.01 m: η_max/ρ = 313 m²/s).
/// Measured: piles held their slope to 0.1° from 3 s to 12 s at 200 m²/s, and slumped 10° at
/// 1.2 m²/s. The backward Euler takes any η (its iterations stop at their cap).
constexpr double kRigid = 1e5;

/// The corrected gradient's matrix A is about the identity in a full neighbourhood and half
/// of it at a flat surface (det ¼); below this determinant a grain has too few granular
/// neighbours (a grain in flight, a corner) to measure its strain rate.
constexpr Real kMinDet = Real(0.05);

/// The fields hold 0 for a grain not measured yet (it starts rigid); a measured η of 0 (no
/// pressure, no cohesion) is kept as this.
constexpr Real kZero = std::numeric_limits<Real>::min();

class Granular final : public Effect {
 public:
  Granular(const std::vector<MaterialDef>& materials, const SolverDef& solver) { materialsChanged(materials, solver); }
  const char* name() const override { return "granular"; }
  bool afterPressure() const override { return true; }
  void materialsChanged(const std::vector<MaterialDef>& materials, const SolverDef&) override {
    member_.clear();
    mu_.clear();
    cohesion_.clear();
    for (const MaterialDef& m : materials) {
      member_.push_back(m.granular() ? 1 : 0);
      mu_.push_back(m.granular() ? Real(std::tan(m.frictionAngle * 3.14159265358979323846 / 180.0)) : Real(0));
      cohesion_.push_back(m.granular() ? Real(m.cohesion) : Real(0));
    }
  }

  std::size_t apply(StepContext& c) override {
    ParticleStore& P = c.P;
    const std::size_t n = P.size();
    if (n == 0 || !(c.dt > 0)) return kNone;
    const std::vector<std::uint32_t>* matField = P.findU32(ParticleStore::kMaterial);
    const std::uint32_t* mat = matField ? matField->data() : nullptr;
    const std::vector<Real>* ratioField = P.find(ParticleStore::kRestRatio);
    const Real* ratio = ratioField ? ratioField->data() : nullptr;
    std::vector<Real>& nu = P.field(kNu);
    std::vector<Real>& wallNu = P.field(kWallNu);
    // η_max/ρ: scale-free (a pile H tall creeps at about sqrt(gH)·(H/R)^1.5/(2 kRigid)), with
    // at least 1 m/s² for g (zero gravity: what holds grains is cohesion alone).
    const double g = std::max(1.0, double(c.gravity.norm()));
    const Real nuMax = Real(kRigid * std::sqrt(g * double(c.R) * double(c.R) * double(c.R)));
    member_i_.resize(n);
    rel_.resize(n);
    nuRel_.resize(n);
    c.pool.parallelFor(n, kStreamBlock, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        const std::uint32_t k = mat ? mat[i] : 0u;
        member_i_[i] = member_[k];
        // 0: a grain not measured yet (new, or loaded from before granular materials): rigid.
        const Real nui = nu[i] > 0 ? std::min(nu[i], nuMax) : nuMax,
                   wi = wallNu[i] > 0 ? std::min(wallNu[i], nuMax) : nuMax;
        rel_[i] = member_[k] ? (ratio ? ratio[i] : Real(1)) * nui / nuMax : Real(0);
        nuRel_[i] = member_[k] ? wi / nuMax : Real(0);
      }
    });
    // The Laplacian viscosity's constants at ν = η_max/ρ0 (viscosity.cpp), its lattice moment included.
    const Real scale = momentScale_(c);
    ViscosityTerm t;
    t.W = ViscosityKernel<Real>(c.R);
    t.muMass = nuMax * scale * c.rho0 * c.mass;
    t.wallFactor = Real(2) * nuMax * scale * c.rho0;
    t.walls = !c.boundary.samples.empty();
    t.noSlip = false;  // no samples in the moving bodies (game solver): their shapes take part instead
    contactBodies(c, t);
    ViscosityWeights w;
    w.ratio = ratio;
    w.rel = rel_.data();
    w.nuRel = nuRel_.data();
    w.member = member_i_.data();
    w.shapes = shapes_.list.empty() ? nullptr : &shapes_;
    const bool count = t.walls && c.wall;
    if (count) wallBlock_.assign((n + kBlock - 1) / kBlock, Vec2d(0, 0));
    const std::size_t bad = implicit_.apply(c, t, w, count, wallBlock_);
    if (count) c.wall->force += sumInOrder(wallBlock_, (n + kBlock - 1) / kBlock) * double(c.momentumMass);
    if (bad != kNone) return bad;
    nextViscosity(c, t, mat, ratio, nu, wallNu, nuMax);
    return kNone;
  }

 private:
  static constexpr const char* kNu = ParticleStore::kGranularNu;
  static constexpr const char* kWallNu = ParticleStore::kGranularWallNu;

  /// η/ρ for the next substep from the solved velocities v + dt·a: the bound over the strain
  /// rate (SPH gradient over the grain's granular neighbours), at most η_max.
  void nextViscosity(StepContext& c, const ViscosityTerm& t, const std::uint32_t* mat, const Real* ratio,
                     std::vector<Real>& nu, std::vector<Real>& wallNu, Real nuMax) {
    ParticleStore& P = c.P;
    const Spiky<Real> S(c.R);
    const Real dt = c.dt;
    const double tau = c.solids ? double(c.time) - c.solids->time0 : 0.0;
    c.pool.parallelFor(P.size(), kBlock, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        if (!member_i_[i]) continue;
        const Vec2 vi = P.v[i] + P.a[i] * dt;
        // ∇v by the corrected gradient (Bonet & Lok 1999): B = Σ V_j (v_j − v_i) ⊗ ∇W_ij and
        // A = Σ V_j (x_j − x_i) ⊗ ∇W_ij, ∇v = B A⁻¹, exact for a linear field also where the
        // neighbourhood is cut by the surface (there the plain sum reads a shear too small).
        Real bxx = 0, bxy = 0, byx = 0, byy = 0, axx = 0, axy = 0, ayx = 0, ayy = 0;
        const std::uint32_t* nb = c.nbr.of(i);
        for (std::uint32_t k = 0; k < c.nbr.count[i]; ++k) {
          const std::uint32_t j = nb[k];
          if (!member_i_[j]) continue;
          Vec2 d = P.x[i] - P.x[j];
          c.periodic.nearest(d.x(), d.y());
          const Vec2 g = S.gradient(d, d.norm()) * (c.mass * (ratio ? ratio[j] : Real(1)) * P.invRho[j]);  // V_j ∇W_ij
          const Vec2 dv = (P.v[j] + P.a[j] * dt) - vi;
          bxx += dv.x() * g.x();
          bxy += dv.x() * g.y();
          byx += dv.y() * g.x();
          byy += dv.y() * g.y();
          axx -= d.x() * g.x();
          axy -= d.x() * g.y();
          ayx -= d.y() * g.x();
          ayy -= d.y() * g.y();
        }
        const Real det = axx * ayy - axy * ayx;
        if (!(det > kMinDet)) {  // too few grains around to tell: rigid until they are
          nu[i] = nuMax;
          continue;
        }
        const Real ixx = ayy / det, ixy = -axy / det, iyx = -ayx / det, iyy = axx / det;  // A⁻¹
        const Real gxx = bxx * ixx + bxy * iyx, gxy = bxx * ixy + bxy * iyy;
        const Real gyx = byx * ixx + byy * iyx, gyy = byx * ixy + byy * iyy;
        const Real a = Real(0.5) * (gxx - gyy), s = Real(0.5) * (gxy + gyx);  // D' = [[a, s], [s, −a]]
        const Real rate = Real(2) * std::sqrt(a * a + s * s);                 // |γ̇| = sqrt(2 D':D')
        const std::uint32_t m = mat ? mat[i] : 0u;
        const Real bound = cohesion_[m] + mu_[m] * std::max(Real(0), P.p[i]);  // c + μs p
        const Real rho = P.rho[i] > 0 ? P.rho[i] : c.rho0;
        nu[i] = rate * rho * nuMax > bound ? std::max(bound / (rho * rate), kZero) : nuMax;
        // The walls: Coulomb friction on the grain's slip. The wall term's force on the grain
        // (viscosity_implicit.cpp), m s_i·(wallFactor IR_i s_i ν_w/ν_max)·Σ_b Ψ_b ∇²W_ib·|v_i|,
        // at most the bound over the grain's share of the wall, dx per unit depth. m is the
        // momentum mass ρ0·dx² (the mass the wall's impulse counts): with the density sums' mass
        // (0.79 of it at the game preset's support) the friction held to 1.27 μs.
        // A moving body's face alike (ShapeContacts), the slip relative to the body there.
        wallNu[i] = nuMax;
        const std::uint32_t bc = t.walls ? c.nbr.boundaryCount[i] : 0u;
        const bool touches = !shapes_.list.empty() && shapes_.start[i] < shapes_.start[i + 1];
        if (bc == 0 && !touches) continue;
        const std::uint32_t* bl = c.nbr.boundaryOf(i);
        Real gi = 0;
        for (std::uint32_t k = 0; k < bc; ++k)
          gi += c.boundary.volume[bl[k]] * t.W.laplacianR2((P.x[i] - c.boundary.samples[bl[k]]).squaredNorm());
        const Real si = ratio ? ratio[i] : Real(1);
        const Real slip = (P.v[i] + P.a[i] * dt).norm();
        const Real per = c.momentumMass * si * si * t.wallFactor / nuMax * P.invRho[i];
        Real perNu = per * gi * slip;  // force per unit ν_w
        if (touches) {
          Real gb = 0;  // Σ over the bodies' faces of g |v_i − v_body|
          for (std::uint32_t k = shapes_.start[i]; k < shapes_.start[i + 1]; ++k) {
            const ShapeContacts::Contact& ct = shapes_.list[k];
            const Vec2d vb = c.solids->bodies[ct.body].velocityAt(tau, P.x[i].cast<double>());
            gb += Real(ct.g) * (vi - vb.cast<Real>()).norm();
          }
          perNu += per * gb;
        }
        if (perNu * nuMax > bound * c.dx) wallNu[i] = std::max(bound * c.dx / perNu, kZero);
      }
    });
  }

  /// The grains within a support of a moving body's shape: shapes_, with g of a flat face at
  /// their distance from it (a table over [0, R], 64 steps, linear between).
  void contactBodies(StepContext& c, const ViscosityTerm& t) {
    shapes_.list.clear();
    shapes_.start.clear();
    if (!c.solids || c.solids->bodies.empty()) return;
    if (face_.empty() || faceR_ != c.R || faceDx_ != c.dx) {
      face_.resize(kFaceSteps + 1);
      for (int k = 0; k <= kFaceSteps; ++k)
        face_[std::size_t(k)] = flatFaceLaplacian(t.W, double(c.dx), double(c.R) * k / kFaceSteps);
      faceR_ = c.R;
      faceDx_ = c.dx;
    }
    const std::size_t n = c.P.size(), blocks = (n + kBlock - 1) / kBlock;
    const double tau = double(c.time) - c.solids->time0, R = double(c.R);
    shapes_.start.resize(n + 1);
    blockLists_.resize(blocks);
    c.pool.parallelFor(n, kBlock, [&](std::size_t lo, std::size_t hi) {
      std::vector<ShapeContacts::Contact>& L = blockLists_[lo / kBlock];
      L.clear();
      for (std::size_t i = lo; i < hi; ++i) {
        shapes_.start[i] = std::uint32_t(L.size());  // within the block; made global below
        if (!member_i_[i]) continue;
        for (std::size_t k = 0; k < c.solids->bodies.size(); ++k) {
          const double d = -c.solids->bodies[k].depth(tau, c.P.x[i].cast<double>());  // distance outside
          if (!(d < R)) continue;
          const double u = std::max(0.0, d) / R * kFaceSteps;
          const std::size_t j = std::min(std::size_t(u), std::size_t(kFaceSteps - 1));
          const double g = face_[j] + (face_[j + 1] - face_[j]) * (u - double(j));
          if (g > 0) L.push_back({std::uint32_t(k), g});
        }
      }
    });
    for (std::size_t b = 0; b < blocks; ++b) {  // the blocks' lists in order
      const std::uint32_t base = std::uint32_t(shapes_.list.size());
      for (std::size_t i = b * kBlock; i < std::min(n, (b + 1) * kBlock); ++i) shapes_.start[i] += base;
      shapes_.list.insert(shapes_.list.end(), blockLists_[b].begin(), blockLists_[b].end());
    }
    shapes_.start[n] = std::uint32_t(shapes_.list.size());
  }

  static constexpr int kFaceSteps = 64;
  ShapeContacts shapes_;                                         ///< this substep's grains near moving bodies
  std::vector<std::vector<ShapeContacts::Contact>> blockLists_;  ///< per block, while they are found
  std::vector<double> face_;                                     ///< flatFaceLaplacian over [0, R]
  Real faceR_ = -1, faceDx_ = -1;
  std::vector<std::uint8_t> member_;    ///< per material: granular
  std::vector<Real> mu_, cohesion_;     ///< per material: μs = tan(friction_angle), c [Pa]
  std::vector<std::uint8_t> member_i_;  ///< per particle: granular
  std::vector<Real> rel_, nuRel_;       ///< per particle: r_i·η_i/(ρ η_max), η_i/(ρ η_max)
  ImplicitViscosity implicit_;
  std::vector<Vec2d> wallBlock_;
  LaplacianMomentScale momentScale_;
};

}  // namespace

/// The granular effect when a material is granular.
std::unique_ptr<Effect> granularEffect(const SceneDef& scene) {
  const std::vector<MaterialDef> materials = sceneMaterials(scene);
  bool any = false;
  for (const MaterialDef& m : materials) any = any || m.granular();
  if (!any) return nullptr;
  return std::make_unique<Granular>(materials, scene.solver);
}

}  // namespace sph2d
