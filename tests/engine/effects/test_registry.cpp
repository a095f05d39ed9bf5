// The effect registry (engine/src/effects/registry.cpp): effects on demand: a
// scene that does not call for an effect gets neither its stage nor its fields.
#include <doctest/doctest.h>

#include <algorithm>

#include "sph2d/world.hpp"
#include "support/fixture.hpp"

using namespace sph2d;

namespace {

bool has(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

}  // namespace

TEST_CASE("a scene without surface tension has no surface-tension stage and no surface-tension field") {
  SceneDef s = test::scene("tests/resting_column.json");
  World plain(s, WorldOptions{1});
  plain.stepFrame();
  CHECK_FALSE(has(plain.stages(), "surface_tension"));
  CHECK_FALSE(has(plain.particleFields(), "surface_tension.nx"));
  CHECK(has(plain.stages(), "density"));
  s.effects.surfaceTension = true;
  World st(s, WorldOptions{1});
  st.stepFrame();
  CHECK(has(st.stages(), "surface_tension"));
  CHECK(has(st.particleFields(), "surface_tension.nx"));
  CHECK(has(st.particleFields(), "surface_tension.ny"));
}
