// `sph2d bench accuracy --quick`: the report's smoke test. It asserts the
// files, the CSV's columns and that every solver produced a finite error, not
// any timing (timings belong to the benchmark itself), and that every solver keeps its rows.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

#include "app_util.hpp"
#include "sph2d/scene.hpp"

using namespace sph2d::apptest;

TEST_CASE(
    "bench accuracy --quick writes the CSV, the table and the charts' scripts, with a finite error per solver and case") {
  const std::string dir = freshDir("accuracy_quick");
  const Result r = run("bench accuracy --quick --out \"" + dir + "\" --assets \"" + std::string(SPH2D_ASSETS) + "\"");
  INFO(r.out);
  REQUIRE(r.code == 0);
  const std::string csv = readText(dir + "/accuracy.csv");
  std::istringstream in(csv);
  std::string header;
  std::getline(in, header);
  CHECK(
      header ==
      "run_id,case,solver,floor,particles,cfl,error_name,error,error2_name,error2,mean_density_error,max_density_error,"
      "wall_s_per_sim_s,ms_per_step,status,build,settings,solver_params");
  std::set<std::string> cases, solvers;
  std::string line;
  int rows = 0;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ls(line);
    std::string cell;
    while (std::getline(ls, cell, ',')) f.push_back(cell);
    REQUIRE(f.size() == 18);
    cases.insert(f[1]);
    solvers.insert(f[2]);
    CHECK(f[14] == "ok");
    // The id names the run: case-solver-particles-cfl1 (one CFL number in --quick).
    CHECK(f[0] == f[1] + "-" + f[2] + "-" + f[4] + "-cfl1");
    const double err = std::stod(f[7]);
    CHECK(std::isfinite(err));
    CHECK(err >= 0);
    if (f[1] == "dam_break")
      CHECK(err < 1.0);  // the surge front within one column width (RMS of Z) at the coarse resolution
    if (f[1] == "poiseuille") CHECK(err < 0.1);  // u/u_c against the series: every solver within 10 % RMS, even coarse
    // The settings that made it, and the solver's parameters.
    CHECK(!f[15].empty());
    CHECK(f[16].find("quick=1;") == 0);
    CHECK(f[17].find("spacing=") == 0);
    ++rows;
  }
  CHECK(cases == std::set<std::string>{"dam_break", "hydrostatic", "taylor_green", "poiseuille"});
  // Every solver keeps its rows (issue 15): the seed's, the three quality presets' and pbf.
  for (const char* s : {"muller2003", "wcsph", "dfsph", "pbf", "game"}) {
    CAPTURE(s);
    CHECK(solvers.count(s) == 1);
  }
  for (const std::string& q : sph2d::qualityPresets()) CHECK(solvers.count(sph2d::qualityPreset(q).type) == 1);
  CHECK(rows == 4 * int(solvers.size()));
  CHECK(readText(dir + "/accuracy.md").find("| dam_break |") != std::string::npos);
  // Each case's chart: its gnuplot script and data, one data row per solver's run and one per run
  // on the Pareto front (the drawing itself: test_bench_accuracy_charts.cpp).
  for (const char* c : {"dam_break", "hydrostatic", "taylor_green", "poiseuille"}) {
    CAPTURE(c);
    CHECK(readText(dir + "/" + c + ".gp").find("plot \\") != std::string::npos);
    std::istringstream dat(readText(dir + "/" + c + ".dat"));
    int rowsThere = 0;
    while (std::getline(dat, line)) rowsThere += !line.empty() && line[0] != '#';
    CHECK(rowsThere > int(solvers.size()));
  }
}
