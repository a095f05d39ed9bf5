// `sph2d bench game`: the game-end benchmark's smoke test. A tiny dam break for a
// quarter of a simulated second: it asserts the CSV's columns, that every figure
// is a measured fraction in its range, and that one and two threads give the
// same physics (the bits are the same: only the wall time may differ). Never a
// timing: timings belong to the benchmark itself (docs/PERFORMANCE.md).
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <vector>

#include "app_util.hpp"

using namespace sph2d::apptest;

namespace {
std::vector<std::vector<std::string>> rows(const std::string& csv, std::string& header) {
  std::istringstream in(csv);
  std::getline(in, header);
  std::vector<std::vector<std::string>> out;
  std::string line;
  while (std::getline(in, line)) out.push_back(csvCells(line));
  return out;
}
}  // namespace

TEST_CASE(
    "bench game writes one row per preset and thread count, fractions in range, the same physics on 1 and 2 threads") {
  const std::string dir = freshDir("bench_game");
  const std::string csvPath = dir + "/game.csv";
  const Result r = run("bench game --particles 600 --seconds 0.25 --presets game,accurate --threads 1,2 --assets " +
                       q(std::string(SPH2D_ASSETS)) + " --csv " + q(csvPath));
  INFO(r.out);
  REQUIRE(r.code == 0);
  std::string header;
  const auto rs = rows(readText(csvPath), header);
  CHECK(header ==
        "run_id,name,floor,particles,threads,wall_s_per_sim_s,ratio_to_peer,substeps_per_frame,iterations_per_frame,"
        "mean_compression,max_compression,energy_gain,surge_rms,outside,end_compression,end_surface_m,build,settings");
  REQUIRE(rs.size() == 4);
  for (const auto& f : rs) {
    REQUIRE(f.size() == 18);
    CHECK((f[1] == "sph2d_game" || f[1] == "sph2d_accurate"));
    CHECK(f[0] == f[1].substr(6) + "-600-t" + f[4]);  // the run id: preset-particles-tthreads
    CHECK(f[2] == "scene");
    CHECK(std::stoul(f[3]) > 400);
    CHECK(std::stod(f[5]) > 0);   // wall seconds per simulated second: measured
    CHECK(std::stod(f[7]) >= 1);  // at least one substep a frame
    const double mean = std::stod(f[9]), mx = std::stod(f[10]);
    CHECK(mean >= 0);
    CHECK(mean < 0.05);  // a fraction, not percent
    CHECK(mx >= mean);
    CHECK(mx < 0.5);
    CHECK(std::stod(f[11]) >= 0);            // energy gain: a fraction of the initial energy
    CHECK(std::isfinite(std::stod(f[12])));  // surge RMS against Martin & Moyce
    CHECK(std::stod(f[13]) == 0);            // nothing outside the tank
    CHECK(!f[16].empty());                   // the build's commit
    CHECK(f[17].find("seconds=0.25;") == 0);
  }
  // Rows come per preset, thread counts in order: the physics columns agree.
  for (std::size_t k = 0; k < rs.size(); k += 2)
    for (std::size_t c : {7u, 8u, 9u, 10u, 11u, 12u, 14u, 15u}) CHECK(rs[k][c] == rs[k + 1][c]);
}

TEST_CASE("bench game refuses a peer that is not an executable, and less than one frame") {
  const Result p =
      run("bench game --particles 600 --seconds 0.25 --presets game --threads 1 --peer /nonexistent/lf_dam_break");
  CHECK(p.code == 2);
  CHECK(p.out.find("--peer /nonexistent/lf_dam_break") != std::string::npos);
  // `--peer` alone looks for the harness this build tree builds; without -DSPH2D_PEER_LIQUIDFUN=ON
  // there is none, and the message says how to build it; with it, the run goes ahead (the assets
  // named, as the tests run outside the repository's root).
  const Result b = run("bench game --particles 600 --seconds 0.25 --presets game --threads 1 --assets " +
                       std::string(SPH2D_ASSETS) + " --peer");
  if (b.code != 0) {
    CHECK(b.code == 2);
    CHECK(b.out.find("SPH2D_PEER_LIQUIDFUN=ON") != std::string::npos);
  }
  const Result s = run("bench game --particles 600 --seconds 0.001");
  CHECK(s.code == 2);
  CHECK(s.out.find("--seconds") != std::string::npos);
}

