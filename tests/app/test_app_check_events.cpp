// `sph2d check` reruns a run through the same game loop, applying the events its
// manifest lists at their frames: a run driven by events checks OK, its record
// replays to the same hashes, and a manifest whose events were changed, dropped or
// moved fails at the first frame the change reaches, with the state differing.
#include <doctest/doctest.h>

#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app_util.hpp"

using namespace sph2d;
using namespace sph2d::apptest;
using nlohmann::json;

namespace {

const std::string kSmall = asset("scenes/tests/small_dam_break.json");

json readManifest(const std::string& dir) { return json::parse(readText(dir + "/manifest.json")); }

std::vector<std::string> column(const json& m, const char* key) {
  std::vector<std::string> h;
  for (const auto& f : m.at("frames")) h.push_back(f.at(key).get<std::string>());
  return h;
}

/// Writes `m` as DIR/manifest.json (beside the run's PNGs, which check reads on a difference).
void writeManifest(const std::string& dir, const json& m) { std::ofstream(dir + "/manifest.json") << m.dump(1); }

/// A run of the small dam break driven by an events file: a drop at 4, a gravity change at 6
/// (acts on the state from frame 7 on), a force at 9 released at 12, a pause nothing can end at 10.
struct EventRun {
  std::string dir, record;
  json manifest;
};

EventRun eventRun(const std::string& name, const std::string& extra = "") {
  EventRun r;
  r.dir = freshDir(name);
  r.record = r.dir + "/run.jsonl";
  const std::string events = r.dir + "/events.jsonl";
  std::ofstream(events)
      << "{\"frame\": 4, \"type\": \"drop\", \"center\": [2, 2.5], \"radius\": 0.15}\n"
      << "{\"frame\": 6, \"type\": \"gravity\", \"gravity\": [3, -9.5]}\n"
      << "{\"frame\": 9, \"type\": \"force\", \"point\": [1, 0.4], \"radius\": 0.4, \"strength\": -40}\n"
      << "{\"frame\": 10, \"type\": \"pause\"}\n"
      << "{\"frame\": 12, \"type\": \"release\"}\n";
  const Result run1 = run("run " + q(kSmall) + " --frames 16 --threads 2 --quiet --input " + q(events) + " --record " +
                          q(r.record) + " --out " + q(r.dir) + extra);
  INFO(run1.out);
  REQUIRE(run1.code == 0);
  CHECK(run1.out.find("5 events applied, 1 warning") != std::string::npos);  // the pause: nothing can resume it
  r.manifest = readManifest(r.dir);
  return r;
}

Result check(const std::string& manifestDir, const std::string& scene = kSmall) {
  return run("check " + q(scene) + " --against " + q(manifestDir + "/manifest.json") + " --threads 1 --out " +
             q(manifestDir + "/check"));
}

}  // namespace

TEST_CASE("check of a run driven by an events file matches, and so does the replay of its record") {
  const EventRun r = eventRun("check_events");
  REQUIRE(r.manifest.at("events").size() == 5);
  Result c = check(r.dir);
  INFO(c.out);
  CHECK(c.code == 0);
  CHECK(c.out.find("OK, 16 frames match") != std::string::npos);

  // The events change the run: without them the state differs from frame 4 (the drop) on.
  const std::string plain = freshDir("check_events_plain");
  REQUIRE(run("run " + q(kSmall) + " --frames 16 --threads 2 --quiet --out " + q(plain)).code == 0);
  const auto withEvents = column(r.manifest, "state_hash"), without = column(readManifest(plain), "state_hash");
  REQUIRE(withEvents.size() == 16);
  for (int f = 0; f < 16; ++f) {
    CAPTURE(f);
    if (f < 4)
      CHECK(withEvents[f] == without[f]);
    else
      CHECK(withEvents[f] != without[f]);
  }

  // Replaying the record (another thread count) gives the same frames, states and events.
  const std::string replay = freshDir("check_events_replay");
  const Result b =
      run("run " + q(kSmall) + " --frames 16 --threads 1 --quiet --input " + q(r.record) + " --out " + q(replay));
  INFO(b.out);
  REQUIRE(b.code == 0);
  const json mb = readManifest(replay);
  CHECK(column(mb, "state_hash") == withEvents);
  CHECK(column(mb, "rgba_xxh64") == column(r.manifest, "rgba_xxh64"));
  CHECK(mb.at("events") == r.manifest.at("events"));
}

