// The game loop end to end: input events from live standard input, files and the
// scene's timeline, applied at frame boundaries; records that replay bit for bit;
// bad lines skipped with their line number; real-time pacing; the frame clock.
#include <doctest/doctest.h>

#include <chrono>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app_util.hpp"
#include "loop/frame_clock.hpp"

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

/// The value after "state-hash: " in a run's output.
std::string stateHashOf(const std::string& out) {
  const auto at = out.rfind("state-hash: ");
  return at == std::string::npos ? "" : out.substr(at + 12, 16);
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string l;
  while (std::getline(in, l))
    if (!l.empty()) out.push_back(l);
  return out;
}

/// small_dam_break.json with an `events` key added.
std::string sceneWithEvents(const std::string& name, const std::string& events) {
  std::string text = readText(kSmall);
  const auto end = text.rfind('}');
  text = text.substr(0, end) + ",\n  \"events\": " + events + "\n}\n";
  const std::string path = freshDir(name) + "/scene.json";
  std::ofstream(path) << text;
  return path;
}

}  // namespace

TEST_CASE("a run fed live events through a pipe is recorded, and replaying the record gives the same hashes") {
  const std::string dir = freshDir("live_record"), replay = freshDir("live_replay");
  const std::string rec = dir + "/run.jsonl";
  // Lines arrive while the run goes: a drop, a gravity change, a bad line, a push, then a
  // pause that holds the loop until the resume 0.3 s later, an effect switch and a release.
  // When each line lands depends on the machine; the record says, and the replay must agree.
  const std::string feed =
      "(printf '%s\\n' '{\"type\": \"drop\", \"center\": [2, 2], \"radius\": 0.15}' "
      "'{\"type\": \"gravity\", \"gravity\": [3, -9]}' 'not json' "
      "'{\"type\": \"force\", \"point\": [1, 0.5], \"radius\": 0.4, \"strength\": -20}'; sleep 0.3; "
      "printf '%s\\n' '{\"type\": \"pause\"}'; sleep 0.3; "
      "printf '%s\\n' '{\"type\": \"resume\"}' '{\"type\": \"effect\", \"name\": \"user_force\", \"enabled\": false}' "
      "'{\"type\": \"release\"}') | ";
  const Result a = run("run " + q(kSmall) + " --frames 20 --threads 2 --input - --record " + q(rec) + " --out " +
                           q(dir) + " --state-hash",
                       feed);
  INFO(a.out);
  REQUIRE(a.code == 0);
  CHECK(a.out.find("warning: stdin:3:1: invalid JSON") != std::string::npos);
  const auto recorded = lines(readText(rec));
  MESSAGE(recorded.size() << " events recorded:\n" << readText(rec));
  REQUIRE(recorded.size() >= 3);  // the first three valid lines arrive before the run starts stepping
  long long prev = -1;
  for (const std::string& l : recorded) {
    const json e = json::parse(l);
    CHECK(e.at("source").get<std::string>() == "live");
    CHECK(e.at("frame").get<long long>() >= prev);  // applied in order, at frame boundaries
    prev = e.at("frame").get<long long>();
  }
  CHECK(json::parse(recorded[0]).at("type") == "drop");
  CHECK(a.out.find(std::to_string(recorded.size()) + " events applied, 1 warning;") != std::string::npos);

  const Result b = run("run " + q(kSmall) + " --frames 20 --threads 1 --input " + q(rec) + " --out " + q(replay) +
                       " --state-hash --quiet");
  INFO(b.out);
  REQUIRE(b.code == 0);
  CHECK(b.out.find(std::to_string(recorded.size()) + " events applied") != std::string::npos);
  CHECK(stateHashOf(a.out).size() == 16);
  CHECK(stateHashOf(a.out) == stateHashOf(b.out));
  const json ma = readManifest(dir), mb = readManifest(replay);
  CHECK(column(ma, "state_hash") == column(mb, "state_hash"));
  CHECK(column(ma, "rgba_xxh64") == column(mb, "rgba_xxh64"));
  CHECK(column(ma, "rgba_xxh64").size() == 20);
  CHECK(ma.at("events") == mb.at("events"));
  // sph2d check applies the events the manifest lists.
  const Result c =
      run("check " + q(kSmall) + " --against " + q(dir + "/manifest.json") + " --threads 2 --out " + q(dir + "/check"));
  INFO(c.out);
  CHECK(c.code == 0);
  CHECK(c.out.find("OK, 20 frames match") != std::string::npos);
}

