// Scene loading: JSON text → SceneDef, with every key checked against what is
// allowed. Errors name file, line, column, key path and the allowed values
// (the Reader of scene_reader.hpp).
//
// Besides types and ranges, the loader refuses what Box2D 2.4.1 would assert
// on (Debian builds it with assertions on: a bad polygon or chain would abort
// the process), what would exhaust memory (particles and boundary samples
// beyond max_particles) and what can only be a mistake (a fluid block holding
// no particle, a degenerate camera, an absurd number of frames): the checks
// of scene_checks.hpp.
#include "sph2d/scene.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "effects/effect.hpp"
#include "json_reader.hpp"
#include "scene_checks.hpp"
#include "scene_reader.hpp"
#include "solvers/solver.hpp"

namespace sph2d {
namespace {

using nlohmann::json;

constexpr std::size_t kMaxSceneBytes = 64u << 20;  ///< scene file size

// ---- Fixtures -----------------------------------------------------------------

ShapeDef readFixture(const Reader& r, const json& j, const std::string& path) {
  r.requireObject(j, path);
  ShapeDef s;
  if (!j.contains("shape")) r.fail(Reader::sub(path, "shape"), "missing; allowed values: box, polygon, circle, edge, chain");
  const std::string shape = r.string(j, path, "shape", "", {"box", "polygon", "circle", "edge", "chain"});
  std::vector<std::string> keys = {"shape", "friction", "restitution"};
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
  return s;
}

RegionDef readRegion(const Reader& r, const nlohmann::json& j, const std::string& path) {
  RegionDef g;
  g.min = r.requiredVec2(j, path, "min");
  g.max = r.requiredVec2(j, path, "max");
  checkMaxAboveMin(r, g.min, g.max, path);
  return g;
}

void readEffects(const Reader& r, const nlohmann::json& j, SceneDef& s) {
  const std::string p = "effects";
  r.requireObject(j, p);
  r.checkKeys(j, p, {"xsph", "shifting", "force_fields", "surface_tension", "lifetime", "sinks", "emitters", "budget"});
  EffectsDef& e = s.effects;
  if (j.contains("shifting")) {
    const auto& x = j.at("shifting");
    const std::string q = "effects.shifting";
    r.requireObject(x, q);
    r.checkKeys(x, q, {"strength"});
    e.shifting = true;
    e.shiftingStrength = r.number(x, q, "strength", e.shiftingStrength, 0, 100);
  }
  if (j.contains("xsph")) {
    const auto& x = j.at("xsph");
    const std::string q = "effects.xsph";
    r.requireObject(x, q);
    r.checkKeys(x, q, {"c"});
    e.xsph = true;
    e.xsphC = r.number(x, q, "c", e.xsphC, 0, 1);
  }
  if (j.contains("force_fields")) {
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
  if (j.contains("surface_tension")) {
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
  if (j.contains("lifetime")) {
    const auto& t = j.at("lifetime");
    const std::string q = "effects.lifetime";
    r.requireObject(t, q);
    r.checkKeys(t, q, {"max_age"});
    e.lifetime = true;
    if (!t.contains("max_age")) r.fail(Reader::sub(q, "max_age"), "missing; expected a number of seconds > 0");
    e.maxAge = r.number(t, q, "max_age", e.maxAge, 0, 1e9, true);
  }
  if (j.contains("sinks")) {
    const auto& a = j.at("sinks");
    if (!a.is_array()) r.fail("effects.sinks", "expected an array of regions {min, max}, got " + describe(a));
    for (std::size_t k = 0; k < a.size(); ++k) {
      const std::string q = "effects.sinks[" + std::to_string(k) + "]";
      r.requireObject(a[k], q);
      r.checkKeys(a[k], q, {"min", "max"});
      e.sinks.push_back(readRegion(r, a[k], q));
    }
  }
  if (j.contains("emitters")) {
    const auto& a = j.at("emitters");
    if (!a.is_array()) r.fail("effects.emitters", "expected an array of emitters, got " + describe(a));
    for (std::size_t k = 0; k < a.size(); ++k) {
      const std::string q = "effects.emitters[" + std::to_string(k) + "]";
      r.requireObject(a[k], q);
      r.checkKeys(a[k], q, {"position", "direction", "width", "rate", "speed", "spread", "jitter", "start", "stop", "seed", "enabled"});
      EmitterDef m;
      m.position = r.requiredVec2(a[k], q, "position");
      m.direction = r.vec2(a[k], q, "direction", m.direction);
      if (m.direction.norm() < 1e-12) r.fail(Reader::sub(q, "direction"), "direction must not be zero");
      m.direction.normalize();
      m.width = r.number(a[k], q, "width", m.width, 0, 1e4);
      m.rate = r.number(a[k], q, "rate", m.rate, 0, 1e8);
      m.speed = r.number(a[k], q, "speed", m.speed, 0, 1e4);
      m.spread = r.number(a[k], q, "spread", m.spread, 0, 6.2832);
      m.jitter = r.number(a[k], q, "jitter", m.jitter, 0, 1);
      m.start = r.number(a[k], q, "start", m.start, 0, 1e9);
      m.stop = r.number(a[k], q, "stop", m.stop, 0, 1e30);
      if (m.stop < m.start) r.fail(Reader::sub(q, "stop"), "stop must not be before start");
      m.seed = static_cast<std::uint64_t>(r.integer64(a[k], q, "seed", static_cast<long long>(m.seed), 0, 9007199254740992LL));
      m.enabled = r.boolean(a[k], q, "enabled", m.enabled);
      e.emitters.push_back(m);
    }
  }
  if (j.contains("budget")) {
    const auto& b = j.at("budget");
    const std::string q = "effects.budget";
    r.requireObject(b, q);
    r.checkKeys(b, q, {"max_particles", "policy"});
    e.budget = static_cast<std::size_t>(r.integer64(b, q, "max_particles", 0, 1, 100000000));
    e.budgetPolicy = r.string(b, q, "policy", "stop_emitting", {"stop_emitting", "recycle_oldest"}) == "recycle_oldest"
                         ? BudgetPolicy::RecycleOldest
                         : BudgetPolicy::StopEmitting;
  }
}

/// The one place where an event's fields are read and checked: the scene's
/// `events` entries and every line of events files and live input come here.
EventDef readEvent(const Reader& r, const nlohmann::json& j, const std::string& path, const SceneDef& scene,
                   EventStamp stamp, bool allowSource) {
  using T = EventDef::Type;
  static const std::vector<std::pair<std::string, T>> kTypes = {
      {"force", T::Force},     {"release", T::Release}, {"block", T::Block},   {"drop", T::Drop},    {"emitter", T::Emitter},
      {"gravity", T::Gravity}, {"effect", T::Effect},   {"pause", T::Pause},   {"resume", T::Resume}};
  std::vector<std::string> typeNames;
  for (const auto& t : kTypes) typeNames.push_back(t.first);
  r.requireObject(j, path);
  if (!j.contains("type")) r.fail(Reader::sub(path, "type"), "missing; allowed values: " + join(typeNames));
  const std::string type = r.string(j, path, "type", "", typeNames);
  EventDef e;
  for (const auto& t : kTypes)
    if (t.first == type) e.type = t.second;

  std::vector<std::string> keys = {"type", "t", "frame"};
  if (allowSource) keys.push_back("source");
  switch (e.type) {
    case T::Force: keys.insert(keys.end(), {"id", "point", "radius", "strength"}); break;
    case T::Release: keys.insert(keys.end(), {"id"}); break;
    case T::Block: keys.insert(keys.end(), {"min", "max", "velocity"}); break;
    case T::Drop: keys.insert(keys.end(), {"center", "radius", "velocity"}); break;
    case T::Emitter: keys.insert(keys.end(), {"index", "enabled", "position", "direction"}); break;
    case T::Gravity: keys.insert(keys.end(), {"gravity", "tilt"}); break;
    case T::Effect: keys.insert(keys.end(), {"name", "enabled"}); break;
    case T::Pause: keys.insert(keys.end(), {"seconds"}); break;
    case T::Resume: break;
  }
  r.checkKeys(j, path, keys);

  // The stamp.
  if (j.contains("t") && j.contains("frame")) r.fail(Reader::sub(path, "frame"), "give either \"t\" or \"frame\", not both");
  if (j.contains("t")) e.t = r.number(j, path, "t", 0, 0, 1e9);
  if (j.contains("frame")) e.frame = r.integer(j, path, "frame", 0, 0, 1000000000);
  if (stamp == EventStamp::Required && e.t < 0 && e.frame < 0)
    r.fail(Reader::sub(path, "t"), "missing; every event needs \"t\" (seconds) or \"frame\" (frame number)");
  if (allowSource) e.source = r.string(j, path, "source", "", {"scene", "file", "live"});

  auto required = [&](const std::string& key, const std::string& what) {
    if (!j.contains(key)) r.fail(Reader::sub(path, key), "missing; expected " + what);
  };
  switch (e.type) {
    case T::Force:
      e.id = r.integer(j, path, "id", 0, 0, 1000);
      e.point = r.requiredVec2(j, path, "point");
      e.radius = r.number(j, path, "radius", 0.5, 0, 1e6, true);
      required("strength", "a number (m/s²; > 0 pulls, < 0 pushes)");
      e.strength = r.number(j, path, "strength", 0, -1e6, 1e6);
      break;
    case T::Release:
      e.id = r.integer(j, path, "id", -1, 0, 1000);
      break;
    case T::Block:
      e.block.min = r.requiredVec2(j, path, "min");
      e.block.max = r.requiredVec2(j, path, "max");
      e.block.velocity = r.vec2(j, path, "velocity", e.block.velocity);
      checkMaxAboveMin(r, e.block.min, e.block.max, path);
      break;
    case T::Drop:
      e.point = r.requiredVec2(j, path, "center");
      required("radius", "a number > 0 (metres)");
      e.radius = r.number(j, path, "radius", 0, 0, 1e4, true);
      e.velocity = r.vec2(j, path, "velocity", e.velocity);
      break;
    case T::Emitter: {
      const std::size_t n = scene.effects.emitters.size();
      if (n == 0) r.fail(Reader::sub(path, "type"), "the scene has no emitters (effects.emitters)");
      required("index", "an emitter index from 0 to " + std::to_string(n - 1));
      e.index = std::size_t(r.integer(j, path, "index", 0, 0, 1000000000));
      if (e.index >= n)
        r.fail(Reader::sub(path, "index"), "emitter " + std::to_string(e.index) + " does not exist; the scene has " +
                                              std::to_string(n) + " (0 to " + std::to_string(n - 1) + ")");
      e.hasEnabled = j.contains("enabled");
      e.enabled = r.boolean(j, path, "enabled", true);
      e.hasPoint = j.contains("position");
      e.point = r.vec2(j, path, "position", e.point);
      e.hasDirection = j.contains("direction");
      e.direction = r.vec2(j, path, "direction", e.direction);
      // Kept as written (World::moveEmitter normalises): a record then replays the same bits.
      if (e.hasDirection && e.direction.norm() < 1e-12) r.fail(Reader::sub(path, "direction"), "direction must not be zero");
      if (!e.hasEnabled && !e.hasPoint && !e.hasDirection)
        r.fail(Reader::sub(path, "enabled"), "missing; an emitter event needs \"enabled\", \"position\" or \"direction\"");
      break;
    }
    case T::Gravity:
      if (j.contains("gravity") == j.contains("tilt"))
        r.fail(Reader::sub(path, "gravity"), "give either \"gravity\": [x, y] (m/s²) or \"tilt\": angle (radians, "
                                             "rotates the scene's gravity counter-clockwise)");
      if (j.contains("gravity")) {
        e.gravity = r.vec2(j, path, "gravity", e.gravity);
      } else {
        const double a = r.number(j, path, "tilt", 0, -1e3, 1e3);
        const Vec2d g = scene.gravity;
        e.gravity = Vec2d(std::cos(a) * g.x() - std::sin(a) * g.y(), std::sin(a) * g.x() + std::cos(a) * g.y());
      }
      if (!(e.gravity.norm() <= 1e4)) r.fail(Reader::sub(path, "gravity"), "gravity above 1e4 m/s² is not allowed");
      break;
    case T::Effect:
      required("name", "one of " + join(switchableEffects(scene)));
      e.effect = r.string(j, path, "name", "", switchableEffects(scene));
      required("enabled", "true or false");
      e.enabled = r.boolean(j, path, "enabled", true);
      break;
    case T::Pause:
      e.seconds = r.number(j, path, "seconds", 0, 0, 1e6);
      break;
    case T::Resume:
      break;
  }
  return e;
}


}  // namespace

std::vector<std::string> switchableEffects(const SceneDef& scene) {
  std::vector<std::string> out;
  for (const auto& e : makeEffects(scene)) out.push_back(e->name());
  out.push_back("user_force");
  return out;
}

const char* eventTypeName(EventDef::Type type) {
  switch (type) {
    case EventDef::Type::Force: return "force";
    case EventDef::Type::Release: return "release";
    case EventDef::Type::Block: return "block";
    case EventDef::Type::Drop: return "drop";
    case EventDef::Type::Emitter: return "emitter";
    case EventDef::Type::Gravity: return "gravity";
    case EventDef::Type::Effect: return "effect";
    case EventDef::Type::Pause: return "pause";
    case EventDef::Type::Resume: return "resume";
  }
  return "?";
}

std::int64_t eventFrame(const EventDef& e, double fps) {
  if (e.frame >= 0) return e.frame;
  if (e.t < 0) return -1;
  return std::int64_t(std::ceil(e.t * fps - 1e-9));
}

EventDef parseEvent(const std::string& text, const std::string& file, int line, const SceneDef& scene, EventStamp stamp) {
  try {
    const JsonDoc doc = parseJsonWithPositions(text, file);
    const Reader r(doc, file);
    return readEvent(r, doc.root, "", scene, stamp, true);
  } catch (const SceneError& e) {
    // Positions inside one line: report the line of the file and the column within it.
    throw SceneError(e.file, e.line > 0 ? line + e.line - 1 : line, e.line > 0 ? e.column : 1, e.key, e.message);
  }
}

std::string eventToJson(const EventDef& e) {
  using T = EventDef::Type;
  nlohmann::ordered_json j;
  auto vec = [](const Vec2d& v) { return nlohmann::ordered_json::array({v.x(), v.y()}); };
  if (e.frame >= 0) j["frame"] = e.frame;
  else if (e.t >= 0) j["t"] = e.t;
  j["type"] = eventTypeName(e.type);
  switch (e.type) {
    case T::Force:
      j["id"] = e.id;
      j["point"] = vec(e.point);
      j["radius"] = e.radius;
      j["strength"] = e.strength;
      break;
    case T::Release:
      if (e.id >= 0) j["id"] = e.id;
      break;
    case T::Block:
      j["min"] = vec(e.block.min);
      j["max"] = vec(e.block.max);
      j["velocity"] = vec(e.block.velocity);
      break;
    case T::Drop:
      j["center"] = vec(e.point);
      j["radius"] = e.radius;
      j["velocity"] = vec(e.velocity);
      break;
    case T::Emitter:
      j["index"] = e.index;
      if (e.hasEnabled) j["enabled"] = e.enabled;
      if (e.hasPoint) j["position"] = vec(e.point);
      if (e.hasDirection) j["direction"] = vec(e.direction);
      break;
    case T::Gravity: j["gravity"] = vec(e.gravity); break;
    case T::Effect:
      j["name"] = e.effect;
      j["enabled"] = e.enabled;
      break;
    case T::Pause:
      if (e.seconds > 0) j["seconds"] = e.seconds;
      break;
    case T::Resume: break;
  }
  if (!e.source.empty()) j["source"] = e.source;
  return j.dump();
}


SceneDef parseScene(const std::string& text, const std::string& file) {
  const JsonDoc doc = parseJsonWithPositions(text, file);
  const Reader r(doc, file);
  const json& root = doc.root;
  r.requireObject(root, "");
  r.checkKeys(root, "", {"name", "gravity", "fps", "duration", "max_particles", "solver", "boundaries", "fluid", "periodic", "effects", "render", "events"});
  SceneDef s;
  s.path = file;
  s.name = r.string(root, "", "name", s.name, {});
  checkName(r, s.name);
  s.gravity = r.vec2(root, "", "gravity", s.gravity);
  s.fps = r.number(root, "", "fps", s.fps, 1, 1000);
  s.duration = r.number(root, "", "duration", s.duration, 0, 1e5);
  checkFrameCount(r, s.duration, s.fps, root.contains("duration") ? "duration" : "fps");
  s.maxParticles = static_cast<std::size_t>(r.integer64(root, "", "max_particles", static_cast<long long>(s.maxParticles), 0, 100000000));

  if (root.contains("solver")) {
    const json& j = root.at("solver");
    const std::string p = "solver";
    r.requireObject(j, p);
    SolverDef& d = s.solver;
    d.type = r.string(j, p, "type", d.type, solverNames());
    // A preset instead of a solver, chosen from docs/ACCURACY.md's measurements.
    if (j.contains("quality")) {
      if (j.contains("type")) r.fail(Reader::sub(p, "quality"), "give either solver.type or solver.quality, not both");
      const std::string q = r.string(j, p, "quality", "balanced", {"game", "balanced", "accurate"});
      d.type = q == "game" ? "pbf" : q == "accurate" ? "dfsph" : "wcsph";
    }
    std::vector<std::string> keys = {"type", "quality", "spacing", "support_ratio", "rest_density", "sound_speed", "viscosity", "no_slip", "cfl",
                                     "max_substeps", "clamp_negative_pressure", "reorder_interval", "max_speed"};
    for (const SolverParam& sp : solverParams(d.type)) keys.push_back(sp.key);
    r.checkKeys(j, p, keys);
    for (const SolverParam& sp : solverParams(d.type)) d.params[sp.key] = r.number(j, p, sp.key, sp.def, sp.lo, sp.hi);
    d.spacing = r.number(j, p, "spacing", d.spacing, 0, 10, true);
    d.supportRatio = r.number(j, p, "support_ratio", d.supportRatio, 1.5, 4);
    d.restDensity = r.number(j, p, "rest_density", d.restDensity, 0, 1e5, true);
    d.soundSpeed = r.number(j, p, "sound_speed", d.soundSpeed, 0, 1e4, true);
    d.viscosity = r.number(j, p, "viscosity", d.viscosity, 0, 100);
    d.noSlip = r.boolean(j, p, "no_slip", d.noSlip);
    d.cfl = r.number(j, p, "cfl", d.cfl, 0, 1, true);
    d.maxSubsteps = r.integer(j, p, "max_substeps", d.maxSubsteps, 1, 100000);
    d.clampNegativePressure = r.boolean(j, p, "clamp_negative_pressure", d.clampNegativePressure);
    d.reorderInterval = r.integer(j, p, "reorder_interval", d.reorderInterval, 0, 1000000);
    d.maxSpeed = r.number(j, p, "max_speed", d.maxSpeed, 0, 1e6, true);
  }

  if (!root.contains("solver"))
    for (const SolverParam& sp : solverParams(s.solver.type)) s.solver.params[sp.key] = sp.def;

  if (root.contains("boundaries")) {
    const json& arr = root.at("boundaries");
    if (!arr.is_array()) r.fail("boundaries", "expected an array of static bodies, got " + describe(arr));
    for (std::size_t b = 0; b < arr.size(); ++b) {
      const std::string p = "boundaries[" + std::to_string(b) + "]";
      const json& j = arr[b];
      r.requireObject(j, p);
      r.checkKeys(j, p, {"position", "angle", "fixtures"});
      BodyDef body;
      body.position = r.vec2(j, p, "position", body.position);
      body.angle = r.number(j, p, "angle", 0, -1e3, 1e3);
      if (!j.contains("fixtures")) r.fail(Reader::sub(p, "fixtures"), "missing; expected an array of fixtures");
      const json& fx = j.at("fixtures");
      if (!fx.is_array()) r.fail(Reader::sub(p, "fixtures"), "expected an array of fixtures, got " + describe(fx));
      for (std::size_t f = 0; f < fx.size(); ++f)
        body.fixtures.push_back(readFixture(r, fx[f], p + ".fixtures[" + std::to_string(f) + "]"));
      s.bodies.push_back(body);
    }
  }

  if (root.contains("fluid")) {
    const json& arr = root.at("fluid");
    if (!arr.is_array()) r.fail("fluid", "expected an array of blocks, got " + describe(arr));
    for (std::size_t b = 0; b < arr.size(); ++b) {
      const std::string p = "fluid[" + std::to_string(b) + "]";
      const json& j = arr[b];
      r.requireObject(j, p);
      r.checkKeys(j, p, {"min", "max", "velocity", "velocity_field"});
      FluidBlockDef blk;
      blk.min = r.requiredVec2(j, p, "min");
      blk.max = r.requiredVec2(j, p, "max");
      blk.velocity = r.vec2(j, p, "velocity", blk.velocity);
      if (j.contains("velocity_field")) {
        const json& f = j.at("velocity_field");
        const std::string pf = Reader::sub(p, "velocity_field");
        r.requireObject(f, pf);
        r.checkKeys(f, pf, {"type", "amplitude", "wavelength", "origin"});
        if (!f.contains("type")) r.fail(Reader::sub(pf, "type"), "missing; allowed values: taylor_green");
        r.string(f, pf, "type", "", {"taylor_green"});
        blk.field.type = VelocityFieldDef::Type::TaylorGreen;
        blk.field.amplitude = r.number(f, pf, "amplitude", blk.field.amplitude, -1e3, 1e3);
        blk.field.wavelength = r.number(f, pf, "wavelength", blk.field.wavelength, 0, 1e4, true);
        blk.field.origin = r.vec2(f, pf, "origin", blk.field.origin);
      }
      checkMaxAboveMin(r, blk.min, blk.max, p);
      checkBlock(r, s, blk, p);
      s.blocks.push_back(blk);
    }
  }

  if (root.contains("periodic")) {
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

  if (root.contains("effects")) readEffects(r, root.at("effects"), s);

  if (root.contains("render")) {
    const json& j = root.at("render");
    const std::string p = "render";
    r.requireObject(j, p);
    r.checkKeys(j, p, {"width", "height", "mode", "background", "water", "solid", "splat_radius", "camera"});
    RenderDef& d = s.render;
    d.width = r.integer(j, p, "width", d.width, 16, 8192);
    d.height = r.integer(j, p, "height", d.height, 16, 8192);
    d.mode = r.string(j, p, "mode", d.mode, {"liquid", "particles"});
    d.background = r.color(j, p, "background", d.background);
    d.water = r.color(j, p, "water", d.water);
    d.solid = r.color(j, p, "solid", d.solid);
    d.splatRadius = r.number(j, p, "splat_radius", d.splatRadius, 0.25, 8);
    if (j.contains("camera")) {
      const json& c = j.at("camera");
      const std::string pc = "render.camera";
      r.requireObject(c, pc);
      r.checkKeys(c, pc, {"min", "max"});
      d.camera.min = r.requiredVec2(c, pc, "min");
      d.camera.max = r.requiredVec2(c, pc, "max");
      d.camera.automatic = false;
      checkCamera(r, d.camera, pc);
    }
  }

  // The timeline last: its events are checked against the emitters, effects and gravity above.
  if (root.contains("events")) {
    const json& arr = root.at("events");
    if (!arr.is_array()) r.fail("events", "expected an array of events {\"t\": seconds, \"type\": ...}, got " + typeName(arr));
    for (std::size_t k = 0; k < arr.size(); ++k)
      s.events.push_back(readEvent(r, arr[k], "events[" + std::to_string(k) + "]", s, EventStamp::Required, false));
  }

  checkParticleBudget(r, s);
  return s;
}

SceneDef loadScene(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw SceneError(path, 0, 0, "", "is a directory, not a scene file");
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    throw SceneError(path, 0, 0, "", std::string("cannot open the scene file") + (err ? std::string(": ") + std::strerror(err) : ""));
  }
  std::string text;
  char buf[65536];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxSceneBytes)
      throw SceneError(path, 0, 0, "", "the file is larger than " + std::to_string(kMaxSceneBytes >> 20) + " MiB; is it a scene file?");
  }
  if (in.bad()) throw SceneError(path, 0, 0, "", "cannot read the scene file");
  return parseScene(text, path);
}

}  // namespace sph2d
