// app/loop/event_intake.cpp — the events of a run (timeline, files, live standard input)
// and the --record file; see event_intake.hpp.
#include "loop/event_intake.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "cli.hpp"

namespace sph2d::cli {

namespace {
bool pauseOrResume(const TimedEvent& t) {
  return t.event.type == EventDef::Type::Pause || t.event.type == EventDef::Type::Resume;
}
}  // namespace

EventIntake::EventIntake(const SceneDef& scene, WarnFn warn) : scene_(scene), warn_(std::move(warn)) {}

void EventIntake::addScene() { schedule_.addScene(scene_); }

std::size_t EventIntake::addFile(const std::string& path) {
  try {
    return addEventsFile(schedule_, path, scene_, warn_, skippedScene_);
  } catch (const std::runtime_error& e) {
    throw UsageError(e.what());
  }
}

void EventIntake::add(TimedEvent e) { schedule_.add(std::move(e)); }

void EventIntake::openLive(int fd, std::shared_ptr<LiveGate> gate) {
  gate_ = std::move(gate);
  live_ = std::make_unique<LiveInput>(fd);
}

void EventIntake::closeLive() { live_.reset(); }

bool EventIntake::liveOpen() const { return (live_ && live_->open()) || queue_; }

std::vector<TimedEvent> EventIntake::takeScheduled(std::int64_t frame) { return schedule_.take(frame); }

void EventIntake::pollLive(bool pausesOnly) {
  // While paused only pause and resume leave the queue: the others wait there, bounded.
  if (queue_)
    for (TimedEvent& t : pausesOnly ? queue_->takePauses() : queue_->take()) liveQueue_.push_back(std::move(t));
  if (!live_) return;
  for (const std::string& w : live_->takeWarnings()) warn_(w);
  for (auto& [lineNo, text] : live_->take()) {
    if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
    try {
      TimedEvent t = parseLiveEvent(text, "stdin", lineNo, scene_);
      if (gate_) {
        const double now = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
        if (const LiveRefusal r = gate_->admit(t.event, now)) {
          warn_(t.where + ": " + r.message + " (line skipped)");
          continue;
        }
      }
      liveQueue_.push_back(std::move(t));
    } catch (const SceneError& e) {
      warn_(std::string(e.what()) + " (line skipped)");
    }
  }
}

std::vector<TimedEvent> EventIntake::takeLive(std::int64_t frame) {
  pollLive(false);
  std::vector<TimedEvent> now, queued;
  queued.swap(liveQueue_);
  for (TimedEvent& t : queued) {
    if (t.frame > frame)
      schedule_.add(std::move(t));
    else
      now.push_back(std::move(t));
  }
  return now;
}

std::vector<TimedEvent> EventIntake::takeLivePauses(std::int64_t frame) {
  pollLive(true);
  std::vector<TimedEvent> now, keep;
  for (TimedEvent& t : liveQueue_) (pauseOrResume(t) && t.frame <= frame ? now : keep).push_back(std::move(t));
  liveQueue_.swap(keep);
  return now;
}

bool EventQueue::push(TimedEvent e, double particles) {
  std::lock_guard<std::mutex> lock(mutex_);
  const bool pause = pauseOrResume(e);
  if (pause ? pauses_ >= capacity_ : events_.size() - pauses_ >= capacity_) return false;
  events_.push_back(std::move(e));
  pauses_ += pause;
  particles_ += particles;
  return true;
}

double EventQueue::particles() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return particles_;
}

std::vector<TimedEvent> EventQueue::take() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<TimedEvent> out;
  out.swap(events_);
  pauses_ = 0;
  particles_ = 0;
  return out;
}

std::vector<TimedEvent> EventQueue::takePauses() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<TimedEvent> out, keep;
  for (TimedEvent& t : events_) (pauseOrResume(t) ? out : keep).push_back(std::move(t));
  events_.swap(keep);
  pauses_ = 0;
  return out;
}

std::size_t EventQueue::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return events_.size();
}

namespace {

/// A particle count for messages: whole below 10^12, else like 2.5e+15.
std::string count(double n) {
  char b[32];
  if (n < 1e12)
    std::snprintf(b, sizeof b, "%.0f", n);
  else
    std::snprintf(b, sizeof b, "%.2g", n);
  return b;
}

/// "the block" / "the drop".
std::string what(const EventDef& e) { return std::string("the ") + eventTypeName(e.type); }

}  // namespace

LiveLimits LiveLimits::forScene(const SceneDef& scene) {
  LiveLimits l;
  l.sceneCount = std::max<std::size_t>(1024, peakParticles(scene));
  l.perEvent = l.sceneCount / 4;
  l.perSecond = l.sceneCount / 2;
  const std::size_t own = scene.effects.budget > 0 ? scene.effects.budget : scene.maxParticles;
  l.budget = std::min(4 * l.sceneCount, own);
  return l;
}

