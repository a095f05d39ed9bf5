// grid_projection.hpp (internal) — a coarse-grid pressure projection of the
// particle velocities (the grid half of Hybrid SPH: Raveendran, Wojtan & Turk
// 2011, "Hybrid smoothed particle hydrodynamics", SCA; the grid solve of
// Bridson's FLIP book, "Fluid Simulation for Computer Graphics", ch. 5).
//
// SPH pressure iterations fix short-range density errors fast, but a deep
// column's long (hydrostatic) mode needs ~(depth/dx)² Jacobi iterations. On a
// MAC grid of cells a few spacings wide that mode is a small linear system:
// the particles' velocities go to the grid faces (bilinear weights), cells
// are solid (inside a collider), a moving body's (more than a tenth of a cell
// inside a kinematic or dynamic Box2D body), fluid (enough particle weight) or air; a
// Poisson equation for κ = p/ρ0 makes the grid velocity divergence-free and
// removes the cells' mean compression over one substep; the change of the
// face velocities goes back to the particles (a FLIP increment, so nothing is
// smoothed away). Walls are closed faces (no-through-flow, free slip); a
// moving body's faces carry its velocity, and a dynamic body's velocity is
// solved with κ (Batty, Bertails & Bridson 2007, "A fast variational framework
// for accurate solid-fluid coupling", SIGGRAPH, on voxels, each body's faces
// corrected to its true area). The free surface is κ = 0 at the air cells'
// centres, or (`grid_surface`) half a spacing above the highest particle, a
// ghost-fluid boundary (Gibou, Fedkiw, Cheng & Kang 2002, JCP). The pressure
// acts through a smooth interpolated field, so it adds no stiffness to the
// particle arrangement (unlike SPH pressure sums under a large uniform pressure).
//
// The compression shift (Kugelstadt, Longva, Thuerey & Bender 2019, "Implicit
// density projection for volume conserving liquids", IEEE TVCG): the same
// Poisson matrix solved once more with the cells' compression (particle weight
// over a full cell's) as the source; its gradient is a move of positions, not of velocities, which the
// prediction adds. It removes the compression that large substeps pile up
// without putting kinetic energy in. With GridShift::fill the source also holds
// the deficit of interior cells (Kugelstadt et al. correct both signs): air that
// the projection would keep in a cell rises out of the water.
//
// Materials of different rest density (the field "rest_ratio", r = ρ0_i/ρ0): the cells'
// compression counts particles (number density: ρ_i/(r_i ρ0)), and each face takes
// β = 1/r_face, r_face the mean of its two cells' mass-weighted ratios: the system is
// −h²∇·(β∇κ) with κ = p/ρ0 continuous across an interface, and a face's velocity changes by
// −dt β ∇κ (the variable-density projection: Bridson's book, ch. 5.2 and ch. 12, as used for
// multiphase FLIP by Boyd & Bridson 2012, "MultiFLIP for energetic two-phase fluid simulation").
//
// Deterministic: particles go to the grid in slot order (each field on one
// thread), the conjugate-gradient sums are taken in cell order. On two threads
// a projection is four steps of a few tasks each (project()): the cells'
// weights, their classification and the matrix beside the u and v faces'
// velocities; the pressure solve beside the shift's solve and face moves; the
// u beside the v faces' changes; then the particles in blocks. The momentum balance
// (grid_momentum.cpp) sums each cluster's particles in slot order on one thread.
#pragma once

#include <cstdint>
#include <vector>

#include "solvers/game/grid_pcg.hpp"
#include "step/step_context.hpp"

