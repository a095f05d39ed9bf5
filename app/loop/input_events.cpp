#include "loop/input_events.hpp"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace sph2d::cli {

std::size_t addEventsFile(EventSchedule& schedule, const std::string& path, const SceneDef& scene, const WarnFn& warn,
                          std::size_t& skippedScene) {
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
        ++skippedScene;
        continue;
      }
      if (t.event.source.empty()) t.event.source = "file";
      t.frame = eventFrame(t.event, scene.fps);
      t.where = path + ":" + std::to_string(lineNo);
      schedule.add(std::move(t));
      ++n;
    } catch (const SceneError& e) {
      warn(std::string(e.what()) + " (line skipped)");
    }
  }
  return n;
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

}  // namespace sph2d::cli
