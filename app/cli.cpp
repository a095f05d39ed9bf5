#include "cli.hpp"

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "sph2d/world.hpp"

namespace sph2d::cli {

std::atomic<bool> stopRequested{false};

namespace {
extern "C" void onSignal(int) { stopRequested.store(true); }
}  // namespace

void installStopHandler() {
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
}

int parseInt(const std::string& flag, const std::string& v, int lo, int hi) {
  char* end = nullptr;
  errno = 0;
  const long x = std::strtol(v.c_str(), &end, 10);
  if (v.empty() || *end || errno || x < lo || x > hi)
    throw UsageError(flag + " expects an integer from " + std::to_string(lo) + " to " + std::to_string(hi) + ", got '" + v + "'");
  return int(x);
}

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

std::vector<int> parseIntList(const std::string& flag, const std::string& v, int lo, int hi) {
  std::vector<int> out;
  std::stringstream ss(v);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(parseInt(flag, item, lo, hi));
  if (out.empty()) throw UsageError(flag + " expects a comma-separated list of integers");
  return out;
}

void printProfile(const World& w) {
  double total = 0;
  for (const auto& t : w.timings()) total += t.seconds;
  std::printf("%-16s %10s %10s %8s %7s\n", "stage", "calls", "seconds", "ms/call", "share");
  for (const auto& t : w.timings())
    std::printf("%-16s %10llu %10.3f %8.4f %6.1f%%\n", t.name.c_str(), (unsigned long long)t.calls, t.seconds,
                t.calls ? 1e3 * t.seconds / double(t.calls) : 0.0, total > 0 ? 100.0 * t.seconds / total : 0.0);
}

}  // namespace sph2d::cli
