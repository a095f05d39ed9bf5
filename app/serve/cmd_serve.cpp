// `sph2d serve`: the scene's game loop at real-time pace, shown live in a browser.
//
//   browser ─ /ws, POST /event ─> ServeServer (io thread) ─ parseEvent ─> EventQueue
//   GameLoop (--realtime pacing) ─ takes the queue at the next boundary ─> World
//        │  applied events ─> --record FILE (one line each, flushed)
//        └─ frame() ─> ServeServer::publish (newest frame + overlay data) ─> clients
//
// Design: serve is the loop of `sph2d run --realtime` with another observer and another
// live source, not a second loop. An event from the network is parsed and validated on
// the io thread (so a bad one is answered to its client and changes nothing), then
// queued; the loop applies it at its next frame boundary like a line of `--input -`,
// so `--record` + `sph2d run SCENE --input RECORD` reproduces the live states and
// frames. Frames are rendered as `sph2d run` renders them (same renderer, same options:
// the overlay is the page's, not drawn into the pixels), so their hashes match the
// replay's manifest. "reset" is the page's one message outside the event format: it
// ends the loop and starts the scene again from frame 0 in a new World; the record
// starts over with it (the record always replays what the page shows since the last
// reset). The loop runs until SIGINT/SIGTERM (exit 130, the record whole): the World shares
// the loop's stop flag, so a signal ends even a step under way within milliseconds.
//
// No request takes the loop out of real time: the particles events from the network may
// add are capped before anything is allocated (LiveGate: per event and per second, and a
// budget on the count the fluid may reach), each cap a share of the scene's own count unless
// an option says otherwise; a refused event is answered 4xx naming the cap and its option.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <deque>
#include <limits>
#include <map>
#include <memory>
#include <mutex>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "commands.hpp"
#include "loop/event_intake.hpp"
#include "loop/game_loop.hpp"
#include "output/output_dir.hpp"
#include "serve/serve_server.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/render/renderer.hpp"
#include "sph2d/scene.hpp"
#include "sph2d/world.hpp"

