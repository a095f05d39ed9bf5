// grid_pcg.hpp (internal) — the coarse-grid projection's pressure system on its own
// (grid_projection.hpp builds it from the particles; tests/engine/solvers/game/test_grid_pcg.cpp
// solves it from cells alone).
//
// The unknowns are the fluid cells of an nx × ny grid, numbered in cell order (row by row).
// Row a of the matrix is the 5-point Laplacian times −h² (unit spacing): diag·x_a − Σ x_b
// over its fluid neighbours b across open faces, where diag counts the open faces to fluid
// or air cells; an air cell holds x = 0 at its centre (Dirichlet), a solid cell or a closed
// face adds nothing (Neumann, no flow). With the ghost-fluid surface the face up to air
// counts 1/θ instead of 1 (the surface a fraction θ of the way to the air cell's centre:
// Gibou, Fedkiw, Cheng & Kang 2002, JCP). With a coefficient per face (materials of
// different density: β = ρ0/ρ_face) each face counts β instead of 1, on the diagonal and
// off it: the matrix of −h²∇·(β∇x), still symmetric (one β per face), the MIC(0) factor
// and both substitutions weighted alike. Without one, the loops run as before (β = 1 is no
// multiplication: the same bits).
//
// A sealed pocket (fluid cells joined by open faces with no open face to air, and none the
// caller vents: a body that can move) is a pure Neumann block: singular, its solution
// defined up to a constant and only for a right-hand side that sums to zero over it. Each
// pocket is found by union-find, its last cell grounded (diagonal + 1, so the system is
// definite), and balance() takes the pocket's mean out of a right-hand side: then the
// grounded cell's x is 0 and every equation holds as before.
//
// The solve: conjugate gradients preconditioned by MIC(0) (Bridson, "Fluid Simulation for
// Computer Graphics", 2nd ed., ch. 5), the vectors in Real, every sum (the dot products) in
// double in cell order. It uses no thread: the same bits wherever it runs, and two solves
// on one system may run at once (each with its own Work).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "sph2d/math.hpp"

namespace sph2d {

class GridPcg {
 public:
  /// Cell kinds (any other value is solid too: the projection's moving bodies).
  enum : std::uint8_t { kAir = 0, kFluid = 1, kSolid = 2 };

  /// The vectors of one solve (two solves on one system need one each).
  struct Work {
    std::vector<Real> r, z, d, q, y;
  };

  /// An addition to the matrix: out += B·in over the unknowns (the projection's dynamic bodies).
  using Extra = std::function<void(const std::vector<Real>& in, std::vector<Real>& out)>;

  /// Numbers the fluid cells of `type` (nx·ny, row by row) and builds their rows. `uOpen`
  /// ((nx + 1)·ny) and `vOpen` (nx·(ny + 1)) say which faces flow may cross (a fluid cell's
  /// faces are read); `thetaUp` (per cell, or null: 1) where the surface lies above a fluid
  /// cell whose face up is open to air; `uBeta` and `vBeta` (laid out as uOpen and vOpen,
  /// both or neither) each face's coefficient β > 0 (null: 1). Fluid cells must not touch
  /// the grid's border (the projection leaves its border cells air). Then vent() and
  /// factor() follow.
  void assemble(int nx, int ny, const std::vector<std::uint8_t>& type, const std::vector<std::uint8_t>& uOpen,
                const std::vector<std::uint8_t>& vOpen, const std::vector<Real>* thetaUp,
                const std::vector<Real>* uBeta = nullptr, const std::vector<Real>* vBeta = nullptr);
  /// Unknown a's region is not sealed (a dynamic body it pushes can give way).
  void vent(std::size_t a) { vented_[a] = 1; }
  /// Grounds the sealed pockets and computes the MIC(0) factor (after assemble() and vent()).
  void factor();

  /// Takes each sealed pocket's mean out of a right-hand side over the unknowns (summed in cell order).
  void balance(std::vector<Real>& rhs) const;
  /// out = A·in over the unknowns.
  void apply(const std::vector<Real>& in, std::vector<Real>& out) const;
  /// Solves (A + B)·x = b from the x given, B the `extra` term (null: none), until the
  /// largest |r| is at most `tol` or after `maxIterations`; `res` gets the largest |r| of
  /// the residual the iteration carries. Returns the iterations taken.
  int solve(std::vector<Real>& x, const std::vector<Real>& b, Real tol, int maxIterations, Real& res, Work& w,
            const Extra* extra = nullptr) const;

