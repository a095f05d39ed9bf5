// `sph2d bench serve`: what a running `sph2d serve` delivers to one WebSocket client.
//
// Connects one client to ws://HOST:PORT/ws and reads frames for --seconds: frames per
// second delivered, their size, and the largest gap. Meanwhile, every --seconds/--drops,
// it POSTs a drop to /event and times the latency from the request to the first frame
// whose overlay data shows the particle count changed (the drop is in that frame: events
// apply at the boundary before it is rendered). A benchmark, not a test: the figures go
// to docs/PERFORMANCE.md, with benchmarks/serve.sh starting the server.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <vector>

#include "cli.hpp"
#include "commands.hpp"
#include "serve/serve_client.hpp"

namespace sph2d::cli {

int cmdBenchServe(const std::vector<std::string>& a) {
  std::string host = "127.0.0.1", csv;
  int port = 8080, drops = 10;
  double seconds = 20, radius = 0.08;
  for (ArgReader opt(a, "bench serve"); opt.next();) {
    const std::string s = opt.arg();
    if (opt.is("--host"))
      host = opt.value();
    else if (opt.is("--port"))
      port = opt.intValue(1, 65535);
    else if (opt.is("--seconds"))
      seconds = opt.numberValue();
    else if (opt.is("--drops"))
      drops = opt.intValue(0, 10000);
    else if (opt.is("--radius"))
      radius = opt.numberValue();
    else if (opt.is("--csv"))
      csv = opt.value();
    else if (opt.help()) {
      std::printf(
          "Usage: sph2d bench serve [--host H] [--port P] [--seconds S] [--drops N] [--radius R] [--csv FILE]\n"
          "Connects one WebSocket client to a running `sph2d serve` for S seconds (default 20) and prints\n"
          "the frames per second it received; POSTs N drops (default 10, radius R m, default 0.08) and\n"
          "prints the latency from each POST to the first frame showing it. --csv FILE: one row per\n"
          "measurement (kind,index,value).\n");
      return 0;
    } else
      throw UsageError("unknown option '" + s +
                       "' for bench serve; options: --host, --port, --seconds, --drops, --radius, --csv");
  }
  if (!(seconds > 0)) throw UsageError("--seconds must be > 0");
  using clock = std::chrono::steady_clock;
  namespace sc = serveclient;
  sc::WsClient ws(host, port);
  const auto start = clock::now();
  const auto end = start + std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(seconds));
  std::uint64_t frames = 0, bytes = 0, firstSeq = 0, lastSeq = 0;
  std::size_t particles = 0;
  std::vector<double> camera;
  std::vector<double> latencies, gaps;
  clock::time_point lastAt{}, dropAt{};
  bool waiting = false;
  int dropsSent = 0;
  const double dropEvery = drops > 0 ? seconds / (drops + 1) : 1e30;
  std::ofstream out;
  if (!csv.empty()) {
    out.open(csv);
    if (!out) throw UsageError("cannot write --csv " + csv);
    out << "kind,index,value\n";
  }
  while (clock::now() < end) {
    auto m = ws.read(std::chrono::milliseconds(10000));
    if (!m) throw std::runtime_error("no frame from the server for 10 s");
    if (!m->frame) continue;
    const auto& h = m->header;
    ++frames;
    bytes += m->image.size();
    const std::uint64_t seq = h.value("seq", std::uint64_t(0));
    if (!firstSeq) firstSeq = seq;
    lastSeq = seq;
    if (lastAt != clock::time_point{})
      gaps.push_back(std::chrono::duration<double, std::milli>(m->at - lastAt).count());
    lastAt = m->at;
    const std::size_t p = h.value("particles", std::size_t(0));
    if (camera.empty() && h.contains("camera") && h["camera"].size() == 4)
      camera = h["camera"].get<std::vector<double>>();
    if (waiting && p != particles) {
      const double ms = std::chrono::duration<double, std::milli>(m->at - dropAt).count();
      latencies.push_back(ms);
      if (out) out << "latency_ms," << latencies.size() << "," << ms << "\n";
      waiting = false;
    }
    particles = p;
    const double t = std::chrono::duration<double>(m->at - start).count();
    if (!waiting && dropsSent < drops && !camera.empty() && t >= dropEvery * (dropsSent + 1)) {
      // A drop near the top of the view, alternating left and right of the middle.
      const double x = camera[0] + (dropsSent % 2 ? 0.6 : 0.4) * (camera[2] - camera[0]);
      const double y = camera[1] + 0.8 * (camera[3] - camera[1]);
      const std::string ev = "{\"type\":\"drop\",\"center\":[" + std::to_string(x) + "," + std::to_string(y) +
                             "],\"radius\":" + std::to_string(radius) + "}";
      dropAt = clock::now();
      const auto r = sc::httpRequest(host, port, sc::http::verb::post, "/event", ev);
      if (r.status != 200) throw std::runtime_error("POST /event answered " + std::to_string(r.status) + ": " + r.body);
      waiting = true;
      ++dropsSent;
    }
  }
  const double wall = std::chrono::duration<double>(lastAt - start).count();
  const double fps = wall > 0 ? double(frames - 1) / wall : 0;
  std::sort(gaps.begin(), gaps.end());
  std::vector<double> lat = latencies;
  std::sort(lat.begin(), lat.end());
  auto pct = [](const std::vector<double>& v, double q) {
    return v.empty() ? 0.0 : v[std::size_t(q * double(v.size() - 1) + 0.5)];
  };
  std::printf(
      "frames received: %llu in %.1f s = %.1f frames/s (server frames %llu..%llu: %llu skipped for this client)\n",
      static_cast<unsigned long long>(frames), wall, fps, static_cast<unsigned long long>(firstSeq),
      static_cast<unsigned long long>(lastSeq),
      static_cast<unsigned long long>(lastSeq - firstSeq + 1 -
                                      std::min<std::uint64_t>(frames, lastSeq - firstSeq + 1)));
  std::printf("frame size: %.1f KB mean; gap between frames: median %.1f ms, 95%% %.1f ms, max %.1f ms\n",
              frames ? double(bytes) / double(frames) / 1e3 : 0.0, pct(gaps, 0.5), pct(gaps, 0.95),
              gaps.empty() ? 0.0 : gaps.back());
  std::printf(
      "input -> frame latency (POST /event drop -> first frame showing it): %zu of %d: min %.1f ms, median %.1f ms, max %.1f ms\n",
      lat.size(), dropsSent, lat.empty() ? 0.0 : lat.front(), pct(lat, 0.5), lat.empty() ? 0.0 : lat.back());
  std::printf("csv: fps,latency_median_ms,latency_max_ms,frame_kb\n%.2f,%.1f,%.1f,%.1f\n", fps, pct(lat, 0.5),
              lat.empty() ? 0.0 : lat.back(), frames ? double(bytes) / double(frames) / 1e3 : 0.0);
  if (out) {
    out << "fps,0," << fps << "\n";
    out << "frame_kb,0," << (frames ? double(bytes) / double(frames) / 1e3 : 0.0) << "\n";
  }
  return 0;
}

}  // namespace sph2d::cli