TEST_CASE("the timeline applies each event at its frame, before that frame is rendered") {
  // 60 fps: t = 0.25 s is frame 15. Gravity changes the state only from the step after it;
  // a drop is part of the frame it is applied at.
  const std::string plain = freshDir("timeline_plain");
  const std::string gravity =
      sceneWithEvents("timeline_gravity", R"([ { "t": 0.25, "type": "gravity", "gravity": [4, -9.81] } ])");
  const std::string drop =
      sceneWithEvents("timeline_drop", R"([ { "frame": 10, "type": "drop", "center": [3, 2], "radius": 0.2 } ])");
  const std::string outG = fs::path(gravity).parent_path().string() + "/out",
                    outD = fs::path(drop).parent_path().string() + "/out";
  const std::string common = " --frames 20 --threads 2 --quiet --out ";
  Result r = run("run " + q(kSmall) + common + q(plain));
  REQUIRE(r.code == 0);
  r = run("run " + q(gravity) + common + q(outG));
  INFO(r.out);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("1 event applied, 0 warnings") != std::string::npos);
  r = run("run " + q(drop) + common + q(outD));
  REQUIRE(r.code == 0);
  const auto p = column(readManifest(plain), "state_hash"), g = column(readManifest(outG), "state_hash"),
             d = column(readManifest(outD), "state_hash");
  REQUIRE(p.size() == 20);
  REQUIRE(g.size() == 20);
  REQUIRE(d.size() == 20);
  for (int f = 0; f < 20; ++f) {
    CAPTURE(f);
    if (f <= 15)
      CHECK(g[f] == p[f]);  // through frame 15: gravity has not acted yet
    else
      CHECK(g[f] != p[f]);
    if (f < 10)
      CHECK(d[f] == p[f]);
    else
      CHECK(d[f] != p[f]);  // the drop is in frame 10 already
  }
  const json m = readManifest(outG);
  REQUIRE(m.at("events").size() == 1);
  CHECK(m.at("events")[0].at("frame").get<int>() == 15);
  CHECK(m.at("events")[0].at("source").get<std::string>() == "scene");
}

TEST_CASE("a bad event line is reported with its line number and skipped, and the run finishes") {
  const std::string dir = freshDir("bad_line");
  const std::string events = dir + "/events.jsonl";
  std::ofstream(events) << "{\"frame\": 2, \"type\": \"drop\", \"center\": [2, 2], \"radius\": 0.1}\n"
                        << "{\"frame\": 3, \"type\": \"gravity\", \"gravity\": [1, -9.81]\n"  // unterminated
                        << "\n"
                        << "{\"frame\": 4, \"type\": \"drop\", \"center\": [2, 2], \"radius\": -1}\n"
                        << "{\"frame\": 5, \"type\": \"effect\", \"name\": \"xsph\", \"enabled\": true}\n"
                        << "{\"frame\": 6, \"type\": \"force\", \"point\": [1, 1], \"strength\": 20}\n"
                        << "{\"t\": 10, \"type\": \"release\"}\n";  // after the run's last frame
  const Result r = run("run " + q(kSmall) + " --frames 8 --threads 2 --no-images --input " + q(events));
  INFO(r.out);
  CHECK(r.code == 0);
  CHECK(r.out.find("warning: " + events + ":2:") != std::string::npos);
  CHECK(r.out.find("invalid JSON") != std::string::npos);
  CHECK(r.out.find("warning: " + events + ":4:") != std::string::npos);
  CHECK(r.out.find("key 'radius': value -1 is out of range") != std::string::npos);
  CHECK(r.out.find("warning: " + events + ":5:") != std::string::npos);
  CHECK(r.out.find("'xsph' is not allowed; allowed values: viscosity, user_force (line skipped)") != std::string::npos);
  CHECK(r.out.find("3 events from") != std::string::npos);
  CHECK(r.out.find("sph2d: 8 frames") != std::string::npos);
  CHECK(r.out.find("2 events applied, 3 warnings") != std::string::npos);
  CHECK(r.out.find("1 event was never applied: stamped after the last frame (7)") != std::string::npos);
  CHECK(r.out.find("worst density error") != std::string::npos);
}

