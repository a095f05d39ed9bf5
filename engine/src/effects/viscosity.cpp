// Viscosity, the Laplacian form of Müller, Charypar & Gross 2003 ("Particle-based
// fluid simulation for interactive applications", SCA 2003, eq. 14):
// a_i += (μ/ρ_i) Σ_j m (v_j − v_i)/ρ_j ∇²W_visc(r_ij), with the 2D Laplacian
// of the viscosity kernel (kernels.hpp: 5(R−r)(R³+R²r+Rr²+9r³)/(3πR⁵r³),
// not the 3D c·(R − r)), r clamped to 0.05 R. μ = ν·ρ0. The sum is divided by
// the Laplacian's lattice moment (kernels.hpp: 0.834 at R = 2.5 dx), so that a
// shear flow feels ν and not 0.83 ν (measured on start-up Poiseuille flow).
// Time-step limit: dt ≤ 0.03 R²/ν (explicit diffusion). That limit is for pairs at
// the lattice's distances: ∇²W grows as 1/r³, so a pair pressed to 0.1 R (two particles
// put against a corner) needs a hundred times less. Each pair's coupling is therefore capped
// (ViscosityTerm::pairCap) so that dt·μm·∇²W_ij/(ρ_i ρ_j) ≤ kViscousPairShare = 1/8 (μm =
// ν_s ρ0 m, ν_s = ν over the lattice moment): the pair loses at most a quarter of its
// relative velocity per substep instead of overshooting, at any density (a lone pair in
// a splash reads far below ρ0). At the time-step limit a lattice neighbour takes at most
// 0.061 and the lattice's row sums 0.42 (R = 2.5 dx), so resolved flows never meet the cap,
// and a particle with four capped pairs besides still takes a convex combination of its
// neighbours' velocities. Without it the game preset's 20k dam break with ν = 0.001 m²/s
// ran away at the far corner after 0.72 s (two particles 3 mm apart at ±240 m/s).
//
// With solver.no_slip, the walls' boundary samples take part as fluid at rest
// (v_b = 0, density ρ0, volume Ψ_b): a_i += ν ρ0/ρ_i Σ_b Ψ_b (0 − v_i) ∇²W_ib,
// the no-slip wall of Morris, Fox & Zhu 1997 with the wall velocity in place
// of their mirrored one. A moving body's samples (body_samples.hpp, for the solvers
// that take them) are such a wall moving with the sample's velocity v_b, and the
// body takes minus the force they exert (its viscous drag, Akinci et al. 2012).
// Without no_slip (the default) walls are free-slip and only the collision stage's
// Coulomb friction acts on the fluid at the wall.
//
// Materials (docs/SCENES.md, "materials"): each has its own ν (absent: solver.viscosity). With
// materials of different viscosity a pair takes the mean of the two dynamic viscosities
// (μ_k = ν_k ρ0_k; the wall terms the particle's own), and ν above is the largest.
//
// Explicit or implicit, substep by substep: the effect does not limit the substep. A substep
// no longer than the explicit limit 0.03 R²/ν runs the explicit step above; a longer one (honey,
// ν of 0.01 m²/s and more, at the solver's own step) runs backward Euler on the same Laplacian
// (viscosity_implicit.hpp), so a stiff material never shortens the substep. The one exception:
// muller2003 computes a single viscosity inside its pressure loop (Solver::foldViscosity), and
// then the explicit limit holds.
#include <algorithm>
#include <cmath>

#include "bodies/body_samples.hpp"
#include "effects/effect.hpp"
#include "effects/viscosity_implicit.hpp"

namespace sph2d {
namespace {

class LaplacianViscosity final : public Effect {
 public:
  LaplacianViscosity(const std::vector<MaterialDef>& materials, const SolverDef& solver) : noSlip_(solver.noSlip) {
    materialsChanged(materials, solver);
  }
  /// ν (the largest) and whether every material has it, from the World's materials.
  void materialsChanged(const std::vector<MaterialDef>& materials, const SolverDef& solver) override {
    nu_ = Real(viscosityOf(materials.front(), solver));
    uniform_ = true;
    for (const MaterialDef& m : materials) {
      nu_ = std::max(nu_, Real(viscosityOf(m, solver)));
      uniform_ = uniform_ && viscosityOf(m, solver) == viscosityOf(materials.front(), solver);
    }
  }
  const char* name() const override { return "viscosity"; }
  const char* limitKey() const override { return "solver.viscosity"; }

  /// Explicit step limit, at the largest viscosity; the effect holds the substep to it only
  /// when folded (see the top).
  Real explicitLimit(const StepContext& c) const { return Real(0.03) * c.R * c.R / nu_; }
  Real maxTimeStep(const StepContext& c) const override {
    return folded ? explicitLimit(c) : std::numeric_limits<Real>::infinity();
  }

