// The scene reader (engine/src/scene_reader.*): typed access to a JSON document
// with positions, and how its failures are worded. The same messages through
// whole scenes are in test_scene_errors.cpp.
#include <doctest/doctest.h>

#include <string>

#include "scene/json_reader.hpp"
#include "scene/scene_reader.hpp"
#include "sph2d/scene.hpp"

using namespace sph2d;
using nlohmann::json;

namespace {

/// The SceneError `fn` throws (a test failure when it throws none).
template <class Fn>
SceneError errorFrom(Fn fn) {
  try {
    fn();
  } catch (const SceneError& e) {
    return e;
  }
  FAIL("no SceneError");
  return SceneError("", 0, 0, "", "");
}

}  // namespace

TEST_CASE("SceneError writes file, position and key only when it has them") {
  CHECK(std::string(SceneError("a.json", 3, 7, "solver.cfl", "too big").what()) ==
        "a.json:3:7: key 'solver.cfl': too big");
  CHECK(std::string(SceneError("a.json", 0, 0, "solver.cfl", "too big").what()) == "a.json: key 'solver.cfl': too big");
  CHECK(std::string(SceneError("a.json", 2, 1, "", "invalid JSON").what()) == "a.json:2:1: invalid JSON");
  const SceneError e("f", 4, 5, "k", "m");
  CHECK(e.file == "f");
  CHECK(e.line == 4);
  CHECK(e.column == 5);
  CHECK(e.key == "k");
  CHECK(e.message == "m");
}

TEST_CASE("the message helpers name types, numbers and keys as the messages need them") {
  CHECK(typeName(json(nullptr)) == "null");
  CHECK(typeName(json(true)) == "a boolean");
  CHECK(typeName(json(3)) == "an integer");
  CHECK(typeName(json(3.5)) == "a number");
  CHECK(typeName(json("x")) == "a string");
  CHECK(typeName(json::object()) == "an object");
  CHECK(describe(json::array({1})) == "an array of 1 element");
  CHECK(describe(json::array({1, 2})) == "an array of 2 elements");
  CHECK(describe(json::object()) == "an object");
  CHECK(join({"a", "b", "c"}) == "a, b, c");
  CHECK(join({}) == "");
  CHECK(fmt(2) == "2");
  CHECK(fmt(-3) == "-3");
  CHECK(fmt(0.5) == "0.5");
  CHECK(fmt(1e300) == "1e+300");
  CHECK(fmt(1.0 / 3) == "0.333333");
  CHECK(printable("a\x01"
                  "b\x7F") == "a\\x01b\\x7F");
  CHECK(printable("caf\xC3\xA9") == "caf\xC3\xA9");  // UTF-8 is shown as it is
}

TEST_CASE("Reader::fail reports the position of the deepest key along the path the document knows") {
  const JsonDoc doc = parseJsonWithPositions("{\n  \"solver\": {\n    \"spacing\": [1, 2]\n  }\n}", "r.json");
  const Reader r(doc, "r.json");
  SceneError e = errorFrom([&] { r.fail("solver.spacing", "m"); });
  CHECK(e.line == 3);
  CHECK(e.column == 5);
  CHECK(e.key == "solver.spacing");
  // Deeper than the document goes: the position of solver.spacing, the key path as given.
  e = errorFrom([&] { r.fail("solver.spacing.more[4].x", "m"); });
  CHECK(e.line == 3);
  CHECK(e.column == 5);
  CHECK(e.key == "solver.spacing.more[4].x");
  e = errorFrom([&] { r.fail("solver.cfl", "m"); });
  CHECK(e.line == 2);
  CHECK(e.column == 3);
  // A path the document does not hold at all: no position.
  e = errorFrom([&] { r.fail("render.width", "m"); });
  CHECK(e.line == 0);
  CHECK(std::string(e.what()) == "r.json: key 'render.width': m");
  CHECK(Reader::sub("", "fps") == "fps");
  CHECK(Reader::sub("render.camera", "min") == "render.camera.min");
}

