// sph2d/field_operators.hpp — SPH interpolation and differential operators on
// any particle set (the SPH interpolant of the GAMES103 course notes' SPH
// introduction: A(x) = Σ_j V_j A_j W(x − x_j), V_j = m_j/ρ_j).
//
// Design note.
// - Nothing here knows about the fluid solver: a `ParticleView` is three
//   borrowed arrays (positions, and volumes or masses + densities), so the
//   same operators run on fluid particles, boundary samples, or a lattice in a
//   test. The caller owns the arrays and keeps them alive.
// - `NeighbourSearch` is a self-contained uniform grid (stable counting sort by
//   cell, cells at least the search radius, so candidates are the 3×3 block).
//   It is independent of the solver's internal grid on purpose: it accepts
//   float or double positions, needs no thread pool, and its candidate order
//   (cell order, then index) is fixed, so every sum below is deterministic.
// - `FieldOperators<K>` is templated on a kernel of kernels.hpp (Poly6, Spiky,
//   ViscosityKernel, CubicSpline, WendlandC2) and works in that kernel's scalar
//   (float or double). Kernels are used, never re-implemented here.
// - Convention: x_ij = x_i − x_j, r = |x_ij|, ∇W_ij = ∇_i W(x_ij) =
//   kernel.gradient(x_ij, r). Sums run over j with r < R (R = kernel support),
//   including j = i where the term does not vanish by itself (only `sample`).
// - Fields are arrays indexed like the particles: `const T*` for scalars and
//   `const V*` (V = the kernel's 2D vector) for vectors.
// The measured accuracy of each form is in docs/KERNELS.md.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "sph2d/math.hpp"

namespace sph2d {

/// A borrowed particle set: n positions plus either per-particle volumes V_j,
/// or masses m_j and densities ρ_j (then V_j = m_j/ρ_j).
template <class T>
struct ParticleView {
  using V = Vector2<T>;
  const V* x = nullptr;        ///< positions [n]
  std::size_t n = 0;           ///< number of particles
  const T* volume = nullptr;   ///< V_j [n], or null when mass and density are given
  const T* mass = nullptr;     ///< m_j [n], or null when volume is given
  const T* density = nullptr;  ///< ρ_j [n], or null when volume is given

  /// A set described by volumes. The symmetric gradient then uses m_j = V_j, ρ_j = 1.
  static ParticleView withVolumes(const V* pos, const T* vol, std::size_t count) {
    ParticleView p;
    p.x = pos;
    p.n = count;
    p.volume = vol;
    return p;
  }
  /// A set described by masses and densities.
  static ParticleView withMassDensity(const V* pos, const T* m, const T* rho, std::size_t count) {
    ParticleView p;
    p.x = pos;
    p.n = count;
    p.mass = m;
    p.density = rho;
    return p;
  }
  /// True when positions and either volumes or masses and densities are set (or n = 0).
  bool valid() const { return n == 0 || (x && (volume || (mass && density))); }
  /// V_j.
  T volumeOf(std::size_t j) const { return volume ? volume[j] : mass[j] / density[j]; }
  /// m_j (V_j for a volume-only set).
  T massOf(std::size_t j) const { return volume ? volume[j] : mass[j]; }
  /// ρ_j (1 for a volume-only set).
  T densityOf(std::size_t j) const { return volume ? T(1) : density[j]; }
};

/// Uniform-grid neighbour search over a fixed set of positions (float or double).
/// Cells are at least the search radius plus a rounding margin, so every point
/// within the radius of a query lies in the 3×3 cells around it; callers filter
/// candidates by distance. Rebuild after the positions move.
class NeighbourSearch {
 public:
  /// An empty search (no candidates until build()).
  NeighbourSearch() = default;
  /// Builds over x[0..n) for queries of radius `radius` (> 0). Throws
  /// std::invalid_argument on a non-positive radius or a non-finite position.
  void build(const Vec2* x, std::size_t n, double radius) { buildImpl(x, n, radius); }
  /// Builds over double positions (see the float overload).
  void build(const Vec2d* x, std::size_t n, double radius) { buildImpl(x, n, radius); }