  /// One viscosity for every particle: a solver may compute it in its own pair loop.
  bool foldable() const override { return uniform_; }

  ViscosityTerm viscosityTerm(const StepContext& c) override {
    const Real nuS = nu_ * momentScale_(c);
    ViscosityTerm t;
    t.W = ViscosityKernel<Real>(c.R);
    t.muMass = nuS * c.rho0 * c.mass;
    t.wallFactor = Real(2) * nuS * c.rho0;
    t.walls = noSlip_ && !c.boundary.samples.empty();
    t.noSlip = noSlip_;
    if (c.dt > 0 && t.muMass > 0) t.pairCap = kViscousPairShare / (c.dt * t.muMass);
    return t;
  }

  std::size_t apply(StepContext& c) override {
    ParticleStore& P = c.P;
    const ViscosityTerm t = viscosityTerm(c);
    const ViscosityWeights wt = weights(c);
    const bool count = t.walls && c.wall;
    const std::size_t blocks = (P.size() + kBlock - 1) / kBlock;
    if (count) wallBlock_.assign(blocks, Vec2d(0, 0));
    std::size_t first;
    if (c.dt > explicitLimit(c))
      first = implicit_.apply(c, t, wt, count, wallBlock_);
    else
      first = explicitStep(c, t, wt, count);
    if (count) c.wall->force += sumInOrder(wallBlock_, blocks) * double(c.momentumMass);
    return first;
  }

 private:
  /// The pairs' weights this substep. Materials of different rest density (wcsph's number
  /// density): 1/ρ̃ = r/ρ for the volumes, and the pair's dynamic viscosity the mean of the two,
  /// over the particle's mass r_i m (momentum-conserving: m_i a_i is symmetric in the pair).
  /// Materials of different viscosity: each particle's dynamic viscosity r_i ν_i/ν.
  ViscosityWeights weights(const StepContext& c) {
    ViscosityWeights w;
    const ParticleStore& P = c.P;
    const std::vector<Real>* ratioField = P.find(ParticleStore::kRestRatio);
    w.ratio = ratioField ? ratioField->data() : nullptr;
    w.rel = w.ratio;
    const std::vector<std::uint32_t>* mat = P.findU32(ParticleStore::kMaterial);
    if (!c.materials || !mat) return w;
    std::vector<Real>& perMaterial = perMaterial_;
    perMaterial.clear();
    bool same = true;
    for (const MaterialDef& m : *c.materials) {
      perMaterial.push_back(Real(viscosityOf(m, c.def)) / nu_);
      same = same && perMaterial.back() == perMaterial.front();
    }
    if (same && perMaterial.front() == Real(1)) return w;
    rel_.resize(P.size());
    nuRel_.resize(P.size());
    for (std::size_t i = 0; i < P.size(); ++i) {
      nuRel_[i] = perMaterial[(*mat)[i]];
      rel_[i] = (w.ratio ? w.ratio[i] : Real(1)) * nuRel_[i];
    }
    w.rel = rel_.data();
    w.nuRel = nuRel_.data();
    return w;
  }

