// Elastic groups (jelly: shape matching with a stiffness below 1, engine/src/world/groups.cpp):
// a dropped block bounces, comes to rest and springs back to its shape; a plastic one stays
// deformed; a breakable one hit by a fast body breaks apart; and a game joins, splits and
// destroys groups, in code and from a scene's `groups`.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "support/fixture.hpp"
#include "test_util.hpp"

using namespace sph2d;

namespace {

/// RMS distance of `x` from the best-fit rigid placement of `rest` (least squares: the
/// centroids matched, the rotation of Σ r q̃ᵀ), over `size`.
double shapeError(const std::vector<Vec2d>& rest, const std::vector<Vec2d>& x, double size) {
  Vec2d c0(0, 0), c(0, 0);
  for (std::size_t i = 0; i < x.size(); ++i) c0 += rest[i] / double(x.size()), c += x[i] / double(x.size());
  double a00 = 0, a01 = 0, a10 = 0, a11 = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const Vec2d r = x[i] - c, q = rest[i] - c0;
    a00 += r.x() * q.x(), a01 += r.x() * q.y(), a10 += r.y() * q.x(), a11 += r.y() * q.y();
  }
  const double th = std::atan2(a10 - a01, a00 + a11), cs = std::cos(th), sn = std::sin(th);
  double e = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const Vec2d q = rest[i] - c0, g = c + Vec2d(cs * q.x() - sn * q.y(), sn * q.x() + cs * q.y());
    e += (x[i] - g).squaredNorm();
  }
  return std::sqrt(e / double(x.size())) / size;
}

std::vector<Vec2d> positions(const World& w, const std::vector<std::uint32_t>& ids) {
  std::vector<Vec2d> xs, vs;
  w.getParticles(ids, xs, vs);
  return xs;
}

struct Drop {
  double firstImpact = -1;  ///< s: when the centre first moved up
  double rebound = 0;       ///< m/s: its fastest rise after that
  double restError = 0;     ///< shapeError at the end
  double endSpeed = 0;      ///< m/s: the centre's speed at the end
  double endX = 0;          ///< m: the centre's x at the end (it was dropped at 0.5)
};

/// A 0.2 m jelly block dropped from `height` (0: placed on the floor) in an empty tank, 4 s.
Drop dropJelly(double stiffness, double yield, double height = 0.5) {
  const double dx = 0.01;
  SceneDef s = test::tank("game", 1.0, 1.2, dx);
  World w(s, WorldOptions{2});
  GroupDef g;
  g.region = test::block({0.4, height + dx / 2}, {0.6, height + 0.2 + dx / 2});
  g.stiffness = stiffness;
  g.yieldStrain = yield;
  IdRange range;
  const std::uint32_t index = w.createGroup(g, &range);
  const std::vector<std::uint32_t> ids = range.ids();
  const std::vector<Vec2d> rest = positions(w, ids);
  Drop d;
  for (int f = 0; f < 240; ++f) {
    w.stepFrame();
    GroupState st;
    REQUIRE(w.groupState(index, st));
    if (st.velocity.y() > 0.05 && d.firstImpact < 0 && f > 5) d.firstImpact = f / 60.0;
    if (d.firstImpact >= 0) d.rebound = std::max(d.rebound, st.velocity.y());
    d.endSpeed = st.velocity.norm();
    d.endX = st.centre.x();
  }
  REQUIRE(test::allFiniteState(w));
  d.restError = shapeError(rest, positions(w, ids), 0.2);
  return d;
}

}  // namespace

TEST_CASE(
    "jelly: a dropped block bounces, comes to rest in the shape it has at rest, within 2 % of its own when stiff") {
  // Its shape at rest is the one it has placed on the floor (a jelly sags under its weight: the
  // softer, the more): the drop leaves nothing of its own.
  for (const double k : {0.25, 0.6}) {
    const Drop d = dropJelly(k, 0), placed = dropJelly(k, 0, 0);
    MESSAGE("stiffness " << k << ": first rise at " << d.firstImpact << " s, rebound " << d.rebound
                         << " m/s, shape error " << 100 * d.restError << " % (placed on the floor: "
                         << 100 * placed.restError << " %), end speed " << d.endSpeed << " m/s");
    CHECK(d.firstImpact > 0.25);  // it fell 0.5 m first (free fall: 0.32 s)
    CHECK(d.firstImpact < 0.5);
    CHECK(d.rebound > 0.2);  // it bounced
    CHECK(d.endSpeed < 0.02);
    CHECK(std::fabs(d.restError - placed.restError) < 0.01);
    if (k > 0.5) CHECK(d.restError < 0.02);
  }
}