namespace sph2d {

class StateOut;
class StateIn;

/// The compression shift (Kugelstadt et al. 2019, "Implicit density projection for volume
/// conserving liquids", IEEE TVCG: a second Poisson solve whose gradient moves positions, not
/// velocities): off when `rate` is 0.
struct GridShift {
  Real rate = 0;   ///< share of a cell's compression (particle weight over a full cell's, − 1, above `above`) removed
                   ///< per substep
  Real above = 0;  ///< compression a cell keeps (left to the particle solve)
  Real tolerance = 0.01;  ///< the solve stops when its largest residual stands for this density change
  /// Share of an interior cell's deficit (1 − its particle weight over a full cell's, above
  /// `above`) closed per substep: air the water holds (a pocket, a porous layer) is moved up
  /// and out through the free surface. Interior: its four neighbours are fluid cells (a cell
  /// at the surface or cut by a wall is short of particles by its nature).
  Real fill = 0;
  /// True when the shift moves particles at all.
  bool on() const { return rate > 0 || fill > 0; }
};

/// What one projection did.
struct GridProjectionStats {
  int iterations = 0;   ///< conjugate-gradient iterations (the pressure's and the shift's solves)
  int fluidCells = 0;   ///< unknowns
  double residual = 0;  ///< largest |Δρ/ρ0| the pressure solve's remaining residual stands for over the substep
  int pockets = 0;      ///< sealed pockets grounded (fluid regions with no open face to air and no dynamic body)
};

class GridProjection {
 public:
  /// Cells of `cellInSpacings`·dx; a cell is fluid above `fluidFraction` of a full cell's
  /// particle weight; the cells' mean compression is removed at `compressionRate` per
  /// substep; CG stops at `tolerance` (density change per substep) or `maxIterations`.
  GridProjection(Real cellInSpacings, Real fluidFraction, Real compressionRate, Real tolerance, int maxIterations,
                 GridShift shift = {});
  /// Projects P.v (reads x, v, rho; writes v). Returns the first bad slot or kNone.
  std::size_t project(StepContext& c);
  /// κ = p/ρ0 of the last projection at `x` (bilinear over the fluid and air cells, air
  /// holding 0; solid cells are left out; 0 outside the grid or before any projection).
  Real kappaAt(const Vec2& x) const;
  /// Writes the warm start the next projection starts from (World::save).
  void saveState(StateOut& out) const;
  /// Reads what saveState() wrote; at most `maxCells` cells.
  void loadState(StateIn& in, std::size_t maxCells);
  /// The last projection's figures.
  const GridProjectionStats& stats() const { return stats_; }

 private:
  /// The cells' kinds (GridPcg's, and kBody: inside a moving body, bodyOf_; solid to the system).
  enum : std::uint8_t { kAir = GridPcg::kAir, kFluid = GridPcg::kFluid, kSolid = GridPcg::kSolid, kBody = 3 };
  /// The grid over the particles' box (cells of cellRatio_·dx, larger for spray).
  void layout(const StepContext& c);
  /// Sizes and clears the cell fields and the face flags (the first task of a projection).
  void resetCells(bool contrast);
  /// Each face's β = 1/r_face from the cells' rest ratios (a density contrast).
  void faceCoefficients();
  /// β of u face f (axis 0) or v face f (axis 1): 1 without a density contrast.
  Real beta(int axis, std::size_t f) const { return uBeta_.empty() ? Real(1) : axis == 0 ? uBeta_[f] : vBeta_[f]; }
  /// Sizes and clears one axis's face fields (0: u, 1: v; that axis's splat task).
  void resetFaces(int axis);
  void classify(const StepContext& c);
  /// The particles' weights (and SPH compression, highest particle) to the cells, in slot order.
  void splatCells(const StepContext& c);
  /// The particles' velocities to the u (axis 0) or v (axis 1) faces, in slot order.
  void splatFaces(const StepContext& c, int axis);
  /// The pressure system of the classified cells (pcg_: grid_pcg.hpp), the ghost surface's θ
  /// and the dynamic bodies' coupling rows with it.
  void assemble();
  /// out += the dynamic bodies' response ρ0 h² G W Gᵀ·in (the coupled pressure solve's extra term).
  void addCoupled(const std::vector<Real>& in, std::vector<Real>& out) const;
  /// Marks the cells whose centre lies more than a tenth of a cell inside a moving body (kBody),
  /// static solids excepted; computes each body's face correction T and its response W as its
  /// resting contacts leave it (bodies_).
  void markBodies(const StepContext& c);
  /// The coupling rows G: one per (fluid cell, dynamic body) pair whose faces touch (their
  /// regions vented: a sealed pocket has no dynamic body).
  void assembleCoupling();
  /// The velocity along +x (axis 0, u face) or +y (axis 1, v face) that a moving body's
  /// cell imposes on face (i, j): g·(v, ω) with the face's corrected coupling g.
  Real bodyFaceVelocity(int body, int axis, int i, int j) const;
  /// The body of whichever of cells k1, k2 is a moving body's (−1: neither).
  int bodyAcross(std::size_t k1, std::size_t k2) const;
  /// The pressure solve's right-hand side (rhs_) and warm start (x_).
  void pressureSystem(const StepContext& c);
  /// The compression shift's right-hand side (rhsS_), its unknowns cleared (xs_).
  void shiftSystem(const StepContext& c);
  void solve(const StepContext& c);
  /// The bilinear weights of a point on the u and v faces, and the lower left face of each.
  struct FaceWeights {
    std::size_t ku, kv;
    Real u[4], v[4];  ///< (i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)
  };
  /// The weights at (px, py) in cell units of the grid.
  FaceWeights faceWeights(Real px, Real py) const;
  /// Bilinear sample of face fields u, v with weights `w`.
  Vec2 sampleFaces(const std::vector<Real>& u, const std::vector<Real>& v, const FaceWeights& w) const;
  /// vp no faster than v0, or than the projected velocities of the faces `w` samples together.
  Vec2 clampToFaces(const Vec2& vp, const Vec2& v0, const FaceWeights& w) const;
  /// The clusters of the momentum balance (grid_momentum.cpp): the fluid regions no wall or
  /// kinematic body holds, joined through the dynamic bodies they touch, with an interior cell
  /// (clusterOf_, per region then per body; cellCluster_). False when there is none.
  bool momentumClusters();
  /// The cluster a particle at (px, py) (cell units) belongs to, −1 for none.
  std::int32_t clusterAt(Real px, Real py) const;
  /// Takes out each cluster's imbalance (its particles' Σ m Δv from the transfer plus its
  /// dynamic bodies' impulse) as one velocity change of its particles and bodies. Returns the
  /// first particle it leaves non-finite or above the speed limit, or kNone.
  std::size_t balanceMomentum(StepContext& c);