  std::size_t explicitStep(StepContext& c, const ViscosityTerm& t, const ViscosityWeights& wt, bool count) {
    ParticleStore& P = c.P;
    const ViscosityKernel<Real>& W = t.W;
    const Real muMass = t.muMass;
    const Vec2* X = P.x.data();
    const Vec2* V = P.v.data();
    const Real* IR = P.invRho.data();
    const Real* ratio = wt.ratio;
    const Real* rel = wt.rel;
    const Real* nuRel = wt.nuRel;
    const BoundarySet& B = c.boundary;
    const bool walls = t.walls;
    BodySamples* moving = t.noSlip && c.bodySamples && c.bodySamples->active() ? c.bodySamples : nullptr;
    // With the walls: their force on the fluid (World::wallImpulse), Σ m a_wall per block, the blocks in order.
    return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      std::size_t bad = kNone;
      Vec2d wallAcc(0, 0);
      for (std::size_t i = b; i < e; ++i) {
        const Real xix = X[i].x(), xiy = X[i].y(), vix = V[i].x(), viy = V[i].y();
        Real fx = 0, fy = 0;
        const Real ri = ratio ? ratio[i] : Real(1);
        const Real irN = IR[i] * ri;         // 1/ρ̃_i
        const Real capI = t.pairCap / irN;   // ViscosityTerm::pairCap · ρ̃_i
        const Real capWall = capI * c.rho0;  // … · ρ0, for a wall sample's ∇²W
        const std::uint32_t* nb = c.nbr.of(i);
        const std::uint32_t cnt = c.nbr.count[i];
        for (std::uint32_t k = 0; k < cnt; ++k) {
          const std::uint32_t j = nb[k];
          Real dx = xix - X[j].x(), dy = xiy - X[j].y();
          c.periodic.nearest(dx, dy);
          const Real r2 = dx * dx + dy * dy;
          Real w = W.laplacianR2(r2) * IR[j];
          if (rel) w *= (ratio ? ratio[j] : Real(1)) * (rel[i] + rel[j]) * Real(0.5) / ri;
          w = std::min(w, capI);
          fx += (V[j].x() - vix) * w;
          fy += (V[j].y() - viy) * w;
        }
        Vec2 acc = Vec2(fx, fy) * (muMass * irN);
        if (walls) {
          const Vec2 xi = X[i];
          Real sum = 0;  // Σ_b Ψ_b ∇²W_ib
          const std::uint32_t* bl = c.nbr.boundaryOf(i);
          for (std::uint32_t k = 0; k < c.nbr.boundaryCount[i]; ++k) {
            const std::uint32_t s = bl[k];
            sum += B.volume[s] * std::min(W.laplacianR2((xi - B.samples[s]).squaredNorm()), capWall);
          }
          Vec2 aWall = Vec2(vix, viy) * (t.wallFactor * irN * sum);
          if (nuRel) aWall *= nuRel[i];
          acc -= aWall;
          wallAcc -= aWall.cast<double>() * double(ri);  // m_i/m
        }
        if (moving && c.nbr.movingCount[i] > 0) {
          // The moving bodies' samples, body by body: the wall term with the sample's
          // velocity; each body's share is its reaction (a force and a torque about its
          // centre of mass), as in the solvers' own wall terms.
          const Vec2 xi = X[i];
          const std::uint32_t* ml = c.nbr.movingOf(i);
          const std::uint32_t mc = c.nbr.movingCount[i];
          const Real vK = t.wallFactor * irN * (nuRel ? nuRel[i] : Real(1));
          moving->forEachBody(ml, mc, [&](std::uint32_t body, const std::uint32_t* run, const std::uint32_t* runEnd) {
            // Against the body's velocity at the particle (BodySamples::velocityAt), not at the
            // sample's: a body turning with the water then feels no torque from its own surface
            // (at the samples' velocities a disc in a turning pool at ν = 0.5 m²/s was spun to 1.5
            // times the water's rate; at the particle's 1.4, the rest the Laplacian form's own,
            // docs/SCENES.md).
            const double omega = c.solids ? c.solids->bodies[body].omega : 0.0;
            const Vec2 vBody = moving->velocityAt(*run, omega, xi).cast<Real>();
            const Vec2 arm = moving->arm[*run] + (xi - moving->x[*run]);  // x_i − the centre of mass
            Real sum = 0;
            for (const std::uint32_t* p = run; p != runEnd; ++p)
              sum += moving->volume[*p] * std::min(W.laplacianR2((xi - moving->x[*p]).squaredNorm()), capWall);
            const Vec2 lv = (Vec2(vix, viy) - vBody) * sum;
            const Real tv = BodySamples::torque(arm, lv);
            const Vec2 aBody = -lv * vK;
            acc += aBody;
            if (moving->placed[body].dynamic)
              moving->addReaction(b / kBlock, body, aBody.cast<double>() * (double(c.momentumMass) * double(ri)),
                                  -double(tv) * double(vK) * (double(c.momentumMass) * double(ri)));
          });
        }
        P.a[i] += acc;
        if (!allFinite(acc) && bad == kNone) bad = i;
      }
      if (count) wallBlock_[b / kBlock] = wallAcc;
      return bad;
    });
  }

  Real nu_ = 0;  ///< the largest material's ν
  bool noSlip_;
  bool uniform_ = true;            ///< every material has ν
  std::vector<Real> rel_, nuRel_;  ///< weights(): per particle, with materials of different viscosity
  std::vector<Real> perMaterial_;  ///< weights(): ν_k/ν per material
  ImplicitViscosity implicit_;
  LaplacianMomentScale momentScale_;
  std::vector<Vec2d> wallBlock_;  ///< with the walls: per block of kBlock particles, Σ of their acceleration
};

}  // namespace

/// The viscosity effect when a material's viscosity (or solver.viscosity) is above 0 (with the
/// walls when solver.no_slip).
std::unique_ptr<Effect> viscosityEffect(const SceneDef& scene) {
  const std::vector<MaterialDef> materials = sceneMaterials(scene);
  double most = 0;
  for (const MaterialDef& m : materials) most = std::max(most, viscosityOf(m, scene.solver));
  if (!(most > 0)) return nullptr;
  return std::make_unique<LaplacianViscosity>(materials, scene.solver);
}

}  // namespace sph2d