  /// The radius the search was built for.
  double radius() const { return radius_; }
  /// Number of indexed positions.
  std::size_t size() const { return sorted_.size(); }
  /// The cell edge actually used (≥ radius; larger when the box would need too many cells).
  double cellSize() const { return cell_; }

  /// Calls f(j) for every indexed point j in the 3×3 cells around p (a superset
  /// of the points within radius()), in cell order then index order. A
  /// non-finite p has no candidates.
  template <class S, class F>
  void forCandidates(const Vector2<S>& p, F&& f) const {
    if (sorted_.empty()) return;
    const double px = double(p.x()), py = double(p.y());
    if (!std::isfinite(px) || !std::isfinite(py)) return;
    const int cx = coord(px, loX_, nx_), cy = coord(py, loY_, ny_);
    const int x0 = cx > 0 ? cx - 1 : 0, x1 = cx + 1 < nx_ ? cx + 1 : nx_ - 1;
    const int y0 = cy > 0 ? cy - 1 : 0, y1 = cy + 1 < ny_ ? cy + 1 : ny_ - 1;
    for (int y = y0; y <= y1; ++y) {
      const std::size_t row = std::size_t(y) * std::size_t(nx_);
      const std::uint32_t b = cellStart_[row + std::size_t(x0)], e = cellStart_[row + std::size_t(x1) + 1];
      for (std::uint32_t k = b; k < e; ++k) f(std::size_t(sorted_[k]));
    }
  }

 private:
  template <class P>
  void buildImpl(const P* x, std::size_t n, double radius);
  int coord(double v, double origin, int count) const {
    double c = std::floor((v - origin) * invCell_);
    if (c < 0) c = 0;
    if (c > double(count - 1)) c = double(count - 1);
    return int(c);
  }

  double radius_ = 0, cell_ = 1, invCell_ = 1, loX_ = 0, loY_ = 0;
  int nx_ = 1, ny_ = 1;
  std::vector<std::uint32_t> cellStart_;  // nx·ny + 1 offsets into sorted_
  std::vector<std::uint32_t> sorted_;     // point indices in cell order (stable)
};

/// Tuning of FieldOperators (docs/KERNELS.md uses the defaults).
template <class T>
struct FieldOperatorOptions {
  /// Smoothing length h of the Brookshaw/Morris denominator |x_ij|² + 0.01 h²;
  /// ≤ 0 means R/2 (R = 2h, the support convention of the cubic and Wendland kernels).
  T smoothingLength = T(0);
  /// The correction matrix M is "near-singular" when |det M| ≤ this · ½‖M‖²_F
  /// (1 for M = I, 0 for rank one); the corrected operators then fall back to
  /// the uncorrected ones.
  T minCorrectionDeterminant = T(1e-3);
};

/// SPH interpolation and differential operators of one kernel over one particle set.
/// Holds a copy of the kernel, the view and a reference to the search (which must
/// stay alive and have been built over the same positions with radius ≥ R).
template <class K>
class FieldOperators {
 public:
  using V = typename K::V;            ///< 2D vector of the kernel's scalar
  using T = typename V::Scalar;       ///< float or double
  using M2 = Eigen::Matrix<T, 2, 2>;  ///< 2×2 matrix (fixed size)
  using E2 = Eigen::Matrix<T, 2, 1>;  ///< V as an Eigen column, for the 2×2 algebra
  static E2 col(const V& a) { return E2(a.x(), a.y()); }

  /// Throws std::invalid_argument when the view is incomplete or the search does
  /// not match it (size, radius < R).
  FieldOperators(const K& kernel, const ParticleView<T>& particles, const NeighbourSearch& search,
                 const FieldOperatorOptions<T>& options = {})
      : k_(kernel), p_(particles), s_(&search), opt_(options) {
    if (!p_.valid()) throw std::invalid_argument("FieldOperators: the particle view lacks positions or volumes");
    if (search.size() != p_.n) throw std::invalid_argument("FieldOperators: the search indexes a different set");
    if (p_.n > 0 && search.radius() < double(k_.R))
      throw std::invalid_argument("FieldOperators: the search radius is below the kernel support");
    h_ = opt_.smoothingLength > T(0) ? opt_.smoothingLength : T(0.5) * k_.R;
  }

