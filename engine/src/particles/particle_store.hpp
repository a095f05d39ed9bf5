// particle_store.hpp — structure-of-arrays particle storage (internal).
//
// Hot fields (read every substep by the neighbour passes) are contiguous
// arrays; the order of particles changes when the grid reorders them for
// locality, so a game holds particles by `id`, which never changes. The
// solver's working fields (a, xPrev, invRho, pOverRho, the optional solver
// fields) live here only: a game sees the read-only view of
// sph2d/particles.hpp (World::particles()).
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>
#include <utility>
#include <vector>

#include "sph2d/math.hpp"

namespace sph2d {

/// All per-particle data of a fluid. Index i is a storage slot; id[i] is stable.
struct ParticleStore {
  std::vector<Vec2> x;            ///< position, relative to World::origin() [m]
  std::vector<Vec2> v;            ///< velocity [m/s]
  std::vector<Vec2> a;            ///< acceleration of the current substep [m/s²]
  std::vector<Vec2> xPrev;        ///< position before the last integration (swept collision)
  std::vector<Real> rho;          ///< density [kg/m³]
  std::vector<Real> p;            ///< pressure [Pa]
  std::vector<Real> invRho;       ///< 1/ρ, set by the pressure stage (saves divisions in pair loops)
  std::vector<Real> pOverRho;     ///< p/ρ, set with p by the solver (every solver)
  std::vector<std::uint32_t> id;  ///< stable identifier

  /// Optional per-particle scalar fields, created only by the solver or effect
  /// that needs them (e.g. "age", "dfsph.kappa"), in creation order. Reordering
  /// permutes them with the rest; push() gives new particles 0. A deque: creating
  /// a field never moves the others, so references from field() stay valid.
  std::deque<std::pair<std::string, std::vector<Real>>> extra;
  /// Optional per-particle integer fields a game asks for (World::setParticleColor:
  /// "color", World::setParticleUserData: "user_data", World::setEmitterTracking:
  /// "emitter"), in creation order; like `extra`, permuted with the rest, 0 for new particles.
  std::deque<std::pair<std::string, std::vector<std::uint32_t>>> extraU32;
  /// Optional per-particle fields in double, for a quantity whose sum must hold to rounding
  /// over many substeps (the mixing effect's concentrations: in float, the updates smaller than
  /// half a float step are lost unevenly either side of a power of two, and the total drifted
  /// by 5e-6 in 3,000 substeps); like `extra`, permuted with the rest, 0 for new particles.
  std::deque<std::pair<std::string, std::vector<double>>> extraD;

