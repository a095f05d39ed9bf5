// `sph2d bench effects`: the per-effect cost benchmark's smoke test. A tiny
// dam break, a few substeps: it asserts that the command runs and writes the
// CSV with one finite row per configuration, never a timing (timings belong to
// the benchmark itself, docs/PERFORMANCE.md).
#include <doctest/doctest.h>

#include <cmath>
#include <sstream>
#include <vector>

#include "app_util.hpp"

using namespace sph2d::apptest;

TEST_CASE("bench effects with a tiny dam break writes the CSV with one row per configuration") {
  const std::string dir = freshDir("bench_effects");
  const std::string csvPath = dir + "/effects.csv";
  const Result r = run("bench effects --scene " + q(asset("scenes/dam_break_muller2003.json")) +
                       " --particles 400 --steps 3 --warmup 2 --rounds 2 --threads 1 --csv " + q(csvPath));
  INFO(r.out);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("bench effects:") != std::string::npos);
  std::istringstream in(readText(csvPath));
  std::string header;
  std::getline(in, header);
  CHECK(header ==
        "effect,particles,threads,rounds,steps_per_round,clock,ms_per_step,ms_per_step_best,ratio_to_none,"
        "effect_ms_per_step,effect_share,substep_s");
  std::vector<std::string> names;
  std::string line;
  while (std::getline(in, line)) {
    const std::vector<std::string> f = csvCells(line);
    REQUIRE(f.size() == 12);
    names.push_back(f[0]);
    CHECK(std::stoul(f[1]) > 300);
    CHECK(f[5] == "wall");
    for (std::size_t k = 6; k < f.size(); ++k) {
      CAPTURE(line);
      CHECK(std::isfinite(std::stod(f[k])));
      // A folded effect's time (columns 9, 10) is a difference of two timers: noise may take it below 0.
      const bool folded = (f[0] == "viscosity" || f[0] == "all") && (k == 9 || k == 10);
      if (!folded) CHECK(std::stod(f[k]) >= 0);
    }
    if (f[0] == "none") CHECK(std::stod(f[8]) == 1.0);
    // muller2003 folds the viscosity into its pressure force (stage pressure_force+viscosity): the
    // effect's time is taken as that stage's minus none's pressure_force, not the 0 of a stage
    // that no longer runs.
    if (f[0] == "viscosity") CHECK(std::stod(f[9]) != 0.0);
  }
  CHECK(r.out.find("runs inside the solver stage pressure_force+viscosity") != std::string::npos);
  CHECK(names == std::vector<std::string>{"none", "none_again", "viscosity", "xsph", "force_field", "csf", "akinci",
                                          "lifetime", "sink", "user_force", "all"});
}

TEST_CASE("bench effects --effects runs only the listed configurations and none, and refuses an unknown one") {
  const std::string dir = freshDir("bench_effects_only");
  const std::string csvPath = dir + "/effects.csv";
  Result r = run("bench effects --scene " + q(asset("scenes/dam_break_muller2003.json")) +
                 " --particles 300 --steps 2 --warmup 0 --rounds 1 --effects csf --clock cpu --csv " + q(csvPath));
  INFO(r.out);
  REQUIRE(r.code == 0);
  const std::string csv = readText(csvPath);
  CHECK(csv.find("\nnone,") != std::string::npos);
  CHECK(csv.find("\ncsf,") != std::string::npos);
  CHECK(csv.find("\nxsph,") == std::string::npos);
  CHECK(csv.find(",cpu,") != std::string::npos);
  r = run("bench effects --effects frobnicate");
  CHECK(r.code == 2);
  CHECK(r.out.find("unknown configuration 'frobnicate'") != std::string::npos);
}