TEST_CASE("block and drop events of any size, from the timeline or a file, stop at max_particles with a warning") {
  // Before (issue 18): a block event of ±1e6 m or a drop of radius 1e4 allocated 4–7 GB,
  // then std::bad_alloc; with max_particles 2000 a block still added 999,400 particles.
  const std::string dir = freshDir("budget_events");
  std::string text = readText(kSmall);
  const auto at = text.find("\"fps\": 60,");
  REQUIRE(at != std::string::npos);
  text.insert(at, "\"max_particles\": 2000, ");
  const auto end = text.rfind('}');
  text = text.substr(0, end) +
         ",\n  \"events\": [{\"frame\": 1, \"type\": \"block\", \"min\": [-1e6, -1e6], \"max\": [1e6, 1e6]}]\n}\n";
  const std::string scene = dir + "/scene.json", events = dir + "/events.jsonl";
  std::ofstream(scene) << text;
  std::ofstream(events) << "{\"frame\": 2, \"type\": \"drop\", \"center\": [2, 2], \"radius\": 1e4}\n";
  const Result r = run("run " + q(scene) + " --frames 4 --threads 2 --no-images --input " + q(events));
  INFO(r.out);
  CHECK(r.code == 0);
  CHECK(r.out.find("sph2d: 4 frames, 2000 particles") != std::string::npos);
  CHECK(r.out.find("particle budget of 2000 (max_particles) reached: added 750 of the block's") != std::string::npos);
  CHECK(r.out.find("particle budget of 2000 (max_particles) reached: added 0 of the drop's") != std::string::npos);
  CHECK(r.out.find("2 events applied, 2 warnings") != std::string::npos);
}

TEST_CASE("--input - is held to the caps of live input: a block over the per-event cap is skipped naming it") {
  // Standard input is input from elsewhere, as the network is to sph2d serve: before, this
  // line added particles up to the 4,000,000 budget (3,998,750) before the next frame.
  const std::string feed =
      "printf '%s\\n' '{\"type\": \"block\", \"min\": [-1e6, -1e6], \"max\": [1e6, 1e6]}' "
      "'{\"type\": \"drop\", \"center\": [2, 2], \"radius\": 0.15}' "
      "'{\"type\": \"drop\", \"center\": [2, 2], \"radius\": 0.15}' | ";
  Result r = run("run " + q(kSmall) + " --frames 20 --realtime --no-images --input -", feed);
  INFO(r.out);
  CHECK(r.code == 0);
  CHECK(r.out.find("stdin:1: the block would add up to 2.5e+15 particles, more than the 312 one live event may add "
                   "(--max-event-particles") != std::string::npos);
  CHECK(r.out.find("2 events applied") != std::string::npos);
  // The other caps, lowered: the second drop (44 more) passes the per-second cap, then the budget.
  r = run("run " + q(kSmall) + " --frames 20 --realtime --no-images --input - --max-particles-per-second 50", feed);
  INFO(r.out);
  CHECK(r.out.find("stdin:3: the drop would add up to 44 particles to the 44 live input added in the last second: "
                   "more than the 50 a second allows (--max-particles-per-second") != std::string::npos);
  CHECK(r.out.find("1 event applied") != std::string::npos);
  r = run("run " + q(kSmall) + " --frames 20 --realtime --no-images --input - --max-particles 1300", feed);
  INFO(r.out);
  CHECK(r.out.find("more than the 1300 live input may bring it to (--max-particles") != std::string::npos);
  CHECK(r.out.find("1 event applied") != std::string::npos);
  r = run("run --help");
  CHECK(r.out.find("--max-event-particles N") != std::string::npos);
}

