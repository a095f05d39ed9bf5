// tests/serve/serve_fixture.hpp — starts a real `sph2d serve` on a free port for the serve
// and browser tests, talks to it (app/serve/serve_client.hpp: Boost.Beast) and stops it.
//
// Design: the server is the real executable on a real socket (--port 0: the kernel picks a
// free port, which the server prints on its first line); tests wait for conditions with
// generous deadlines and never assert on speed (a loaded machine may be slow).
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <doctest/doctest.h>

#include "app/app_runner.hpp"
#include "serve/serve_client.hpp"
#include "sph2d/render/png_io.hpp"

namespace sph2d::servetest {

namespace sc = sph2d::serveclient;
using namespace std::chrono_literals;

/// The text of a file ("" when it cannot be read).
inline std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Polls `cond` every 50 ms until it holds or `timeout` passes; returns its last value.
inline bool waitFor(const std::function<bool()>& cond, std::chrono::milliseconds timeout = 60000ms) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (cond()) return true;
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(50ms);
  }
}

/// A running `sph2d serve`.
struct Server {
  pid_t pid = -1;
  int port = 0;
  std::string log;

  /// Starts `sph2d serve SCENE --port 0 ARGS...`, its output into `log`, and waits for its address.
  Server(const std::string& scene, std::vector<std::string> args, const std::string& logPath) : log(logPath) {
    std::vector<std::string> all{"serve", scene, "--port", "0"};
    all.insert(all.end(), args.begin(), args.end());
    pid = apptest::spawnSph2d(all, log);
    const std::regex re("http://127\\.0\\.0\\.1:([0-9]+)/");
    waitFor([&] {
      std::smatch m;
      const std::string text = slurp(log);
      if (std::regex_search(text, m, re)) port = std::stoi(m[1]);
      int st;
      return port != 0 || ::waitpid(pid, &st, WNOHANG) == pid;
    });
  }
  ~Server() {
    if (pid > 0) {
      ::kill(pid, SIGKILL);
      int st;
      ::waitpid(pid, &st, 0);
    }
  }
  /// SIGTERM, then waits (at most `timeout`) for the exit code; -1 when it did not end
  /// (then it is killed) or ended by a signal.
  int stop(int sig = SIGTERM, std::chrono::milliseconds timeout = 20000ms) {
    ::kill(pid, sig);
    int st = 0;
    const bool ended = waitFor([&] { return ::waitpid(pid, &st, WNOHANG) == pid; }, timeout);
    if (!ended) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &st, 0);
    }
    pid = -1;
    return ended && WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  }
  /// GET /state as JSON (null when it fails).
  nlohmann::json state() const {
    try {
      const auto r = sc::httpRequest("127.0.0.1", port, sc::http::verb::get, "/state");
      return r.status == 200 ? nlohmann::json::parse(r.body, nullptr, false) : nlohmann::json();
    } catch (const std::exception&) {
      return nlohmann::json();
    }
  }
  /// POST /event with `body`.
  sc::HttpResult post(const std::string& body) const {
    return sc::httpRequest("127.0.0.1", port, sc::http::verb::post, "/event", body);
  }
};

/// The fraction of pixels of an RGBA image, within its rectangle [x0, x1) × [y0, y1), that are
/// the water's blue (the scene's default water colour 0.10, 0.45, 0.85 and its darker depths).
inline double blueFraction(const std::vector<std::uint8_t>& rgba, int width, int x0, int y0, int x1, int y1) {
  std::size_t blue = 0, all = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const std::uint8_t* p = &rgba[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 4];
      ++all;
      if (p[2] > 60 && p[2] > p[0] + 40 && p[2] >= p[1]) ++blue;
    }
  return all ? double(blue) / double(all) : 0;
}

/// Decodes PNG bytes (through a file: the renderer's readPng).
inline void decodePng(const std::string& bytes, const std::string& tmpPath, int& w, int& h,
                      std::vector<std::uint8_t>& rgba) {
  {
    std::ofstream out(tmpPath, std::ios::binary);
    out << bytes;
  }
  readPng(tmpPath, w, h, rgba);
}

/// The frames of a manifest by number: frame → (rgba_xxh64, state_hash).
inline std::map<std::int64_t, std::pair<std::string, std::string>> manifestHashes(const std::string& path) {
  std::map<std::int64_t, std::pair<std::string, std::string>> out;
  const nlohmann::json m = nlohmann::json::parse(slurp(path));
  for (const auto& f : m.at("frames"))
    out[f.at("frame").get<std::int64_t>()] = {f.at("rgba_xxh64"), f.at("state_hash")};
  return out;
}

/// Replays `record` with `sph2d run SCENE --input RECORD` (into DIR/replay) up to the last of
/// the `live` frames' headers and checks that each of them has the replay's frame and state hash.
inline void checkReplay(const std::string& scene, const std::string& record, const std::vector<nlohmann::json>& live,
                        const std::string& dir) {
  REQUIRE(!live.empty());
  const std::int64_t last = live.back()["frame"].get<std::int64_t>();
  const auto r =
      apptest::runSph2d("run " + apptest::q(scene) + " --input " + apptest::q(record) + " --frames " +
                        std::to_string(last + 1) + " --out " + apptest::q(dir + "/replay") + " --threads 2 --quiet");
  REQUIRE_MESSAGE(r.code == 0, r.out);
  const auto replay = manifestHashes(dir + "/replay/manifest.json");
  for (const auto& f : live) {
    const auto it = replay.find(f["frame"].get<std::int64_t>());
    REQUIRE(it != replay.end());
    CHECK(it->second.first == f["frame_hash"].get<std::string>());
    CHECK(it->second.second == f["state_hash"].get<std::string>());
  }
}

}  // namespace sph2d::servetest
