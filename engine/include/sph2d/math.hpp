// sph2d/math.hpp — scalar and vector types of the engine.
//
// Hot particle data is single precision (Real = float): a 2D step is memory
// bound, and float halves the bytes per particle. Positions are stored
// relative to World::origin() (a double offset), so a scene 10 km from the
// world origin keeps the precision of one near it.
//
// Vector2 is the engine's own 2D vector, so the public headers pull in no
// linear-algebra library (a game includes world.hpp in milliseconds). Its
// members are the subset of Eigen's names the engine uses (x(), y(), dot,
// norm, squaredNorm, cwiseMin...), each computed in the order Eigen computes
// it for a fixed 2-vector (x·x + y·y; a division per component), so the bits
// of every step stayed as they were when Vec2 was an Eigen type.
#pragma once

#include <cmath>
#include <type_traits>

struct b2Vec2;  // Box2D's vector: a Vector2 is made from one (below) without including Box2D here

namespace sph2d {

/// A 2D vector of T: two values, no padding (std::vector<Vector2<float>> is x0 y0 x1 y1 ...).
template <class T>
struct Vector2 {
  using Scalar = T;       ///< the component type
  T v[2] = {T(0), T(0)};  ///< x, y

  /// The zero vector.
  constexpr Vector2() = default;
  /// (x, y), each converted to T.
  template <class A, class B>
  constexpr Vector2(A x, B y) : v{T(x), T(y)} {}
  /// Box2D's b2Vec2 (x, y), implicitly: a game sets the fields of the scene and input
  /// structs (EmitterDef::position, UserForce::point, FluidBlockDef::min ...) from its Box2D
  /// vectors as they are. A template only b2Vec2 satisfies, so no other type converts.
  template <class B2, std::enable_if_t<std::is_same<B2, ::b2Vec2>::value, int> = 0>
  constexpr Vector2(const B2& b) : v{T(b.x), T(b.y)} {}  // NOLINT: implicit on purpose

  /// The zero vector.
  static constexpr Vector2 Zero() { return Vector2(); }

  /// First component.
  constexpr T& x() { return v[0]; }
  /// First component.
  constexpr const T& x() const { return v[0]; }
  /// Second component.
  constexpr T& y() { return v[1]; }
  /// Second component.
  constexpr const T& y() const { return v[1]; }
  /// Component i (0 or 1).
  constexpr T& operator[](int i) { return v[i]; }
  /// Component i (0 or 1).
  constexpr const T& operator[](int i) const { return v[i]; }
  /// Component i (0 or 1).
  constexpr T& operator()(int i) { return v[i]; }
  /// Component i (0 or 1).
  constexpr const T& operator()(int i) const { return v[i]; }

  /// The two components, contiguous (for hashing and uploads).
  constexpr T* data() { return v; }
  /// The two components, contiguous (for hashing and uploads).
  constexpr const T* data() const { return v; }

  /// Componentwise sum.
  constexpr Vector2 operator+(const Vector2& o) const { return Vector2(v[0] + o.v[0], v[1] + o.v[1]); }
  /// Componentwise difference.
  constexpr Vector2 operator-(const Vector2& o) const { return Vector2(v[0] - o.v[0], v[1] - o.v[1]); }
  /// Negation.
  constexpr Vector2 operator-() const { return Vector2(-v[0], -v[1]); }
  /// Each component times s.
  constexpr Vector2 operator*(T s) const { return Vector2(v[0] * s, v[1] * s); }
  /// Each component divided by s (a division each, not a multiplication by 1/s).
  constexpr Vector2 operator/(T s) const { return Vector2(v[0] / s, v[1] / s); }
  /// Adds o.
  constexpr Vector2& operator+=(const Vector2& o) {
    v[0] += o.v[0];
    v[1] += o.v[1];
    return *this;
  }
  /// Subtracts o.
  constexpr Vector2& operator-=(const Vector2& o) {
    v[0] -= o.v[0];
    v[1] -= o.v[1];
    return *this;
  }
  /// Multiplies each component by s.
  constexpr Vector2& operator*=(T s) {
    v[0] *= s;
    v[1] *= s;
    return *this;
  }
  /// Divides each component by s.
  constexpr Vector2& operator/=(T s) {
    v[0] /= s;
    v[1] /= s;
    return *this;
  }
  /// Both components equal.
  constexpr bool operator==(const Vector2& o) const { return v[0] == o.v[0] && v[1] == o.v[1]; }
  /// Some component differs.
  constexpr bool operator!=(const Vector2& o) const { return !(*this == o); }

  /// x·o.x + y·o.y.
  constexpr T dot(const Vector2& o) const { return v[0] * o.v[0] + v[1] * o.v[1]; }
  /// x² + y².
  constexpr T squaredNorm() const { return v[0] * v[0] + v[1] * v[1]; }
  /// √(x² + y²).
  T norm() const { return std::sqrt(squaredNorm()); }
  /// This vector divided by its norm; the vector itself when its norm is 0.
  Vector2 normalized() const {
    const T n2 = squaredNorm();
    return n2 > T(0) ? *this / std::sqrt(n2) : *this;
  }
  /// Divides this vector by its norm (unchanged when the norm is 0).
  void normalize() {
    const T n2 = squaredNorm();
    if (n2 > T(0)) *this /= std::sqrt(n2);
  }
  /// Componentwise minimum.
  constexpr Vector2 cwiseMin(const Vector2& o) const {
    return Vector2(o.v[0] < v[0] ? o.v[0] : v[0], o.v[1] < v[1] ? o.v[1] : v[1]);
  }
  /// Componentwise maximum.
  constexpr Vector2 cwiseMax(const Vector2& o) const {
    return Vector2(v[0] < o.v[0] ? o.v[0] : v[0], v[1] < o.v[1] ? o.v[1] : v[1]);
  }
  /// Componentwise absolute value.
  Vector2 cwiseAbs() const { return Vector2(std::abs(v[0]), std::abs(v[1])); }
  /// The smaller component.
  constexpr T minCoeff() const { return v[1] < v[0] ? v[1] : v[0]; }
  /// The larger component.
  constexpr T maxCoeff() const { return v[1] > v[0] ? v[1] : v[0]; }
  /// The same vector in another scalar type.
  template <class U>
  constexpr Vector2<U> cast() const {
    return Vector2<U>(U(v[0]), U(v[1]));
  }
};

/// s times each component of a.
template <class T>
constexpr Vector2<T> operator*(typename Vector2<T>::Scalar s, const Vector2<T>& a) {
  return Vector2<T>(s * a.v[0], s * a.v[1]);
}

/// Scalar of the per-particle arrays.
using Real = float;
/// 2D vector of Real.
using Vec2 = Vector2<Real>;
/// 2D vector of double, for world coordinates and scene definitions.
using Vec2d = Vector2<double>;

/// Pi in the requested precision.
template <class T>
constexpr T kPi = T(3.14159265358979323846264338327950288);

/// True when every component of v is finite.
template <class V>
inline bool allFinite(const V& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y());
}

}  // namespace sph2d