namespace sph2d::cli {

const std::string& embeddedPage();  // embedded_web.cpp (app/serve/embed_web.cmake)

namespace {

const char* kServeHelp =
    "Usage: sph2d serve SCENE.json [options]\n"
    "\n"
    "Runs SCENE's game loop at real-time pace (as `sph2d run --realtime`) and serves it\n"
    "at http://127.0.0.1:8080/: the live frames, an overlay (frames per second, particles,\n"
    "solver, simulated time, dropped frames), and input from the page in the event format\n"
    "of `--input` (docs/SCENES.md): drag = force (P or Shift: push), click = drop,\n"
    "arrows = gravity tilt, space = pause/resume, R = reset, 1-9 = switch effect k.\n"
    "Also: GET /snapshot.png (the latest frame), GET /state (the overlay data as JSON),\n"
    "POST /event (one event as JSON), WebSocket /ws (frames out, events in).\n"
    "\n"
    "Options:\n"
    "  --port P         TCP port (default 8080; 0: any free port, printed at start)\n"
    "  --bind ADDR      address to listen on (default 127.0.0.1; 0.0.0.0 for every interface)\n"
    "  --record FILE    write every applied event with its frame, flushed per event; replay\n"
    "                   with `sph2d run SCENE --input FILE` (a reset starts the file over)\n"
    "  --threads T      simulation threads (default: all cores)\n"
    "  --max-clients N  WebSocket clients at once, 1..64 (default 4; more are refused)\n"
    "  --format F       live frames as jpeg (default) or png\n"
    "  --quality Q      JPEG quality 1..100 (default 80)\n"
    "  --catch-up N     at most N frames stepped per render (default 4)\n"
    "  --max-event-particles N      the most particles one event may add (a block's or a drop's\n"
    "                   lattice points; default a quarter of S, the scene's own particle count:\n"
    "                   max(1024, its blocks, emitters and timeline)); more: 422\n"
    "  --max-particles-per-second N the most particles events may add in any second (default\n"
    "                   S/2); more: 429 with Retry-After\n"
    "  --max-particles N            no event takes the fluid past N particles (default 4 x S,\n"
    "                   at most the scene's own budget); more: 409\n"
    "%s"
    "  --quiet          print only the address, warnings and the summary\n"
    "  --help           this text\n"
    "\n"
    "Exit codes: 130 stopped by SIGINT/SIGTERM (the normal end); 1 runtime failure;\n"
    "2 bad input (command line, scene, a port that cannot be used); 3 the simulation guard.\n";

/// The options of one `sph2d serve`.
struct ServeArgs {
  std::string scene;                      ///< the scene file
  ServeConfig server;                     ///< --port, --bind, --max-clients, --format, --quality
  std::string record;                     ///< --record FILE ("" : none)
  int threads = 0;                        ///< --threads (0: all cores)
  int catchUp = 4;                        ///< --catch-up
  RenderOptions render;                   ///< the render flags
  bool quiet = false;                     ///< --quiet
  std::size_t maxEventParticles = 0;      ///< --max-event-particles (0: the scene's default)
  std::size_t maxParticlesPerSecond = 0;  ///< --max-particles-per-second (0: the scene's default)
  std::size_t maxParticles = 0;           ///< --max-particles (0: the scene's default)
};

ServeArgs parseServeArgs(const std::vector<std::string>& a) {
  ServeArgs r;
  for (ArgReader opt(a, "serve"); opt.next();) {
    const std::string s = opt.arg();
    if (parseRenderFlag(opt, r.render)) continue;
    if (opt.is("--port"))
      r.server.port = opt.intValue(0, 65535);
    else if (opt.is("--bind")) {
      r.server.bind = opt.value();
      if (r.server.bind.empty()) throw UsageError("--bind expects an IP address (127.0.0.1, 0.0.0.0, ::1), got ''");
    } else if (opt.is("--record"))
      r.record = opt.value();
    else if (opt.is("--threads"))
      r.threads = opt.intValue(1, 256);
    else if (opt.is("--max-clients"))
      r.server.maxClients = opt.intValue(1, 64);
    else if (opt.is("--quality"))
      r.server.jpegQuality = opt.intValue(1, 100);
    else if (opt.is("--catch-up"))
      r.catchUp = opt.intValue(1, 1000);
    else if (opt.is("--max-event-particles"))
      r.maxEventParticles = std::size_t(opt.intValue(1, 100000000));
    else if (opt.is("--max-particles-per-second"))
      r.maxParticlesPerSecond = std::size_t(opt.intValue(1, 100000000));
    else if (opt.is("--max-particles"))
      r.maxParticles = std::size_t(opt.intValue(1, 100000000));
    else if (opt.is("--format")) {
      const std::string v = opt.value();
      if (v == "jpeg" || v == "jpg")
        r.server.format = ImageFormat::Jpeg;
      else if (v == "png")
        r.server.format = ImageFormat::Png;
      else
        throw UsageError("--format expects jpeg or png, got '" + v + "'");
    } else if (opt.is("--quiet"))
      r.quiet = true;
    else if (opt.option())
      throw UsageError(
          "unknown option '" + s +
          "' for serve; options: --port, --bind, --record, --threads, "
          "--max-clients, --format, --quality, --catch-up, --max-event-particles, --max-particles-per-second, "
          "--max-particles, --mode, --color-by, --range, --overlay, --outline, "
          "--foam-speed, --depth-scale, --splat, --quiet (see sph2d serve --help)");
    else if (r.scene.empty())
      r.scene = s;
    else
      throw UsageError("serve takes one scene file; got '" + r.scene + "' and '" + s + "'");
  }
  if (r.scene.empty()) throw UsageError("serve needs a scene file: sph2d serve SCENE.json [options]");
  return r;
}

/// The overlay data shared between the loop's thread (writes) and the io thread (GET /state).
struct ServeStatus {
  std::mutex mutex;
  nlohmann::json state;  ///< what GET /state returns
};

/// What `sph2d serve` does with the loop: records applied events, tracks the overlay data,
/// and publishes each rendered frame with it.
class ServeOutputs : public LoopObserver {
 public:
  ServeOutputs(const SceneDef& scene, const ServeArgs& a, EventRecord& record, ServeServer& server, ServeStatus& status,
               Renderer& renderer, std::map<std::string, bool>& effects, int reset, std::atomic<std::size_t>& liveCount)
      : scene_(scene),
        a_(a),
        record_(record),
        server_(server),
        status_(status),
        renderer_(renderer),
        effects_(effects),
        reset_(reset),
        liveCount_(liveCount) {}