  /// The unknowns.
  std::size_t size() const { return cells_.size(); }
  /// Unknown → cell (j·nx + i).
  const std::vector<std::int32_t>& cells() const { return cells_; }
  /// The sealed pockets the last factor() grounded.
  std::size_t pockets() const { return pocketLast_.size(); }
  /// Per unknown, its region: the fluid cells joined by open faces, numbered 0.. in order of
  /// their first unknowns (set by factor()).
  const std::vector<std::int32_t>& regionOf() const { return regionOf_; }
  /// The regions' count.
  std::size_t regions() const { return regions_; }
  /// Calls f(a, i, j) for every unknown a (cell (i, j)), in cell order, row by row.
  template <class F>
  void forUnknowns(F f) const {
    for (int j = 0; j < ny_; ++j)
      for (std::int32_t a = rowStart_[std::size_t(j)]; a < rowStart_[std::size_t(j) + 1]; ++a)
        f(std::size_t(a), cells_[std::size_t(a)] - j * nx_, j);
  }

 private:
  void groundPockets();
  template <bool Weighted>
  void factorRows();
  template <bool Weighted>
  void precondition(const std::vector<Real>& r, std::vector<Real>& z, std::vector<Real>& y) const;
  /// apply(in, out), returning in·out (summed in cell order, in double); `in` holds m + 1 values, the last 0.
  template <bool Weighted>
  double applyDot(const std::vector<Real>& in, std::vector<Real>& out) const;
  /// a·b over the unknowns, summed in cell order in double.
  double dot(const std::vector<Real>& a, const std::vector<Real>& b) const;

  int nx_ = 0, ny_ = 0;
  std::vector<std::int32_t> index_;     ///< cell → unknown (−1: none)
  std::vector<std::int32_t> cells_;     ///< unknown → cell
  std::vector<std::int32_t> rowStart_;  ///< per grid row: its first unknown (ny + 1 entries, the last m)
  std::vector<Real> diag_;              ///< per unknown
  std::vector<std::int32_t> adj_;       ///< per unknown: left, right, down, up unknown (−1: none)
  std::vector<std::int32_t> nbrPad_;    ///< adj_ with m for none (applyDot reads a 0 there)
  std::vector<Real> beta_;              ///< per unknown, its four faces' β as adj_ (empty: every β is 1)
  std::vector<Real> precon_, precon2_;  ///< MIC(0) factor: 1/diag(L), and its square
  std::vector<std::uint8_t> vented_;    ///< per unknown: an open face to air (then per region root: the region has one)
  std::vector<std::int32_t> pocketOf_;  ///< per unknown: its sealed pocket (−1: a vented region)
  std::vector<std::int32_t> regionOf_;  ///< per unknown: its region (regionOf())
  std::size_t regions_ = 0;
  std::vector<std::int32_t> pocketCells_, pocketLast_;  ///< per pocket: its cell count, its grounded (last) unknown
};

/// A Poisson problem on cells alone (GridPcg without the projection): `cells` (nx·ny, row by
/// row) GridPcg::kAir, kFluid or kSolid, every face open, no fluid cell on the border; `rhs`
/// per cell, read at the fluid cells. Solves A·p = rhs (A = −h²∇², the sealed pockets'
/// right-hand sides balanced first) from p = 0.
struct GridPoissonResult {
  std::vector<Real> pressure;  ///< per cell (0 at air and solid cells)
  int iterations = 0;
  Real residual = 0;  ///< the largest |r| of the iteration's residual (of the balanced right-hand side)
  int unknowns = 0;   ///< fluid cells
  int pockets = 0;    ///< sealed pockets grounded
};
GridPoissonResult solveGridPoisson(int nx, int ny, const std::vector<std::uint8_t>& cells, const std::vector<Real>& rhs,
                                   Real tolerance, int maxIterations);

}  // namespace sph2d
