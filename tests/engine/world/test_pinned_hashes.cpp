// Pinned state hashes (Box2D v3's test_determinism with its EXPECTED_HASH): every
// solver on standard scenes, checked for 1, 2 and 3 threads against a hash fixed
// in this file. A change that moves bits on purpose updates the table in a commit
// of its own that says why; a change that should not (a refactoring, a new stage
// elsewhere) must leave it alone. The hashes are of ids, positions and velocities
// (World::stateHash) after whole frames, so they pin the substep split too.
#include <doctest/doctest.h>

#include <cinttypes>
#include <cstdio>
#include <string>

#include "sph2d/world.hpp"
#include "step/stages.hpp"
#include "test_util.hpp"

using namespace sph2d;

namespace {

struct Pinned {
  const char* scene;   ///< under assets/scenes/
  const char* solver;  ///< solver type, overriding the scene's
  int frames;          ///< frames stepped
  bool userForce;      ///< a push at frame 10 (the user_force stage)
  std::uint64_t hash;  ///< expected World::stateHash()
};

// To regenerate after a change that moves bits on purpose: run the test, copy
// the "actual" values it prints, and say why in the commit message.
const Pinned kPinned[] = {
    {"tests/small_dam_break.json", "muller2003", 30, false, 0x78602e8a04231883ULL},
    {"tests/small_dam_break.json", "wcsph", 30, false, 0x5fd7e8d5d06f17f8ULL},
    {"tests/small_dam_break.json", "pbf", 30, false, 0x528217728d8f741eULL},
    {"tests/small_dam_break.json", "dfsph", 30, false, 0xa9a801ef350459c4ULL},
    {"tests/small_dam_break.json", "game", 30, false, 0x41d2f8aa4a34bbe8ULL},
    {"tests/every_stage.json", "muller2003", 20, true, 0xeb7aeb6c84aa241eULL},
    {"tests/every_stage.json", "wcsph", 20, true, 0xd6c98e3b9b9a0d8bULL},
    {"tests/every_stage.json", "pbf", 20, true, 0xdab73aa1fec082e7ULL},
    {"tests/every_stage.json", "dfsph", 20, true, 0xb2169165f6f130d8ULL},
    {"tests/every_stage.json", "game", 20, true, 0x57917061fa5fe3beULL},
    {"validation/poiseuille.json", "wcsph", 20, false, 0x377f8c008f15fca1ULL},
    {"validation/poiseuille.json", "dfsph", 20, false, 0x44658900286c76fbULL},
    // Dynamic and kinematic bodies in the water: the game solver's bodies in its grid solve,
    // wcsph's body samples with the scene's b2World stepped every substep.
    {"tests/small_crates.json", "game", 30, false, 0xebacfe6621a9b8bcULL},
    {"tests/small_crates.json", "wcsph", 30, false, 0xd461314a380210ccULL},
    // Two materials (of one density): each particle's material in the hash, an emitter of the second.
    {"tests/two_materials.json", "muller2003", 30, false, 0x55730670a408a696ULL},
    {"tests/two_materials.json", "game", 30, false, 0x9777fab8fa2d3a8cULL},
    // Oil on water: wcsph's number density (the materials' own masses and pressures); game's and
    // pbf's projection weighed by inverse mass, game's grid by 1/ρ per face.
    {"tests/oil_on_water.json", "wcsph", 30, false, 0x0ee1e88b42abdcbeULL},
    {"tests/oil_on_water.json", "game", 30, false, 0x358e125b78d74ed8ULL},
    {"tests/oil_on_water.json", "pbf", 30, false, 0x3d7e594325c6bf94ULL},
    // A viscosity per material, syrup's past the explicit limit: the implicit step (wcsph: with the
    // floating box's velocity among its unknowns); honey with a density contrast beside water.
    {"tests/syrup_and_water.json", "game", 30, false, 0x5dde3072f760ba0dULL},
    {"tests/syrup_and_water.json", "wcsph", 30, false, 0xff8c087937298b4cULL},
    {"honey.json", "wcsph", 30, false, 0x178865a15eed3c1cULL},
    // Sand poured (granular friction after the grid projection) beside water, a jelly (elastic
    // group), a rigid blob of particles and a Box2D crate.
    {"sandbox.json", "game", 90, false, 0x8025230cc620d584ULL},
};

std::uint64_t run(const Pinned& p, int threads) {
  SceneDef s = test::scene(p.scene);
  if (s.solver.type != p.solver) {  // the solver's own parameters, and the shared keys it tunes (the game solver's)
    const SolverDef d = solverDefaults(p.solver), plain;
    s.solver.type = p.solver;
    s.solver.params = d.params;
    if (d.viscosity != plain.viscosity) s.solver.viscosity = d.viscosity;
    if (d.supportRatio != plain.supportRatio) s.solver.supportRatio = d.supportRatio;
  }
  World w(s, WorldOptions{threads});
  for (int f = 0; f < p.frames; ++f) {
    if (p.userForce && f == 10) w.setUserForces({UserForce{Vec2d(0.5, 0.4), 0.4, -30}});
    w.stepFrame();
  }
  return w.stateHash();
}

}  // namespace

TEST_CASE("pinned state hashes: every solver on the standard scenes, for 1, 2 and 3 threads") {
  for (const Pinned& p : kPinned) {
    for (int threads = 1; threads <= 3; ++threads) {
      const std::uint64_t h = run(p, threads);
      char line[160];
      std::snprintf(line, sizeof line, "%s, %s, %d frames, %d threads: actual 0x%016" PRIx64 "ULL", p.scene, p.solver,
                    p.frames, threads, h);
      INFO(line);
      if (h != p.hash) MESSAGE(line);
      CHECK(h == p.hash);
    }
  }
}

namespace {

/// The pinned rows at 2 threads with the pair loops held to one path (stages.hpp), restored
/// even when a run throws: every path must give the pinned bits.
void checkOnPath(bool baselineOnly, bool scalarOnly) {
  struct Path {
    Path(bool b, bool s) {
      setBaselineSimdOnly(b);
      setScalarPairLoops(s);
    }
    ~Path() {
      setBaselineSimdOnly(false);
      setScalarPairLoops(false);
    }
  } path(baselineOnly, scalarOnly);
  for (const Pinned& p : kPinned) {
    const std::uint64_t h = run(p, 2);
    const std::string row = std::string(p.scene) + ", " + p.solver;
    INFO(row);
    CHECK(h == p.hash);
  }
}

}  // namespace

TEST_CASE("pinned state hashes: the same on the baseline SIMD path (SSE2) as on the CPU's widest") {
  // The pair loops choose wider vectors at run time where the CPU has them (setBaselineSimdOnly).
  checkOnPath(true, false);
}

TEST_CASE("pinned state hashes: the same on the scalar pair loops as with SIMD") {
  // The scalar references of the SIMD pair loops (setScalarPairLoops: the paths a periodic
  // scene takes) add the same terms in the same order.
  checkOnPath(false, true);
}