TEST_CASE(
    "--record: a write error stops the run with exit 1 naming the file, and an --input file is never the record") {
  // Before (issue 18): --record on a full disk wrote 0 bytes, exited 0 and the summary said the
  // events were recorded; --input F --record F truncated F.
  const std::string dir = freshDir("record_errors");
  const std::string events = dir + "/events.jsonl";
  const std::string text =
      "{\"frame\": 1, \"type\": \"drop\", \"center\": [2, 2], \"radius\": 0.1}\n"
      "{\"frame\": 2, \"type\": \"gravity\", \"tilt\": 0.2}\n";
  std::ofstream(events) << text;
  if (fs::exists("/dev/full")) {
    const Result r = run("run " + q(kSmall) + " --frames 4 --no-images --input " + q(events) + " --record /dev/full");
    INFO(r.out);
    CHECK(r.code == 1);
    CHECK(r.out.find("error: cannot write the record file '/dev/full': No space left on device") != std::string::npos);
    CHECK(r.out.find("events recorded in") == std::string::npos);
  }
  // The same file under another spelling is refused before anything is opened for writing.
  const Result same = run("run " + q(kSmall) + " --frames 4 --no-images --input " + q(events) + " --record " +
                          q(dir + "/./events.jsonl"));
  INFO(same.out);
  CHECK(same.code == 2);
  CHECK(same.out.find("is also an --input file: recording would overwrite it") != std::string::npos);
  CHECK(readText(events) == text);
}

TEST_CASE("a live input line over 1 MiB is skipped with a warning naming its line, and the next line is read") {
  // Before (issue 18): a partial line was scanned again on every read (a 30 MB line held the
  // next event back by 225 frames) and grew without bound (1 GB of memory for a 1 GB line).
  const std::string feed =
      "(head -c 3000000 /dev/zero | tr '\\0' 'x'; "
      "printf '\\n%s\\n' '{\"type\": \"drop\", \"center\": [2, 2], \"radius\": 0.15}') | ";
  // --realtime: the run lasts 0.5 s of wall time, so the lines arrive while it goes.
  const Result r = run("run " + q(kSmall) + " --frames 30 --realtime --no-images --input -", feed);
  INFO(r.out);
  CHECK(r.code == 0);
  CHECK(r.out.find(
            "warning: stdin:1: a line of 3000000 bytes, more than the 1048576 an event line may hold, was skipped") !=
        std::string::npos);
  CHECK(r.out.find("drop at (2, 2), radius 0.15 m (stdin:2)") != std::string::npos);
  CHECK(r.out.find("1 event applied, 1 warning") != std::string::npos);
}

TEST_CASE("bad input sources and timeline events exit 2 with a message") {
  Result r = run("run " + q(kSmall) + " --frames 2 --no-images --input /nonexistent/events.jsonl");
  CHECK(r.code == 2);
  CHECK(r.out.find("cannot read the events file /nonexistent/events.jsonl") != std::string::npos);
  r = run("run " + q(kSmall) + " --frames 2 --no-images --input - --input -");
  CHECK(r.code == 2);
  CHECK(r.out.find("--input - may be given once") != std::string::npos);
  r = run("run " + q(kSmall) + " --frames 2 --no-images --record /nonexistent/dir/run.jsonl");
  CHECK(r.code == 2);
  const std::string bad =
      sceneWithEvents("timeline_bad", R"([ { "t": 1, "type": "emitter", "index": 0, "enabled": true } ])");
  r = run("run " + q(bad) + " --frames 2 --no-images");
  CHECK(r.code == 2);
  CHECK(r.out.find(bad + ":17:25: key 'events[0].type': the scene has no emitters") != std::string::npos);
  r = run("run --help");
  CHECK(r.code == 0);
  for (const char* flag : {"--realtime", "--catch-up N", "--input FILE", "--input -", "--record FILE", "Exit codes:"})
    CHECK(r.out.find(flag) != std::string::npos);
}

