// CTest registers each doctest case by name and runs it with --test-case=NAME;
// a ';' in a name splits it into filters that match nothing, so the case
// would "pass" without running. This test keeps every name runnable.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

TEST_CASE("no test case name contains a semicolon (CTest would run nothing for it)") {
  namespace fs = std::filesystem;
  const fs::path root = fs::path(SPH2D_ASSETS).parent_path() / "tests";
  int names = 0, bad = 0;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (e.path().extension() != ".cpp") continue;
    std::ifstream in(e.path());
    std::string line;
    while (std::getline(in, line)) {
      auto at = line.find("TEST_CASE");
      if (at == std::string::npos) continue;
      std::string next;
      // A long name goes on the line after `TEST_CASE(` or `TEST_CASE_TEMPLATE(` (.clang-format breaks there).
      if (line.find('"', at) == std::string::npos && line.back() == '(' && std::getline(in, next)) line = next, at = 0;
      const auto q0 = line.find('"', at), q1 = q0 == std::string::npos ? q0 : line.find('"', q0 + 1);
      if (q1 == std::string::npos) continue;
      ++names;
      if (line.substr(q0, q1 - q0).find(';') != std::string::npos) {
        ++bad;
        MESSAGE(e.path().string() << ": " << line);
      }
    }
  }
  CHECK(names > 20);
  CHECK(bad == 0);
}
