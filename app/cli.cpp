// app/cli.cpp — command-line helpers shared by the sph2d commands; see cli.hpp.
#include "cli.hpp"

#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <semaphore.h>
#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <thread>

namespace sph2d::cli {

std::atomic<bool> stopRequested{false};
std::atomic<bool> signalReceived{false};

namespace {
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handlers use atomic<bool>");
sem_t watchdogWake;  ///< posted by the first signal (sem_post is async-signal-safe)

/// Writes a message with write(2) (async-signal-safe, unlike stdio) and ends the process.
[[noreturn]] void exitNow(const char* msg, std::size_t n) {
  const ssize_t w = ::write(2, msg, n);
  (void)w;
  ::_exit(130);
}
extern "C" void onSignal(int) {
  if (signalReceived.exchange(true)) {
    static const char msg[] = "sph2d: second SIGINT/SIGTERM: exiting now\n";
    exitNow(msg, sizeof msg - 1);
  }
  stopRequested.store(true);
  sem_post(&watchdogWake);
}
extern "C" void onSignalExit(int) {
  static const char msg[] = "sph2d: interrupted (SIGINT or SIGTERM)\n";
  exitNow(msg, sizeof msg - 1);
}
/// Waits for the first signal, then gives the command kStopGraceSeconds to end on its own.
void watchdog() {
  while (sem_wait(&watchdogWake) != 0) {
  }
  timespec left{0, long(kStopGraceSeconds * 1e9)};
  while (nanosleep(&left, &left) != 0) {
  }
  static const char msg[] =
      "sph2d: still busy 0.8 s after SIGINT/SIGTERM: exiting now (exit 130; the files "
      "written are whole)\n";
  exitNow(msg, sizeof msg - 1);
}
void setHandler(int sig, void (*fn)(int)) {
  struct sigaction sa {};
  sa.sa_handler = fn;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(sig, &sa, nullptr);
}
}  // namespace

void installStopHandler() {
  static const bool started = [] {
    sem_init(&watchdogWake, 0, 0);
    std::thread(watchdog).detach();
    return true;
  }();
  (void)started;
  setHandler(SIGINT, onSignal);
  setHandler(SIGTERM, onSignal);
}

void installExitHandler() {
  setHandler(SIGINT, onSignalExit);
  setHandler(SIGTERM, onSignalExit);
}

double parseBytes(const std::string& flag, const std::string& v) {
  char* end = nullptr;
  errno = 0;
  double x = std::strtod(v.c_str(), &end);
  std::string unit = end ? std::string(end) : std::string();
  if (!unit.empty() && (unit.back() == 'B' || unit.back() == 'b')) unit.pop_back();
  double scale = 1;
  if (unit == "K" || unit == "k")
    scale = 1e3;
  else if (unit == "M" || unit == "m")
    scale = 1e6;
  else if (unit == "G" || unit == "g")
    scale = 1e9;
  else if (!unit.empty())
    x = -1;
  if (v.empty() || errno || !(x > 0) || !std::isfinite(x * scale))
    throw UsageError(flag + " expects a size such as 512M or 2G (bytes, K, M or G), got '" + v + "'");
  return x * scale;
}

double availableMemoryBytes() {
  double avail = 0;
  {
    std::ifstream in("/proc/meminfo");
    std::string key;
    double kb = 0;
    std::string unit;
    while (in >> key >> kb >> unit)
      if (key == "MemAvailable:") {
        avail = kb * 1024;
        break;
      }
  }
  // A container's limit (cgroup v2), when it is lower.
  std::ifstream maxIn("/sys/fs/cgroup/memory.max"), curIn("/sys/fs/cgroup/memory.current");
  std::string maxText;
  double cur = 0;
  if (maxIn >> maxText && maxText != "max" && curIn >> cur) {
    const double left = std::strtod(maxText.c_str(), nullptr) - cur;
    if (left > 0 && (avail == 0 || left < avail)) avail = left;
  }
  return avail;
}

double estimateRunBytes(const SceneDef& scene, bool images) {
  return estimateWorldBytes(scene) + (images ? Renderer::estimateBytes(scene.render.width, scene.render.height) : 0.0);
}

void checkMemory(const SceneDef& scene, bool images, double limit) {
  const bool given = limit > 0;
  if (!given) limit = availableMemoryBytes();
  const double need = estimateRunBytes(scene, images);
  if (!(limit > 0) || need <= limit) return;
  std::ostringstream o;
  o.setf(std::ios::fixed);
  o.precision(0);
  o << "the scene would hold about " << need / 1e6 << " MB at its peak (" << peakParticles(scene)
    << " particles: its blocks, emitters and timeline, capped by the particle budget"
    << (images ? "; the renderer and its images" : "") << "), more than "
    << (given ? "--max-memory" : "the memory available") << " (" << limit / 1e6
    << " MB); use a larger spacing, a lower max_particles or effects.budget"
    << (given ? ", or raise --max-memory" : "");
  throw UsageError(o.str());
}

ArgReader::ArgReader(const std::vector<std::string>& args, std::string command)
    : args_(args), command_(std::move(command)) {}

bool ArgReader::next() {
  ++i_;
  if (i_ >= args_.size()) return false;
  flag_ = args_[i_];
  return true;
}

std::string ArgReader::value() {
  if (i_ + 1 >= args_.size()) throw UsageError(flag_ + " needs a value");
  return args_[++i_];
}

std::string ArgReader::valueOr(std::string otherwise) {
  if (i_ + 1 < args_.size() && args_[i_ + 1].rfind("--", 0) != 0) return args_[++i_];
  return otherwise;
}

int ArgReader::intValue(int lo, int hi) {
  const std::string flag = flag_;
  return parseInt(flag, value(), lo, hi);
}

double ArgReader::numberValue() {
  const std::string flag = flag_;
  return parseNumber(flag, value());
}

double ArgReader::bytesValue() {
  const std::string flag = flag_;
  return parseBytes(flag, value());
}

std::vector<int> ArgReader::intListValue(int lo, int hi) {
  const std::string flag = flag_;
  return parseIntList(flag, value(), lo, hi);
}

std::vector<std::string> ArgReader::listValue() { return splitList(value()); }

void ArgReader::unknown() const {
  throw UsageError("unknown option '" + arg() + "' (see sph2d " + command_ + " --help)");
}

void ArgReader::unexpected() const { throw UsageError("unexpected argument '" + arg() + "'"); }

int parseInt(const std::string& flag, const std::string& v, int lo, int hi) {
  char* end = nullptr;
  errno = 0;
  const long x = std::strtol(v.c_str(), &end, 10);
  if (v.empty() || *end || errno || x < lo || x > hi)
    throw UsageError(flag + " expects an integer from " + std::to_string(lo) + " to " + std::to_string(hi) + ", got '" +
                     v + "'");
  return int(x);
}

double parseNumber(const std::string& flag, const std::string& v) {
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  if (v.empty() || *end || !std::isfinite(x)) throw UsageError(flag + " expects a number, got '" + v + "'");
  return x;
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

const char* kRenderFlagsHelp =
    "  --mode M        liquid (default: the scene's) or particles\n"
    "  --color-by F    particles mode: speed (default), pressure, density, age, material (each\n"
    "                  particle in its material's colour) or color (the particles' own colours,\n"
    "                  setParticleColor; without one, the material's or the fluid's colour)\n"
    "  --range LO,HI   particles mode: fixed colour range (default: each frame's min..max)\n"
    "  --overlay       draw frame number, simulated time and particle count\n"
    "  --outline       draw the fluid's outline (World::surfaceCurves) over it\n"
    "  --foam-speed V  liquid: foam starts at V m/s, full at 2V (default 0.35·sqrt(g·view height))\n"
    "  --depth-scale D liquid: D metres of water above darken the colour by 1/e (default 1)\n"
    "  --splat P       liquid: where the field is summed: cpu, gl (point sprites) or auto (the\n"
    "                  default: cpu when the OpenGL is a software rasterizer such as llvmpipe)\n";

bool parseRenderFlag(ArgReader& a, RenderOptions& o) {
  const std::string s = a.arg();
  auto value = [&]() { return a.value(); };
  if (s == "--mode") {
    o.mode = value();
    if (o.mode != "liquid" && o.mode != "particles")
      throw UsageError("--mode expects liquid or particles, got '" + o.mode + "'");
  } else if (s == "--color-by") {
    const std::string v = value();
    if (!parseColorField(v, o.colorBy))
      throw UsageError("--color-by expects speed, pressure, density, age, material or color, got '" + v + "'");
  } else if (s == "--range") {
    const std::string v = value();
    const auto c = v.find(',');
    if (c == std::string::npos) throw UsageError("--range expects LO,HI, got '" + v + "'");
    const double lo = parseNumber(s, v.substr(0, c)), hi = parseNumber(s, v.substr(c + 1));
    if (!(hi > lo)) throw UsageError("--range needs HI > LO, got '" + v + "'");
    o.range = std::array<double, 2>{lo, hi};
  } else if (s == "--overlay") {
    o.overlay = true;
  } else if (s == "--outline") {
    o.outline = true;
  } else if (s == "--foam-speed") {
    o.foamSpeed = parseNumber(s, value());
    if (!(o.foamSpeed > 0)) throw UsageError("--foam-speed must be > 0");
  } else if (s == "--splat") {
    const std::string v = value();
    if (!parseSplatPath(v, o.splat)) throw UsageError("--splat expects auto, cpu or gl, got '" + v + "'");
  } else if (s == "--depth-scale") {
    o.depthScale = parseNumber(s, value());
    if (!(o.depthScale > 0)) throw UsageError("--depth-scale must be > 0");
  } else {
    return false;
  }
  return true;
}

}  // namespace sph2d::cli
