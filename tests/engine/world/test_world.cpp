// The World's construction and public API (engine/src/world/world.cpp): the particle
// mass, the local frame, what a scene is refused for, the effect switches, and the
// stop flag (a long step or set-up ended on request, with no bit changed otherwise).
#include <doctest/doctest.h>

#include <box2d/box2d.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>

#include "sph2d/world.hpp"
#include "support/fixture.hpp"

using namespace sph2d;

TEST_CASE("the particle mass makes a full square lattice exactly rho0 under each solver's own density kernel") {
  // A fully periodic box filled by one block at rest: every particle has a full
  // lattice neighbourhood, so its summation density is the lattice sum the mass
  // was chosen for (poly6 for muller2003, spiky for pbf, Wendland C2 for wcsph and
  // dfsph; the masses differ from ρ0 dx² by the kernels' lattice errors: pbf's by 12 %).
  for (const std::string& solver : test::solvers()) {
    for (double dx : {0.04, 0.05}) {
      CAPTURE(solver);
      CAPTURE(dx);
      SceneDef s = test::periodicShearLayer(solver, 0, dx);
      s.blocks = {test::block({0, 0}, {1, 1})};
      World w(s, WorldOptions{1});
      double lo = 1e300, hi = 0;
      for (std::size_t i = 0; i < w.particleCount(); ++i) {
        lo = std::min(lo, double(w.particles().rho[i]));
        hi = std::max(hi, double(w.particles().rho[i]));
      }
      MESSAGE(solver << " at dx = " << dx << ": density from " << lo << " to " << hi << " kg/m³, mass "
                     << w.particleMass());
      CHECK(lo == doctest::Approx(1000.0).epsilon(1e-5));
      CHECK(hi == doctest::Approx(1000.0).epsilon(1e-5));
    }
  }
}

TEST_CASE("a scene 10 km from the origin runs in a local frame: the origin a multiple of 64 m near its centre") {
  SceneDef s = test::tank("wcsph", 1, 1, 0.05);
  s.blocks.push_back(test::block({0, 0}, {0.5, 0.5}));
  const Vec2d shift(10000.0, -3000.0);
  SceneDef far = s;
  for (auto& b : far.bodies) b.position += shift;
  for (auto& b : far.blocks) {
    b.min += shift;
    b.max += shift;
  }
  World near(s, WorldOptions{1}), away(far, WorldOptions{1});
  const Vec2d o = away.origin();
  CHECK(std::fmod(o.x(), 64.0) == 0);
  CHECK(std::fmod(o.y(), 64.0) == 0);
  CHECK((o - (shift + Vec2d(0.25, 0.25))).cwiseAbs().maxCoeff() <= 32);  // the scene's centre, rounded
  CHECK(near.origin() == Vec2d(0, 0));
  // The same particles, each within float rounding of the local frame's small numbers.
  REQUIRE(away.particleCount() == near.particleCount());
  double worst = 0;
  for (std::size_t i = 0; i < near.particleCount(); ++i) {
    const Vec2d local = Vec2d(away.particles().x[i].x(), away.particles().x[i].y());
    CHECK(local.norm() < 100);  // stored small, not as 10 km in a float
    worst = std::max(worst, (away.worldPosition(i) - shift - near.worldPosition(i)).norm());
  }
  MESSAGE("largest difference of a particle's position from the scene at the origin: " << worst << " m");
  CHECK(worst < 1e-5);
}

TEST_CASE("a periodic axis shorter than 3 support radii is refused, naming the axis and the length it needs") {
  SceneDef s = test::scene("validation/taylor_green.json");
  s.periodic.max.x() = s.periodic.min.x() + 2.9 * s.solver.supportRatio * s.solver.spacing;
  s.blocks = {test::block({0, 0}, {0.05, 1})};
  try {
    World w(s, WorldOptions{1});
    FAIL("a period of 2.9 support radii was accepted");
  } catch (const SceneError& e) {
    CHECK(e.key == "periodic.x");
    CHECK(e.message.find("at least 3 support radii") != std::string::npos);
  }
}

TEST_CASE("setEffectEnabled switches a scene's effect and refuses one the scene does not have, naming its effects") {
  SceneDef s = test::scene("tests/resting_column.json");  // viscosity
  s.effects.xsph = true;
  World w(s, WorldOptions{1});
  CHECK(w.effects() == std::vector<std::string>{"viscosity", "xsph"});
  try {
    w.setEffectEnabled("surface_tension", true);
    FAIL("an effect the scene does not have was switched on");
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    CHECK(what.find("surface_tension") != std::string::npos);
    CHECK(what.find("viscosity") != std::string::npos);
    CHECK(what.find("xsph") != std::string::npos);
  }
  w.setEffectEnabled("viscosity", false);
  const auto st = w.stages();
  CHECK(std::find(st.begin(), st.end(), "viscosity") == st.end());
  CHECK(std::find(st.begin(), st.end(), "xsph") != st.end());
}