TEST_CASE("Reader's accessors return the default when the key is absent and check type and range when present") {
  const JsonDoc doc = parseJsonWithPositions(
      "{\"n\": 0.5, \"i\": 1e3, \"f\": 2.5, \"big\": 1e30, \"b\": 1, \"s\": \"a\\u0001\", \"v\": [1, 2], \"c\": [0, 0.5, 1]}",
      "r.json");
  const Reader r(doc, "r.json");
  const json& o = doc.root;
  // Absent: the default, unchecked.
  CHECK(r.number(o, "", "absent", 99, 0, 1) == 99);
  CHECK(r.integer(o, "", "absent", -5, 0, 10) == -5);
  CHECK(r.boolean(o, "", "absent", true));
  CHECK(r.string(o, "", "absent", "def", {"x"}) == "def");
  CHECK(r.vec2(o, "", "absent", Vec2d(3, 4)) == Vec2d(3, 4));
  // Present.
  CHECK(r.number(o, "", "n", 0, 0, 1) == 0.5);
  CHECK(errorFrom([&] { r.number(o, "", "n", 0, 0.5, 1, true); }).message ==
        "value 0.5 is out of range; allowed: > 0.5 and <= 1");
  CHECK(errorFrom([&] { r.number(o, "", "n", 0, 0.6, 1); }).message ==
        "value 0.5 is out of range; allowed: >= 0.6 and <= 1");
  CHECK(errorFrom([&] { r.number(o, "", "s", 0, 0, 1); }).message == "expected a number, got a string");
  CHECK(r.integer(o, "", "i", 0, 0, 5000) == 1000);
  CHECK(errorFrom([&] { r.integer(o, "", "f", 0, 0, 10); }).message == "expected an integer from 0 to 10, got 2.5");
  CHECK(errorFrom([&] { r.integer64(o, "", "big", 0, 0, 10); }).message ==
        "value 1e+30 is out of range; allowed: an integer from 0 to 10");
  CHECK(errorFrom([&] { r.boolean(o, "", "b", false); }).message == "expected true or false, got an integer");
  // An empty list allows any string; otherwise the value is shown printable.
  CHECK(r.string(o, "", "s", "", {}) == "a\x01");
  CHECK(errorFrom([&] {
          r.string(o, "", "s", "", {"x", "y"});
        }).message == "'a\\x01' is not allowed; allowed values: x, y");
  CHECK(r.requiredVec2(o, "", "v") == Vec2d(1, 2));
  const SceneError missing = errorFrom([&] { r.requiredVec2(o, "", "w"); });
  CHECK(missing.key == "w");
  CHECK(missing.message == "missing; expected [x, y]");
  const std::array<double, 3> rgb{0, 0.5, 1};
  CHECK(r.color(o, "", "c", {}) == rgb);
  CHECK(errorFrom([&] { r.color(o, "", "v", {}); }).message ==
        "expected [r, g, b] with components in 0..1, got an array of 2 elements");
}

TEST_CASE("Reader's vectors stay within the coordinate limit and points name the element that is wrong") {
  const JsonDoc doc = parseJsonWithPositions(
      "{\"edge\": [10000000, -10000000], \"over\": [10000001, 0], \"pts\": [[0, 0], [1, \"y\"]], \"one\": 1}",
      "r.json");
  const Reader r(doc, "r.json");
  const json& o = doc.root;
  CHECK(r.vec2(o, "", "edge", Vec2d(0, 0)) == Vec2d(kMaxCoordinate, -kMaxCoordinate));
  CHECK(errorFrom([&] { r.vec2(o, "", "over", Vec2d(0, 0)); }).message ==
        "[10000001, 0] is out of range; each component must be within +-10000000");
  const SceneError e = errorFrom([&] { r.points(o, "", "pts"); });
  CHECK(e.key == "pts[1]");
  CHECK(e.message == "expected [x, y] (two numbers), got a string at [1]");
  CHECK(errorFrom([&] { r.points(o, "", "one"); }).message == "expected an array of [x, y] points, got an integer");
  CHECK(errorFrom([&] { r.points(o, "", "none"); }).message == "missing; expected an array of [x, y] points");
}

TEST_CASE("Reader::checkKeys suggests an allowed key only when the typo is small for the key's length") {
  const auto hintFor = [](const std::string& key, const std::vector<std::string>& allowed) {
    const JsonDoc doc = parseJsonWithPositions("{\"" + key + "\": 1}", "k.json");
    const Reader r(doc, "k.json");
    const SceneError e = errorFrom([&] { r.checkKeys(doc.root, "", allowed); });
    CHECK(e.key == key);
    CHECK(e.line == 1);
    CHECK(e.column == 2);
    return e.message;
  };
  CHECK(hintFor("sapcing", {"spacing", "cfl"}) ==
        "unknown key 'sapcing' (did you mean 'spacing'?); allowed keys: spacing, cfl");
  CHECK(hintFor("velocty_fild", {"min", "velocity_field"}) ==
        "unknown key 'velocty_fild' (did you mean 'velocity_field'?); allowed keys: min, velocity_field");
  // Three edits away from a 7-letter key: no suggestion.
  CHECK(hintFor("spac", {"spacing"}) == "unknown key 'spac'; allowed keys: spacing");
  // Two edits are too many for a short key.
  CHECK(hintFor("fxx", {"fps"}) == "unknown key 'fxx'; allowed keys: fps");
  // The nearest of several.
  CHECK(hintFor("widht", {"width", "height"}) ==
        "unknown key 'widht' (did you mean 'width'?); allowed keys: width, height");
  // Allowed keys pass; a non-object has no keys to check.
  const JsonDoc ok = parseJsonWithPositions("{\"a\": 1, \"b\": 2}", "k.json");
  const Reader r(ok, "k.json");
  r.checkKeys(ok.root, "", {"b", "a"});
  CHECK(errorFrom([&] { r.requireObject(json::array(), "render"); }).message ==
        "expected an object, got an array of 0 elements");
  CHECK(errorFrom([&] { r.requireObject(json(7), ""); }).message ==
        "a scene is a JSON object ({ ... }) at the top level, got an integer");
}