  /// The kernel.
  const K& kernel() const { return k_; }
  /// The particle set.
  const ParticleView<T>& particles() const { return p_; }
  /// The smoothing length h used by the Brookshaw denominator.
  T smoothingLength() const { return h_; }

  /// Calls f(j, d, r) for every particle j with r = |d| < R, d = x − x_j, in
  /// the search's fixed order. The building block of every operator below.
  template <class F>
  void forNeighbours(const V& x, F&& f) const {
    const T R2 = k_.R * k_.R;
    s_->forCandidates(x, [&](std::size_t j) {
      const V d = x - p_.x[j];
      const T r2 = d.squaredNorm();
      if (r2 < R2) f(j, d, std::sqrt(r2));
    });
  }

  /// Plain SPH interpolation Σ_j V_j A_j W(x − x_j) at any point x (the textbook form).
  /// Exact in the continuum limit; near a free surface or the edge of the set it
  /// under-estimates (the kernel is truncated). Use it when the deficit is the
  /// point, e.g. density by summation (A = ρ gives Σ m_j W).
  template <class A>
  A sample(const V& x, const A* field) const {
    checkField<A>();
    A sum = zero<A>();
    forNeighbours(x, [&](std::size_t j, const V&, T r) { sum += field[j] * (p_.volumeOf(j) * k_.value(r)); });
    return sum;
  }

  /// Shepard kernel sum Σ_j V_j W(x − x_j): 1 in the bulk, < 1 near the edge of the set.
  T shepardSum(const V& x) const {
    T sum = T(0);
    forNeighbours(x, [&](std::size_t j, const V&, T r) { sum += p_.volumeOf(j) * k_.value(r); });
    return sum;
  }

  /// Shepard-normalised interpolation Σ V_j A_j W / Σ V_j W at any point x.
  /// Reproduces constants exactly (zeroth-order consistent) on any particle
  /// layout, including truncated supports, so it is the form to sample a field
  /// for output or at a surface; it is not exact for linear fields on an
  /// irregular layout (error ∇A · first moment). Zero where no particle is in range.
  template <class A>
  A sampleShepard(const V& x, const A* field) const {
    checkField<A>();
    A sum = zero<A>();
    T w = T(0);
    forNeighbours(x, [&](std::size_t j, const V&, T r) {
      const T vw = p_.volumeOf(j) * k_.value(r);
      sum += field[j] * vw;
      w += vw;
    });
    return w > T(0) ? A(sum / w) : zero<A>();
  }

  /// Gradient, difference form Σ_j V_j (A_j − A_i) ∇W_ij at particle i.
  /// Exactly zero for a constant field on any layout (no kernel-sum error), so
  /// it is the usual choice to measure a gradient; not antisymmetric in i, j,
  /// so a force built from it does not conserve momentum.
  V gradient(std::size_t i, const T* field) const {
    V g = V::Zero();
    const T ai = field[i];
    forNeighbours(p_.x[i],
                  [&](std::size_t j, const V& d, T r) { g += k_.gradient(d, r) * (p_.volumeOf(j) * (field[j] - ai)); });
    return g;
  }

  /// Gradient, symmetric form ρ_i Σ_j m_j (A_i/ρ_i² + A_j/ρ_j²) ∇W_ij at particle i.
  /// Pairwise antisymmetric, so Σ_i V_i (result) = 0: a pressure force built from
  /// it conserves linear momentum exactly — the choice for forces. Not zero for a
  /// constant field off a perfect lattice (it carries the kernel-sum error).
  V gradientSymmetric(std::size_t i, const T* field) const {
    V g = V::Zero();
    const T rhoi = p_.densityOf(i);
    const T ai = field[i] / (rhoi * rhoi);
    forNeighbours(p_.x[i], [&](std::size_t j, const V& d, T r) {
      const T rhoj = p_.densityOf(j);
      g += k_.gradient(d, r) * (p_.massOf(j) * (ai + field[j] / (rhoj * rhoj)));
    });
    return g * rhoi;
  }

