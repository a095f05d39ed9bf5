// Sweeps split into single runs for a scheduler (`--list`, `--only`, `--merge`; docs/ACCURACY.md,
// "Running a sweep on many cores or machines"): the runs of `--list` run by GNU parallel and
// merged give the one-process CSV row for row, wall times apart; a run id the sweep lacks is a
// usage error; rows of different builds or settings are not merged silently; surge_long's floors.
// GNU parallel is Debian's `parallel` (.ci/setup.sh installs it).
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

#include "app_util.hpp"

using namespace sph2d::apptest;

namespace {

struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  int col(const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return int(i);
    FAIL("no column " << name);
    return -1;
  }
};

Table readTable(const std::string& path) {
  Table t;
  std::istringstream in(readText(path));
  std::string line;
  std::getline(in, line);
  t.header = csvCells(line);
  while (std::getline(in, line)) {
    std::vector<std::string> f = csvCells(line);
    if (!line.empty() && line.back() == ',') f.push_back("");
    t.rows.push_back(f);
  }
  return t;
}

std::vector<std::string> lines(const std::string& text, const std::string& containing) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if (line.find(containing) != std::string::npos) out.push_back(line);
  return out;
}

void requireParallel() {
  const Result p = runShell("parallel --version");
  INFO(p.out);
  REQUIRE_MESSAGE(p.code == 0, "GNU parallel is missing: install Debian's `parallel` (.ci/setup.sh lists it)");
}

/// Every row of `a` equals the row of `b` at the same place, but for the columns named in `skip`.
void checkSameRows(const Table& a, const Table& b, const std::set<std::string>& skip) {
  REQUIRE(a.header == b.header);
  REQUIRE(a.rows.size() == b.rows.size());
  for (std::size_t r = 0; r < a.rows.size(); ++r) {
    REQUIRE(a.rows[r].size() == a.header.size());
    REQUIRE(b.rows[r].size() == a.header.size());
    for (std::size_t c = 0; c < a.header.size(); ++c) {
      if (skip.count(a.header[c])) continue;
      CAPTURE(r);
      CAPTURE(a.header[c]);
      CHECK(a.rows[r][c] == b.rows[r][c]);
    }
  }
}

}  // namespace

TEST_CASE("bench accuracy --quick: --list run by parallel -j2 and merged gives the one-process CSV, wall times apart") {
  requireParallel();
  const std::string dir = freshDir("sweep_accuracy");
  const std::string common = "--quick --threads 1 --assets " + q(std::string(SPH2D_ASSETS));
  const Result one = run("bench accuracy " + common + " --out " + q(dir + "/one"));
  INFO(one.out);
  REQUIRE(one.code == 0);

  const Result listed = run("bench accuracy " + common + " --list --out " + q(dir + "/runs"));
  REQUIRE(listed.code == 0);
  const std::vector<std::string> commands = lines(listed.out, " bench accuracy --only ");
  CHECK(commands.size() == 20);  // 5 solvers x 4 cases, one resolution and CFL number each
  for (const std::string& c : commands) {
    CAPTURE(c);
    CHECK(c.find(" --out " + dir + "/runs/") != std::string::npos);  // each run its own folder
    CHECK(c.find(" --quick") != std::string::npos);
    CHECK(c.find(" --threads 1") != std::string::npos);
  }
  {
    std::ofstream f(dir + "/commands.txt");
    for (const std::string& c : commands) f << c << "\n";
  }
  const Result par = runShell("parallel -j2 < " + q(dir + "/commands.txt"));
  INFO(par.out);
  REQUIRE(par.code == 0);
  CHECK(filesEnding(dir + "/runs", "").size() == commands.size());

  const Result merged = run("bench accuracy --merge " + q(dir + "/runs") + " --out " + q(dir + "/merged"));
  INFO(merged.out);
  REQUIRE(merged.code == 0);
  const Table a = readTable(dir + "/one/accuracy.csv"), b = readTable(dir + "/merged/accuracy.csv");
  CHECK(a.rows.size() == 20);
  checkSameRows(a, b, {"wall_s_per_sim_s", "ms_per_step"});
  // The rows carry the build and the settings, the same in every row.
  for (const auto& r : b.rows) {
    CHECK(r[std::size_t(b.col("build"))] == a.rows[0][std::size_t(a.col("build"))]);
    CHECK(r[std::size_t(b.col("settings"))].find("quick=1;levels=3;threads=1;assets=") == 0);
  }
  // The merge's charts are the one process's: the same points but for the wall times, so the same
  // labels (the Pareto front, which the wall times move, apart).
  for (const char* chart : {"dam_break.dat", "hydrostatic.dat", "taylor_green.dat", "poiseuille.dat"}) {
    CAPTURE(chart);
    auto labels = [](const std::string& text) {
      std::multiset<std::string> out;
      std::istringstream in(text);
      std::string l;
      while (std::getline(in, l) && l != "# Pareto front")
        if (!l.empty() && l[0] != '#') {
          const std::size_t from = l.find('"'), to = l.find('"', l.find('"', l.find('"', from + 1) + 1) + 1);
          out.insert(l.substr(from, to + 1 - from));  // label, CFL index and run id, not where the label goes
        }
      return out;
    };
    const auto fromMerge = labels(readText(dir + "/merged/" + chart));
    CHECK(fromMerge.size() >= 5);
    CHECK(fromMerge == labels(readText(dir + "/one/" + chart)));
  }
}

