// Same scene, same bits: for any thread count and across runs (every solver:
// test_pinned_hashes.cpp; reordering: test_stages.cpp).
#include <doctest/doctest.h>

#include "sph2d/world.hpp"
#include "test_util.hpp"

using namespace sph2d;

TEST_CASE("the dam break's state hash after 200 substeps is identical for 1, 2 and 3 threads and for two runs") {
  const SceneDef s = test::scene("dam_break.json");
  std::uint64_t h[4] = {0, 0, 0, 0};
  const int threads[4] = {1, 2, 3, 2};
  for (int k = 0; k < 4; ++k) {
    World w(s, WorldOptions{threads[k]});
    for (int i = 0; i < 200; ++i) sph2d::bench::stepSubstep(w);
    REQUIRE(w.counters().substeps == 200);
    h[k] = w.stateHash();
  }
  CHECK(h[0] == h[1]);
  CHECK(h[0] == h[2]);
  CHECK(h[1] == h[3]);
}