  /// The kernel-gradient correction L_i = M_i⁻¹, M_i = Σ_j V_j ∇W_ij ⊗ (x_j − x_i)
  /// (Bonet & Lok 1999). Writes L and returns true, or returns false (L = I) when
  /// M_i is near-singular (see FieldOperatorOptions) or not finite.
  bool correctionMatrix(std::size_t i, M2& L) const {
    M2 M = M2::Zero();
    forNeighbours(p_.x[i], [&](std::size_t j, const V& d, T r) {
      M.noalias() -= col(k_.gradient(d, r) * p_.volumeOf(j)) * col(d).transpose();  // x_j − x_i = −d
    });
    return invertCorrection(M, L);
  }

  /// Corrected gradient L_i Σ_j V_j (A_j − A_i) ∇W_ij (Bonet & Lok 1999): exact
  /// for linear fields on any layout where M_i is invertible (also at a free
  /// surface), first-order consistent. The choice for accurate gradients on
  /// disordered particles; not antisymmetric, so not for conservative forces.
  /// Falls back to gradient() where M_i is near-singular.
  V gradientCorrected(std::size_t i, const T* field) const {
    M2 M = M2::Zero();
    V g = V::Zero();
    const T ai = field[i];
    forNeighbours(p_.x[i], [&](std::size_t j, const V& d, T r) {
      const V gw = k_.gradient(d, r) * p_.volumeOf(j);
      M.noalias() -= col(gw) * col(d).transpose();
      g += gw * (field[j] - ai);
    });
    M2 L;
    if (!invertCorrection(M, L)) return g;
    const E2 lg = L * col(g);
    return V(lg(0), lg(1));
  }

  /// Divergence, difference form Σ_j V_j (A_j − A_i) · ∇W_ij. Zero for a
  /// uniform field on any layout (e.g. the velocity divergence of a rigid translation).
  T divergence(std::size_t i, const V* field) const { return jacobian(i, field, false).trace(); }

  /// 2D curl ∂A_y/∂x − ∂A_x/∂y, difference form Σ_j V_j ∇W_ij × (A_j − A_i)
  /// (a × b = a_x b_y − a_y b_x). Zero for a uniform field on any layout.
  T curl(std::size_t i, const V* field) const {
    const M2 J = jacobian(i, field, false);
    return J(0, 1) - J(1, 0);
  }

  /// Divergence with the kernel-gradient correction: trace of L_i Σ_j V_j ∇W_ij ⊗ (A_j − A_i).
  /// Exact for linear vector fields where M_i is invertible.
  T divergenceCorrected(std::size_t i, const V* field) const { return jacobian(i, field, true).trace(); }

  /// 2D curl with the kernel-gradient correction. Exact for linear vector fields
  /// where M_i is invertible.
  T curlCorrected(std::size_t i, const V* field) const {
    const M2 J = jacobian(i, field, true);
    return J(0, 1) - J(1, 0);
  }

  /// Laplacian, kernel-Laplacian form Σ_j V_j (A_j − A_i) ∇²W_ij (the textbook form).
  /// Cheap and zero for constants, but it uses the second kernel derivative, so
  /// it is sensitive to particle disorder and converges only with many
  /// neighbours; on a lattice with fixed h/dx it stalls at a lattice-dependent
  /// error (docs/KERNELS.md). Needs a kernel with hasLaplacian.
  template <class A>
  A laplacian(std::size_t i, const A* field) const {
    static_assert(K::hasLaplacian, "this kernel has no usable Laplacian (use laplacianBrookshaw)");
    checkField<A>();
    A sum = zero<A>();
    const A ai = field[i];
    forNeighbours(p_.x[i],
                  [&](std::size_t j, const V&, T r) { sum += A(field[j] - ai) * (p_.volumeOf(j) * k_.laplacian(r)); });
    return sum;
  }