 public:
  Real pic_ = 0;          ///< share of the projected grid velocity given to the particles (PIC; the rest FLIP)
  bool surface_ = false;  ///< ghost-fluid free surface at the fill level (else at the air cells' centres)
  /// grid_flip_clamp: a particle's new speed stays within its old one or what the projected
  /// velocities of the faces it samples reach (grid_projection.cpp, clampToFaces).
  bool flipClamp_ = false;
  /// grid_conserve: a fluid region no wall holds keeps its momentum with the dynamic bodies it
  /// touches through the transfer (grid_momentum.cpp).
  bool conserve_ = true;
  /// Per particle (slot order), the move the last projection's compression shift asks for
  /// (empty when the shift is off); read by the prediction of the same substep.
  const std::vector<Vec2>& shift() const { return shift_; }

 private:
  std::size_t transferToParticles(StepContext& c);
  /// The compression shift's face moves −dt²∇φ (su_, sv_) from the last shift solve.
  void shiftMoves(const StepContext& c);
  static void extrapolate(std::vector<Real>& d, int w, int h, const std::vector<std::uint8_t>& known);
  /// Cached solid flags of cell (I, J) and blocked flags of its left/bottom faces (anchored indices).
  std::uint8_t cacheEntry(const StepContext& c, long I, long J);

