// render_env.cpp — environment pinning and the CPU probe (see sph2d/render/render_env.hpp).
//
// Design: the list of variables below is the measured set (docs/RENDERING.md, "Determinism"):
// those that change pixels or make a run read the user's home are pinned when unset, the rest
// are only recorded. Pinning happens once per process under a mutex, before any context.
#include "sph2d/render/render_env.hpp"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <mutex>

namespace sph2d {
namespace {

// Environment variables recorded in manifests. Values that sph2d pins when unset come first.
struct EnvPin {
  const char* name;
  const char* pinned;  // nullptr: record only
};
const EnvPin kEnv[] = {
    {"GALLIUM_DRIVER", "llvmpipe"},         // softpipe rasterises point sprites differently
    {"MESA_SHADER_CACHE_DISABLE", "true"},  // hermetic runs: nothing read from or written to ~/.cache
    // Pixels are identical for 0, 1, 2 and 8 (docs/RENDERING.md). 0 rasterises on the GL
    // thread: the simulation's threads already hold the cores, and llvmpipe's own threads
    // only add hand-offs (the demo on 2 cores, median of paired rounds: 4.2 s with 0, 4.5 s
    // with 2; the figures in docs/RENDERING.md).
    {"LP_NUM_THREADS", "0"},
    {"LP_NATIVE_VECTOR_WIDTH", nullptr},     // measured: 128 and 256 give identical pixels
    {"GALLIUM_OVERRIDE_CPU_CAPS", nullptr},  // changes pixels when it removes AVX/FMA (measured)
    {"LP_DEBUG", nullptr},
    {"LP_PERF", nullptr},
    {"MESA_LOADER_DRIVER_OVERRIDE", nullptr},
};

}  // namespace

std::vector<EnvSetting> pinRenderEnvironment() {
  static std::mutex m;
  static std::vector<EnvSetting> record;
  std::lock_guard<std::mutex> lock(m);
  if (record.empty()) {
    for (const EnvPin& e : kEnv) {
      const char* v = std::getenv(e.name);
      if (v)
        record.push_back({e.name, v, "user"});
      else if (e.pinned) {
        setenv(e.name, e.pinned, 1);
        record.push_back({e.name, e.pinned, "sph2d"});
      } else {
        record.push_back({e.name, "", "unset"});
      }
    }
  }
  return record;
}

std::vector<std::string> recordedEnvironmentNames() {
  std::vector<std::string> names;
  for (const EnvPin& e : kEnv) names.push_back(e.name);
  return names;
}

std::string cpuSummary() {
  std::ifstream in("/proc/cpuinfo");
  std::string line, model, flags;
  while (std::getline(in, line) && (model.empty() || flags.empty())) {
    auto value = [&] {
      const auto c = line.find(':');
      return c == std::string::npos ? std::string() : line.substr(std::min(line.size(), c + 2));
    };
    if (model.empty() && line.rfind("model name", 0) == 0) model = value();
    if (flags.empty() && line.rfind("flags", 0) == 0) flags = " " + value() + " ";
  }
  std::string out = model.empty() ? "unknown CPU" : model;
  out += ";";
  for (const char* f : {"sse4_1", "avx", "avx2", "fma", "f16c", "avx512f"})
    if (flags.find(std::string(" ") + f + " ") != std::string::npos) out += std::string(" ") + f;
  return out;
}

}  // namespace sph2d