  void warn(const std::string& m) override { std::fprintf(stderr, "warning: %s\n", m.c_str()); }
  void note(const std::string& m) override {
    if (!a_.quiet) std::printf("sph2d serve: %s\n", m.c_str());
    std::fflush(stdout);
  }
  void applied(const TimedEvent& t, std::int64_t frame) override {
    record_.write(recordLine(t.event, frame));
    ++applied_;
    if (t.event.type == EventDef::Type::Effect) effects_[t.event.effect] = t.event.enabled;
    // The frame rendered at a pause's boundary already says so (progress() comes after it).
    if (t.event.type == EventDef::Type::Pause) paused_ = true;
    if (t.event.type == EventDef::Type::Resume) paused_ = false;
    // A drag sends a force per frame: those are counted, not printed.
    if (!a_.quiet && t.event.type != EventDef::Type::Force) {
      std::printf("event at frame %lld: %s (%s)\n", static_cast<long long>(frame), describeEvent(t.event).c_str(),
                  t.where.c_str());
      std::fflush(stdout);
    }
  }
  void notApplied(const TimedEvent& t, std::int64_t frame, const std::string& why) override {
    warn(t.where + ": " + describeEvent(t.event) + " at frame " + std::to_string(frame) + " not applied: " + why);
  }
  void boundary(const World& world, std::int64_t frame, bool rendered) override {
    liveCount_.store(world.particleCount());  // every boundary: the network's budget check reads it
    if (rendered) particles_ = world.particleCount();
  }
  bool keeps(std::int64_t) override { return true; }
  bool frame(const FrameState& state, const Frame& image) override {
    const auto now = std::chrono::steady_clock::now();
    times_.push_back(now);
    while (times_.size() > 2 && now - times_.front() > std::chrono::seconds(1)) times_.pop_front();
    const double span = std::chrono::duration<double>(times_.back() - times_.front()).count();
    const double fps = times_.size() > 1 && span > 0 ? double(times_.size() - 1) / span : 0;
    if (camera_.empty()) camera_ = renderer_.cameraRect();
    nlohmann::json m = base();
    m["frame"] = state.frame;
    m["time"] = state.time;
    m["particles"] = particles_;
    m["state_hash"] = hex(state.stateHash);
    m["frame_hash"] = hex(xxh64(image.rgba.data(), image.rgba.size()));
    m["render_fps"] = fps;
    m["width"] = image.width;
    m["height"] = image.height;
    {
      std::lock_guard<std::mutex> lock(status_.mutex);
      for (auto it = m.begin(); it != m.end(); ++it) status_.state[it.key()] = it.value();
    }
    server_.publish(image, m);
    return true;
  }
  void progress(const World& world, const LoopStatus& s, bool) override {
    dropped_ = s.dropped;
    late_ = s.late;
    paused_ = s.paused;
    std::lock_guard<std::mutex> lock(status_.mutex);
    status_.state["dropped"] = dropped_;
    status_.state["late"] = late_;
    status_.state["paused"] = paused_;
    status_.state["applied"] = applied_;
    status_.state["clients"] = server_.clients();
  }

  /// Events applied in this World.
  int applied() const { return applied_; }

 private:
  static std::string hex(std::uint64_t v) {
    char b[17];
    std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(v));
    return b;
  }
  nlohmann::json base() const {
    nlohmann::json m;
    m["scene"] = scene_.name;
    m["solver"] = scene_.solver.type;
    m["fps_target"] = scene_.fps;
    m["camera"] = camera_;
    m["effects"] = effects_;
    m["dropped"] = dropped_;
    m["late"] = late_;
    m["paused"] = paused_;
    m["applied"] = applied_;
    m["reset"] = reset_;
    m["clients"] = server_.clients();
    return m;
  }

  const SceneDef& scene_;
  const ServeArgs& a_;
  EventRecord& record_;
  ServeServer& server_;
  ServeStatus& status_;
  Renderer& renderer_;
  std::map<std::string, bool>& effects_;
  int reset_;
  std::atomic<std::size_t>& liveCount_;  ///< the World's particles at the last boundary (read by the io thread)
  std::size_t particles_ = 0;
  std::uint64_t dropped_ = 0, late_ = 0;
  bool paused_ = false;
  int applied_ = 0;
  std::vector<double> camera_;
  std::deque<std::chrono::steady_clock::time_point> times_;
};

}  // namespace