  Real cellRatio_, fluidFraction_, rate_, tol_;
  int maxIt_;
  Real h_ = 0, invH_ = 0;
  long I0_ = 0, J0_ = 0;  ///< anchored index of cell (0, 0)
  int nx_ = 0, ny_ = 0;
  std::vector<std::uint8_t> type_;             ///< per cell
  std::vector<std::uint8_t> uOpen_, vOpen_;    ///< per face: flow may cross it
  std::vector<std::uint8_t> fluidU_, fluidV_;  ///< per face: next to a fluid cell (its change is known)
  std::vector<Real> w_, comp_;                 ///< per cell: particle weight, weighted compression
  std::vector<Real> wr_;                       ///< per cell: weighted rest ratio (a density contrast only)
  std::vector<Real> uBeta_, vBeta_;            ///< per face: 1/r_face (a density contrast only; else empty)
  std::vector<Real> top_;                      ///< per cell: its highest particle's y (the ghost surface only)
  std::vector<Real> thetaUp_;                  ///< per cell: where the ghost surface lies above it, in cells (1: none)
  Real dx_ = 0;                                ///< the particle spacing
  std::vector<Real> u_, uw_, v_, vw_;          ///< face velocities and weights
  std::vector<std::uint8_t> uKnown_, vKnown_;  ///< per face: a particle reaches it (splatFaces)
  std::vector<Real> du_, dv_;                  ///< face velocity changes
  std::vector<Real> uNew_, vNew_;              ///< projected face velocities (for the PIC share)
  std::vector<Real> kappa_, rhs_, x_;  ///< per cell: κ; per unknown: the pressure solve's right-hand side and unknowns
  GridPcg pcg_;                        ///< the matrix of the fluid cells (both solves)
  GridPcg::Work cgMain_, cgShift_;
  GridShift shiftDef_;
  std::vector<Real> kappaS_, rhsS_, xs_, su_,
      sv_;                   ///< the shift's potential (per cell; right-hand side and unknowns) and face moves
  std::vector<Vec2> shift_;  ///< per particle
  // Warm start: the last substep's κ by anchored cell.
  Real pH_ = 0;  ///< the cell size of prevKappa_
  long pI0_ = 0, pJ0_ = 0;
  int pnx_ = 0, pny_ = 0;
  std::vector<Real> prevKappa_;
  // Solid/face cache over an anchored box, valid for one boundary version.
  std::uint64_t cacheVersion_ = 0;
  bool cacheValid_ = false;
  long cI0_ = 0, cJ0_ = 0;
  int cnx_ = 0, cny_ = 0;
  std::vector<std::uint8_t> cache_;  ///< bit 0 known, bit 1 solid, bit 2 left face blocked, bit 3 bottom face blocked
  GridProjectionStats stats_;
  // Moving bodies (moving_solid.hpp) in this projection: their centre and velocity at the
  // substep's start (the velocity after the solve for a dynamic body), and the coupling
  // rows: fluid cell a's faces into body k sum to G = Σ (n, r × n) (n into the body).
  struct BodyState {
    Vec2d centre{0, 0}, v{0, 0};
    double omega = 0, invMass = 0, invInertia = 0;
    bool held = false;  ///< Box2D holds it (MovingSolid::held): a wall to the momentum balance
    /// Its response to the pressure's impulse (J, L) as its resting contacts leave it
    /// (MovingSolid::restingResponse): diag(1/m, 1/m, 1/I) for a body resting on nothing.
    double W[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    bool movable = false;  ///< W is not zero: the pressure can move it (and the region is not sealed)
    double T[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  ///< the faces' correction (markBodies)
    /// g = T·(n, r × n) of a face at `face` with normal n into the body.
    void coupling(const Vec2d& n, const Vec2d& face, double g[3]) const;
  };
  std::vector<BodyState> bodies_;
  std::vector<std::int32_t> bodyOf_;  ///< per cell: the body of a kBody cell
  struct Coupling {
    std::int32_t unknown;  ///< the fluid cell's unknown
    std::int32_t body;
    double g[3];  ///< Σ over its faces into the body of (n_x, n_y, r × n)
  };
  std::vector<Coupling> coupling_;       ///< in unknown order
  double couplingScale_ = 0;             ///< ρ0 h²
  mutable std::vector<double> bodySum_;  ///< addCoupled()'s scratch: Gᵀ·in per body (the main solve only)
  std::vector<std::uint8_t> bodyCells_;  ///< markBodies' scratch: one body's cells over its box
  std::vector<double> bodyImpulse_;      ///< solve()'s scratch: each body's impulse Gᵀκ
  // The momentum balance (grid_momentum.cpp).
  static constexpr std::int32_t kNoFluid = -2;  ///< cellCluster_ of a cell that is not fluid
  std::vector<std::int32_t> clusterRoot_;       ///< union-find over the regions, then the bodies
  std::vector<std::uint8_t> clusterWalled_;     ///< per region or body: held by a wall, has an interior cell
  std::vector<std::int32_t> clusterOf_;         ///< per region, then per body: its cluster (−1: none)
  std::size_t clusters_ = 0;
  std::vector<std::int32_t> cellCluster_;  ///< per cell: its cluster (−1: none, kNoFluid: not a fluid cell)
  std::vector<std::int32_t> partCluster_;  ///< per particle: its cluster (−1: none)
  std::vector<Vec2> partDelta_;            ///< per particle: the transfer's change of its velocity
  std::vector<double> clusterSum_;         ///< per cluster: Σ m Δv and Σ m
  std::vector<Vec2> clusterShift_;         ///< per cluster: the velocity change that balances it
};

}  // namespace sph2d
