// app_util.hpp — helpers of the app tests: run the sph2d executable, read files,
// hash decoded PNGs. Each run logs to its own file, so CTest may run tests in parallel.
// Result, q and asset come from app_runner.hpp: one definition each in the test binary
// (two different inline q's broke the quoting of whichever test got the other one).
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app_runner.hpp"
#include "sph2d/hash.hpp"
#include "sph2d/render/png_io.hpp"

namespace sph2d::apptest {

namespace fs = std::filesystem;

/// A fresh, empty directory under the test build's tmp folder.
inline std::string freshDir(const std::string& name) {
  const std::string dir = std::string(SPH2D_TEST_TMP) + "/" + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

/// The whole text of a file ("" when missing).
inline std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Runs `sph2d ARGS` through the shell (optionally prefixed by environment assignments).
inline Result run(const std::string& args, const std::string& envPrefix = "") {
  static std::atomic<int> counter{0};
  fs::create_directories(SPH2D_TEST_TMP);
  const std::string log =
      std::string(SPH2D_TEST_TMP) + "/cmd_" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + ".log";
  const std::string cmd = envPrefix + " \"" + std::string(SPH2D_EXE) + "\" " + args + " > \"" + log + "\" 2>&1";
  const int status = std::system(cmd.c_str());
  Result r{WIFEXITED(status) ? WEXITSTATUS(status) : -1, readText(log)};
  fs::remove(log);
  return r;
}

/// XXH64 (hex) of a PNG's decoded RGBA pixels, as the manifest records them.
inline std::string pngHash(const std::string& path) {
  int w = 0, h = 0;
  std::vector<std::uint8_t> rgba;
  readPng(path, w, h, rgba);
  return hex64(xxh64(rgba.data(), rgba.size()));
}

/// Names of the files in `dir` ending with `suffix`, sorted.
inline std::vector<std::string> filesEnding(const std::string& dir, const std::string& suffix) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.size() >= suffix.size() && n.compare(n.size() - suffix.size(), suffix.size(), suffix) == 0) out.push_back(n);
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// True when a file name in `dir` contains ".tmp" (a write that was not finished).
/// The cells of one CSV line (no quoting: sph2d's CSVs hold numbers and plain names).
inline std::vector<std::string> csvCells(const std::string& line) {
  std::vector<std::string> f;
  std::stringstream ls(line);
  std::string cell;
  while (std::getline(ls, cell, ',')) f.push_back(cell);
  return f;
}

inline bool anyTemporary(const std::string& dir) {
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp") != std::string::npos) return true;
  return false;
}

}  // namespace sph2d::apptest