TEST_CASE("jelly: a plastic block stays deformed where an elastic one springs back") {
  const Drop elastic = dropJelly(0.5, 0), plastic = dropJelly(0.5, 0.2), placed = dropJelly(0.5, 0.2, 0);
  MESSAGE("shape error at rest: elastic " << 100 * elastic.restError << " %, plastic " << 100 * plastic.restError
                                          << " % (placed on the floor: " << 100 * placed.restError
                                          << " %); end speed: elastic " << elastic.endSpeed << " m/s, plastic "
                                          << plastic.endSpeed << " m/s");
  CHECK(elastic.restError < 0.03);
  CHECK(elastic.endSpeed < 0.02);
  CHECK(plastic.restError > 3 * placed.restError);  // dented, where placed it only sags
  CHECK(plastic.endSpeed < 0.02);                   // and at rest
}

TEST_CASE("jelly: stiff and soft plastic blocks dropped 0.5 m stay finite and come to rest") {
  // A landing strains a stiff plastic block far past its yield within a substep; its rest shape
  // flows at most half a spacing a substep (groups.cpp), so its places neither cross nor meet.
  // Before, stiffness 0.9 and 0.97 blew up in the grid projection and a dented block crept along
  // the floor faster and faster (docs/notes/plastic-jelly-creep.md).
  for (const double k : {0.6, 0.9, 0.97})
    for (const double yield : {0.05, 0.2}) {
      const Drop d = dropJelly(k, yield);
      MESSAGE("stiffness " << k << ", yield strain " << yield << ": shape error " << 100 * d.restError
                           << " %, end speed " << d.endSpeed << " m/s, centre " << d.endX - 0.5
                           << " m from where it fell");
      CHECK(d.endSpeed < 0.05);  // the stiffest still rocks a little at 4 s (0.04 m/s, gone by 5 s)
      // Where it landed: it does not creep away. The stiffest ones are chaotic (0.97 with yield
      // 0.2 has drifted 0.066 m while it rocked, 0.011 m, and 0.116 m once the grid kept the
      // falling block's momentum; docs/notes/plastic-jelly-creep.md): reported, not checked.
      if (k < 0.95) CHECK(std::fabs(d.endX - 0.5) < 0.03);
      CHECK(d.restError < 0.2);
      if (yield < 0.1) CHECK(d.restError > 0.06);  // dented: elastic blocks end within 4.5 %
    }
}

TEST_CASE("jelly: a breakable column hit by a fast body breaks in two, an unbreakable one does not") {
  for (const double strain : {0.0, 0.3}) {
    const double dx = 0.01;
    SceneDef s = test::tank("game", 2.0, 1.0, dx);
    BodyDef ball;
    ball.type = BodyDef::Type::Dynamic;
    ball.position = Vec2d(0.3, 0.2);
    ball.velocity = Vec2d(8, 0);
    ShapeDef disc;
    disc.type = ShapeDef::Type::Circle;
    disc.radius = 0.08;
    disc.density = 3000;
    ball.fixtures.push_back(disc);
    s.bodies.push_back(ball);
    World w(s, WorldOptions{2});
    GroupDef g;
    g.region = test::block({0.9, 0}, {0.96, 0.4});  // 6 × 40 particles, struck at mid-height
    g.stiffness = 0.5;
    g.breakStrain = strain;
    w.createGroup(g);
    for (int f = 0; f < 120; ++f) w.stepFrame();
    REQUIRE(test::allFiniteState(w));
    std::vector<std::size_t> sizes;
    for (std::uint32_t k = 0; k < w.groupCount(); ++k) {
      GroupState st;
      if (w.groupState(k, st)) sizes.push_back(st.particles);
    }
    std::sort(sizes.rbegin(), sizes.rend());
    MESSAGE("break strain " << strain << ": " << sizes.size() << " groups, the largest "
                            << (sizes.size() > 0 ? sizes[0] : 0) << " and " << (sizes.size() > 1 ? sizes[1] : 0)
                            << " particles (of " << w.particleCount() << ")");
    if (strain > 0) {
      REQUIRE(sizes.size() >= 2);
      CHECK(sizes[1] >= 20);  // two pieces, not a chip
    } else {
      REQUIRE(sizes.size() == 1);
      CHECK(sizes[0] == w.particleCount());
    }
  }
}

