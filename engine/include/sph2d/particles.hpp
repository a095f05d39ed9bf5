// sph2d/particles.hpp — a fluid's particles as read-only arrays.
//
// World::particles() shows the World's own storage without copying: one
// array per field, indexed by storage slot. Slots change when the grid
// reorders the particles for locality or some are removed, so a game holds
// particles by `id`, which never changes (World::slotOf, getParticle). The
// World keeps its view pointing at its arrays after every step and change, so
// a reference to it stays good; a copy of the view (a Particles value) shows
// the arrays of the moment it was taken and goes stale with the next step. The
// solver's working fields stay inside the engine.
//
// A program that keeps particles to draw later (on another thread, or read
// from a file) owns them in a ParticleBuffer and passes its view().
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "sph2d/math.hpp"

namespace sph2d {

/// A read-only array someone else owns: a pointer and a length.
template <class T>
class ArrayView {
 public:
  /// An empty view.
  constexpr ArrayView() = default;
  /// The `size` values at `data`.
  constexpr ArrayView(const T* data, std::size_t size) : data_(data), size_(size) {}
  /// The values of `v` (valid while v is neither changed nor destroyed).
  ArrayView(const std::vector<T>& v) : data_(v.data()), size_(v.size()) {}  // NOLINT: implicit on purpose
  /// Not of a temporary vector: the view would outlive its values.
  ArrayView(const std::vector<T>&&) = delete;

  /// Value i (no bounds check).
  constexpr const T& operator[](std::size_t i) const { return data_[i]; }
  /// Number of values.
  constexpr std::size_t size() const { return size_; }
  /// True when there are no values.
  constexpr bool empty() const { return size_ == 0; }
  /// The first value (the view must not be empty).
  constexpr const T& front() const { return data_[0]; }
  /// The last value (the view must not be empty).
  constexpr const T& back() const { return data_[size_ - 1]; }
  /// The first value's address (null when empty and never set).
  constexpr const T* data() const { return data_; }
  /// Start of the values.
  constexpr const T* begin() const { return data_; }
  /// One past the last value.
  constexpr const T* end() const { return data_ + size_; }

 private:
  const T* data_ = nullptr;
  std::size_t size_ = 0;
};

/// A fluid's particles, one read-only array per field, indexed by storage slot.
/// Optional fields are empty when the World has none of them.
struct Particles {
  ArrayView<Vec2> x;            ///< position, relative to World::origin() [m]
  ArrayView<Vec2> v;            ///< velocity [m/s]
  ArrayView<Real> rho;          ///< density [kg/m³]
  ArrayView<Real> p;            ///< pressure [Pa]
  ArrayView<std::uint32_t> id;  ///< stable identifier
  ArrayView<Real> age;          ///< optional: time since emission [s] (scenes with lifetimes)
  ArrayView<std::uint32_t>
      color;  ///< optional: each particle's own colour 0xRRGGBB (World::setParticleColor; 0 = none)
  ArrayView<std::uint32_t> userData;  ///< optional: the game's value per particle (World::setParticleUserData)
  /// optional: 1 + the index of the emitter that made the particle, 0 for one no emitter made
  /// (World::setEmitterTracking; World::particleEmitter gives the index itself)
  ArrayView<std::uint32_t> emitter;
  /// optional: each particle's material, an index in World::materials() (a World of one
  /// material has none: every particle is of material 0)
  ArrayView<std::uint32_t> material;
  /// optional: with miscible materials, each particle's colour from its concentrations
  /// (0xRRGGBB, the materials' colours weighted), what the renderer draws it in
  ArrayView<std::uint32_t> mixedColor;
  /// optional: 1 + the index of the particle's group (World::createGroup), 0 for one in no
  /// group (a World that never had a group has none)
  ArrayView<std::uint32_t> group;

  /// Number of particles.
  std::size_t size() const { return x.size(); }
};

/// Particles a program owns: copies of a World's arrays taken between frames (to draw on
/// another thread), or particles read from a file. view() shows them as Particles.
struct ParticleBuffer {
  std::vector<Vec2> x;                    ///< position, in the local frame of the World they came from [m]
  std::vector<Vec2> v;                    ///< velocity [m/s]
  std::vector<Real> rho;                  ///< density [kg/m³]
  std::vector<Real> p;                    ///< pressure [Pa]
  std::vector<std::uint32_t> id;          ///< stable identifier
  std::vector<Real> age;                  ///< optional (empty or one per particle)
  std::vector<std::uint32_t> color;       ///< optional (empty or one per particle)
  std::vector<std::uint32_t> userData;    ///< optional (empty or one per particle)
  std::vector<std::uint32_t> emitter;     ///< optional (empty or one per particle)
  std::vector<std::uint32_t> material;    ///< optional (empty or one per particle)
  std::vector<std::uint32_t> mixedColor;  ///< optional (empty or one per particle)
  std::vector<std::uint32_t> group;       ///< optional (empty or one per particle)

  /// Number of particles.
  std::size_t size() const { return x.size(); }
  /// Appends one particle with pressure 0 (and 0 in the optional fields it has).
  void push(const Vec2& pos, const Vec2& vel, std::uint32_t pid, Real density) {
    x.push_back(pos);
    v.push_back(vel);
    rho.push_back(density);
    p.push_back(0);
    id.push_back(pid);
    if (!age.empty()) age.push_back(0);
    if (!color.empty()) color.push_back(0);
    if (!userData.empty()) userData.push_back(0);
    if (!emitter.empty()) emitter.push_back(0);
    if (!material.empty()) material.push_back(0);
    if (!mixedColor.empty()) mixedColor.push_back(0);
    if (!group.empty()) group.push_back(0);
  }
  /// Replaces the contents with copies of every array of `view` (capacity is kept, so a
  /// buffer reused frame after frame stops allocating).
  void assign(const Particles& view) {
    copy(view.x, x);
    copy(view.v, v);
    copy(view.rho, rho);
    copy(view.p, p);
    copy(view.id, id);
    copy(view.age, age);
    copy(view.color, color);
    copy(view.userData, userData);
    copy(view.emitter, emitter);
    copy(view.material, material);
    copy(view.mixedColor, mixedColor);
    copy(view.group, group);
  }
  /// The buffer as Particles (valid until the buffer changes).
  Particles view() const& {
    Particles P;
    P.x = x;
    P.v = v;
    P.rho = rho;
    P.p = p;
    P.id = id;
    P.age = age;
    P.color = color;
    P.userData = userData;
    P.emitter = emitter;
    P.material = material;
    P.mixedColor = mixedColor;
    P.group = group;
    return P;
  }
  /// Not of a temporary buffer: the views would outlive their values.
  Particles view() const&& = delete;

 private:
  template <class T>
  static void copy(const ArrayView<T>& from, std::vector<T>& to) {
    to.assign(from.begin(), from.end());
  }
};

}  // namespace sph2d
