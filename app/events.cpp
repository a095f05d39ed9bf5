#include "events.hpp"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace sph2d::cli {

void EventSchedule::insert(TimedEvent e) {
  // After every event of the same or an earlier frame: stable within a frame.
  const auto at = std::upper_bound(events_.begin(), events_.end(), e.frame,
                                   [](std::int64_t f, const TimedEvent& x) { return f < x.frame; });
  events_.insert(at, std::move(e));
}

void EventSchedule::addScene(const SceneDef& scene) {
  for (std::size_t k = 0; k < scene.events.size(); ++k) {
    TimedEvent t;
    t.event = scene.events[k];
    t.event.source = "scene";
    t.frame = eventFrame(t.event, scene.fps);
    t.where = (scene.path.empty() ? std::string("scene") : scene.path) + " events[" + std::to_string(k) + "]";
    insert(std::move(t));
  }
}

std::size_t EventSchedule::addFile(const std::string& path, const SceneDef& scene, const WarnFn& warn) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read the events file " + path);
  std::string line;
  std::size_t n = 0;
  for (int lineNo = 1; std::getline(in, line); ++lineNo) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    try {
      TimedEvent t;
      t.event = parseEvent(line, path, lineNo, scene, EventStamp::Required);
      if (t.event.source == "scene") {
        ++skippedScene_;
        continue;
      }
      if (t.event.source.empty()) t.event.source = "file";
      t.frame = eventFrame(t.event, scene.fps);
      t.where = path + ":" + std::to_string(lineNo);
      insert(std::move(t));
      ++n;
    } catch (const SceneError& e) {
      warn(std::string(e.what()) + " (line skipped)");
    }
  }
  return n;
}

std::vector<TimedEvent> EventSchedule::take(std::int64_t frame) {
  std::vector<TimedEvent> out;
  std::size_t k = 0;
  while (k < events_.size() && events_[k].frame <= frame) ++k;
  out.assign(std::make_move_iterator(events_.begin()), std::make_move_iterator(events_.begin() + std::ptrdiff_t(k)));
  events_.erase(events_.begin(), events_.begin() + std::ptrdiff_t(k));
  return out;
}

LiveInput::LiveInput(int fd) : thread_([this, fd] { loop(fd); }) {}

LiveInput::~LiveInput() {
  stop_.store(true);
  thread_.join();
}

void LiveInput::loop(int fd) {
  // Each byte is looked at once (memchr over what was just read), and a line holds at
  // most kMaxLiveLine bytes: a longer one is dropped as it arrives, up to its newline,
  // and reported with its number and size.
  std::string partial;
  bool skipping = false;
  std::size_t skipped = 0;
  int lineNo = 0;
  char buf[65536];
  std::vector<std::pair<int, std::string>> got;
  std::vector<std::string> warned;
  auto endLine = [&] {
    ++lineNo;
    if (skipping) {
      warned.push_back("stdin:" + std::to_string(lineNo) + ": a line of " + std::to_string(skipped) +
                       " bytes, more than the " + std::to_string(kMaxLiveLine) +
                       " an event line may hold, was skipped (one JSON object per line)");
      skipping = false;
      skipped = 0;
    } else {
      got.emplace_back(lineNo, std::move(partial));
    }
    partial.clear();
  };
  auto publish = [&] {
    if (got.empty() && warned.empty()) return;
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto& g : got) lines_.push_back(std::move(g));
    for (auto& w : warned) warnings_.push_back(std::move(w));
    got.clear();
    warned.clear();
  };
  while (!stop_.load()) {
    pollfd p{fd, POLLIN, 0};
    const int r = ::poll(&p, 1, 50);  // wake up now and then to notice stop_
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) break;
    if (r == 0) continue;
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n <= 0) break;  // end of input (or an error: treated alike)
    std::size_t pos = 0;
    while (pos < std::size_t(n)) {
      const void* hit = std::memchr(buf + pos, '\n', std::size_t(n) - pos);
      const std::size_t end = hit ? std::size_t(static_cast<const char*>(hit) - buf) : std::size_t(n);
      if (skipping) {
        skipped += end - pos;
      } else {
        partial.append(buf + pos, end - pos);
        if (partial.size() > kMaxLiveLine) {
          skipping = true;
          skipped = partial.size();
          std::string().swap(partial);  // give the memory back
        }
      }
      if (!hit) break;
      endLine();
      pos = end + 1;
    }
    publish();
  }
  if (skipping || !partial.empty()) endLine();
  publish();
  eof_.store(true);
}