TEST_CASE("jelly: a game joins, splits and destroys groups") {
  const double dx = 0.02;
  SceneDef s = test::tank("game", 2.0, 1.0, dx);
  s.gravity = Vec2d(0, 0);
  World w(s, WorldOptions{1});
  GroupDef a;
  a.region = test::block({0.2, 0.2}, {0.4, 0.4});
  a.stiffness = 0.5;
  GroupDef b = a;
  b.region = test::block({0.4, 0.2}, {0.6, 0.4});  // a's neighbour: one spacing apart
  GroupDef c = a;
  c.region = test::block({1.2, 0.2}, {1.4, 0.4});
  IdRange ra, rb, rc;
  const std::uint32_t ga = w.createGroup(a, &ra), gb = w.createGroup(b, &rb), gc = w.createGroup(c, &rc);
  CHECK(w.groupCount() == 3);
  // Join: b's particles are a's now, a's stiffness; b is empty.
  CHECK(w.joinGroups(ga, gb));
  GroupState st;
  CHECK_FALSE(w.groupState(gb, st));
  REQUIRE(w.groupState(ga, st));
  CHECK(st.particles == ra.size() + rb.size());
  CHECK_FALSE(w.joinGroups(ga, gb));  // b has none left
  // Join a far group, then split: the two parts come apart again (the larger keeps the index).
  CHECK(w.joinGroups(ga, gc));
  const std::vector<std::uint32_t> made = w.splitGroup(ga);
  REQUIRE(made.size() == 1);
  REQUIRE(w.groupState(ga, st));
  CHECK(st.particles == ra.size() + rb.size());
  REQUIRE(w.groupState(made[0], st));
  CHECK(st.particles == rc.size());
  // Destroy: without its particles the fluid keeps them, with them the listener hears of each.
  const std::size_t before = w.particleCount();
  CHECK(w.destroyGroup(made[0]));
  CHECK(w.particleCount() == before);
  CHECK_FALSE(w.groupState(made[0], st));
  std::vector<Removal> heard;
  w.setDestructionListener([&](const std::vector<Removal>& r) { heard.insert(heard.end(), r.begin(), r.end()); });
  CHECK(w.destroyGroup(ga, true));
  CHECK(w.particleCount() == before - ra.size() - rb.size());
  CHECK(heard.size() == ra.size() + rb.size());
  CHECK(std::all_of(heard.begin(), heard.end(), [](const Removal& r) { return r.reason == RemovalReason::game; }));
  CHECK_FALSE(w.destroyGroup(ga, true));
}

TEST_CASE("jelly: splitting a large group finds its parts, a ring's in one piece") {
  // A group of about 25,000 particles: two blocks joined, then split (each pair within 1.5
  // spacings is asked only through a grid of cells: the old all-pairs search asked 3e8), and a
  // ring of 2,000, whose particles link all the way round, stays whole.
  const double dx = 0.01;
  SceneDef s = test::tank("game", 4.0, 2.0, dx);
  s.gravity = Vec2d(0, 0);
  World w(s, WorldOptions{2});
  GroupDef a;
  a.region = test::block({0.2, 0.2}, {1.2, 1.4});
  a.stiffness = 0.5;
  GroupDef b = a;
  b.region = test::block({1.4, 0.2}, {2.4, 1.4});
  IdRange ra, rb;
  const std::uint32_t ga = w.createGroup(a, &ra), gb = w.createGroup(b, &rb);
  REQUIRE(w.joinGroups(ga, gb));
  const std::vector<std::uint32_t> made = w.splitGroup(ga);
  REQUIRE(made.size() == 1);
  GroupState st;
  REQUIRE(w.groupState(ga, st));
  CHECK(st.particles == std::max(ra.size(), rb.size()));
  REQUIRE(w.groupState(made[0], st));
  CHECK(st.particles == std::min(ra.size(), rb.size()));
  CHECK(ra.size() + rb.size() > 20000);
  GroupDef ring;
  ring.region.shape = FluidBlockDef::Shape::Circle;
  ring.region.center = Vec2d(3.2, 1.0);
  ring.region.radius = 0.4;
  ring.region.min = ring.region.center - Vec2d(0.4, 0.4);
  ring.region.max = ring.region.center + Vec2d(0.4, 0.4);
  const std::uint32_t gr = w.createGroup(ring);
  std::vector<std::uint32_t> inner;  // the disc's middle taken out: a ring 0.1 m thick
  for (std::size_t i = 0; i < w.particleCount(); ++i)
    if (w.particles().group[i] == gr + 1 && (w.worldPosition(i) - ring.region.center).norm() < 0.3)
      inner.push_back(w.particles().id[i]);
  w.removeParticles(inner);
  CHECK(w.splitGroup(gr).empty());
}

