// The scene's section readers (scene_sections.hpp), all but `events`
// (events.cpp). Each reads its keys in a fixed order and calls the checks of
// scene_checks.hpp as soon as the values they look at are read, so a file with
// several mistakes always reports the same first one.
#include "scene/scene_sections.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "scene/scene_checks.hpp"
#include "solvers/solver.hpp"

namespace sph2d {

using nlohmann::json;

namespace {

// ---- boundaries ------------------------------------------------------------------

ShapeDef readFixture(const Reader& r, const json& j, const std::string& path) {
  r.requireObject(j, path);
  ShapeDef s;
  if (!j.contains("shape"))
    r.fail(Reader::sub(path, "shape"), "missing; allowed values: box, polygon, circle, edge, chain");
  const std::string shape = r.string(j, path, "shape", "", {"box", "polygon", "circle", "edge", "chain"});
  std::vector<std::string> keys = {"shape", "friction", "restitution", "density"};
  if (shape == "box") {
    s.type = ShapeDef::Type::Box;
    keys.insert(keys.end(), {"center", "half_size", "angle"});
    r.checkKeys(j, path, keys);
    s.center = r.vec2(j, path, "center", s.center);
    s.halfSize = r.requiredVec2(j, path, "half_size");
    checkBoxHalfSize(r, s.halfSize, path);
    s.angle = r.number(j, path, "angle", 0, -1e3, 1e3);
  } else if (shape == "polygon") {
    s.type = ShapeDef::Type::Polygon;
    keys.insert(keys.end(), {"vertices"});
    r.checkKeys(j, path, keys);
    s.vertices = r.points(j, path, "vertices");
    checkPolygon(r, s.vertices, Reader::sub(path, "vertices"));
  } else if (shape == "circle") {
    s.type = ShapeDef::Type::Circle;
    keys.insert(keys.end(), {"center", "radius"});
    r.checkKeys(j, path, keys);
    s.center = r.vec2(j, path, "center", s.center);
    if (!j.contains("radius")) r.fail(Reader::sub(path, "radius"), "missing; expected a number > 0");
    s.radius = r.number(j, path, "radius", 0, 0, 1e6, true);
    checkCircleRadius(r, s.radius, path);
  } else if (shape == "edge") {
    s.type = ShapeDef::Type::Edge;
    keys.insert(keys.end(), {"vertices"});
    r.checkKeys(j, path, keys);
    s.vertices = r.points(j, path, "vertices");
    checkEdge(r, s.vertices, Reader::sub(path, "vertices"));
  } else {
    s.type = ShapeDef::Type::Chain;
    keys.insert(keys.end(), {"vertices", "loop"});
    r.checkKeys(j, path, keys);
    s.vertices = r.points(j, path, "vertices");
    s.loop = r.boolean(j, path, "loop", false);
    checkChain(r, s.vertices, s.loop, Reader::sub(path, "vertices"));
  }
  s.friction = r.number(j, path, "friction", s.friction, 0, 10);
  s.restitution = r.number(j, path, "restitution", s.restitution, 0, 1);
  s.density =
      r.number(j, path, "density", s.density, 1, 1e6);  // below 1 kg/m² the coupled grid solve is ill-conditioned
  return s;
}

BodyDef readBody(const Reader& r, const json& j, const std::string& p) {
  r.requireObject(j, p);
  BodyDef body;
  const std::string type =
      j.contains("type") ? r.string(j, p, "type", "static", {"static", "kinematic", "dynamic"}) : "static";
  if (type == "kinematic" || type == "dynamic") {
    body.type = type == "dynamic" ? BodyDef::Type::Dynamic : BodyDef::Type::Kinematic;
    r.checkKeys(j, p, {"type", "position", "angle", "velocity", "angular_velocity", "fixtures"});
    body.velocity = r.vec2(j, p, "velocity", body.velocity);
    if (!(body.velocity.norm() <= 1e3)) r.fail(Reader::sub(p, "velocity"), "at most 1000 m/s");
    body.angularVelocity = r.number(j, p, "angular_velocity", 0, -1e3, 1e3);
  } else {
    r.checkKeys(j, p, {"type", "position", "angle", "fixtures"});
  }
  body.position = r.vec2(j, p, "position", body.position);
  body.angle = r.number(j, p, "angle", 0, -1e3, 1e3);
  if (!j.contains("fixtures")) r.fail(Reader::sub(p, "fixtures"), "missing; expected an array of fixtures");
  const json& fx = j.at("fixtures");
  if (!fx.is_array()) r.fail(Reader::sub(p, "fixtures"), "expected an array of fixtures, got " + describe(fx));
  for (std::size_t f = 0; f < fx.size(); ++f) {
    const std::string pf = p + ".fixtures[" + std::to_string(f) + "]";
    body.fixtures.push_back(readFixture(r, fx[f], pf));
    const ShapeDef::Type t = body.fixtures.back().type;
    if (body.type != BodyDef::Type::Static && (t == ShapeDef::Type::Edge || t == ShapeDef::Type::Chain))
      r.fail(Reader::sub(pf, "shape"), "a " + type + " body's fixtures enclose an area: box, polygon or circle");
    if (body.type != BodyDef::Type::Dynamic && fx[f].is_object() && fx[f].contains("density"))
      r.fail(Reader::sub(pf, "density"),
             "only a dynamic body's fixtures have a density (a " + type + " body is not moved by forces)");
  }
  return body;
}

// ---- fluid -------------------------------------------------------------------------

VelocityFieldDef readVelocityField(const Reader& r, const json& f, const std::string& pf) {
  r.requireObject(f, pf);
  if (!f.contains("type")) r.fail(Reader::sub(pf, "type"), "missing; allowed values: taylor_green, strain, linear");
  const std::string type = r.string(f, pf, "type", "", {"taylor_green", "strain", "linear"});
  VelocityFieldDef field;
  if (type == "linear") {
    r.checkKeys(f, pf, {"type", "gradient", "origin"});
    field.type = VelocityFieldDef::Type::Linear;
    const std::string pg = Reader::sub(pf, "gradient");
    const char* want = "expected the velocity gradient [[du/dx, du/dy], [dv/dx, dv/dy]] in 1/s, each within -1e4..1e4";
    if (!f.contains("gradient")) r.fail(pg, std::string("missing; ") + want);
    const json& g = f.at("gradient");
    if (!g.is_array() || g.size() != 2 || !g[0].is_array() || !g[1].is_array()) r.fail(pg, want);
    for (int row = 0; row < 2; ++row) {
      const Vec2d v = r.vec2(g[std::size_t(row)], pg + "[" + std::to_string(row) + "]");
      if (!(std::fabs(v.x()) <= 1e4 && std::fabs(v.y()) <= 1e4)) r.fail(pg, want);
      field.gradient[std::size_t(2 * row)] = v.x();
      field.gradient[std::size_t(2 * row + 1)] = v.y();
    }
  } else if (type == "strain") {
    r.checkKeys(f, pf, {"type", "rate", "origin"});
    field.type = VelocityFieldDef::Type::Strain;
    if (!f.contains("rate"))
      r.fail(Reader::sub(pf, "rate"), "missing; expected the strain rate s in 1/s (u = -s x, v = s y)");
    field.rate = r.number(f, pf, "rate", 0, -1e4, 1e4);
  } else {
    r.checkKeys(f, pf, {"type", "amplitude", "wavelength", "origin"});
    field.type = VelocityFieldDef::Type::TaylorGreen;
    field.amplitude = r.number(f, pf, "amplitude", field.amplitude, -1e3, 1e3);
    field.wavelength = r.number(f, pf, "wavelength", field.wavelength, 0, 1e4, true);
  }
  field.origin = r.vec2(f, pf, "origin", field.origin);
  return field;
}

FluidBlockDef readBlock(const Reader& r, const json& j, const std::string& p, const SceneDef& s) {
  r.requireObject(j, p);
  FluidBlockDef blk;
  const std::string shape = j.contains("shape") ? r.string(j, p, "shape", "box", {"box", "circle", "polygon"}) : "box";
  const double dx = s.solver.spacing;
  if (shape == "circle") {
    // The lattice of a drop (World::addDrop): a square of whole spacings around the centre.
    r.checkKeys(j, p, {"shape", "center", "radius", "velocity", "velocity_field", "material"});
    const Vec2d center = r.requiredVec2(j, p, "center");
    if (!j.contains("radius")) r.fail(Reader::sub(p, "radius"), "missing; expected a number > 0 [m]");
    blk = circleRegion(center, r.number(j, p, "radius", 0, 0, 1e6, true), dx);
  } else if (shape == "polygon") {
    r.checkKeys(j, p, {"shape", "vertices", "velocity", "velocity_field", "material"});
    std::vector<Vec2d> vertices = r.points(j, p, "vertices");
    checkFluidPolygon(r, vertices, Reader::sub(p, "vertices"));
    blk = polygonRegion(std::move(vertices));
  } else {
    r.checkKeys(j, p, {"shape", "min", "max", "velocity", "velocity_field", "material"});
    blk.min = r.requiredVec2(j, p, "min");
    blk.max = r.requiredVec2(j, p, "max");
    checkMaxAboveMin(r, blk.min, blk.max, p);
  }
  blk.velocity = r.vec2(j, p, "velocity", blk.velocity);
  blk.material = readMaterialName(r, j, p, s);
  if (j.contains("velocity_field"))
    blk.field = readVelocityField(r, j.at("velocity_field"), Reader::sub(p, "velocity_field"));
  checkBlock(r, s, blk, p);
  return blk;
}

// ---- effects -----------------------------------------------------------------------

RegionDef readRegion(const Reader& r, const json& j, const std::string& path) {
  RegionDef g;
  g.min = r.requiredVec2(j, path, "min");
  g.max = r.requiredVec2(j, path, "max");
  checkMaxAboveMin(r, g.min, g.max, path);
  return g;
}

void readShifting(const Reader& r, const json& j, EffectsDef& e) {
  if (!j.contains("shifting")) return;
  const auto& x = j.at("shifting");
  const std::string q = "effects.shifting";
  r.requireObject(x, q);
  r.checkKeys(x, q, {"strength"});
  e.shifting = true;
  e.shiftingStrength = r.number(x, q, "strength", e.shiftingStrength, 0, 100);
}

void readXsph(const Reader& r, const json& j, EffectsDef& e) {
  if (!j.contains("xsph")) return;
  const auto& x = j.at("xsph");
  const std::string q = "effects.xsph";
  r.requireObject(x, q);
  r.checkKeys(x, q, {"c"});
  e.xsph = true;
  e.xsphC = r.number(x, q, "c", e.xsphC, 0, 1);
}

void readForceFields(const Reader& r, const json& j, EffectsDef& e) {
  if (!j.contains("force_fields")) return;
  const auto& a = j.at("force_fields");
  if (!a.is_array()) r.fail("effects.force_fields", "expected an array of force fields, got " + describe(a));
  for (std::size_t k = 0; k < a.size(); ++k) {
    const std::string q = "effects.force_fields[" + std::to_string(k) + "]";
    r.requireObject(a[k], q);
    r.checkKeys(a[k], q, {"acceleration", "min", "max"});
    ForceFieldDef f;
    f.acceleration = r.requiredVec2(a[k], q, "acceleration");
    if (a[k].contains("min") || a[k].contains("max")) {
      f.everywhere = false;
      f.region = readRegion(r, a[k], q);
    }
    e.forceFields.push_back(f);
  }
}

void readSurfaceTension(const Reader& r, const json& j, EffectsDef& e) {
  if (!j.contains("surface_tension")) return;
  const auto& t = j.at("surface_tension");
  const std::string q = "effects.surface_tension";
  r.requireObject(t, q);
  r.checkKeys(t, q, {"model", "sigma", "gamma", "threshold"});
  e.surfaceTension = true;
  e.tension.model = r.string(t, q, "model", e.tension.model, {"csf", "akinci"});
  e.tension.sigma = r.number(t, q, "sigma", e.tension.sigma, 0, 1e4);
  e.tension.gamma = r.number(t, q, "gamma", e.tension.gamma, 0, 1e4);
  e.tension.threshold = r.number(t, q, "threshold", e.tension.threshold, 0, 10);
}

void readLifetime(const Reader& r, const json& j, EffectsDef& e) {
  if (!j.contains("lifetime")) return;
  const auto& t = j.at("lifetime");
  const std::string q = "effects.lifetime";
  r.requireObject(t, q);
  r.checkKeys(t, q, {"max_age"});
  e.lifetime = true;
  if (!t.contains("max_age")) r.fail(Reader::sub(q, "max_age"), "missing; expected a number of seconds > 0");
  e.maxAge = r.number(t, q, "max_age", e.maxAge, 0, 1e9, true);
}

void readFoam(const Reader& r, const json& j, EffectsDef& e) {
  if (!j.contains("foam")) return;
  const auto& f = j.at("foam");
  const std::string q = "effects.foam";
  r.requireObject(f, q);
  r.checkKeys(f, q, {"trapped_air", "wave_crest", "energy", "rate", "lifetime", "buoyancy", "drag", "max_particles"});
  e.foam = true;
  FoamDef& d = e.foamDef;
  // [lo, hi] with lo < hi (lo ≤ hi for the lifetime), both in [lo0, hi0].
  auto range = [&](const char* key, Vec2d& v, double lo0, double hi0, bool equalOk) {
    if (!f.contains(key)) return;
    const Vec2d got = r.vec2(f, q, key, v);
    const std::string k = Reader::sub(q, key);
    if (!(got.x() >= lo0 && got.y() <= hi0 && (equalOk ? got.x() <= got.y() : got.x() < got.y()))) {
      std::ostringstream o;
      o << "expected [low, high] with " << lo0 << " <= low " << (equalOk ? "<=" : "<") << " high <= " << hi0
        << ", got [" << got.x() << ", " << got.y() << "]";
      r.fail(k, o.str());
    }
    v = got;
  };
  range("trapped_air", d.trappedAir, 0, FoamDef::kMaxThreshold, false);
  range("wave_crest", d.waveCrest, 0, FoamDef::kMaxThreshold, false);
  range("energy", d.energy, 0, FoamDef::kMaxThreshold, false);
  range("lifetime", d.lifetime, 1e-3, FoamDef::kMaxLifetime, true);
  d.rate = r.number(f, q, "rate", d.rate, 0, FoamDef::kMaxRate);
  d.buoyancy = r.number(f, q, "buoyancy", d.buoyancy, 0, FoamDef::kMaxBuoyancy);
  d.drag = r.number(f, q, "drag", d.drag, 0, FoamDef::kMaxDrag);
  d.maxParticles =
      std::size_t(r.integer64(f, q, "max_particles", (long long)d.maxParticles, 1, (long long)FoamDef::kMaxParticles));
}

void readSinks(const Reader& r, const json& j, EffectsDef& e) {
  if (!j.contains("sinks")) return;
  const auto& a = j.at("sinks");
  if (!a.is_array()) r.fail("effects.sinks", "expected an array of regions {min, max}, got " + describe(a));
  for (std::size_t k = 0; k < a.size(); ++k) {
    const std::string q = "effects.sinks[" + std::to_string(k) + "]";
    r.requireObject(a[k], q);
    r.checkKeys(a[k], q, {"min", "max"});
    e.sinks.push_back(readRegion(r, a[k], q));
  }
}

EmitterDef readEmitter(const Reader& r, const json& j, const std::string& q, const SceneDef& s) {
  r.requireObject(j, q);
  r.checkKeys(j, q,
              {"position", "direction", "width", "rate", "speed", "spread", "jitter", "start", "stop", "seed",
               "enabled", "material"});
  EmitterDef m;
  m.position = r.requiredVec2(j, q, "position");
  m.direction = r.vec2(j, q, "direction", m.direction);
  if (m.direction.norm() < 1e-12) r.fail(Reader::sub(q, "direction"), "direction must not be zero");
  m.direction.normalize();
  m.width = r.number(j, q, "width", m.width, 0, EmitterDef::kMaxWidth);
  m.rate = r.number(j, q, "rate", m.rate, 0, EmitterDef::kMaxRate);
  m.speed = r.number(j, q, "speed", m.speed, 0, EmitterDef::kMaxSpeed);
  m.spread = r.number(j, q, "spread", m.spread, 0, EmitterDef::kMaxSpread);
  m.jitter = r.number(j, q, "jitter", m.jitter, 0, EmitterDef::kMaxJitter);
  m.start = r.number(j, q, "start", m.start, 0, EmitterDef::kMaxStart);
  m.stop = r.number(j, q, "stop", m.stop, 0, EmitterDef::kMaxStop);
  if (m.stop < m.start) r.fail(Reader::sub(q, "stop"), "stop must not be before start");
  m.seed = static_cast<std::uint64_t>(
      r.integer64(j, q, "seed", static_cast<long long>(m.seed), 0, static_cast<long long>(EmitterDef::kMaxSeed)));
  m.enabled = r.boolean(j, q, "enabled", m.enabled);
  m.material = readMaterialName(r, j, q, s);
  return m;
}

void readEmitters(const Reader& r, const json& j, EffectsDef& e, const SceneDef& s) {
  if (!j.contains("emitters")) return;
  const auto& a = j.at("emitters");
  if (!a.is_array()) r.fail("effects.emitters", "expected an array of emitters, got " + describe(a));
  for (std::size_t k = 0; k < a.size(); ++k)
    e.emitters.push_back(readEmitter(r, a[k], "effects.emitters[" + std::to_string(k) + "]", s));
}

void readBudget(const Reader& r, const json& j, EffectsDef& e) {
  if (!j.contains("budget")) return;
  const auto& b = j.at("budget");
  const std::string q = "effects.budget";
  r.requireObject(b, q);
  r.checkKeys(b, q, {"max_particles", "policy"});
  e.budget = static_cast<std::size_t>(r.integer64(b, q, "max_particles", 0, 1, 100000000));
  e.budgetPolicy = r.string(b, q, "policy", "stop_emitting", {"stop_emitting", "recycle_oldest"}) == "recycle_oldest"
                       ? BudgetPolicy::RecycleOldest
                       : BudgetPolicy::StopEmitting;
}

// ---- render ------------------------------------------------------------------------

void readCamera(const Reader& r, const json& c, CameraDef& camera) {
  const std::string pc = "render.camera";
  r.requireObject(c, pc);
  r.checkKeys(c, pc, {"min", "max"});
  camera.min = r.requiredVec2(c, pc, "min");
  camera.max = r.requiredVec2(c, pc, "max");
  camera.automatic = false;
  checkCamera(r, camera, pc);
}

}  // namespace

void readTopLevel(const Reader& r, const json& root, SceneDef& s) {
  s.name = r.string(root, "", "name", s.name, {});
  checkName(r, s.name);
  s.gravity = r.vec2(root, "", "gravity", s.gravity);
  s.fps = r.number(root, "", "fps", s.fps, 1, 1000);
  s.duration = r.number(root, "", "duration", s.duration, 0, 1e5);
  checkFrameCount(r, s.duration, s.fps, root.contains("duration") ? "duration" : "fps");
  s.maxParticles = static_cast<std::size_t>(
      r.integer64(root, "", "max_particles", static_cast<long long>(s.maxParticles), 0, 100000000));
}

void readSolver(const Reader& r, const json& root, SceneDef& s) {
  // Without a `solver` key the section reads as {}: every value, the solver's
  // own parameters included, at its default.
  const json absent = json::object();
  const json& j = root.contains("solver") ? root.at("solver") : absent;
  const std::string p = "solver";
  r.requireObject(j, p);
  SolverDef& d = s.solver;
  // The named solver's own defaults (the shared keys it tunes, e.g. the game solver's viscosity,
  // and its parameters), or a preset's, chosen from docs/ACCURACY.md's measurements; a scene
  // that names neither is real time: the game preset (issue 15).
  if (j.contains("quality") && j.contains("type"))
    r.fail(Reader::sub(p, "quality"), "give either solver.type or solver.quality, not both");
  if (j.contains("type"))
    d = solverDefaults(r.string(j, p, "type", "game", solverNames()));
  else
    d = qualityPreset(r.string(j, p, "quality", "game", qualityPresets()));
  std::vector<std::string> keys = {
      "type",    "quality", "spacing",      "support_ratio",           "rest_density",     "sound_speed", "viscosity",
      "no_slip", "cfl",     "max_substeps", "clamp_negative_pressure", "reorder_interval", "max_speed"};
  for (const SolverParam& sp : solverParams(d.type)) keys.push_back(sp.key);
  r.checkKeys(j, p, keys);
  // A preset's parameter values are the defaults a scene may change.
  for (const SolverParam& sp : solverParams(d.type))
    d.params[sp.key] = r.number(j, p, sp.key, d.params.count(sp.key) ? d.params.at(sp.key) : sp.def, sp.lo, sp.hi);
  // The shared keys' ranges are the World's too (sharedSolverKeys).
  auto range = [](const std::string& key) -> const SharedSolverKey& {
    for (const SharedSolverKey& k : sharedSolverKeys())
      if (key == k.key) return k;
    throw std::logic_error("no shared solver key " + key);
  };
  auto num = [&](const char* key, double cur) {
    const SharedSolverKey& k = range(key);
    return r.number(j, p, key, cur, k.lo, k.hi, k.loOpen);
  };
  auto whole = [&](const char* key, int cur) {
    const SharedSolverKey& k = range(key);
    return r.integer(j, p, key, cur, int(k.lo), int(k.hi));
  };
  d.spacing = num("spacing", d.spacing);
  d.supportRatio = num("support_ratio", d.supportRatio);
  d.restDensity = num("rest_density", d.restDensity);
  d.soundSpeed = num("sound_speed", d.soundSpeed);
  d.viscosity = num("viscosity", d.viscosity);
  d.noSlip = r.boolean(j, p, "no_slip", d.noSlip);
  d.cfl = num("cfl", d.cfl);
  d.maxSubsteps = whole("max_substeps", d.maxSubsteps);
  d.clampNegativePressure = r.boolean(j, p, "clamp_negative_pressure", d.clampNegativePressure);
  d.reorderInterval = whole("reorder_interval", d.reorderInterval);
  d.maxSpeed = num("max_speed", d.maxSpeed);
}

void readBoundaries(const Reader& r, const json& root, SceneDef& s) {
  if (!root.contains("boundaries")) return;
  const json& arr = root.at("boundaries");
  if (!arr.is_array()) r.fail("boundaries", "expected an array of static bodies, got " + describe(arr));
  for (std::size_t b = 0; b < arr.size(); ++b)
    s.bodies.push_back(readBody(r, arr[b], "boundaries[" + std::to_string(b) + "]"));
}

void readFluid(const Reader& r, const json& root, SceneDef& s) {
  if (!root.contains("fluid")) return;
  const json& arr = root.at("fluid");
  if (!arr.is_array()) r.fail("fluid", "expected an array of blocks, got " + describe(arr));
  for (std::size_t b = 0; b < arr.size(); ++b)
    s.blocks.push_back(readBlock(r, arr[b], "fluid[" + std::to_string(b) + "]", s));
}

void readGroups(const Reader& r, const json& root, SceneDef& s) {
  if (!root.contains("groups")) return;
  const json& arr = root.at("groups");
  if (!arr.is_array()) r.fail("groups", "expected an array of groups, got " + describe(arr));
  for (std::size_t k = 0; k < arr.size(); ++k) {
    const std::string p = "groups[" + std::to_string(k) + "]";
    r.requireObject(arr[k], p);
    GroupDef g;
    const bool elastic = r.string(arr[k], p, "kind", "rigid", {"rigid", "elastic"}) == "elastic";
    if (!elastic && arr[k].contains("stiffness"))
      r.fail(Reader::sub(p, "stiffness"), "a rigid group has stiffness 1: give \"kind\": \"elastic\" for less");
    // An elastic group's share of the way back to its shape per substep: below 1.
    g.stiffness = elastic ? r.number(arr[k], p, "stiffness", GroupDef::kElasticStiffness, 0, 1, true) : 1.0;
    if (elastic && !(g.stiffness < 1))
      r.fail(Reader::sub(p, "stiffness"), "an elastic group's stiffness must be below 1 (1 is rigid), got 1");
    for (const char* key : {"yield_strain", "break_strain"}) {
      if (!arr[k].contains(key)) continue;
      if (!elastic) r.fail(Reader::sub(p, key), "a rigid group neither yields nor breaks: give \"kind\": \"elastic\"");
      (std::string(key) == "yield_strain" ? g.yieldStrain : g.breakStrain) = r.number(arr[k], p, key, 0, 0, 10);
    }
    if (arr[k].contains("color")) {  // 0xRRGGBB; black is 0x010101 (0 means "the material's")
      const std::array<double, 3> c = r.color(arr[k], p, "color", {});
      for (const double v : c) g.color = (g.color << 8) | std::uint32_t(std::lround(v * 255));
      if (!g.color) g.color = 0x010101u;
    }
    json region = arr[k];  // the region's keys are a fluid block's (errors name this path's lines)
    for (const char* key : {"kind", "stiffness", "yield_strain", "break_strain", "color"}) region.erase(key);
    g.region = readBlock(r, region, p, s);
    s.groups.push_back(g);
  }
}

void readPeriodic(const Reader& r, const json& root, SceneDef& s) {
  if (!root.contains("periodic")) return;
  const json& j = root.at("periodic");
  const std::string p = "periodic";
  r.requireObject(j, p);
  r.checkKeys(j, p, {"x", "y"});
  if (j.empty()) r.fail(p, "give \"x\": [min, max] and/or \"y\": [min, max], the periodic range of each wrapping axis");
  const double R = s.solver.supportRatio * s.solver.spacing;
  for (int axis = 0; axis < 2; ++axis) {
    const std::string key = axis == 0 ? "x" : "y";
    if (!j.contains(key)) continue;
    const Vec2d range = r.vec2(j, p, key, Vec2d(0, 0));
    checkPeriod(r, range, R, Reader::sub(p, key));
    (axis == 0 ? s.periodic.x : s.periodic.y) = true;
    s.periodic.min[axis] = range.x();
    s.periodic.max[axis] = range.y();
  }
}

void readEffects(const Reader& r, const json& root, SceneDef& s) {
  if (!root.contains("effects")) return;
  const json& j = root.at("effects");
  const std::string p = "effects";
  r.requireObject(j, p);
  r.checkKeys(
      j, p, {"xsph", "shifting", "force_fields", "surface_tension", "lifetime", "sinks", "emitters", "budget", "foam"});
  EffectsDef& e = s.effects;
  readShifting(r, j, e);
  readXsph(r, j, e);
  readForceFields(r, j, e);
  readSurfaceTension(r, j, e);
  readLifetime(r, j, e);
  readFoam(r, j, e);
  readSinks(r, j, e);
  readEmitters(r, j, e, s);
  readBudget(r, j, e);
}

void readRender(const Reader& r, const json& root, SceneDef& s) {
  if (!root.contains("render")) return;
  const json& j = root.at("render");
  const std::string p = "render";
  r.requireObject(j, p);
  r.checkKeys(j, p,
              {"width", "height", "mode", "background", "water", "solid", "splat_radius", "transmission", "refraction",
               "tiles", "camera"});
  RenderDef& d = s.render;
  d.width = r.integer(j, p, "width", d.width, 16, 8192);
  d.height = r.integer(j, p, "height", d.height, 16, 8192);
  d.mode = r.string(j, p, "mode", d.mode, {"liquid", "particles"});
  d.background = r.color(j, p, "background", d.background);
  d.water = r.color(j, p, "water", d.water);
  d.solid = r.color(j, p, "solid", d.solid);
  d.splatRadius = r.number(j, p, "splat_radius", d.splatRadius, 0.25, 8);
  d.transmission = r.color(j, p, "transmission", d.transmission);
  d.refraction = r.number(j, p, "refraction", d.refraction, 0, RenderDef::kMaxRefraction);
  d.tiles = r.number(j, p, "tiles", d.tiles, 0, 1e6);
  if (j.contains("camera")) readCamera(r, j.at("camera"), d.camera);
}

}  // namespace sph2d