std::vector<std::string> LiveInput::takeWarnings() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::string> out;
  out.swap(warnings_);
  return out;
}

std::vector<std::pair<int, std::string>> LiveInput::take() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::pair<int, std::string>> out;
  out.swap(lines_);
  return out;
}

bool LiveInput::open() const {
  if (!eof_.load()) return true;
  std::lock_guard<std::mutex> lock(mutex_);
  return !lines_.empty();
}

std::string EventApplier::apply(World& w, const EventDef& e) {
  using T = EventDef::Type;
  try {
    switch (e.type) {
      case T::Force: {
        UserForce f;
        f.point = e.point;
        f.radius = e.radius;
        f.strength = e.strength;
        forces_[e.id] = f;
        break;
      }
      case T::Release:
        if (e.id < 0) forces_.clear();
        else forces_.erase(e.id);
        break;
      case T::Block: w.addBlock(e.block); break;
      case T::Drop: w.addDrop(e.point, e.radius, e.velocity); break;
      case T::Emitter:
        if (e.hasPoint || e.hasDirection) {
          const EmitterDef& cur = w.emitter(e.index);
          w.moveEmitter(e.index, e.hasPoint ? e.point : cur.position, e.hasDirection ? e.direction : cur.direction);
        }
        if (e.hasEnabled) w.setEmitterEnabled(e.index, e.enabled);
        break;
      case T::Gravity: w.setGravity(e.gravity); break;
      case T::Effect: w.setEffectEnabled(e.effect, e.enabled); break;
      case T::Pause:
        paused_ = true;
        pauseSeconds_ = e.seconds;
        break;
      case T::Resume: paused_ = false; break;
    }
    if (e.type == T::Force || e.type == T::Release) {
      std::vector<UserForce> list;
      for (const auto& f : forces_) list.push_back(f.second);
      w.setUserForces(list);
    }
  } catch (const std::exception& ex) {
    return ex.what();
  }
  return "";
}

std::string describeEvent(const EventDef& e) {
  using T = EventDef::Type;
  std::ostringstream o;
  o.precision(4);
  auto v = [&](const Vec2d& p) {
    std::ostringstream s;
    s.precision(4);
    s << "(" << p.x() << ", " << p.y() << ")";
    return s.str();
  };
  o << eventTypeName(e.type);
  switch (e.type) {
    case T::Force:
      o << " " << e.id << " at " << v(e.point) << ", radius " << e.radius << " m, " << e.strength << " m/s²";
      break;
    case T::Release: o << (e.id < 0 ? " all forces" : " force " + std::to_string(e.id)); break;
    case T::Block: o << " " << v(e.block.min) << " – " << v(e.block.max); break;
    case T::Drop: o << " at " << v(e.point) << ", radius " << e.radius << " m"; break;
    case T::Emitter:
      o << " " << e.index;
      if (e.hasEnabled) o << (e.enabled ? " on" : " off");
      if (e.hasPoint) o << " at " << v(e.point);
      if (e.hasDirection) o << " towards " << v(e.direction);
      break;
    case T::Gravity: o << " " << v(e.gravity) << " m/s²"; break;
    case T::Effect: o << " " << e.effect << (e.enabled ? " on" : " off"); break;
    case T::Pause:
      if (e.seconds > 0) o << " " << e.seconds << " s";
      break;
    case T::Resume: break;
  }
  return o.str();
}

}  // namespace sph2d::cli
