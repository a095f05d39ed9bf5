// effects/viscosity_implicit.hpp (internal) — the viscosity effect's implicit step, for a
// substep longer than its explicit limit (viscosity.cpp): backward Euler on the same
// Laplacian, solved by conjugate gradients.
#pragma once

#include <cstdint>
#include <vector>

#include "effects/effect.hpp"

namespace sph2d {

/// Particles' contacts with the moving bodies' shapes, for a solver that places no samples in
/// the bodies (the game solver): per particle, each body within its support and g = Σ_s Ψ_s
/// ∇²W_is of the samples a flat face of the body would hold at the particle's distance from
/// it (flatFaceLaplacian), taking part as the samples do (no-slip, a dynamic body a row of
/// the system, its reaction pushed onto it when the solve ends).
struct ShapeContacts {
  struct Contact {
    std::uint32_t body;  ///< index in StepContext::solids
    double g;            ///< Σ_s Ψ_s ∇²W_is of the body's face
  };
  std::vector<std::uint32_t> start;  ///< per particle its first contact, n + 1 entries (empty: no contact)
  std::vector<Contact> list;
};

/// Σ_s Ψ_s ∇²W(|x − x_s|) over the samples of a flat face at `distance` from x (≥ 0): layers
/// `dx` apart from dx/2 behind the face, each integrated along the face (a lattice of
/// spacing dx, each sample's volume dx², averaged over its offset), as a static wall's.
double flatFaceLaplacian(const ViscosityKernel<Real>& W, double dx, double distance);

/// Per-particle weights of the viscosity's pairs (viscosity.cpp); a null pointer: all 1.
struct ViscosityWeights {
  const Real* ratio = nullptr;  ///< rest ratio r_i = ρ0_i/ρ0 (density contrast: the particle's mass is r_i m)
  const Real* rel = nullptr;    ///< r_i·ν_i/ν: the particle's dynamic viscosity over ν ρ0 (a pair takes the mean)
  const Real* nuRel = nullptr;  ///< ν_i/ν (the wall terms), present with materials of different viscosity
  /// Non-null: a pair takes part only when both its particles do (1): the granular friction
  /// acts between grains, not between a grain and the water around it.
  const std::uint8_t* member = nullptr;
  /// Non-null (and no moving samples placed): the particles' contacts with the moving bodies.
  const ShapeContacts* shapes = nullptr;
};

/// Backward Euler for the Laplacian viscosity over one substep (Weiler et al. 2018, "A
/// physically consistent implicit viscosity solver for SPH fluids", solve their
/// (M − dt·A) v' = M v* by matrix-free conjugate gradients; here with the explicit effect's
/// Laplacian): with v* = v + dt·a (the accelerations so far), find v' from
///   m_i v'_i = m_i v*_i + dt Σ_j S_ij (v'_j − v'_i) + dt Σ_s e_is (v_s − v'_i),
/// S_ij = μm ∇²W_ij/(ρ_i ρ_j)·(pair weights) symmetric, e_is the no-slip coupling to the walls'
/// samples (v_s = 0) and the moving bodies' (v_s their velocity); then a_i += (v'_i − v*_i)/dt.
/// A dynamic body's velocity and spin are unknowns of the same system (its rows: its mass and
/// inertia, and minus what the fluid gains), so that a stiff material cannot throw a light
/// body past the fluid's velocity: the body takes the reaction the solved velocities give.
/// The matrix is symmetric positive definite at any dt: no pair cap is needed, and a stiff
/// material (honey) takes the solver's substep. Jacobi-preconditioned; every reduction is
/// summed block by block in block order, so the result has the same bits on any thread count.
class ImplicitViscosity {
 public:
  /// Runs the step; adds the walls' force to `wallBlock` (per block, when `count`) and the
  /// moving bodies' reactions as the explicit step does (samples), or pushed onto the bodies
  /// when the solve ends (ShapeContacts). Returns the first bad slot or kNone.
  std::size_t apply(StepContext& c, const ViscosityTerm& t, const ViscosityWeights& w, bool count,
                    std::vector<Vec2d>& wallBlock);
  /// Conjugate-gradient iterations of the last apply().
  int iterations() const { return iterations_; }

  static constexpr int kMaxIterations = 100;
  /// Stop when |r| ≤ kTolerance·|b| (b = m v* + …): velocities to about 1e-5 of their scale.
  static constexpr double kTolerance = 1e-5;

 private:
  /// A body's entry of a vector of the system: its velocity and spin.
  struct BodyVel {
    Vec2d v{0, 0};
    double w = 0;
  };
  /// A vector of the system: the particles' velocities and the dynamic bodies' (v, ω).
  struct Vec {
    std::vector<Vec2d> p;
    std::vector<BodyVel> b;
  };
  /// A particle's coupling to one dynamic body: E = Σ_s e_is, P = Σ_s e_is (ω × arm_s per unit ω).
  struct Link {
    std::uint32_t particle, body;
    double E;
    Vec2d P;
    double A;  ///< Σ_s e_is |arm_s|²: the body's spin row
  };
  /// out = K x. Returns x·Kx (the particles' block partials in order, then the bodies).
  double multiply(StepContext& c, const Vec& x, Vec& out);
  /// Σ a·b, likewise.
  double dot(StepContext& c, const Vec& a, const Vec& b);
  /// The bodies' diagonal preconditioner applied to r (z = r / diag).
  void precondition(StepContext& c, const Vec& r, Vec& z);

  std::vector<std::vector<Real>> coef_;        ///< dt·S_ij per fluid neighbour entry, aligned with nbr.perBlock
  std::vector<double> diag_;                   ///< m_i(1 + dt g_i) + dt Σ_j S_ij, in units of m
  std::vector<std::uint8_t> coupled_;          ///< per particle: a pair or a body link (else its row is diag_ alone)
  std::vector<std::vector<Link>> links_;       ///< per block: its particles' links to dynamic bodies
  std::vector<std::vector<BodyVel>> partial_;  ///< per block × body: Σ over its links (multiply)
  std::vector<double> mass_, inertia_;         ///< per body, in units of m (inertia 0: it cannot turn)
  std::vector<double> wallG_;                  ///< per particle, the static walls' coupling alone (their force)
  std::vector<BodyVel> bodyDiag_;              ///< the bodies' rows: diagonal (v.x = v.y, ω)
  std::vector<std::uint8_t> linked_;           ///< per body: a particle links to it (its row is solved)
  std::vector<Vec2d> bodyP_;                   ///< Σ of its links' P: the v–ω coupling
  Vec b_, x_, r_, z_, d_, q_;
  int iterations_ = 0;
};

}  // namespace sph2d