TEST_CASE("bench game refuses a --set value outside the key's range before any run, as a scene file would") {
  // Above and below, a parameter and a shared key; --only's runs are checked as
  // --presets' are. Nothing runs: no row is printed.
  for (const std::string& set : {"max_move=50", "max_move=0.01", "support_ratio=9", "cfl=0", "grid_cell=17"}) {
    for (const std::string& runs : {"--presets game --particles 600 --threads 1", "--only game-600-t1"}) {
      INFO(set << " " << runs);
      const Result r = run("bench game " + runs + " --seconds 0.25 --set " + set);
      CHECK(r.code == 2);
      const std::string key = set.substr(0, set.find('='));
      CHECK(r.out.find("--set (preset game): solver." + key + ": value ") != std::string::npos);
      CHECK(r.out.find("out of range; allowed: ") != std::string::npos);
      CHECK(r.out.find("sph2d_game ") == std::string::npos);
    }
  }
  // A combination the solver cannot run is refused the same way (the shift would become velocity).
  const Result c =
      run("bench game --presets game --particles 600 --seconds 0.25 --threads 1 --set correction_to_velocity=1");
  CHECK(c.code == 2);
  CHECK(c.out.find("solver.grid_shift") != std::string::npos);
}

TEST_CASE("bench game at two particle counts ends with the cost growth, per particle too, from its own rows") {
  const std::string dir = freshDir("bench_game_growth");
  const std::string csvPath = dir + "/game.csv";
  const Result r = run("bench game --particles 400,900 --seconds 0.05 --presets game --threads 1 --assets " +
                       q(std::string(SPH2D_ASSETS)) + " --csv " + q(csvPath));
  INFO(r.out);
  REQUIRE(r.code == 0);
  std::string header;
  const auto rs = rows(readText(csvPath), header);
  REQUIRE(rs.size() == 2);
  const double n0 = std::stod(rs[0][3]), n1 = std::stod(rs[1][3]);
  const double t0 = std::stod(rs[0][5]), t1 = std::stod(rs[1][5]);
  REQUIRE(n1 > n0);
  const std::size_t at = r.out.find("cost growth, sph2d_game t1: ");
  REQUIRE(at != std::string::npos);
  unsigned long a = 0, b = 0;
  double ratio = 0, wall = 0, perParticle = 0;
  REQUIRE(std::sscanf(r.out.c_str() + at,
                      "cost growth, sph2d_game t1: %lu -> %lu particles (x%lf): wall/sim x%lf, per particle x%lf", &a,
                      &b, &ratio, &wall, &perParticle) == 5);
  CHECK(double(a) == n0);
  CHECK(double(b) == n1);
  CHECK(ratio == doctest::Approx(n1 / n0).epsilon(0.005));
  CHECK(wall == doctest::Approx(t1 / t0).epsilon(0.01));
  CHECK(perParticle == doctest::Approx(t1 / t0 / (n1 / n0)).epsilon(0.01));
  CHECK(r.out.find("cost growth", at + 1) == std::string::npos);  // one run, one larger count: one line
}

TEST_CASE("bench game runs the column in two materials: a dye changes no physics, oil only where the solver takes it") {
  const std::string dir = freshDir("bench_game_materials");
  const std::string csvPath = dir + "/game.csv";
  const Result r =
      run("bench game --particles 600 --seconds 0.25 --presets game,game_dye,game_oil,balanced_oil --threads 1 "
          "--assets " +
          q(std::string(SPH2D_ASSETS)) + " --csv " + q(csvPath));
  INFO(r.out);
  REQUIRE(r.code == 0);
  std::string header;
  const auto rs = rows(readText(csvPath), header);
  REQUIRE(rs.size() == 4);
  std::map<std::string, std::vector<std::string>> by;
  for (const auto& f : rs) by[f[1]] = f;
  REQUIRE(by.count("sph2d_game_dye"));
  REQUIRE(by.count("sph2d_balanced_oil"));
  CHECK(by["sph2d_game_dye"][0] == "game_dye-600-t1");
  CHECK(by["sph2d_balanced_oil"][0] == "balanced_oil-600-t1");
  // Water below and dye of its density above move as water alone: the same particles,
  // substeps, compression, surge and surface.
  for (std::size_t c : {3u, 7u, 8u, 9u, 10u, 12u, 14u, 15u}) CHECK(by["sph2d_game_dye"][c] == by["sph2d_game"][c]);
  for (const char* oil : {"sph2d_balanced_oil", "sph2d_game_oil"}) {
    REQUIRE(by.count(oil));
    CHECK(std::stod(by[oil][13]) == 0);  // nothing outside the tank
    CHECK(std::stod(by[oil][9]) < 0.05);
  }
  // Oil needs a solver that takes a density contrast: the accurate preset's (dfsph) refuses,
  // naming what runs.
  const Result refused = run("bench game --particles 600 --seconds 0.25 --presets accurate_oil");
  CHECK(refused.code == 2);
  CHECK(refused.out.find("runs on game and balanced") != std::string::npos);
  const Result unknown = run("bench game --only game_syrup-600-t1");
  CHECK(unknown.code == 2);
  const Result oilId = run("bench game --only accurate_oil-600-t1");
  CHECK(oilId.code == 2);
  CHECK(oilId.out.find("runs on game and balanced") != std::string::npos);
}