TEST_CASE("a World in a game's b2World ignores the scene's own bodies and says so") {
  b2World game(b2Vec2(0, -9.81f));
  SceneDef s = test::tank("wcsph", 1, 1, 0.05);  // four bodies' worth of walls, ignored
  s.blocks.push_back(test::block({0.2, 0.2}, {0.4, 0.4}));
  World w(s, game, WorldOptions{1});
  const auto warnings = w.takeWarnings();
  REQUIRE(warnings.size() == 1);
  CHECK(warnings[0].find("1 boundary bodies are ignored") != std::string::npos);
  CHECK(w.colliders().empty());
  CHECK(&w.box2d() == &game);
}

// --- the stop flag (WorldOptions::stop, World::setStopFlag) ----------------------

namespace {

/// The small dam break with a row of `n` particles 1 km below it, `n` × 4 cm long: the neighbour
/// grid over that span cannot keep cells of the support radius, so its frames are slow (200,000
/// particles: 18 substeps of 0.15 s on 2 threads here; the shape, a million particles smaller,
/// of the block from the network that froze `sph2d serve`).
std::unique_ptr<World> spreadWorld(std::size_t n, const std::atomic<bool>* stop, int threads) {
  const SceneDef s = test::scene("tests/small_dam_break.json");
  auto w = std::make_unique<World>(s, WorldOptions{threads, stop});
  FluidBlockDef row;
  row.min = Vec2d(-0.02 * double(n), -1000);
  row.max = Vec2d(0.02 * double(n), -1000 + 0.05);
  w->addBlock(row);
  return w;
}

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace

TEST_CASE("the stop flag ends a long step within 0.3 s, naming the stage, and the World then refuses to step") {
  // Before: nothing could end World::step early. A frame of this World takes about 6 s here;
  // the flag, set 0.5 s into it from another thread, must end it at the next block of work.
  for (int threads : {1, 2}) {
    CAPTURE(threads);
    std::atomic<bool> stop{false};
    auto w = spreadWorld(400000, &stop, threads);
    REQUIRE(w->particleCount() > 400000);
    Clock::time_point setAt;
    std::thread setter([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
      setAt = Clock::now();
      stop.store(true);
    });
    std::string stage, what;
    const auto t0 = Clock::now();
    try {
      w->stepFrame();
    } catch (const Interrupted& e) {
      stage = e.stage;
      what = e.what();
    }
    const double total = since(t0);
    setter.join();
    const double afterFlag = std::chrono::duration<double>(Clock::now() - setAt).count();
    MESSAGE(threads << " thread(s): the step ran " << total << " s and ended " << 1e3 * afterFlag
                    << " ms after the flag, in stage '" << stage << "'");
    REQUIRE_MESSAGE(!stage.empty(), "the step ended without Interrupted (it was not long enough to test)");
    CHECK(total >= 0.5);
    CHECK(afterFlag < 0.3);
    CHECK(what.find("stopped by the stop flag in stage '" + stage + "'") != std::string::npos);
    CHECK(w->interrupted());
    CHECK(w->frame() == 0);
    // Abandoned: every array still one length, and a later step is refused even with the flag down.
    CHECK(w->particles().x.size() == w->particleCount());
    CHECK(w->particles().id.size() == w->particleCount());
    stop.store(false);
    std::string again;
    try {
      w->stepFrame();
    } catch (const Interrupted& e) {
      again = e.what();
    }
    CHECK(again.find("was interrupted in stage '" + stage + "' and does not step again") != std::string::npos);
  }
}

TEST_CASE("a stop flag that is never set changes no bit: the pinned state hash of the small dam break") {
  // tests/engine/test_pinned_hashes.cpp pins muller2003 on the small dam break after 30 frames.
  for (int threads : {1, 2, 3}) {
    CAPTURE(threads);
    std::atomic<bool> stop{false};
    World w(test::scene("tests/small_dam_break.json"), WorldOptions{threads, &stop});
    for (int f = 0; f < 30; ++f) w.stepFrame();
    CHECK(w.stateHash() == 0x78602e8a04231883ULL);
    CHECK(!w.interrupted());
  }
}

TEST_CASE("a stop flag set before a step or an addBlock changes nothing: the World steps on to the same hash") {
  const SceneDef s = test::scene("tests/small_dam_break.json");
  std::atomic<bool> stop{false};
  World w(s, WorldOptions{2, &stop});
  World ref(s, WorldOptions{2});
  for (int f = 0; f < 5; ++f) {
    w.stepFrame();
    ref.stepFrame();
  }
  stop.store(true);
  const std::size_t n = w.particleCount();
  std::string stage;
  try {
    w.stepFrame();
  } catch (const Interrupted& e) {
    stage = e.stage;
  }
  CHECK(stage == "step");
  CHECK(!w.interrupted());
  // A block of a million lattice points: the flag is read before its first row and every 4096 points.
  FluidBlockDef big;
  big.min = Vec2d(0.5, 2.0);
  big.max = Vec2d(40.5, 3.0);
  std::string what;
  try {
    w.addBlock(big);
  } catch (const Interrupted& e) {
    stage = e.stage;
    what = e.what();
  }
  CHECK(stage == "addBlock");
  CHECK(what.find("nothing was added") != std::string::npos);
  CHECK(w.particleCount() == n);
  stop.store(false);
  for (int f = 0; f < 5; ++f) {
    w.stepFrame();
    ref.stepFrame();
  }
  CHECK(w.stateHash() == ref.stateHash());
}

TEST_CASE("a World built with its stop flag set throws Interrupted naming the construction phase") {
  std::atomic<bool> stop{true};
  std::string stage;
  try {
    World w(test::scene("tests/small_dam_break.json"), WorldOptions{1, &stop});
  } catch (const Interrupted& e) {
    stage = e.stage;
  }
  CHECK(stage.rfind("construction: ", 0) == 0);
}

TEST_CASE("an interrupted World steps again after load(): to the same hash as the World it was saved from") {
  const SceneDef s = test::scene("tests/small_dam_break.json");
  World ref(s, WorldOptions{2});
  for (int f = 0; f < 3; ++f) ref.stepFrame();
  std::stringstream saved;
  ref.save(saved);
  std::atomic<bool> stop{false};
  // Frames until the flag, set 50 ms in, lands in one (a single frame once finished inside the
  // wait on a fast hour, and did not throw).
  auto w = spreadWorld(100000, &stop, 2);
  std::thread setter([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    stop.store(true);
  });
  bool thrown = false;
  for (int f = 0; f < 10000 && !thrown; ++f) {
    try {
      w->stepFrame();
    } catch (const Interrupted&) {
      thrown = true;
    }
  }
  CHECK(thrown);
  setter.join();
  REQUIRE(w->interrupted());
  stop.store(false);
  w->load(saved);
  CHECK(!w->interrupted());
  for (int f = 0; f < 3; ++f) {
    w->stepFrame();
    ref.stepFrame();
  }
  CHECK(w->stateHash() == ref.stateHash());
}

TEST_CASE(
    "every setter has a getter: gravity, user forces, an emitter's and an effect's switch read back what was set, and steer the step") {
  SceneDef s = test::scene("tests/resting_column.json");  // muller2003 with viscosity
  EmitterDef e;
  e.position = Vec2d(0.1, 0.9);
  e.direction = Vec2d(0, -1);
  e.rate = 200;
  e.speed = 1.0;
  s.effects.emitters.push_back(e);
  World w(s, WorldOptions{1});
  CHECK(w.gravity() == s.gravity);
  CHECK(w.userForces().empty());
  CHECK(w.emitterEnabled(0));
  CHECK(w.effectEnabled("viscosity"));

  w.setGravity(Vec2d(1.5, -4.0));
  CHECK(w.gravity() == Vec2d(1.5, -4.0));
  w.setUserForces({UserForce{Vec2d(0.2, 0.2), 0.3, 5.0}});
  REQUIRE(w.userForces().size() == 1);
  CHECK(w.userForces()[0].strength == 5.0);
  CHECK(w.effectEnabled("user_force"));
  w.setEmitterEnabled(0, false);
  CHECK_FALSE(w.emitterEnabled(0));
  w.setEffectEnabled("viscosity", false);
  CHECK_FALSE(w.effectEnabled("viscosity"));

  // What the getters report is what the step does: a disabled emitter emits nothing and a
  // disabled effect has no stage.
  const std::uint64_t before = w.emittedCount(0);
  for (int f = 0; f < 10; ++f) w.stepFrame();
  CHECK(w.emittedCount(0) == before);
  w.setEmitterEnabled(0, true);  // the same emitter, switched back on, emits (rate 200/s)
  CHECK(w.emitterEnabled(0));
  for (int f = 0; f < 10; ++f) w.stepFrame();
  CHECK(w.emittedCount(0) > before + 20);
  for (const std::string& st : w.stages()) CHECK(st.find("viscosity") == std::string::npos);

  CHECK_THROWS_AS(w.emitterEnabled(1), std::out_of_range);
  CHECK_THROWS_WITH_AS(w.effectEnabled("foam"), doctest::Contains("its effects: viscosity"), std::invalid_argument);
}
