// External forces: constant or region-limited force fields (wind, currents)
// and user forces (push/pull at a point, the mouse of a game). Both act on
// each particle alone, so they need no neighbours.
#include <cmath>

#include "effects/effect.hpp"

namespace sph2d {
namespace {

class ForceFields final : public Effect {
 public:
  explicit ForceFields(std::vector<ForceFieldDef> f) : fields_(std::move(f)) {}
  const char* name() const override { return "force_fields"; }
  std::size_t apply(StepContext& c) override {
    ParticleStore& P = c.P;
    return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      std::size_t bad = kNone;
      for (std::size_t i = b; i < e; ++i) {
        const Vec2d w = Vec2d(P.x[i].x(), P.x[i].y()) + c.origin;
        for (const ForceFieldDef& f : fields_)
          if (f.everywhere || f.region.contains(w)) P.a[i] += Vec2(Real(f.acceleration.x()), Real(f.acceleration.y()));
        if (!allFinite(P.a[i]) && bad == kNone) bad = i;
      }
      return bad;
    });
  }

 private:
  std::vector<ForceFieldDef> fields_;
};

class UserForces final : public Effect {
 public:
  explicit UserForces(const std::vector<UserForce>* f) : forces_(f) {}
  const char* name() const override { return "user_force"; }
  std::size_t apply(StepContext& c) override {
    ParticleStore& P = c.P;
    return firstBad(c.pool, P.size(), [&](std::size_t b, std::size_t e) {
      std::size_t bad = kNone;
      for (std::size_t i = b; i < e; ++i) {
        for (const UserForce& u : *forces_) {
          // Towards the point, falling linearly to zero at the radius.
          const Vec2d d = u.point - (Vec2d(P.x[i].x(), P.x[i].y()) + c.origin);
          const double r = d.norm();
          if (!(r < u.radius)) continue;
          const double s = u.strength * (1.0 - r / u.radius);
          const Vec2d dir = r > 0 ? Vec2d(d / r) : Vec2d(0, 0);
          P.a[i] += Vec2(Real(dir.x() * s), Real(dir.y() * s));
        }
        if (!allFinite(P.a[i]) && bad == kNone) bad = i;
      }
      return bad;
    });
  }

 private:
  const std::vector<UserForce>* forces_;
};

}  // namespace

/// The force fields of effects.force_fields, when there are any.
std::unique_ptr<Effect> forceFieldsEffect(const SceneDef& scene) {
  if (scene.effects.forceFields.empty()) return nullptr;
  return std::make_unique<ForceFields>(scene.effects.forceFields);
}

std::unique_ptr<Effect> makeUserForceEffect(const std::vector<UserForce>* forces) {
  return std::make_unique<UserForces>(forces);
}

}  // namespace sph2d