TEST_CASE("jelly: a scene's groups make rigid and elastic groups, and bad keys are refused at their key") {
  const auto scene = [](const std::string& groups) {
    return "{\"solver\": {\"type\": \"game\", \"spacing\": 0.02},\n\"boundaries\": [{\"fixtures\": [{\"shape\": "
           "\"box\", \"center\": [1, -0.1], \"half_size\": [1.2, 0.1]}]}],\n\"groups\": [\n" +
           groups + "]}";
  };
  World w(parseScene(scene("{\"min\": [0.2, 0.2], \"max\": [0.4, 0.4]},\n{\"min\": [1, 0.2], \"max\": [1.2, 0.4], "
                           "\"kind\": \"elastic\", \"stiffness\": 0.3, \"yield_strain\": 0.1, \"break_strain\": 0.25}"),
                     "t.json"));
  CHECK(w.groupCount() == 2);
  GroupState st;
  REQUIRE(w.groupState(0, st));
  CHECK(st.particles == 100);
  REQUIRE(w.groupState(1, st));
  CHECK(st.particles == 100);
  auto refused = [&](const std::string& groups, const std::string& key, const std::string& why) {
    try {
      parseScene(scene(groups), "t.json");
      FAIL("accepted " << groups);
    } catch (const SceneError& e) {
      CHECK(e.key == key);
      CHECK(e.line == 4);
      CHECK(e.message.find(why) != std::string::npos);
    }
  };
  refused("{\"min\": [0.2, 0.2], \"max\": [0.4, 0.4], \"stiffness\": 0.5}", "groups[0].stiffness", "elastic");
  refused("{\"min\": [0.2, 0.2], \"max\": [0.4, 0.4], \"kind\": \"elastic\", \"stiffness\": 1}", "groups[0].stiffness",
          "below 1");
  refused("{\"min\": [0.2, 0.2], \"max\": [0.4, 0.4], \"kind\": \"soft\"}", "groups[0].kind", "elastic");
  refused("{\"min\": [0.2, 0.2], \"max\": [0.4, 0.4], \"break_strain\": 0.2}", "groups[0].break_strain", "elastic");
  try {  // beyond what the game solver's neighbour lists see: refused when the World makes it
    World big(parseScene(
        scene("{\"min\": [0.2, 0.2], \"max\": [0.4, 0.4], \"kind\": \"elastic\", \"break_strain\": 0.5}"), "t.json"));
    FAIL("accepted a break strain of 0.5");
  } catch (const SceneError& e) {
    CHECK(e.key == "groups[0]");
    CHECK(e.message.find("at most 0.333") != std::string::npos);
  }
  refused("{\"min\": [0.2, 0.2], \"max\": [0.4, 0.4], \"colour\": 1}", "groups[0].colour", "");
  refused("{\"min\": [0.2, 0.2], \"max\": [0.4, 0.4], \"color\": [1, 0.5, 2]}", "groups[0].color", "0..1");
  // A colour of its own: the group's particles carry it (the particles' colour field), the
  // others none; a group's index is in particles().group.
  World c(parseScene(scene("{\"min\": [0.2, 0.2], \"max\": [0.4, 0.4], \"color\": [1, 0.5, 0]}"), "t.json"));
  const Particles& P = c.particles();
  REQUIRE(P.color.size() == P.size());
  REQUIRE(P.group.size() == P.size());
  std::size_t red = 0, grouped = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    red += P.color[i] == 0xFF8000u;
    grouped += P.group[i] == 1;
    CHECK((P.color[i] == 0xFF8000u) == (P.group[i] == 1));
  }
  CHECK(red == 100);
  CHECK(grouped == 100);
}

