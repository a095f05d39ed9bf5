// app/event_intake.cpp — the events of a run (timeline, files, live standard input)
// and the --record file; see event_intake.hpp.
#include "event_intake.hpp"

#include <cerrno>
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

void EventIntake::openLive(int fd) { live_ = std::make_unique<LiveInput>(fd); }

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
      liveQueue_.push_back(parseLiveEvent(text, "stdin", lineNo, scene_));
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
    if (t.frame > frame) schedule_.add(std::move(t));
    else now.push_back(std::move(t));
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

bool EventQueue::push(TimedEvent e) {
  std::lock_guard<std::mutex> lock(mutex_);
  const bool pause = pauseOrResume(e);
  if (pause ? pauses_ >= capacity_ : events_.size() - pauses_ >= capacity_) return false;
  events_.push_back(std::move(e));
  pauses_ += pause;
  return true;
}

std::vector<TimedEvent> EventQueue::take() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<TimedEvent> out;
  out.swap(events_);
  pauses_ = 0;
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
