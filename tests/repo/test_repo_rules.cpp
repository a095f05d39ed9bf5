// What must stay true of the repository itself (CONTRIBUTING.md): no source file over 600
// lines; no include against the engine's folder order (docs/ARCHITECTURE.md); no reference doc
// naming an issue, a session or a date, or a path outside the repository (docs/notes/ and
// CHANGELOG.md are history: they may).
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

const fs::path kRoot = fs::path(SPH2D_SOURCE_DIR);

std::vector<std::string> lines(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::string> out;
  std::string l;
  while (std::getline(in, l)) out.push_back(l);
  return out;
}

bool isSource(const fs::path& p) {
  const std::string e = p.extension().string();
  return e == ".cpp" || e == ".hpp" || e == ".h" || e == ".glsl" || e == ".def";
}

/// Our own sources (third-party code under benchmarks/peers is not ours).
std::vector<fs::path> ownSources() {
  std::vector<fs::path> out;
  for (const char* top : {"engine", "app", "tests", "shaders", "benchmarks"})
    for (const auto& e : fs::recursive_directory_iterator(kRoot / top)) {
      const std::string rel = fs::relative(e.path(), kRoot).generic_string();
      if (rel.rfind("benchmarks/peers/", 0) == 0 || rel.rfind("tests/fuzz/corpus", 0) == 0) continue;
      if (e.is_regular_file() && isSource(e.path())) out.push_back(e.path());
    }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST_CASE("repository: no source file of ours is over 600 lines") {
  int checked = 0;
  for (const fs::path& p : ownSources()) {
    ++checked;
    CAPTURE(fs::relative(p, kRoot).generic_string());
    CHECK(lines(p).size() <= 600);
  }
  CHECK(checked > 100);
}

TEST_CASE(
    "repository: engine includes follow the folder order core < particles < boundary < bodies < step < effects < solvers < scene < world") {
  // A folder may include its own headers, lower folders' and the public API (sph2d/...);
  // never a higher folder's. docs/ARCHITECTURE.md draws the same order.
  const std::vector<std::string> order = {"core",    "particles", "boundary", "bodies", "step",
                                          "effects", "solvers",   "scene",    "world"};
  auto rank = [&](const std::string& folder) {
    const auto it = std::find(order.begin(), order.end(), folder);
    return it == order.end() ? -1 : int(it - order.begin());
  };
  const std::regex include(R"re(^\s*#\s*include\s*"([^"]+)")re");
  int edges = 0;
  for (const auto& e : fs::recursive_directory_iterator(kRoot / "engine" / "src")) {
    if (!e.is_regular_file() || !isSource(e.path())) continue;
    const std::string rel = fs::relative(e.path(), kRoot / "engine" / "src").generic_string();
    const std::string from = rel.substr(0, rel.find('/'));
    REQUIRE_MESSAGE(rank(from) >= 0, "engine/src/" << rel << " is in no folder of the order");
    for (const std::string& l : lines(e.path())) {
      std::smatch m;
      if (!std::regex_search(l, m, include)) continue;
      const std::string target = m[1];
      if (target.rfind("sph2d/", 0) == 0) continue;  // the public API
      const std::string to = target.substr(0, target.find('/'));
      if (target.find('/') == std::string::npos) continue;  // a file's own .def beside it
      ++edges;
      CAPTURE(rel);
      CAPTURE(target);
      CHECK(rank(to) >= 0);
      CHECK(rank(to) <= rank(from));
    }
  }
  CHECK(edges > 50);
}

TEST_CASE("repository: reference docs name no issue, session or date, and no path outside the repository") {
  // CHANGELOG.md is history and docs/notes/ holds what was tried and dropped: both may date.
  std::vector<fs::path> docs = {kRoot / "README.md", kRoot / "CONTRIBUTING.md"};
  for (const auto& e : fs::recursive_directory_iterator(kRoot / "docs")) {
    const std::string rel = fs::relative(e.path(), kRoot).generic_string();
    if (e.is_regular_file() && e.path().extension() == ".md" && rel.rfind("docs/notes/", 0) != 0)
      docs.push_back(e.path());
  }
  const std::regex issue(
      R"(\b[Ii]ssues? #?\d+|\b(first|second|third|fourth|fifth|sixth|seventh|eighth|ninth|tenth|\d+(st|nd|rd|th)) session\b)");
  const std::regex date(
      R"(\b20\d\d-\d\d-\d\d\b|\b\d{1,2} (Jan|Feb|Mar|Apr|May|Jun|Jul|Aug|Sep|Oct|Nov|Dec)[a-z]*\b|\b(Jan|Feb|Mar|Apr|May|Jun|Jul|Aug|Sep|Oct|Nov|Dec)[a-z]* \d{1,2}\b)");
  const std::regex outside(R"(\.\./shared|/work/|/home/|/tmp/)");
  int checked = 0;
  for (const fs::path& p : docs) {
    const std::vector<std::string> ls = lines(p);
    for (std::size_t k = 0; k < ls.size(); ++k) {
      ++checked;
      const std::string where = fs::relative(p, kRoot).generic_string() + ":" + std::to_string(k + 1) + ": " + ls[k];
      CAPTURE(where);
      CHECK_FALSE(std::regex_search(ls[k], issue));
      CHECK_FALSE(std::regex_search(ls[k], date));
      CHECK_FALSE(std::regex_search(ls[k], outside));
    }
  }
  CHECK(checked > 500);
}
