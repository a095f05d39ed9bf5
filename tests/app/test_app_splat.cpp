// `--splat auto|cpu|gl` end to end: a run records the path its liquid splat took in its
// manifest (render.splat), `sph2d check` renders the frames again by that path, and a value
// outside the three is a usage error naming the flag.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "app_util.hpp"

using namespace sph2d;
using namespace sph2d::apptest;
using nlohmann::json;

namespace {

const std::string kSmall = asset("scenes/tests/small_dam_break.json");  // liquid mode, 192 × 144

}  // namespace

TEST_CASE("--splat: the run's manifest names the splat's path and sph2d check renders by it") {
  for (const std::string path : {"", "gl", "cpu"}) {
    CAPTURE(path);
    const std::string dir = freshDir("splat_" + (path.empty() ? std::string("default") : path));
    const Result r = run("run " + q(kSmall) + " --frames 6 --every 5 --threads 2 --quiet --out " + q(dir) +
                         (path.empty() ? "" : " --splat " + path));
    INFO(r.out);
    REQUIRE(r.code == 0);
    const json m = json::parse(readText(dir + "/manifest.json"));
    // The default on OSMesa's llvmpipe, a software rasterizer: the CPU's sums.
    CHECK(m.at("render").at("splat").get<std::string>() == (path.empty() ? "cpu" : path));
    const std::string again = freshDir("splat_check_" + (path.empty() ? std::string("default") : path));
    const Result c = run("check " + q(kSmall) + " --against " + q(dir + "/manifest.json") + " --out " + q(again));
    INFO(c.out);
    CHECK(c.code == 0);
    CHECK(c.out.find("check: OK, 2 frames match") != std::string::npos);
  }
  const Result bad = run("run " + q(kSmall) + " --frames 1 --no-images --splat vulkan");
  CHECK(bad.code == 2);
  CHECK(bad.out.find("--splat expects auto, cpu or gl, got 'vulkan'") != std::string::npos);
}
