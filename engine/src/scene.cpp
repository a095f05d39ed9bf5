// Scene loading: JSON text → SceneDef, with every key checked against what is
// allowed. Errors name file, line, column, key path and the allowed values.
#include "sph2d/scene.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include "effects/effect.hpp"
#include "json_reader.hpp"
#include "solvers/solver.hpp"

namespace sph2d {

SceneError::SceneError(std::string file_, int line_, int column_, std::string key_, std::string message_)
    : std::runtime_error([&] {
        std::string w = file_;
        if (line_ > 0) w += ":" + std::to_string(line_) + ":" + std::to_string(column_);
        w += ": ";
        if (!key_.empty()) w += "key '" + key_ + "': ";
        return w + message_;
      }()),
      file(std::move(file_)),
      line(line_),
      column(column_),
      key(std::move(key_)),
      message(std::move(message_)) {}

namespace {

using nlohmann::json;

std::string typeName(const json& j) {
  switch (j.type()) {
    case json::value_t::null: return "null";
    case json::value_t::boolean: return "a boolean";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned: return "an integer";
    case json::value_t::number_float: return "a number";
    case json::value_t::string: return "a string";
    case json::value_t::array: return "an array";
    case json::value_t::object: return "an object";
    default: return "something else";
  }
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + v[i];
  return s;
}

std::string fmt(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

/// Typed, position-aware access to one JSON object of the scene.
class Reader {
 public:
  Reader(const JsonDoc& doc, std::string file) : doc_(doc), file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& path, const std::string& msg) const {
    // Report the deepest known position along the path.
    std::string p = path;
    for (;;) {
      auto it = doc_.where.find(p);
      if (it != doc_.where.end()) throw SceneError(file_, it->second.first, it->second.second, path, msg);
      const auto cut = p.find_last_of(".[");
      if (cut == std::string::npos || cut == 0) break;
      p = p.substr(0, cut);
    }
    throw SceneError(file_, 0, 0, path, msg);
  }

  static std::string sub(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }

  void requireObject(const json& j, const std::string& path) const {
    if (!j.is_object()) fail(path, "expected an object, got " + typeName(j));
  }
  void checkKeys(const json& obj, const std::string& path, const std::vector<std::string>& allowed) const {
    for (auto it = obj.begin(); it != obj.end(); ++it) {
      bool ok = false;
      for (const auto& a : allowed) ok = ok || a == it.key();
      if (!ok) fail(sub(path, it.key()), "unknown key '" + it.key() + "'; allowed keys: " + join(allowed));
    }
  }
  double number(const json& obj, const std::string& path, const std::string& key, double def, double lo, double hi,
                bool loOpen = false) const {
    if (!obj.contains(key)) return def;
    const json& j = obj.at(key);
    const std::string p = sub(path, key);
    if (!j.is_number()) fail(p, "expected a number, got " + typeName(j));
    const double v = j.get<double>();
    const bool below = loOpen ? !(v > lo) : !(v >= lo);
    if (!std::isfinite(v) || below || v > hi)
      fail(p, "value " + fmt(v) + " is out of range; allowed: " + (loOpen ? "> " : ">= ") + fmt(lo) + " and <= " + fmt(hi));
    return v;
  }
  int integer(const json& obj, const std::string& path, const std::string& key, int def, int lo, int hi) const {
    if (!obj.contains(key)) return def;
    const json& j = obj.at(key);
    const std::string p = sub(path, key);
    if (!j.is_number_integer()) fail(p, "expected an integer, got " + typeName(j));
    const long long v = j.get<long long>();
    if (v < lo || v > hi) fail(p, "value " + std::to_string(v) + " is out of range; allowed: " + std::to_string(lo) + " to " + std::to_string(hi));
    return static_cast<int>(v);
  }
  bool boolean(const json& obj, const std::string& path, const std::string& key, bool def) const {
    if (!obj.contains(key)) return def;
    const json& j = obj.at(key);
    if (!j.is_boolean()) fail(sub(path, key), "expected true or false, got " + typeName(j));
    return j.get<bool>();
  }
  std::string string(const json& obj, const std::string& path, const std::string& key, const std::string& def,
                     const std::vector<std::string>& allowed) const {
    if (!obj.contains(key)) return def;
    const json& j = obj.at(key);
    const std::string p = sub(path, key);
    if (!j.is_string()) fail(p, "expected a string, got " + typeName(j));
    const std::string v = j.get<std::string>();
    if (allowed.empty()) return v;
    for (const auto& a : allowed)
      if (a == v) return v;
    fail(p, "'" + v + "' is not allowed; allowed values: " + join(allowed));
  }
  Vec2d vec2(const json& j, const std::string& p) const {
    if (!j.is_array() || j.size() != 2 || !j[0].is_number() || !j[1].is_number())
      fail(p, "expected [x, y] (two numbers), got " + (j.is_array() ? "an array of " + std::to_string(j.size()) : typeName(j)));
    const Vec2d v(j[0].get<double>(), j[1].get<double>());
    if (!std::isfinite(v.x()) || !std::isfinite(v.y())) fail(p, "coordinates must be finite");
    return v;
  }
  Vec2d vec2(const json& obj, const std::string& path, const std::string& key, const Vec2d& def) const {
    if (!obj.contains(key)) return def;
    return vec2(obj.at(key), sub(path, key));
  }
  Vec2d requiredVec2(const json& obj, const std::string& path, const std::string& key) const {
    if (!obj.contains(key)) fail(sub(path, key), "missing; expected [x, y]");
    return vec2(obj.at(key), sub(path, key));
  }
  std::array<double, 3> color(const json& obj, const std::string& path, const std::string& key,
                              const std::array<double, 3>& def) const {
    if (!obj.contains(key)) return def;
    const json& j = obj.at(key);
    const std::string p = sub(path, key);
    if (!j.is_array() || j.size() != 3) fail(p, "expected [r, g, b] with components in 0..1");
    std::array<double, 3> c{};
    for (int k = 0; k < 3; ++k) {
      if (!j[k].is_number()) fail(p, "expected [r, g, b] with components in 0..1");
      c[k] = j[k].get<double>();
      if (!(c[k] >= 0 && c[k] <= 1)) fail(p, "colour components must be in 0..1");
    }
    return c;
  }
  std::vector<Vec2d> points(const json& obj, const std::string& path, const std::string& key) const {
    const std::string p = sub(path, key);
    if (!obj.contains(key)) fail(p, "missing; expected an array of [x, y] points");
    const json& j = obj.at(key);
    if (!j.is_array()) fail(p, "expected an array of [x, y] points, got " + typeName(j));
    std::vector<Vec2d> out;
    for (std::size_t i = 0; i < j.size(); ++i) out.push_back(vec2(j[i], p + "[" + std::to_string(i) + "]"));
    return out;
  }

 private:
  const JsonDoc& doc_;
  std::string file_;
};

double cross(const Vec2d& a, const Vec2d& b) { return a.x() * b.y() - a.y() * b.x(); }

ShapeDef readFixture(const Reader& r, const json& j, const std::string& path) {
  r.requireObject(j, path);
  ShapeDef s;
  if (!j.contains("shape")) r.fail(Reader::sub(path, "shape"), "missing; allowed values: box, polygon, circle, edge, chain");
  const std::string shape = r.string(j, path, "shape", "", {"box", "polygon", "circle", "edge", "chain"});
  std::vector<std::string> keys = {"shape", "friction", "restitution"};
  s.friction = r.number(j, path, "friction", s.friction, 0, 10);
  s.restitution = r.number(j, path, "restitution", s.restitution, 0, 1);
  if (shape == "box") {
    s.type = ShapeDef::Type::Box;
    keys.insert(keys.end(), {"center", "half_size", "angle"});
    r.checkKeys(j, path, keys);
    s.center = r.vec2(j, path, "center", s.center);
    s.halfSize = r.requiredVec2(j, path, "half_size");
    if (!(s.halfSize.x() > 0 && s.halfSize.y() > 0)) r.fail(Reader::sub(path, "half_size"), "both half sizes must be > 0");
    s.angle = r.number(j, path, "angle", 0, -1e3, 1e3);
  } else if (shape == "polygon") {
    s.type = ShapeDef::Type::Polygon;
    keys.insert(keys.end(), {"vertices"});
    r.checkKeys(j, path, keys);
    s.vertices = r.points(j, path, "vertices");
    const std::string p = Reader::sub(path, "vertices");
    if (s.vertices.size() < 3 || s.vertices.size() > 8) r.fail(p, "a polygon needs 3 to 8 vertices (Box2D 2.4.1), got " + std::to_string(s.vertices.size()));
    double area = 0;
    int sign = 0;
    const std::size_t n = s.vertices.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2d& a = s.vertices[i];
      const Vec2d& b = s.vertices[(i + 1) % n];
      const Vec2d& c = s.vertices[(i + 2) % n];
      area += cross(a, b);
      const double turn = cross(b - a, c - b);
      const int sg = turn > 1e-12 ? 1 : (turn < -1e-12 ? -1 : 0);
      if (sg != 0) {
        if (sign != 0 && sg != sign) r.fail(p, "the polygon must be convex (split a concave shape into several fixtures)");
        sign = sg;
      }
    }
    if (std::fabs(area) < 1e-10) r.fail(p, "the polygon has no area");
  } else if (shape == "circle") {
    s.type = ShapeDef::Type::Circle;
    keys.insert(keys.end(), {"center", "radius"});
    r.checkKeys(j, path, keys);
    s.center = r.vec2(j, path, "center", s.center);
    if (!j.contains("radius")) r.fail(Reader::sub(path, "radius"), "missing; expected a number > 0");
    s.radius = r.number(j, path, "radius", 0, 0, 1e6, true);
  } else if (shape == "edge") {
    s.type = ShapeDef::Type::Edge;
    keys.insert(keys.end(), {"vertices"});
    r.checkKeys(j, path, keys);
    s.vertices = r.points(j, path, "vertices");
    if (s.vertices.size() != 2) r.fail(Reader::sub(path, "vertices"), "an edge needs exactly 2 vertices");
    if ((s.vertices[0] - s.vertices[1]).norm() < 1e-6) r.fail(Reader::sub(path, "vertices"), "the edge has zero length");
  } else {
    s.type = ShapeDef::Type::Chain;
    keys.insert(keys.end(), {"vertices", "loop"});
    r.checkKeys(j, path, keys);
    s.vertices = r.points(j, path, "vertices");
    s.loop = r.boolean(j, path, "loop", false);
    const std::size_t need = s.loop ? 3 : 2;
    if (s.vertices.size() < need) r.fail(Reader::sub(path, "vertices"), std::string("a ") + (s.loop ? "looped" : "open") + " chain needs at least " + std::to_string(need) + " vertices");
    for (std::size_t i = 1; i < s.vertices.size(); ++i)
      if ((s.vertices[i] - s.vertices[i - 1]).norm() < 0.005)  // b2_linearSlop
        r.fail(Reader::sub(path, "vertices[" + std::to_string(i) + "]"), "chain vertices closer than 0.005 m (Box2D's linear slop)");
  }
  return s;
}

RegionDef readRegion(const Reader& r, const nlohmann::json& j, const std::string& path) {
  RegionDef g;
  g.min = r.requiredVec2(j, path, "min");
  g.max = r.requiredVec2(j, path, "max");
  if (!(g.max.x() > g.min.x() && g.max.y() > g.min.y())) r.fail(Reader::sub(path, "max"), "max must be greater than min in x and in y");
  return g;
}

void readEffects(const Reader& r, const nlohmann::json& j, SceneDef& s) {
  const std::string p = "effects";
  r.requireObject(j, p);
  r.checkKeys(j, p, {"xsph", "force_fields", "surface_tension", "lifetime", "sinks", "emitters", "budget"});
  EffectsDef& e = s.effects;
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
    if (!a.is_array()) r.fail("effects.force_fields", "expected an array of force fields, got " + typeName(a));
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
    if (!a.is_array()) r.fail("effects.sinks", "expected an array of regions {min, max}, got " + typeName(a));
    for (std::size_t k = 0; k < a.size(); ++k) {
      const std::string q = "effects.sinks[" + std::to_string(k) + "]";
      r.requireObject(a[k], q);
      r.checkKeys(a[k], q, {"min", "max"});
      e.sinks.push_back(readRegion(r, a[k], q));
    }
  }
  if (j.contains("emitters")) {
    const auto& a = j.at("emitters");
    if (!a.is_array()) r.fail("effects.emitters", "expected an array of emitters, got " + typeName(a));
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
      m.seed = std::uint64_t(r.number(a[k], q, "seed", double(m.seed), 0, 9007199254740992.0));
      m.enabled = r.boolean(a[k], q, "enabled", m.enabled);
      e.emitters.push_back(m);
    }
  }
  if (j.contains("budget")) {
    const auto& b = j.at("budget");
    const std::string q = "effects.budget";
    r.requireObject(b, q);
    r.checkKeys(b, q, {"max_particles", "policy"});
    e.budget = std::size_t(r.number(b, q, "max_particles", 0, 1, 1e8));
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
      if (!(e.block.max.x() > e.block.min.x() && e.block.max.y() > e.block.min.y()))
        r.fail(Reader::sub(path, "max"), "max must be greater than min in x and in y");
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

std::size_t countBlockParticles(const SceneDef& scene) {
  std::size_t n = 0;
  const double dx = scene.solver.spacing;
  for (const auto& b : scene.blocks) {
    const double nx = std::floor((b.max.x() - b.min.x()) / dx + 1e-9);
    const double ny = std::floor((b.max.y() - b.min.y()) / dx + 1e-9);
    if (nx > 0 && ny > 0) n += static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
  }
  return n;
}

SceneDef parseScene(const std::string& text, const std::string& file) {
  const JsonDoc doc = parseJsonWithPositions(text, file);
  const Reader r(doc, file);
  const json& root = doc.root;
  r.requireObject(root, "");
  r.checkKeys(root, "", {"name", "gravity", "fps", "duration", "max_particles", "solver", "boundaries", "fluid", "effects", "render", "events"});
  SceneDef s;
  s.path = file;
  s.name = r.string(root, "", "name", s.name, {});
  s.gravity = r.vec2(root, "", "gravity", s.gravity);
  s.fps = r.number(root, "", "fps", s.fps, 1, 1000);
  s.duration = r.number(root, "", "duration", s.duration, 0, 1e5);
  s.maxParticles = static_cast<std::size_t>(r.number(root, "", "max_particles", double(s.maxParticles), 0, 1e8));

  if (root.contains("solver")) {
    const json& j = root.at("solver");
    const std::string p = "solver";
    r.requireObject(j, p);
    SolverDef& d = s.solver;
    d.type = r.string(j, p, "type", d.type, solverNames());
    std::vector<std::string> keys = {"type", "spacing", "support_ratio", "rest_density", "sound_speed", "viscosity", "cfl",
                                     "max_substeps", "clamp_negative_pressure", "reorder_interval", "max_speed"};
    for (const SolverParam& sp : solverParams(d.type)) keys.push_back(sp.key);
    r.checkKeys(j, p, keys);
    for (const SolverParam& sp : solverParams(d.type)) d.params[sp.key] = r.number(j, p, sp.key, sp.def, sp.lo, sp.hi);
    d.spacing = r.number(j, p, "spacing", d.spacing, 0, 10, true);
    d.supportRatio = r.number(j, p, "support_ratio", d.supportRatio, 1.5, 4);
    d.restDensity = r.number(j, p, "rest_density", d.restDensity, 0, 1e5, true);
    d.soundSpeed = r.number(j, p, "sound_speed", d.soundSpeed, 0, 1e4, true);
    d.viscosity = r.number(j, p, "viscosity", d.viscosity, 0, 100);
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
    if (!arr.is_array()) r.fail("boundaries", "expected an array of static bodies, got " + typeName(arr));
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
      if (!fx.is_array()) r.fail(Reader::sub(p, "fixtures"), "expected an array of fixtures, got " + typeName(fx));
      for (std::size_t f = 0; f < fx.size(); ++f)
        body.fixtures.push_back(readFixture(r, fx[f], p + ".fixtures[" + std::to_string(f) + "]"));
      s.bodies.push_back(body);
    }
  }

  if (root.contains("fluid")) {
    const json& arr = root.at("fluid");
    if (!arr.is_array()) r.fail("fluid", "expected an array of blocks, got " + typeName(arr));
    for (std::size_t b = 0; b < arr.size(); ++b) {
      const std::string p = "fluid[" + std::to_string(b) + "]";
      const json& j = arr[b];
      r.requireObject(j, p);
      r.checkKeys(j, p, {"min", "max", "velocity"});
      FluidBlockDef blk;
      blk.min = r.requiredVec2(j, p, "min");
      blk.max = r.requiredVec2(j, p, "max");
      blk.velocity = r.vec2(j, p, "velocity", blk.velocity);
      if (!(blk.max.x() > blk.min.x() && blk.max.y() > blk.min.y()))
        r.fail(Reader::sub(p, "max"), "max must be greater than min in x and in y");
      s.blocks.push_back(blk);
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
      if (!(d.camera.max.x() > d.camera.min.x() && d.camera.max.y() > d.camera.min.y()))
        r.fail(Reader::sub(pc, "max"), "max must be greater than min in x and in y");
    }
  }

  // The timeline last: its events are checked against the emitters, effects and gravity above.
  if (root.contains("events")) {
    const json& arr = root.at("events");
    if (!arr.is_array()) r.fail("events", "expected an array of events {\"t\": seconds, \"type\": ...}, got " + typeName(arr));
    for (std::size_t k = 0; k < arr.size(); ++k)
      s.events.push_back(readEvent(r, arr[k], "events[" + std::to_string(k) + "]", s, EventStamp::Required, false));
  }

  const std::size_t n = countBlockParticles(s);
  if (n > s.maxParticles)
    r.fail("solver.spacing", "spacing " + fmt(s.solver.spacing) + " fills the fluid blocks with " + std::to_string(n) +
                                 " particles, more than max_particles = " + std::to_string(s.maxParticles) +
                                 "; use a larger spacing or raise max_particles");
  return s;
}

SceneDef loadScene(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path, 0, 0, "", "cannot open the scene file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parseScene(ss.str(), path);
}

}  // namespace sph2d
