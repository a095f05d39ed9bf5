// Input events (sph2d/events.hpp): reading one event object, the scene's
// `events` section, and writing an event back as one line of JSON.
//
// readEvent is the one place where an event's fields are read and checked:
// the scene's timeline (readEvents, called by parseScene) and every line of
// an events file or of live input (parseEvent) go through it, so a mistake
// gets the same message wherever it is written. parseEvent parses a line as
// its own JSON document and shifts the reported line to the file's. An event
// naming an emitter or an effect is checked against the scene's; a gravity
// tilt is resolved against the scene's gravity when read, so eventToJson
// writes the gravity it gave and a record replays the same bits.
#include "sph2d/events.hpp"

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "effects/effect.hpp"
#include "scene/json_reader.hpp"
#include "scene/scene_checks.hpp"
#include "scene/scene_reader.hpp"
#include "scene/scene_sections.hpp"
#include "sph2d/scene.hpp"

namespace sph2d {
namespace {

/// The one place where an event's fields are read and checked: the scene's
/// `events` entries and every line of events files and live input come here.
EventDef readEvent(const Reader& r, const nlohmann::json& j, const std::string& path, const SceneDef& scene,
                   EventStamp stamp, bool allowSource) {
  using T = EventDef::Type;
  static const std::vector<std::pair<std::string, T>> kTypes = {
      {"force", T::Force},   {"release", T::Release}, {"block", T::Block},
      {"drop", T::Drop},     {"emitter", T::Emitter}, {"gravity", T::Gravity},
      {"effect", T::Effect}, {"pause", T::Pause},     {"resume", T::Resume}};
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
    case T::Force:
      keys.insert(keys.end(), {"id", "point", "radius", "strength"});
      break;
    case T::Release:
      keys.insert(keys.end(), {"id"});
      break;
    case T::Block:
      keys.insert(keys.end(), {"min", "max", "velocity", "material"});
      break;
    case T::Drop:
      keys.insert(keys.end(), {"center", "radius", "velocity", "material"});
      break;
    case T::Emitter:
      keys.insert(keys.end(), {"index", "enabled", "position", "direction"});
      break;
    case T::Gravity:
      keys.insert(keys.end(), {"gravity", "tilt"});
      break;
    case T::Effect:
      keys.insert(keys.end(), {"name", "enabled"});
      break;
    case T::Pause:
      keys.insert(keys.end(), {"seconds"});
      break;
    case T::Resume:
      break;
  }
  r.checkKeys(j, path, keys);

  // The stamp.
  if (j.contains("t") && j.contains("frame"))
    r.fail(Reader::sub(path, "frame"), "give either \"t\" or \"frame\", not both");
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
      if (j.contains("material")) e.material = sceneMaterials(scene)[readMaterialName(r, j, path, scene)].name;
      break;
    case T::Drop:
      e.point = r.requiredVec2(j, path, "center");
      required("radius", "a number > 0 (metres)");
      e.radius = r.number(j, path, "radius", 0, 0, 1e4, true);
      e.velocity = r.vec2(j, path, "velocity", e.velocity);
      if (j.contains("material")) e.material = sceneMaterials(scene)[readMaterialName(r, j, path, scene)].name;
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
      if (e.hasDirection && e.direction.norm() < 1e-12)
        r.fail(Reader::sub(path, "direction"), "direction must not be zero");
      if (!e.hasEnabled && !e.hasPoint && !e.hasDirection)
        r.fail(Reader::sub(path, "enabled"),
               "missing; an emitter event needs \"enabled\", \"position\" or \"direction\"");
      break;
    }
    case T::Gravity:
      if (j.contains("gravity") == j.contains("tilt"))
        r.fail(Reader::sub(path, "gravity"),
               "give either \"gravity\": [x, y] (m/s²) or \"tilt\": angle (radians, "
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

void readEvents(const Reader& r, const nlohmann::json& root, SceneDef& s) {
  if (!root.contains("events")) return;
  const nlohmann::json& arr = root.at("events");
  if (!arr.is_array())
    r.fail("events", "expected an array of events {\"t\": seconds, \"type\": ...}, got " + typeName(arr));
  for (std::size_t k = 0; k < arr.size(); ++k)
    s.events.push_back(readEvent(r, arr[k], "events[" + std::to_string(k) + "]", s, EventStamp::Required, false));
}

std::vector<std::string> switchableEffects(const SceneDef& scene) {
  std::vector<std::string> out;
  for (const auto& e : makeEffects(scene)) out.push_back(e->name());
  out.push_back("user_force");
  return out;
}

const char* eventTypeName(EventDef::Type type) {
  switch (type) {
    case EventDef::Type::Force:
      return "force";
    case EventDef::Type::Release:
      return "release";
    case EventDef::Type::Block:
      return "block";
    case EventDef::Type::Drop:
      return "drop";
    case EventDef::Type::Emitter:
      return "emitter";
    case EventDef::Type::Gravity:
      return "gravity";
    case EventDef::Type::Effect:
      return "effect";
    case EventDef::Type::Pause:
      return "pause";
    case EventDef::Type::Resume:
      return "resume";
  }
  return "?";
}

double eventParticles(const EventDef& e, double spacing) {
  if (!(spacing > 0)) return 0;
  if (e.type == EventDef::Type::Block) return regionLatticeCount(e.block, spacing);  // a box: nx·ny
  if (e.type != EventDef::Type::Drop) return 0;
  const FluidBlockDef region = circleRegion(e.point, e.radius, spacing);
  const double rows = std::floor((region.max.y() - region.min.y()) / spacing + 1e-9);
  if (rows <= 4096) return regionLatticeCount(region, spacing);  // the points World::addDrop keeps
  const double r = e.radius / spacing + 1;
  return 3.14159265358979323846 * r * r;
}

std::int64_t eventFrame(const EventDef& e, double fps) {
  if (e.frame >= 0) return e.frame;
  if (e.t < 0) return -1;
  return std::int64_t(std::ceil(e.t * fps - 1e-9));
}

EventDef parseEvent(const std::string& text, const std::string& file, int line, const SceneDef& scene,
                    EventStamp stamp) {
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
  if (e.frame >= 0)
    j["frame"] = e.frame;
  else if (e.t >= 0)
    j["t"] = e.t;
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
      if (!e.material.empty()) j["material"] = e.material;
      break;
    case T::Drop:
      j["center"] = vec(e.point);
      j["radius"] = e.radius;
      j["velocity"] = vec(e.velocity);
      if (!e.material.empty()) j["material"] = e.material;
      break;
    case T::Emitter:
      j["index"] = e.index;
      if (e.hasEnabled) j["enabled"] = e.enabled;
      if (e.hasPoint) j["position"] = vec(e.point);
      if (e.hasDirection) j["direction"] = vec(e.direction);
      break;
    case T::Gravity:
      j["gravity"] = vec(e.gravity);
      break;
    case T::Effect:
      j["name"] = e.effect;
      j["enabled"] = e.enabled;
      break;
    case T::Pause:
      if (e.seconds > 0) j["seconds"] = e.seconds;
      break;
    case T::Resume:
      break;
  }
  if (!e.source.empty()) j["source"] = e.source;
  return j.dump();
}

}  // namespace sph2d
