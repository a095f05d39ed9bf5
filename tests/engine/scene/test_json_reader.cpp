// The position-aware JSON reader (engine/src/scene/json_reader.cpp): the same value as
// nlohmann::json, and the 1-based line and byte column of every key and array
// element, which the scene loader's messages name. (The scene loader's messages
// for bad files: test_scene_errors.cpp.)
#include <doctest/doctest.h>

#include <string>
#include <utility>

#include "scene/json_reader.hpp"
#include "sph2d/scene.hpp"

using namespace sph2d;

namespace {

using LineCol = std::pair<int, int>;

// Positions counted by hand (and by a script: line = newlines before the byte + 1,
// column = bytes since the line's start + 1). The tab is one byte; "é" is two.
const std::string kText =
    "{\n"
    "  \"solver\": {\"type\": \"wcsph\",\n"
    "\t\"spacing\": 0.02},\n"
    "  \"fluid\": [ {\"min\": [0, 0], \"max\": [1, 2]},\n"
    "             {\"min\": [3, 0]} ],\n"
    "  \"name\": \"caf\xC3\xA9\", \"fps\": 60\n"
    "}\n";

void checkPositions(const JsonDoc& d, int lineShift) {
  const auto at = [&](const char* path) {
    CAPTURE(path);
    REQUIRE(d.where.count(path) == 1);
    return d.where.at(path);
  };
  const auto L = [&](int line, int col) { return LineCol(line + lineShift, col); };
  CHECK(at("solver") == L(2, 3));
  CHECK(at("solver.type") == L(2, 14));
  CHECK(at("solver.spacing") == L(3, 2));
  CHECK(at("fluid") == L(4, 3));
  CHECK(at("fluid[0]") == L(4, 14));
  CHECK(at("fluid[0].min") == L(4, 15));
  CHECK(at("fluid[0].min[1]") == L(4, 26));
  CHECK(at("fluid[0].max") == L(4, 30));
  CHECK(at("fluid[0].max[1]") == L(4, 41));
  CHECK(at("fluid[1]") == L(5, 14));
  CHECK(at("fluid[1].min") == L(5, 15));
  CHECK(at("name") == L(6, 3));
  CHECK(at("fps") == L(6, 20));  // bytes, not characters: "é" counts twice
  CHECK(d.where.count("fluid[2]") == 0);
  CHECK(d.where.count("solver.missing") == 0);
}

}  // namespace

TEST_CASE("the JSON reader gives the line and byte column of every key and array element, and nlohmann's value") {
  const JsonDoc d = parseJsonWithPositions(kText, "scene.json");
  CHECK(d.root == nlohmann::json::parse(kText));
  CHECK(d.where.at("") == LineCol(1, 1));  // the root object
  checkPositions(d, 0);
  // 18 paths: the root; solver, its 2 keys; fluid, fluid[0], its 2 keys and their
  // 2 + 2 elements; fluid[1], its key and its 2 elements; name, fps.
  CHECK(d.where.size() == 1 + 3 + 1 + 1 + 2 + 4 + 1 + 1 + 2 + 2);
}

TEST_CASE(
    "the JSON reader's positions: a byte order mark is no column, CRLF line ends and blank lines shift only lines") {
  // A BOM on line 1: columns there are counted after it.
  const JsonDoc bom = parseJsonWithPositions("\xEF\xBB\xBF{\"a\": 1, \"b\": [true]}", "bom.json");
  CHECK(bom.where.at("a") == LineCol(1, 2));
  CHECK(bom.where.at("b") == LineCol(1, 10));
  CHECK(bom.where.at("b[0]") == LineCol(1, 16));
  CHECK(bom.root == nlohmann::json::parse("{\"a\": 1, \"b\": [true]}"));
  // The same document with CRLF line ends and two blank lines first.
  std::string crlf = "\n\r\n";
  for (char ch : kText) crlf += ch == '\n' ? std::string("\r\n") : std::string(1, ch);
  const JsonDoc d = parseJsonWithPositions(crlf, "crlf.json");
  CHECK(d.root == nlohmann::json::parse(kText));
  checkPositions(d, 2);
}

TEST_CASE("the JSON reader reports a syntax error at the offending byte, in the file it names") {
  // Line 5 of kText with its ']' dropped: the '}' that follows (column 27) is unexpected.
  std::string bad = kText;
  bad.replace(bad.find("[3, 0]"), 6, "[3, 0");
  try {
    parseJsonWithPositions(bad, "bad.json");
    FAIL("the reader accepted a missing ']'");
  } catch (const SceneError& e) {
    CHECK(e.file == "bad.json");
    CHECK(e.line == 5);
    CHECK(e.column == 27);
    CHECK(e.message.find("expected ',' or ']'") != std::string::npos);
  }
}