TEST_CASE("bench accuracy --only: an id the sweep lacks exits 2 saying how to list the ids, a known one runs alone") {
  const std::string dir = freshDir("sweep_only");
  const std::string assets = " --assets " + q(std::string(SPH2D_ASSETS));
  const Result bad = run("bench accuracy --quick --only dam_break-nosuch-1250-cfl1 --out " + q(dir + "/bad") + assets);
  CHECK(bad.code == 2);
  CHECK(bad.out.find("--only") != std::string::npos);
  CHECK(bad.out.find("dam_break-nosuch-1250-cfl1") != std::string::npos);
  CHECK(bad.out.find("--list-ids --quick") != std::string::npos);
  CHECK(!std::filesystem::exists(dir + "/bad/accuracy.csv"));
  // A full sweep's id is not a run of --quick's sweep.
  const Result other = run("bench accuracy --quick --only dam_break-game-5000-cfl1 --out " + q(dir + "/bad") + assets);
  CHECK(other.code == 2);
  CHECK(run("bench accuracy --only dam_break-game-1250-cfl1 --solvers game --quick" + assets).code == 2);

  const Result good =
      run("bench accuracy --quick --threads 1 --only dam_break-game-1250-cfl1 --out " + q(dir + "/good") + assets);
  INFO(good.out);
  REQUIRE(good.code == 0);
  const Table t = readTable(dir + "/good/accuracy.csv");
  REQUIRE(t.rows.size() == 1);
  CHECK(t.rows[0][0] == "dam_break-game-1250-cfl1");
  CHECK(t.rows[0][std::size_t(t.col("status"))] == "ok");
}

TEST_CASE("bench accuracy --merge refuses rows of different builds or settings unless --allow-mixed, and a run twice") {
  const std::string dir = freshDir("sweep_mixed");
  const std::string assets = " --assets " + q(std::string(SPH2D_ASSETS));
  REQUIRE(run("bench accuracy --quick --threads 1 --only dam_break-game-1250-cfl1 --out " + q(dir + "/runs/a") + assets)
              .code == 0);
  REQUIRE(
      run("bench accuracy --quick --threads 2 --only hydrostatic-game-800-cfl1 --out " + q(dir + "/runs/b") + assets)
          .code == 0);
  // Settings differ (threads): refused, naming both files and what differs.
  const Result mixed = run("bench accuracy --merge " + q(dir + "/runs") + " --out " + q(dir + "/merged"));
  CHECK(mixed.code == 2);
  CHECK(mixed.out.find(dir + "/runs/a/accuracy.csv") != std::string::npos);
  CHECK(mixed.out.find(dir + "/runs/b/accuracy.csv") != std::string::npos);
  CHECK(mixed.out.find("threads=1") != std::string::npos);
  CHECK(mixed.out.find("threads=2") != std::string::npos);
  CHECK(mixed.out.find("--allow-mixed") != std::string::npos);
  CHECK(!std::filesystem::exists(dir + "/merged/accuracy.csv"));
  // With --allow-mixed: merged, each row keeps its settings, and the report names both kinds.
  const Result allowed =
      run("bench accuracy --merge " + q(dir + "/runs") + " --allow-mixed --out " + q(dir + "/merged"));
  INFO(allowed.out);
  REQUIRE(allowed.code == 0);
  const Table m = readTable(dir + "/merged/accuracy.csv");
  REQUIRE(m.rows.size() == 2);
  CHECK(m.rows[0][0] == "hydrostatic-game-800-cfl1");  // the sweep's order: hydrostatic before dam_break
  CHECK(m.rows[0][std::size_t(m.col("settings"))].find("threads=2") != std::string::npos);
  CHECK(m.rows[1][std::size_t(m.col("settings"))].find("threads=1") != std::string::npos);
  CHECK(readText(dir + "/merged/accuracy.md").find("mixed") != std::string::npos);

  // Another build: the same row with another commit (and id, not to be a duplicate) is refused.
  std::string csv = readText(dir + "/runs/a/accuracy.csv");
  const Table a = readTable(dir + "/runs/a/accuracy.csv");
  const std::string build = a.rows[0][std::size_t(a.col("build"))];
  REQUIRE(!build.empty());
  csv.replace(csv.find("," + build + ","), build.size() + 2, ",0123456789ab,");
  csv.replace(csv.find("dam_break-game-1250-cfl1"), 24, "dam_break-game-1250-cfl2");
  std::filesystem::create_directories(dir + "/c");
  { std::ofstream(dir + "/c/accuracy.csv") << csv; }
  const Result builds = run("bench accuracy --from-csv " + q(dir + "/runs/a/accuracy.csv") + "," +
                            q(dir + "/c/accuracy.csv") + " --out " + q(dir + "/merged2"));
  CHECK(builds.code == 2);
  CHECK(builds.out.find("build " + build + " against 0123456789ab") != std::string::npos);
  // One run twice.
  const Result twice = run("bench accuracy --from-csv " + q(dir + "/runs/a/accuracy.csv") + "," +
                           q(dir + "/runs/a/accuracy.csv") + " --out " + q(dir + "/merged3"));
  CHECK(twice.code == 2);
  CHECK(twice.out.find("dam_break-game-1250-cfl1") != std::string::npos);
}