int cmdServe(const std::vector<std::string>& args) {
  if (std::any_of(args.begin(), args.end(), [](const std::string& s) { return s == "--help" || s == "-h"; })) {
    std::printf(kServeHelp, kRenderFlagsHelp);
    return 0;
  }
  const ServeArgs a = parseServeArgs(args);
  // From here SIGINT/SIGTERM stop the loop, and the World inside its step or its construction
  // (exit 130); the watchdog ends the process 0.8 s after the signal whatever it is doing.
  std::signal(SIGPIPE, SIG_IGN);  // a vanished client shows up as EPIPE, never as a kill
  installStopHandler();
  const SceneDef scene = loadScene(a.scene);
  checkMemory(scene, true, 0);
  LiveLimits limits = LiveLimits::forScene(scene);
  if (a.maxEventParticles) limits.perEvent = a.maxEventParticles;
  if (a.maxParticlesPerSecond) limits.perSecond = a.maxParticlesPerSecond;
  if (a.maxParticles) limits.budget = a.maxParticles;
  auto gate = std::make_shared<LiveGate>(scene, limits);
  std::atomic<std::size_t> liveCount{0};  // the World's particles at the last boundary

  // Events from the network: parsed, validated and held to the caps here (io thread), applied
  // by the loop.
  auto queue = std::make_shared<EventQueue>(256);
  std::atomic<bool> resetRequested{false};
  std::atomic<int> received{0};
  const auto clock0 = std::chrono::steady_clock::now();
  ServeEventHandler onEvent = [&](const std::string& text, const std::string& where) -> EventReply {
    const int n = ++received;
    auto refuse = [](std::string why, int status = 400, double retry = 0) {
      return EventReply{status, std::move(why), retry};
    };
    // "reset" is the page's own message (not an event of the format: a replay cannot reset).
    const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
    if (!j.is_discarded() && j.is_object() && j.contains("type") && j["type"] == "reset") {
      if (j.size() != 1)
        return refuse(where + ":" + std::to_string(n) + ": {\"type\": \"reset\"} takes no other keys; nothing reset");
      resetRequested.store(true);
      stopRequested.store(true);
      return {};
    }
    try {
      TimedEvent t = parseLiveEvent(text, where, n, scene);
      // A stamp would park the event in the schedule until its frame (unbounded for a
      // client that sends far-future stamps): the network's events apply at the next boundary.
      if (t.event.frame >= 0 || t.event.t >= 0)
        return refuse(t.where +
                      ": keys 'frame' and 't' are not allowed in events from the network (they apply at the "
                      "next frame boundary); nothing applied");
      // The caps, before anything is allocated: the event's particles are counted from its numbers.
      const double now = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock0).count();
      const double adds = liveEventParticles(t.event, scene);
      if (const LiveRefusal r = gate->admit(t.event, now, double(liveCount.load()) + queue->particles()))
        return refuse(t.where + ": " + r.message + "; nothing applied", r.status, r.retryAfter);
      const std::string at = t.where;
      const EventDef admitted = t.event;
      if (!queue->push(std::move(t), adds)) {
        gate->forget(admitted);
        return refuse(at + ": too many events waiting for the next frame (at most 256; while paused only pause and "
                           "resume are taken); nothing applied",
                      429, 1);
      }
      return {};
    } catch (const SceneError& e) {
      return refuse(std::string(e.what()) + " (not applied)");
    } catch (const std::exception& e) {
      return refuse(std::string("not applied: ") + e.what());
    }
  };
  // The record starts over at each reset, but the first one must not replace a file sph2d did not write.
  if (!a.record.empty()) refuseExistingFile(a.record, "--record");
  ServeStatus status;
  ServeServer server(a.server, embeddedPage(), onEvent, [&] {
    std::lock_guard<std::mutex> lock(status.mutex);
    nlohmann::json s = status.state;
    s["events_waiting"] = queue->size();
    s["limits"] = {{"event_particles", limits.perEvent},
                   {"particles_per_second", limits.perSecond},
                   {"max_particles", limits.budget}};
    return s;
  });

  Renderer renderer(scene.render, a.render);
  try {
    server.start();
  } catch (const std::exception& e) {
    throw UsageError(std::string("--port/--bind: ") + e.what());
  }
  const std::string host = a.server.bind.find(':') != std::string::npos ? "[" + a.server.bind + "]" : a.server.bind;
  std::printf("sph2d serve: http://%s:%d/ (scene %s, solver %s, %d×%d, %s frames; Ctrl-C stops)\n", host.c_str(),
              server.port(), scene.name.c_str(), scene.solver.type.c_str(), scene.render.width, scene.render.height,
              imageFormatName(a.server.format));
  if (!a.quiet)
    std::printf(
        "sph2d serve: events from the network add at most %zu particles each, %zu a second, and take the "
        "fluid to at most %zu (--max-event-particles, --max-particles-per-second, --max-particles)\n",
        limits.perEvent, limits.perSecond, limits.budget);
  std::fflush(stdout);

  std::map<std::string, bool> effects;
  for (const std::string& e : switchableEffects(scene))
    if (e != "user_force") effects[e] = true;
  int resets = 0, appliedTotal = 0;
  std::int64_t framesTotal = 0;
  const auto start = std::chrono::steady_clock::now();
  std::string failure;
  int code = 130;
  for (;;) {
    // The World reads the stop flag too: a signal (or a reset) ends its construction or a step
    // under way within milliseconds.
    std::unique_ptr<World> built;
    try {
      built = std::make_unique<World>(scene, WorldOptions{a.threads, &stopRequested});
    } catch (const Interrupted&) {
      stopRequested.store(false);
      if (signalReceived.load() || !resetRequested.exchange(false)) break;  // a signal: exit 130
      queue->take();
      ++resets;
      continue;  // a reset while the World was being built: build it again
    }
    World& world = *built;
    liveCount.store(world.particleCount());
    for (const auto& w : world.takeWarnings()) std::fprintf(stderr, "warning: %s\n", w.c_str());
    EventIntake input(scene, [](const std::string& m) { std::fprintf(stderr, "warning: %s\n", m.c_str()); });
    input.addScene();
    input.openQueue(queue);
    EventRecord record(a.record);  // (re)started: the record replays the run since the last reset
    {
      std::lock_guard<std::mutex> lock(status.mutex);
      status.state["frame"] = 0;
      status.state["time"] = 0.0;
      status.state["paused"] = false;
      status.state["particles"] = world.particleCount();
      status.state["solver"] = scene.solver.type;
      status.state["scene"] = scene.name;
      status.state["record"] = a.record;
      status.state["reset"] = resets;
    }
    ServeOutputs outputs(scene, a, record, server, status, renderer, effects, resets, liveCount);
    LoopSettings settings;
    settings.frames = std::numeric_limits<std::int64_t>::max();
    settings.fps = scene.fps;
    settings.realtime = true;
    settings.catchUp = a.catchUp;
    settings.stop = &stopRequested;
    settings.live = limits;
    GameLoop loop(world, input, outputs, &renderer, settings);
    LoopEnd end = LoopEnd::Finished;
    try {
      end = loop.run();
    } catch (const SimulationError& e) {
      failure = e.what();
      code = 3;
    } catch (const std::exception& e) {
      failure = e.what();
      code = 1;
    }
    framesTotal += loop.status().done;
    appliedTotal += outputs.applied();
    if (!failure.empty() || end != LoopEnd::Interrupted) break;
    // A reset, unless a signal came too: clear the flag first, then look for a signal, so
    // a signal that arrives in between is never lost.
    stopRequested.store(false);
    if (signalReceived.load() || !resetRequested.exchange(false)) break;
    queue->take();  // events sent to the old World do not carry over
    for (auto& e : effects) e.second = true;
    ++resets;
    if (!a.quiet)
      std::printf("sph2d serve: reset: the scene starts again at frame 0%s\n",
                  a.record.empty() ? "" : (" (" + a.record + " starts over)").c_str());
    std::fflush(stdout);
  }
  server.stop();
  const ServeCounters c = server.counters();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!failure.empty()) std::fprintf(stderr, "error: %s\n", failure.c_str());
  std::printf(
      "sph2d serve: stopped after %.1f s: %lld frames stepped, %d events applied, %d resets; "
      "%llu frames encoded (%.1f ms each), %llu sent to %llu clients, %llu refused, %llu messages rejected%s\n",
      wall, static_cast<long long>(framesTotal), appliedTotal, resets, static_cast<unsigned long long>(c.encoded),
      c.encoded ? 1e3 * c.encodeSeconds / double(c.encoded) : 0.0, static_cast<unsigned long long>(c.sent),
      static_cast<unsigned long long>(c.clients), static_cast<unsigned long long>(c.refused),
      static_cast<unsigned long long>(c.rejected), a.record.empty() ? "" : ("; record " + a.record).c_str());
  std::fflush(stdout);
  return code;
}

}  // namespace sph2d::cli