TEST_CASE("--realtime keeps pace with the wall clock and reports dropped and late frames") {
  // A tiny scene steps far faster than real time: 31 frames at 60 fps must take at least 0.5 s.
  const std::string path = freshDir("realtime") + "/tiny.json";
  std::ofstream(path) << R"({ "name": "tiny", "fps": 60, "solver": { "spacing": 0.05 },
    "boundaries": [ { "fixtures": [ { "shape": "box", "center": [0.5, -0.1], "half_size": [0.7, 0.1] } ] } ],
    "fluid": [ { "min": [0, 0], "max": [0.3, 0.3] } ] })";
  const auto t0 = std::chrono::steady_clock::now();
  Result r = run("run " + q(path) + " --frames 31 --threads 1 --no-images --realtime --state-hash");
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  INFO(r.out);
  REQUIRE(r.code == 0);
  MESSAGE("31 frames at 60 fps in real time took " << wall << " s");
  CHECK(wall >= 0.5);
  CHECK(r.out.find("sph2d: realtime at 60 fps: ") != std::string::npos);
  CHECK(r.out.find("frames late (the simulation fell") != std::string::npos);
  // Pacing changes when frames are computed, never what they are.
  const Result h = run("run " + q(path) + " --frames 31 --threads 1 --no-images --state-hash");
  CHECK(stateHashOf(h.out) == stateHashOf(r.out));
}

TEST_CASE("the frame clock steps whole frames, waits when ahead and forgets the backlog beyond its catch-up") {
  using sph2d::cli::FrameClock;
  FrameClock c(0.1, true, 4);
  c.resync(10.0);
  c.tick(10.05);
  CHECK_FALSE(c.due());
  CHECK(c.untilDue() == doctest::Approx(0.05));
  c.tick(10.1);
  CHECK(c.due());
  c.consume();
  CHECK_FALSE(c.due());
  c.tick(11.0);  // 0.9 s late: 9 frames due
  int steps = 0;
  while (c.due() && steps < c.maxStepsPerRender()) {
    c.consume();
    ++steps;
  }
  CHECK(steps == 4);
  CHECK(c.dropBacklog() == 5);
  CHECK(c.late() == 5);
  CHECK(c.behindSeconds() == doctest::Approx(0.5));
  CHECK_FALSE(c.due());
  // The loop may tick ahead (a step scheduled for its due time); a tick behind that adds
  // nothing and does not move the clock back, so the span is never counted twice.
  FrameClock a(0.1, true, 4);
  a.resync(20.0);
  a.tick(20.04);
  a.tick(20.04 + a.untilDue());  // ahead: the step is due at 20.1
  CHECK(a.due());
  a.consume();
  a.tick(20.08);  // behind the tick ahead
  CHECK(a.untilDue() == doctest::Approx(0.1));
  a.tick(20.19);  // 0.09 s after 20.1, not 0.11 s after 20.08
  CHECK_FALSE(a.due());
  CHECK(a.untilDue() == doctest::Approx(0.01));
  a.tick(20.2);
  CHECK(a.due());
  a.consume();
  CHECK_FALSE(a.due());
  FrameClock h(0.1, false, 4);  // headless: one frame per tick, never a wait
  h.resync(0);
  h.tick(0);
  CHECK(h.due());
  h.consume();
  CHECK_FALSE(h.due());
  CHECK(h.untilDue() == 0);
}