TEST_CASE("bench accuracy surge_long: one row per floor, both errors measured, each floor's settings in its row") {
  const std::string dir = freshDir("sweep_surge_long");
  const Result r = run("bench accuracy --quick --threads 1 --cases surge_long --solvers game --out " + q(dir) +
                       " --assets " + q(std::string(SPH2D_ASSETS)));
  INFO(r.out);
  REQUIRE(r.code == 0);
  const Table t = readTable(dir + "/accuracy.csv");
  REQUIRE(t.rows.size() == 5);
  const char* floors[] = {"free", "mu0.2", "mu0.5", "mu1", "noslip"};
  std::set<std::string> errors;
  for (std::size_t i = 0; i < 5; ++i) {
    const auto& f = t.rows[i];
    CAPTURE(i);
    CHECK(f[std::size_t(t.col("floor"))] == floors[i]);
    CHECK(f[0] == std::string("surge_long-game-1250-cfl1-") + floors[i]);
    CHECK(f[std::size_t(t.col("status"))] == "ok");
    CHECK(f[std::size_t(t.col("error2_name"))] == "surge_front_rms_Z_to_T3.35");
    const double all = std::stod(f[std::size_t(t.col("error"))]), early = std::stod(f[std::size_t(t.col("error2"))]);
    CHECK(std::isfinite(all));
    CHECK(std::isfinite(early));
    CHECK(all < 3.0);  // the front within three column widths over the whole run, even this coarse
    errors.insert(f[std::size_t(t.col("error"))]);
    const std::string params = f[std::size_t(t.col("solver_params"))];
    CHECK(params.find(i == 4 ? "no_slip=1" : "no_slip=0") != std::string::npos);
  }
  CHECK(t.rows[4][std::size_t(t.col("solver_params"))].find("viscosity=7.3e-05") != std::string::npos);
  CHECK(errors.size() > 1);  // the floor changes the front
  // The chart labels each point with its resolution and floor.
  const std::string dat = readText(dir + "/surge_long.dat");
  for (const char* f : floors) CHECK(dat.find(std::string("\"1.25k ") + f + "\"") != std::string::npos);
}

TEST_CASE(
    "bench game: --list run by parallel -j2 and merged gives the one-process CSV, wall times apart, --only checks ids") {
  requireParallel();
  const std::string dir = freshDir("sweep_game");
  const std::string sweep =
      "bench game --particles 600 --seconds 0.25 --presets game --threads 1,2 --floors scene,noslip --assets " +
      q(std::string(SPH2D_ASSETS));
  const Result one = run(sweep + " --out " + q(dir + "/one"));
  INFO(one.out);
  REQUIRE(one.code == 0);
  const Result listed = run(sweep + " --list --out " + q(dir + "/runs"));
  REQUIRE(listed.code == 0);
  const std::vector<std::string> commands = lines(listed.out, " bench game --only ");
  REQUIRE(commands.size() == 4);
  CHECK(commands[0].find("--only game-600-t1 ") != std::string::npos);
  CHECK(commands[3].find("--only game-600-t2-noslip ") != std::string::npos);
  {
    std::ofstream f(dir + "/commands.txt");
    for (const std::string& c : commands) f << c << "\n";
  }
  const Result par = runShell("parallel -j2 < " + q(dir + "/commands.txt"));
  INFO(par.out);
  REQUIRE(par.code == 0);
  const Result merged = run("bench game --merge " + q(dir + "/runs") + " --out " + q(dir + "/merged"));
  INFO(merged.out);
  REQUIRE(merged.code == 0);
  const Table a = readTable(dir + "/one/game.csv"), b = readTable(dir + "/merged/game.csv");
  REQUIRE(a.rows.size() == 4);
  checkSameRows(a, b, {"wall_s_per_sim_s", "ratio_to_peer"});
  // The floor is applied: no-slip walls change the flow (the game solver takes no Coulomb friction).
  CHECK(a.rows[2][0] == "game-600-t1-noslip");
  bool differs = false;
  for (const char* c : {"surge_rms", "max_compression", "end_surface_m"})
    differs = differs || a.rows[0][std::size_t(a.col(c))] != a.rows[2][std::size_t(a.col(c))];
  CHECK(differs);

  const Result bad = run("bench game --only game-600-x2 --out " + q(dir + "/bad"));
  CHECK(bad.code == 2);
  CHECK(bad.out.find("--only") != std::string::npos);
  CHECK(bad.out.find("game-600-x2") != std::string::npos);
  CHECK(bad.out.find("--list-ids") != std::string::npos);
  CHECK(run("bench game --only game-600-t1-noslip --presets game").code == 2);
  CHECK(run("bench game --only liquidfun_static-600").code == 2);  // a peer run needs --peer
}
