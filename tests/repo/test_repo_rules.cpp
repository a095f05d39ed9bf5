// What must stay true of the repository itself (CONTRIBUTING.md): no include against the
// engine's folder order (docs/ARCHITECTURE.md).
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

}  // namespace

TEST_CASE("repository: engine includes follow the folder order core < particles < boundary < bodies < step < effects < solvers < scene < world") {
  // A folder may include its own headers, lower folders' and the public API (sph2d/...);
  // never a higher folder's. docs/ARCHITECTURE.md draws the same order.
  const std::vector<std::string> order = {"core", "particles", "boundary", "bodies", "step",
                                          "effects", "solvers", "scene", "world"};
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