  /// Number of particles.
  std::size_t size() const { return x.size(); }
  /// The optional field `name`, or nullptr when nothing created it.
  std::vector<Real>* find(const std::string& name) {
    for (auto& f : extra)
      if (f.first == name) return &f.second;
    return nullptr;
  }
  /// Const variant of find().
  const std::vector<Real>* find(const std::string& name) const {
    for (const auto& f : extra)
      if (f.first == name) return &f.second;
    return nullptr;
  }
  /// The optional field `name`, created (filled with `init`) on first use.
  std::vector<Real>& field(const std::string& name, Real init = 0) {
    if (auto* f = find(name)) return *f;
    extra.emplace_back(name, std::vector<Real>(size(), init));
    return extra.back().second;
  }
  /// The names of the optional integer fields (a save that holds one makes it one).
  static constexpr const char* kColor = "color";
  static constexpr const char* kUserData = "user_data";
  /// The World time at which each particle leaves [s] (a double field; 0: never;
  /// World::setLifetimes).
  static constexpr const char* kLifeEnd = "life_end";
  /// Groups (World::createGroup): 1 + the particle's group (0: none), its place in the
  /// group's rest shape, and the group's stiffness.
  static constexpr const char* kGroup = "group";
  static constexpr const char* kGroupQx = "group_qx";
  static constexpr const char* kGroupQy = "group_qy";
  static constexpr const char* kGroupStiffness = "group_stiffness";
  /// Elastic groups that yield or break (GroupDef::yieldStrain, breakStrain): the strains.
  static constexpr const char* kGroupYield = "group_yield";
  static constexpr const char* kGroupBreak = "group_break";
  /// Granular materials (effects/granular.cpp): each grain's viscosity over its density, and
  /// its wall's, for the next substep (0: not measured yet).
  static constexpr const char* kGranularNu = "granular.nu";
  static constexpr const char* kGranularWallNu = "granular.wall_nu";
  /// 1 + the index of the emitter that made the particle; 0: none (World::setEmitterTracking).
  static constexpr const char* kEmitter = "emitter";
  /// The particle's material (an index in World::materials()); only while the World has more than one.
  static constexpr const char* kMaterial = "material";
  /// ρ0 of the particle's material over the first material's (a Real field): only while two
  /// materials of the World differ in rest density (a solver that takes the contrast reads it).
  static constexpr const char* kRestRatio = "rest_ratio";
  /// With mixing (miscible materials): each particle's colour from its concentrations, 0xRRGGBB
  /// (an integer field), and its concentration of material k (a double field, concentration(k)).
  static constexpr const char* kMixedColor = "mixed_color";
  static std::string concentration(std::size_t k) { return "concentration." + std::to_string(k); }
  /// True for the name of an optional integer field a game sets (absent from a save: zeros on load).
  static bool integerField(const std::string& name) {
    return name == kColor || name == kUserData || name == kEmitter || name == kGroup;
  }
  /// True for the name of an optional float field a game's calls or a stage make (groups,
  /// granular; absent from a save: zeros on load, which hold "none" or "not measured yet").
  static bool gameRealField(const std::string& name) {
    return name == kGroupQx || name == kGroupQy || name == kGroupStiffness || name == kGroupYield ||
           name == kGroupBreak || name == kGranularNu || name == kGranularWallNu;
  }
  /// Removes the optional integer field `name` (nothing when it does not exist).
  void dropU32(const std::string& name) {
    for (auto it = extraU32.begin(); it != extraU32.end(); ++it)
      if (it->first == name) {
        extraU32.erase(it);
        return;
      }
  }
  /// The optional integer field `name`, or nullptr when nothing created it.
  std::vector<std::uint32_t>* findU32(const std::string& name) {
    for (auto& f : extraU32)
      if (f.first == name) return &f.second;
    return nullptr;
  }
  /// Const variant of findU32().
  const std::vector<std::uint32_t>* findU32(const std::string& name) const {
    for (const auto& f : extraU32)
      if (f.first == name) return &f.second;
    return nullptr;
  }
  /// The optional double field `name`, or nullptr when nothing created it.
  std::vector<double>* findD(const std::string& name) {
    for (auto& f : extraD)
      if (f.first == name) return &f.second;
    return nullptr;
  }
  /// Const variant of findD().
  const std::vector<double>* findD(const std::string& name) const {
    for (const auto& f : extraD)
      if (f.first == name) return &f.second;
    return nullptr;
  }
  /// The optional double field `name`, created (filled with 0) on first use.
  std::vector<double>& fieldD(const std::string& name) {
    if (auto* f = findD(name)) return *f;
    extraD.emplace_back(name, std::vector<double>(size(), 0.0));
    return extraD.back().second;
  }
  /// The optional integer field `name`, created (filled with 0) on first use.
  std::vector<std::uint32_t>& fieldU32(const std::string& name) {
    if (auto* f = findU32(name)) return *f;
    extraU32.emplace_back(name, std::vector<std::uint32_t>(size(), 0u));
    return extraU32.back().second;
  }
  /// Calls f(name, field) for every per-particle array: the fixed ones, then
  /// the optional ones in creation order. The one list of fields: storage,
  /// removal, reordering and memory accounting all go through it.
  template <class F>
  void forEachField(F&& f) {
    f("x", x);
    f("v", v);
    f("a", a);
    f("xPrev", xPrev);
    f("rho", rho);
    f("p", p);
    f("invRho", invRho);
    f("pOverRho", pOverRho);
    f("id", id);
    for (auto& e : extra) f(e.first.c_str(), e.second);
    for (auto& e : extraU32) f(e.first.c_str(), e.second);
    for (auto& e : extraD) f(e.first.c_str(), e.second);
  }
  /// Const variant of forEachField().
  template <class F>
  void forEachField(F&& f) const {
    const_cast<ParticleStore*>(this)->forEachField([&](const char* name, const auto& field) { f(name, field); });
  }
  /// Appends one particle at rest-density with zero pressure (optional fields 0).
  void push(const Vec2& pos, const Vec2& vel, std::uint32_t pid, Real rho0) {
    x.push_back(pos);
    v.push_back(vel);
    a.push_back(Vec2::Zero());
    xPrev.push_back(pos);
    rho.push_back(rho0);
    p.push_back(0);
    invRho.push_back(1 / rho0);
    pOverRho.push_back(0);
    id.push_back(pid);
    for (auto& f : extra) f.second.push_back(0);
    for (auto& f : extraU32) f.second.push_back(0);
    for (auto& f : extraD) f.second.push_back(0);
  }
  /// Removes the particles whose flag in `remove` is non-zero, keeping the
  /// order of the rest (serial: deterministic). Returns how many were removed.
  std::size_t compact(const std::vector<unsigned char>& remove) {
    const std::size_t n = size();
    std::size_t out = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (remove[i]) continue;
      if (out != i) forEachField([&](const char*, auto& field) { field[out] = field[i]; });
      ++out;
    }
    forEachField([&](const char*, auto& field) { field.resize(out); });
    return n - out;
  }
  /// Keeps the first n particles (n <= size()), every field cut alike.
  void truncate(std::size_t n) {
    forEachField([&](const char*, auto& field) { field.resize(n); });
  }
  /// Bytes held by the particle arrays (capacity, not size).
  std::size_t bytes() const {
    std::size_t b = 0;
    forEachField([&](const char*, const auto& field) { b += field.capacity() * sizeof(field[0]); });
    return b;
  }
};

}  // namespace sph2d