TEST_CASE("check of a manifest whose events were changed, dropped or moved fails where the change first acts") {
  const EventRun r = eventRun("check_changed");
  const json original = r.manifest;
  auto eventIndex = [&](const char* type) {
    for (std::size_t k = 0; k < original.at("events").size(); ++k)
      if (original["events"][k].at("type") == type) return k;
    FAIL("no event of type " << type);
    return std::size_t(0);
  };

  // A drop of another size: the drop is part of the frame it is applied at (4).
  json m = original;
  m["events"][eventIndex("drop")]["radius"] = 0.12;
  writeManifest(r.dir, m);
  Result c = check(r.dir);
  INFO(c.out);
  CHECK(c.code == 1);
  CHECK(c.out.find("check: frame 4 differs") != std::string::npos);
  CHECK(c.out.find("state hash differs too") != std::string::npos);
  CHECK(c.out.find("FAILED at frame 4 (4 frames matched before it)") != std::string::npos);

  // Without the gravity change of frame 6: it is applied before frame 6 is rendered but acts
  // on the state only from the step to 7, so frame 6 has the manifest's state and other
  // pixels (the liquid's default foam speed follows gravity).
  m = original;
  m["events"].erase(eventIndex("gravity"));
  writeManifest(r.dir, m);
  c = check(r.dir);
  INFO(c.out);
  CHECK(c.code == 1);
  CHECK(c.out.find("check: frame 6 differs") != std::string::npos);
  CHECK(c.out.find("state hash matches") != std::string::npos);
  CHECK(c.out.find("FAILED at frame 6 (6 frames matched before it)") != std::string::npos);

  // The force one frame late (10 instead of 9): frame 10 is the first it did not push.
  m = original;
  m["events"][eventIndex("force")]["frame"] = 10;
  writeManifest(r.dir, m);
  c = check(r.dir);
  INFO(c.out);
  CHECK(c.code == 1);
  CHECK(c.out.find("check: frame 10 differs") != std::string::npos);
  CHECK(c.out.find("state hash differs too") != std::string::npos);

  // The release two frames early (10 instead of 12): the force acted one step less.
  m = original;
  m["events"][eventIndex("release")]["frame"] = 10;
  writeManifest(r.dir, m);
  c = check(r.dir);
  INFO(c.out);
  CHECK(c.code == 1);
  CHECK(c.out.find("check: frame 11 differs") != std::string::npos);
  CHECK(c.out.find("state hash differs too") != std::string::npos);

  // An event that cannot be applied is a note, changes nothing, and the frames match.
  m = original;
  m["events"].insert(m["events"].begin(),
                     json{{"frame", 2}, {"type", "effect"}, {"name", "user_force"}, {"enabled", false}});
  writeManifest(r.dir, m);
  c = check(r.dir);
  INFO(c.out);
  CHECK(c.code == 0);
  CHECK(c.out.find("note: frame 2: effect user_force off not applied: ") != std::string::npos);
  CHECK(c.out.find("OK, 16 frames match") != std::string::npos);

  // The original manifest still checks.
  writeManifest(r.dir, original);
  CHECK(check(r.dir).code == 0);
}

TEST_CASE("check of a real-time run that dropped frames compares the frames it rendered") {
  // At 1000 fps a frame is due every millisecond: stepping and rendering cannot keep up,
  // so the loop drops kept frames (and falls behind beyond --catch-up). Which frames are
  // rendered depends on the machine; the states never do. The frames are 1280x960: at the
  // scene's 192x144 a fast machine draws one in under a millisecond and drops none.
  const std::string dir = freshDir("check_realtime");
  std::string text = readText(kSmall);
  text.replace(text.find("\"fps\": 60"), 9, "\"fps\": 1000");
  const std::string size = "\"width\": 192, \"height\": 144";
  text.replace(text.find(size), size.size(), "\"width\": 1280, \"height\": 960");
  const std::string scene = dir + "/fast.json";
  std::ofstream(scene) << text;
  const std::string events = dir + "/events.jsonl";
  std::ofstream(events) << "{\"frame\": 10, \"type\": \"drop\", \"center\": [2, 2.5], \"radius\": 0.15}\n"
                        << "{\"frame\": 20, \"type\": \"gravity\", \"tilt\": 0.3}\n";
  const std::string out = dir + "/out";
  const Result r =
      run("run " + q(scene) + " --frames 60 --threads 2 --quiet --realtime --input " + q(events) + " --out " + q(out));
  INFO(r.out);
  REQUIRE(r.code == 0);
  std::smatch match;
  REQUIRE(std::regex_search(r.out, match, std::regex("realtime at 1000 fps: (\\d+) frames dropped")));
  const int dropped = std::stoi(match[1]);
  const json m = readManifest(out);
  MESSAGE(dropped << " frames dropped, " << m.at("frames").size() << " rendered");
  CHECK(dropped > 0);
  CHECK(int(m.at("frames").size()) + dropped == 60);
  CHECK(m.at("events").size() == 2);
  const Result c = check(out, scene);
  INFO(c.out);
  CHECK(c.code == 0);
  CHECK(c.out.find("OK, " + std::to_string(m.at("frames").size()) + " frames match") != std::string::npos);
}