  /// Laplacian, Brookshaw (1985) / Morris et al. (1997) form
  /// 2 Σ_j V_j (A_i − A_j) (x_ij · ∇W_ij) / (|x_ij|² + 0.01 h²), approximating +∇²A.
  /// Uses only the first kernel derivative (works with any kernel, Spiky
  /// included), so it is far less sensitive to disorder than the kernel-Laplacian
  /// form; the pair term is symmetric, so a diffusion (viscosity, heat) built from
  /// it conserves the diffused quantity. The usual choice for viscosity.
  template <class A>
  A laplacianBrookshaw(std::size_t i, const A* field) const {
    checkField<A>();
    A sum = zero<A>();
    const A ai = field[i];
    const T eta2 = T(0.01) * h_ * h_;
    forNeighbours(p_.x[i], [&](std::size_t j, const V& d, T r) {
      const T xg = d.dot(k_.gradient(d, r));  // x_ij · ∇W_ij = r W'(r) ≤ 0
      sum += A(ai - field[j]) * (T(2) * p_.volumeOf(j) * xg / (r * r + eta2));
    });
    return sum;
  }

  /// Renormalised Brookshaw Laplacian: the Brookshaw sum of A divided by the
  /// Brookshaw sum of |x − x_i|² (whose Laplacian is 4), times 4:
  /// 4 Σ_j w_j (A_j − A_i) / Σ_j w_j |x_ij|², w_j = −2 V_j (x_ij·∇W_ij)/(|x_ij|² + 0.01 h²) ≥ 0.
  /// The plain forms carry the particle layout's error in the kernel's second
  /// moment, a relative error that does not shrink when dx shrinks at fixed h/dx;
  /// dividing it out makes this form exact for quadratics on a regular lattice
  /// and second-order convergent there. It does not remove the first-moment
  /// error of disordered particles, and it is not pairwise symmetric (it does
  /// not conserve the diffused quantity): use it to measure a Laplacian. Zero
  /// without neighbours.
  template <class A>
  A laplacianBrookshawNormalised(std::size_t i, const A* field) const {
    checkField<A>();
    A sum = zero<A>();
    T moment = T(0);
    const A ai = field[i];
    const T eta2 = T(0.01) * h_ * h_;
    forNeighbours(p_.x[i], [&](std::size_t j, const V& d, T r) {
      const T r2 = r * r;
      const T w = T(-2) * p_.volumeOf(j) * d.dot(k_.gradient(d, r)) / (r2 + eta2);
      sum += A(field[j] - ai) * w;
      moment += w * r2;
    });
    return moment > T(0) ? A(sum * (T(4) / moment)) : zero<A>();
  }

 private:
  template <class A>
  static void checkField() {
    static_assert(std::is_same<A, T>::value || std::is_same<A, V>::value,
                  "a field is an array of the kernel's scalar or of its 2D vector");
  }
  template <class A>
  static A zero() {
    if constexpr (std::is_same<A, T>::value)
      return T(0);
    else
      return V::Zero();
  }

  // J(a, b) ≈ ∂A_b/∂x_a: Σ_j V_j ∇W_ij (A_j − A_i)ᵀ, corrected by L_i on request.
  M2 jacobian(std::size_t i, const V* field, bool corrected) const {
    M2 M = M2::Zero(), J = M2::Zero();
    const V ai = field[i];
    forNeighbours(p_.x[i], [&](std::size_t j, const V& d, T r) {
      const V gw = k_.gradient(d, r) * p_.volumeOf(j);
      if (corrected) M.noalias() -= col(gw) * col(d).transpose();
      J.noalias() += col(gw) * col(field[j] - ai).transpose();
    });
    M2 L;
    if (corrected && invertCorrection(M, L)) return L * J;
    return J;
  }

  bool invertCorrection(const M2& M, M2& L) const {
    const T det = M.determinant();
    const T scale = T(0.5) * M.squaredNorm();
    if (std::isfinite(det) && std::fabs(det) > opt_.minCorrectionDeterminant * scale && scale > T(0)) {
      L = M.inverse();
      if (L.allFinite()) return true;
    }
    L = M2::Identity();
    return false;
  }

  K k_;
  ParticleView<T> p_;
  const NeighbourSearch* s_;
  FieldOperatorOptions<T> opt_;
  T h_ = T(0);
};

}  // namespace sph2d
