// The substep's stage list (engine/src/step/stage_list.cpp): it runs its stages in
// order, counts their calls by name across rebuilds, refuses a stage without
// work, and turns a bad particle a stage reports into a call of `fail` naming
// the stage.
#include <doctest/doctest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "step/stage_list.hpp"

using namespace sph2d;

namespace {

/// The parts a StepContext refers to, empty: the stages under test do not touch them.
struct Context {
  ParticleStore P;
  Grid grid;
  NeighbourLists nbr;
  BoundarySet boundary;
  ThreadPool pool{1};
  Scratch scratch;
  SolverDef def;
  StepContext c{P, grid, nbr, boundary, pool, scratch, def};
};

/// A stage that appends its name to `log` and reports `bad`.
Stage logging(const std::string& name, std::vector<std::string>& log, std::size_t bad = kNone) {
  return Stage{name, [name, &log, bad](StepContext&) {
                 log.push_back(name);
                 return bad;
               }};
}

std::uint64_t callsOf(const StageList& list, const std::string& name) {
  for (const StageTiming& t : list.timings())
    if (t.name == name) return t.calls;
  return 0;
}

const StageList::Fail kNeverFails = [](const std::string& stage, std::size_t) {
  throw std::logic_error("unexpected fail from " + stage);
};

}  // namespace

TEST_CASE("the stage list runs its stages in the order they were added, each once per run") {
  Context k;
  std::vector<std::string> log;
  StageList list;
  for (const char* name : {"grid", "neighbours", "density", "pressure", "integrate"}) list.add(logging(name, log));
  list.run(k.c, kNeverFails);
  list.run(k.c, kNeverFails);
  CHECK(log == std::vector<std::string>{"grid", "neighbours", "density", "pressure", "integrate", "grid", "neighbours",
                                        "density", "pressure", "integrate"});
  REQUIRE(list.stages().size() == 5);
  CHECK(list.stages()[2].name == "density");
  for (const char* name : {"grid", "neighbours", "density", "pressure", "integrate"}) CHECK(callsOf(list, name) == 2);
}

TEST_CASE(
    "the stage list keeps its timings by name across rebuilds, in the order names first entered, and resets them") {
  Context k;
  std::vector<std::string> log;
  StageList list;
  list.add(logging("a", log));
  list.add(logging("b", log));
  list.run(k.c, kNeverFails);
  list.clear();  // a rebuild: b moves to the front, c is new, a stays
  CHECK(list.stages().empty());
  list.add(logging("b", log));
  list.add(logging("c", log));
  list.add(logging("a", log));
  list.run(k.c, kNeverFails);
  list.run(k.c, kNeverFails);
  CHECK(log == std::vector<std::string>{"a", "b", "b", "c", "a", "b", "c", "a"});
  const std::vector<StageTiming>& t = list.timings();
  REQUIRE(t.size() == 3);
  CHECK(t[0].name == "a");
  CHECK(t[1].name == "b");
  CHECK(t[2].name == "c");
  CHECK(t[0].calls == 3);
  CHECK(t[1].calls == 3);
  CHECK(t[2].calls == 2);
  // A stage that appears twice in one list counts both runs under its name.
  list.add(logging("a", log));
  list.run(k.c, kNeverFails);
  CHECK(callsOf(list, "a") == 5);
  list.resetTimings();
  for (const StageTiming& s : list.timings()) {
    CHECK(s.calls == 0);
    CHECK(s.seconds == 0);
  }
  CHECK(list.timings().size() == 3);
}

TEST_CASE(
    "a stage that reports a bad particle makes the list call fail with the stage's name and the slot, and stop there") {
  Context k;
  std::vector<std::string> log;
  StageList list;
  list.add(logging("density", log));
  list.add(logging("pressure_force", log, 17));
  list.add(logging("integrate", log));
  std::string failedStage;
  std::size_t failedSlot = 0;
  const StageList::Fail fail = [&](const std::string& stage, std::size_t slot) {
    failedStage = stage;
    failedSlot = slot;
    throw std::runtime_error("stopped");
  };
  CHECK_THROWS_AS(list.run(k.c, fail), std::runtime_error);
  CHECK(failedStage == "pressure_force");
  CHECK(failedSlot == 17);
  CHECK(log == std::vector<std::string>{"density", "pressure_force"});  // integrate did not run
  CHECK(callsOf(list, "pressure_force") == 1);                          // the failing run is counted
  CHECK(callsOf(list, "integrate") == 0);
  // plainStage never reports a particle.
  StageList plain;
  int runs = 0;
  plain.add(plainStage("collide", [&](StepContext&) { ++runs; }));
  plain.run(k.c, kNeverFails);
  CHECK(runs == 1);
}

TEST_CASE("the stage list refuses the effects marker and a stage without work, naming it") {
  StageList list;
  try {
    list.add(Stage::effects());
    FAIL("the effects marker was added as a stage");
  } catch (const std::logic_error& e) {
    CHECK(std::string(e.what()).find("has no work") != std::string::npos);
  }
  try {
    list.add(Stage{"empty", nullptr});
    FAIL("a stage without work was added");
  } catch (const std::logic_error& e) {
    CHECK(std::string(e.what()).find("'empty'") != std::string::npos);
  }
  CHECK(list.stages().empty());
  CHECK(list.timings().empty());
}
