// app/loop/game_loop.cpp — the fixed-step game loop of `sph2d run` and `sph2d check`;
// see game_loop.hpp for the order of things at a frame boundary.
#include "loop/game_loop.hpp"

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <exception>
#include <memory>
#include <thread>
#include <utility>

namespace sph2d::cli {

int defaultStepThreads(bool stepsAhead) {
  const int cores = int(std::thread::hardware_concurrency());   // 0 when unknown
  return stepsAhead && cores > 0 ? std::max(1, cores - 1) : 0;  // 0: the World's default, every core
}

GameLoop::GameLoop(World& world, EventIntake& input, LoopObserver& observer, Renderer* renderer, LoopSettings settings)
    : world_(world),
      input_(input),
      observer_(observer),
      renderer_(renderer),
      settings_(settings),
      clock_(1.0 / settings.fps, settings.realtime, settings.catchUp),
      start_(std::chrono::steady_clock::now()) {
  status_.frames = settings.frames;
}

double GameLoop::wallNow() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

bool GameLoop::stopRequested() const { return settings_.stop && settings_.stop->load(); }

LoopEnd GameLoop::run() {
  try {
    return runFrames();
  } catch (const Interrupted&) {
    // The World read the loop's stop flag inside a step or while adding an event's fluid:
    // the loop ends as at a stop between frames (the frame that was being stepped is not done).
    if (!stopRequested()) throw;
    status_.paused = applier_.paused();
    return LoopEnd::Interrupted;
  }
}

LoopEnd GameLoop::runFrames() {
  if (settings_.frames < 1) return LoopEnd::Finished;
  if (runsAhead()) return runAhead();
  std::int64_t& f = status_.frame;
  f = 0;
  applyDue(0);
  if (!finishBoundary(false)) return LoopEnd::Ended;
  // Frame 0 is drawn before the clock starts: the first frame compiles the shaders
  // (about 0.2 s on llvmpipe), which real time would otherwise count as lateness.
  if (!renderPending()) return LoopEnd::Ended;
  if (settings_.frames == 1) observer_.progress(world_, status_, true);
  clock_.resync(wallNow());
  // One more step is due now (the clock says so; headless: always) and may be taken
  // in this render iteration.
  int steps = 0;
  auto stepDue = [&] {
    return clock_.due() && steps < clock_.maxStepsPerRender() && f + 1 < settings_.frames && !applier_.paused();
  };
  while (f + 1 < settings_.frames) {
    if (stopRequested()) {
      renderPending();
      return LoopEnd::Interrupted;
    }
    if (applier_.paused()) {
      if (!renderPending()) return LoopEnd::Ended;
      holdPause();
      clock_.resync(wallNow());
      continue;
    }
    clock_.tick(wallNow());
    double startAt = 0;  // wall time at which the next step may start (0: at once)
    if (!clock_.due()) {
      if (pending_.active) {
        // Ahead of the wall clock with a frame to draw: draw it now, and let the next step
        // start on the other thread when it falls due, so that drawing and stepping overlap
        // (drawn first and then stepped, a heavy frame's two halves added up past 1/fps).
        startAt = wallNow() + clock_.untilDue();
        clock_.tick(startAt);
      } else {
        // Ahead of the wall clock with nothing to draw: sleep (in short slices, so Ctrl-C stays prompt).
        std::this_thread::sleep_for(std::chrono::duration<double>(std::min(clock_.untilDue(), 0.02)));
        continue;
      }
    }
    steps = 0;
    while (stepDue()) {
      const StepOutcome o = stepAndRender(startAt);
      if (o == StepOutcome::Ended) return LoopEnd::Ended;
      if (o == StepOutcome::Stopped) return LoopEnd::Interrupted;  // the frame is drawn, the step not taken
      startAt = 0;
      ++f;
      ++steps;
      clock_.consume();
      for (const auto& w : world_.takeWarnings()) observer_.warn(w);
      applyDue(f);
      // Render the last frame of this iteration; a kept frame that another step follows
      // at once (the loop is behind the wall clock) is dropped.
      if (!finishBoundary(stepDue())) return LoopEnd::Ended;
    }
    if (settings_.realtime && steps == clock_.maxStepsPerRender()) clock_.dropBacklog();
    status_.late = clock_.late();
    status_.behindSeconds = clock_.behindSeconds();
    status_.paused = applier_.paused();
    if (f + 1 == settings_.frames && !renderPending()) return LoopEnd::Ended;
    observer_.progress(world_, status_, f + 1 == settings_.frames);
  }
  return LoopEnd::Finished;
}

void GameLoop::applyOne(const TimedEvent& t, std::int64_t frame) {
  const std::string err = applier_.apply(world_, t.event);
  if (!err.empty()) {
    observer_.notApplied(t, frame, err);
    return;
  }
  ++status_.applied;
  observer_.applied(t, frame);
  for (const auto& w : world_.takeWarnings()) observer_.warn(w);
}

void GameLoop::applyDue(std::int64_t frame) {
  for (const TimedEvent& t : input_.takeScheduled(frame)) applyOne(t, frame);
  for (const TimedEvent& t : input_.takeLive(frame)) {
    if (settings_.live.budget) {
      const LiveRefusal r = checkLiveBudget(t.event, world_.scene(), settings_.live, double(world_.particleCount()));
      if (r) {
        observer_.notApplied(t, frame, r.message);
        continue;
      }
    }
    applyOne(t, frame);
  }
  status_.paused = applier_.paused();
}

bool GameLoop::finishBoundary(bool drop) {
  const std::int64_t f = status_.frame;
  const bool kept = renderer_ && observer_.keeps(f);
  observer_.boundary(world_, f, kept && !drop);
  status_.done = f + 1;
  if (!kept) return true;
  if (drop) {
    ++status_.dropped;
    return true;
  }
  capture(f);
  return true;
}

void GameLoop::capture(std::int64_t f) { captureInto(pending_, f); }

void GameLoop::captureInto(Pending& q, std::int64_t f) {
  q.particles.assign(world_.particles());  // with the ages and the particles' own colours, when there are
  q.colliders = world_.colliders();
  q.input = RenderInput{};
  q.input.particles = q.particles.view();
  q.input.origin = world_.origin();
  q.input.spacing = world_.spacing();
  q.input.colliders = &q.colliders;
  q.input.moving = world_.movingColliders();  // where the moving bodies are in this frame
  q.diffuse.assign(world_.diffuse());
  q.input.diffuse = q.diffuse.view();
  q.input.materialColors = materialColors(world_);
  q.input.materialGranular = materialGranular(world_);
  q.input.materialTransmission = materialTransmission(world_);
  q.input.gravity = world_.scene().gravity.norm();
  q.input.frame = world_.frame();
  q.input.time = world_.time();
  q.state = FrameState{f, world_.time(), world_.stateHash()};
  q.active = true;
}

std::size_t GameLoop::Pending::bytes() const {
  auto b = [](const auto& v) { return v.capacity() * sizeof(v[0]); };  // what the copy holds, reused or not
  const ParticleBuffer& P = particles;
  return b(P.x) + b(P.v) + b(P.rho) + b(P.p) + b(P.id) + b(P.age) + b(P.color) + b(P.userData) + b(P.emitter) +
         b(P.material) + b(P.mixedColor) + b(P.group) + b(diffuse.x) + b(diffuse.v) + b(diffuse.age) + b(diffuse.life) +
         b(diffuse.kind) + b(colliders);
}

bool GameLoop::renderPending() {
  if (!pending_.active) return true;
  return renderSnapshot(pending_, status_.renderSeconds);
}

bool GameLoop::renderSnapshot(Pending& q, double& seconds) {
  q.active = false;
  const auto r0 = std::chrono::steady_clock::now();
  const Frame& image = renderer_->render(q.input);
  seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
  return observer_.frame(q.state, image);
}

GameLoop::StepOutcome GameLoop::stepAndRender(double startAt) {
  std::atomic<bool> abandon{false};  // the render ended the loop (or threw): a waiting step is not taken
  bool stepped = false;
  auto step = [&] {
    // Real time: wait (in short slices, so a stop stays prompt) until the step is due; a stop
    // or an ended loop meanwhile leaves it untaken.
    for (double left = startAt - wallNow(); left > 0; left = startAt - wallNow()) {
      if (stopRequested() || abandon.load()) return;
      std::this_thread::sleep_for(std::chrono::duration<double>(std::min(left, 0.005)));
    }
    const auto s0 = std::chrono::steady_clock::now();
    world_.stepFrame();
    status_.simSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
    stepped = true;
  };
  if (!pending_.active) {
    step();
    return stepped ? StepOutcome::Stepped : StepOutcome::Stopped;
  }
  // The World steps on a second thread; the renderer stays on this one (its GL
  // context's). Both are joined before anything else touches the World.
  std::exception_ptr stepError, renderError;
  std::thread stepper([&] {
    try {
      step();
    } catch (...) {
      stepError = std::current_exception();
    }
  });
  bool more = true;
  try {
    more = renderPending();
  } catch (...) {
    renderError = std::current_exception();
  }
  if (!more || renderError) abandon = true;
  stepper.join();
  if (stepError) std::rethrow_exception(stepError);
  if (renderError) std::rethrow_exception(renderError);
  if (!more) return StepOutcome::Ended;
  return stepped ? StepOutcome::Stepped : StepOutcome::Stopped;
}

// Paused at boundary f (already rendered): waits for a resume, or the pause's own seconds
// (real time only). Live pause/resume take effect at once; other live events wait for the
// next frame.
void GameLoop::holdPause() {
  const std::int64_t f = status_.frame;
  const double start = wallNow();
  const double seconds = applier_.pauseSeconds();
  if (seconds > 0 && !settings_.realtime) {  // headless: a timed pause takes no time
    applier_.endPause();
    return;
  }
  if (seconds <= 0 && !input_.liveOpen()) {
    observer_.warn("pause at frame " + std::to_string(f) + ": no live input (--input -) can resume it; ignored");
    applier_.endPause();
    return;
  }
  observer_.note("paused at frame " + std::to_string(f) +
                 (seconds > 0 ? " for " + std::to_string(seconds) + " s" : ": waiting for {\"type\": \"resume\"}"));
  while (applier_.paused() && !stopRequested()) {
    for (const TimedEvent& t : input_.takeLivePauses(f)) applyOne(t, f);
    if (!applier_.paused()) break;
    if (seconds > 0 && wallNow() - start >= seconds) {
      applier_.endPause();
      break;
    }
    if (seconds <= 0 && !input_.liveOpen()) {
      observer_.warn("standard input closed while paused at frame " + std::to_string(f) + "; resuming");
      applier_.endPause();
      break;
    }
    status_.paused = true;
    observer_.progress(world_, status_, false);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  status_.paused = applier_.paused();
  if (!applier_.paused()) observer_.note("resumed at frame " + std::to_string(f));
}

bool GameLoop::runsAhead() const { return renderer_ && !settings_.realtime && !input_.liveOpen(); }

LoopEnd GameLoop::runAhead() {
  // The queue between the two threads: snapshots in frame order, and at most kSpares spent ones
  // kept for reuse (the others are freed: a copy keeps the capacity of the largest frame it held).
  constexpr std::size_t kSpares = 2;
  std::mutex m;
  std::condition_variable cv;
  std::deque<std::unique_ptr<Pending>> ready, spare;
  std::deque<std::size_t> readySizes;
  std::size_t readyBytes = 0;
  bool producerDone = false;
  std::atomic<bool> abandon{false};  // the drawing ended the loop: the stepping stops
  std::exception_ptr stepError;
  const auto slice = std::chrono::milliseconds(20);  // a stop is noticed within this while waiting

  // A free snapshot once the queue has room (null: the loop is ending).
  auto slot = [&]() -> std::unique_ptr<Pending> {
    std::unique_lock<std::mutex> lock(m);
    for (;;) {
      if (abandon.load() || stopRequested()) return nullptr;
      if (ready.empty() || (ready.size() < kAheadFrames && readyBytes < kAheadBytes)) break;
      cv.wait_for(lock, slice);
    }
    if (spare.empty()) return std::make_unique<Pending>();
    std::unique_ptr<Pending> q = std::move(spare.back());
    spare.pop_back();
    return q;
  };
  // Completes boundary f (stepped to, its events applied): tells the observer and queues the
  // frame when it is kept. False: the loop is ending.
  auto boundaryAt = [&](std::int64_t f) {
    const bool kept = observer_.keeps(f);
    observer_.boundary(world_, f, kept);
    status_.done = f + 1;
    if (!kept) return true;
    std::unique_ptr<Pending> q = slot();
    if (!q) return false;
    captureInto(*q, f);
    const std::size_t bytes = q->bytes();
    std::lock_guard<std::mutex> lock(m);
    ready.push_back(std::move(q));
    readySizes.push_back(bytes);
    readyBytes += bytes;
    status_.aheadMost = std::max<std::uint64_t>(status_.aheadMost, ready.size());
    cv.notify_all();
    return true;
  };
  std::thread producer([&] {
    try {
      std::int64_t& f = status_.frame;
      f = 0;
      applyDue(0);
      bool more = boundaryAt(0);
      while (more && f + 1 < settings_.frames && !stopRequested() && !abandon.load()) {
        if (applier_.paused()) {
          holdPause();  // headless with nothing live: a pause ends at once (with a warning if untimed)
          continue;
        }
        const auto s0 = std::chrono::steady_clock::now();
        world_.stepFrame();
        status_.simSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
        ++f;
        for (const auto& w : world_.takeWarnings()) observer_.warn(w);
        applyDue(f);
        more = boundaryAt(f);
        status_.paused = applier_.paused();
        if (f + 1 < settings_.frames) observer_.progress(world_, status_, false);
      }
    } catch (...) {
      stepError = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(m);
    producerDone = true;
    cv.notify_all();
  });
  // Whatever this thread meets, the stepping thread is stopped and joined before it returns.
  auto finish = [&] {
    abandon = true;
    cv.notify_all();
    producer.join();
  };

  // This thread (the renderer's GL context's) draws the queue in order. Frames queued before
  // a failed step are drawn before its error propagates, as in the interleaved loop.
  LoopEnd end = LoopEnd::Finished;
  std::exception_ptr renderError;
  double renderSeconds = 0;  // added to status_ once the stepping (which reads it in progress()) is joined
  try {
    for (;;) {
      std::unique_ptr<Pending> q;
      {
        std::unique_lock<std::mutex> lock(m);
        while (ready.empty() && !producerDone && !stopRequested()) cv.wait_for(lock, slice);
        if (ready.empty()) break;  // the stepping is done (or a stop came while waiting)
        q = std::move(ready.front());
        ready.pop_front();
        readyBytes -= readySizes.front();
        readySizes.pop_front();
      }
      bool more = true;
      try {
        more = renderSnapshot(*q, renderSeconds);
      } catch (...) {
        renderError = std::current_exception();
      }
      {
        std::lock_guard<std::mutex> lock(m);
        if (spare.size() < kSpares) spare.push_back(std::move(q));
        cv.notify_all();
      }
      q.reset();
      if (renderError || !more) {
        end = LoopEnd::Ended;
        break;
      }
      if (stopRequested()) break;  // the frame at hand is drawn; the queue's others are not
    }
  } catch (...) {
    finish();
    throw;
  }
  finish();
  status_.renderSeconds += renderSeconds;
  // The drawing's end comes first: a step error is of a frame later than any drawn, which a
  // failed write or check's first difference has already ended the loop before.
  if (renderError) std::rethrow_exception(renderError);
  if (end == LoopEnd::Ended) return end;
  if (stepError) std::rethrow_exception(stepError);
  if (stopRequested()) return LoopEnd::Interrupted;
  observer_.progress(world_, status_, true);
  return LoopEnd::Finished;
}

void GameLoop::SerialObserver::warn(const std::string& msg) {
  std::lock_guard<std::mutex> lock(m_);
  o_.warn(msg);
}
void GameLoop::SerialObserver::note(const std::string& msg) {
  std::lock_guard<std::mutex> lock(m_);
  o_.note(msg);
}
void GameLoop::SerialObserver::applied(const TimedEvent& e, std::int64_t frame) {
  std::lock_guard<std::mutex> lock(m_);
  o_.applied(e, frame);
}
void GameLoop::SerialObserver::notApplied(const TimedEvent& e, std::int64_t frame, const std::string& why) {
  std::lock_guard<std::mutex> lock(m_);
  o_.notApplied(e, frame, why);
}
void GameLoop::SerialObserver::boundary(const World& world, std::int64_t frame, bool rendered) {
  std::lock_guard<std::mutex> lock(m_);
  o_.boundary(world, frame, rendered);
}
bool GameLoop::SerialObserver::keeps(std::int64_t frame) {
  std::lock_guard<std::mutex> lock(m_);
  return o_.keeps(frame);
}
bool GameLoop::SerialObserver::frame(const FrameState& state, const Frame& image) {
  std::lock_guard<std::mutex> lock(m_);
  return o_.frame(state, image);
}
void GameLoop::SerialObserver::progress(const World& world, const LoopStatus& status, bool force) {
  std::lock_guard<std::mutex> lock(m_);
  o_.progress(world, status, force);
}

}  // namespace sph2d::cli