double liveEventParticles(const EventDef& e, const SceneDef& scene) { return eventParticles(e, scene.solver.spacing); }

LiveRefusal checkLiveBudget(const EventDef& e, const SceneDef& scene, const LiveLimits& limits, double particles) {
  const double n = liveEventParticles(e, scene);
  if (!(n > 0) || limits.budget == 0 || !(particles + n > double(limits.budget))) return {};
  return {409,
          what(e) + " would add up to " + count(n) + " particles to the fluid's " + count(particles) +
              ": more than the " + std::to_string(limits.budget) +
              " live input may bring it to (--max-particles, default 4 x the scene's " +
              std::to_string(limits.sceneCount) + ")",
          0};
}

LiveRefusal LiveGate::admit(const EventDef& e, double now, double particles) {
  const double n = liveEventParticles(e, scene_);
  if (!(n > 0)) return {};
  if (limits_.perEvent && n > double(limits_.perEvent))
    return {422,
            what(e) + " would add up to " + count(n) + " particles, more than the " + std::to_string(limits_.perEvent) +
                " one live event may add (--max-event-particles, default a quarter of the scene's " +
                std::to_string(limits_.sceneCount) + ")",
            0};
  if (limits_.perSecond && n > double(limits_.perSecond))
    return {422,
            what(e) + " would add up to " + count(n) + " particles, more than the " +
                std::to_string(limits_.perSecond) +
                " live input may add in a second (--max-particles-per-second, default half the scene's " +
                std::to_string(limits_.sceneCount) + ")",
            0};
  if (particles >= 0)
    if (LiveRefusal r = checkLiveBudget(e, scene_, limits_, particles)) return r;
  std::lock_guard<std::mutex> lock(mutex_);
  while (!window_.empty() && window_.front().first <= now - 1.0) {
    inWindow_ -= window_.front().second;
    window_.pop_front();
  }
  if (window_.empty()) inWindow_ = 0;  // no rounding drift
  if (limits_.perSecond && inWindow_ + n > double(limits_.perSecond)) {
    // The earliest time the window, losing its oldest entries, has room for n.
    double room = double(limits_.perSecond) - inWindow_, at = now;
    for (const auto& [t, m] : window_) {
      if (room >= n) break;
      room += m;
      at = t + 1.0;
    }
    const double wait = std::max(0.0, at - now);  // room >= n here: n <= perSecond
    char after[32];
    std::snprintf(after, sizeof after, "%.2f", wait);
    return {429,
            what(e) + " would add up to " + count(n) + " particles to the " + count(inWindow_) +
                " live input added in the last second: more than the " + std::to_string(limits_.perSecond) +
                " a second allows (--max-particles-per-second, default half the scene's " +
                std::to_string(limits_.sceneCount) + "); retry in " + after + " s",
            wait};
  }
  window_.emplace_back(now, n);
  inWindow_ += n;
  return {};
}

void LiveGate::forget(const EventDef& e) {
  const double n = liveEventParticles(e, scene_);
  if (!(n > 0)) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (window_.empty()) return;
  inWindow_ -= window_.back().second;
  window_.pop_back();
}

TimedEvent parseLiveEvent(const std::string& text, const std::string& name, int number, const SceneDef& scene) {
  TimedEvent t;
  t.event = parseEvent(text, name, number, scene, EventStamp::Optional);
  t.event.source = "live";
  t.frame = eventFrame(t.event, scene.fps);
  t.where = name + ":" + std::to_string(number);
  return t;
}

std::string recordLine(const EventDef& e, std::int64_t frame) {
  EventDef stamped = e;
  stamped.frame = frame;
  stamped.t = -1;
  return eventToJson(stamped);
}

EventRecord::EventRecord(const std::string& path) : path_(path) {
  if (path.empty()) return;
  out_.open(path, std::ios::trunc);
  if (!out_) throw UsageError("cannot write the record file '" + path + "'");
}

void EventRecord::write(const std::string& line) {
  if (!out_.is_open()) return;
  hash_.update(line.data(), line.size());
  hash_.update("\n", 1);
  if (beforeWrite_) beforeWrite_(hash_.digest());
  errno = 0;
  out_ << line << '\n';
  out_.flush();
  // A record that silently lost its lines would replay another run: stop the run (exit 1).
  if (!out_) {
    const int err = errno;
    failed_ = true;
    throw std::runtime_error("cannot write the record file '" + path_ + "'" +
                             (err ? std::string(": ") + std::strerror(err) : std::string()));
  }
}

}  // namespace sph2d::cli