namespace {

/// The zero-gravity collision of the momentum test: a block of water at 1 m/s in a closed 4 m
/// box runs into a rigid group, a jelly and a dynamic box at rest (each when asked), all in the
/// box's middle (no wall is reached within the 1.2 s). The largest change of the total
/// momentum (the particles' and the box's) over its start, and the speeds each partner reached.
struct MomentumRun {
  double worst = 0, rigid = 0, jelly = 0, box = 0;
};

MomentumRun momentumRun(const char* solver, bool withRigid, bool withJelly, bool withBox) {
  SceneDef s;
  s.solver = solverDefaults(solver);
  s.solver.spacing = 0.02;
  if (std::string(solver) == "wcsph") s.solver.params["expected_speed"] = 2;  // wcsph's alone
  s.gravity = Vec2d(0, 0);
  s.bodies.push_back(test::arena());
  MaterialDef water;
  water.name = "water";
  water.density = s.solver.restDensity;
  s.materials = {water};
  s.blocks = {test::block({0.8, 1.8}, {1.2, 2.2}, Vec2d(1, 0))};
  if (withBox) {
    BodyDef box;
    box.type = BodyDef::Type::Dynamic;
    box.position = Vec2d(2.2, 2.0);
    ShapeDef shape = test::boxShape({0, 0}, {0.1, 0.1});
    shape.density = 1000;
    shape.friction = 0;
    box.fixtures.push_back(shape);
    s.bodies.push_back(box);
  }
  World w(s, WorldOptions{2});
  int rigidIndex = -1, jellyIndex = -1, groups = 0;
  if (withRigid) {
    GroupDef rigid;
    rigid.region = test::block({1.3, 1.85}, {1.5, 2.05});
    w.createGroup(rigid);
    rigidIndex = groups++;
  }
  if (withJelly) {
    GroupDef jelly;
    jelly.region = test::block({1.6, 1.95}, {1.9, 2.2});
    jelly.stiffness = 0.5;
    w.createGroup(jelly);
    jellyIndex = groups++;
  }
  const b2Body* body = withBox ? test::dynamicBody(w) : nullptr;
  auto momentum = [&]() {
    Vec2d p = test::momentum(w);
    if (body) p += Vec2d(body->GetLinearVelocity().x, body->GetLinearVelocity().y) * double(body->GetMass());
    return p;
  };
  const Vec2d p0 = momentum();
  MomentumRun run;
  for (int f = 0; f < 72; ++f) {
    w.stepFrame();
    run.worst = std::max(run.worst, (momentum() - p0).norm() / p0.norm());
    if (body) run.box = std::max(run.box, double(body->GetLinearVelocity().Length()));
  }
  REQUIRE(test::allFiniteState(w));
  GroupState g;
  if (rigidIndex >= 0 && w.groupState(std::size_t(rigidIndex), g)) run.rigid = g.velocity.x();
  if (jellyIndex >= 0 && w.groupState(std::size_t(jellyIndex), g)) run.jelly = g.velocity.x();
  const std::string what =
      std::string(solver) + (withRigid ? " rigid" : "") + (withJelly ? " jelly" : "") + (withBox ? " box" : "");
  MESSAGE(what << ": worst change of momentum " << 100 * run.worst << " %; rigid group at " << run.rigid
               << " m/s, jelly " << run.jelly << ", box up to " << run.box);
  return run;
}

}  // namespace

TEST_CASE("groups: momentum of water, a rigid and an elastic group and a Box2D body holds in zero gravity") {
  // Momentum is exchanged between them and their sum holds, all together and with each partner
  // alone (a gain at one collision cannot hide behind a loss at another). wcsph has no position
  // corrections: within 1 %. The game solver's grid transfer through faces the meeting blobs
  // fill in part gained or lost momentum (5.4 % with the rigid group, 4.3 % with the box, 7.2 %
  // all together) until a region no wall holds kept its momentum with the bodies it touches
  // (grid_conserve): measured 0.001 %, 0.0007 % and 0.92 %; what is left is the jelly's (1.02 %
  // alone), which takes its own position corrections into its velocity. A jelly once took the
  // moves of its pairs with the water into its velocity, the water not: it gained 20.4 %. The
  // box gained 6.0 % while the particles' momentum counted the density sums' mass (0.79 ρ0·dx²
  // at the game preset's support) and the grid pushed the box with ρ0κ
  // (docs/notes/free-blob-momentum.md).
  struct Bounds {
    const char* solver;
    double all, rigid, jelly, box;
  };
  for (const Bounds& b : {Bounds{"wcsph", 0.01, 0.01, 0.01, 0.01}, Bounds{"game", 0.02, 0.001, 0.02, 0.001}}) {
    CAPTURE(b.solver);
    const MomentumRun all = momentumRun(b.solver, true, true, true);
    CHECK(all.rigid > 0.1);  // each was pushed
    CHECK(all.jelly > 0.1);
    CHECK(all.box > 0.05);  // the box meets the water last, after the groups: 0.08-0.13 m/s
    CHECK(all.worst < b.all);
    const MomentumRun rigid = momentumRun(b.solver, true, false, false),
                      jelly = momentumRun(b.solver, false, true, false),
                      box = momentumRun(b.solver, false, false, true);
    CHECK(rigid.rigid > 0.1);
    CHECK(jelly.jelly > 0.1);
    CHECK(box.box > 0.1);
    CHECK(rigid.worst < b.rigid);
    CHECK(jelly.worst < b.jelly);
    CHECK(box.worst < b.box);
  }
}
