// tests/serve/test_browser.cpp — `sph2d serve` in a real browser: Debian's headless Chromium,
// driven through the DevTools protocol (a WebSocket to the page target, Boost.Beast), loads
// the page, and the test checks that the screenshot shows the liquid, that a synthetic mouse
// drag on the page reaches the record as `force` events (a click as a drop, the left arrow as a
// gravity tilt), and that replaying the record with
// `sph2d run --input` gives the frame and state hashes of the live frames.
//
// Design: no Node, no Python packages: the DevTools client is ~60 lines over the same Beast
// the server uses. Chromium runs in its own process group (killed as a group at the end).
// Without /usr/bin/chromium (or $SPH2D_CHROMIUM) the test fails and says to install it
// (./test.sh installs it through .ci/setup.sh). SPH2D_BROWSER_SCENE picks another scene and
// SPH2D_BROWSER_SHOT copies the screenshot there, SPH2D_BROWSER_SETTLE waits that many more
// seconds before it (how docs/images/serve_page.png was made, README.md).
#include <doctest/doctest.h>
#include <fcntl.h>

#include <cstdlib>
#include <filesystem>

#include "serve_fixture.hpp"

using namespace sph2d::servetest;
using sph2d::apptest::asset;
using sph2d::apptest::scratch;

namespace {

std::string base64Decode(const std::string& in) {
  static const std::string chars = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  int val = 0, bits = -8;
  for (char c : in) {
    const auto pos = chars.find(c);
    if (pos == std::string::npos) continue;  // '=' and whitespace
    val = (val << 6) + int(pos);
    bits += 6;
    if (bits >= 0) {
      out.push_back(char((val >> bits) & 0xFF));
      bits -= 8;
    }
  }
  return out;
}

/// Headless Chromium with a DevTools port, in its own process group.
struct Chromium {
  pid_t pid = -1;
  int port = 0;
  explicit Chromium(const std::string& exe, const std::string& dir) {
    const std::string log = dir + "/chromium.log";
    pid = fork();
    if (pid == 0) {
      setpgid(0, 0);
      const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(fd, 1);
      ::dup2(fd, 2);
      const std::string profile = "--user-data-dir=" + dir + "/profile";
      std::vector<std::string> args{exe,
                                    "--headless",
                                    "--no-sandbox",
                                    "--disable-gpu",
                                    "--disable-background-networking",
                                    "--no-first-run",
                                    "--remote-debugging-port=0",
                                    "--window-size=1000,760",
                                    "--disable-extensions",
                                    profile,
                                    "about:blank"};
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      execv(exe.c_str(), argv.data());
      _exit(127);
    }
    setpgid(pid, pid);
    const std::regex re("DevTools listening on ws://127\\.0\\.0\\.1:([0-9]+)/");
    waitFor(
        [&] {
          std::smatch m;
          const std::string text = slurp(log);
          if (std::regex_search(text, m, re)) port = std::stoi(m[1]);
          return port != 0;
        },
        60000ms);
  }
  ~Chromium() {
    if (pid > 0) {
      ::kill(-pid, SIGKILL);
      int st;
      ::waitpid(pid, &st, 0);
    }
  }
};

/// A DevTools protocol session on one page target.
class Cdp {
 public:
  Cdp(int port, const std::string& path) : ws_(ioc_) {
    sc::tcp::resolver resolver(ioc_);
    sc::beast::get_lowest_layer(ws_).connect(resolver.resolve("127.0.0.1", std::to_string(port)));
    ws_.handshake("127.0.0.1:" + std::to_string(port), path);
    ws_.read_message_max(256u << 20);
  }
  /// Sends one command and waits (at most 60 s) for its result; events in between are skipped.
  nlohmann::json call(const std::string& method, nlohmann::json params = nlohmann::json::object()) {
    const int id = ++id_;
    const std::string text = nlohmann::json{{"id", id}, {"method", method}, {"params", params}}.dump();
    ws_.text(true);
    ws_.write(sc::net::buffer(text));
    for (;;) {
      sc::beast::flat_buffer buf;
      sc::beast::error_code ec;
      bool done = false;
      ws_.async_read(buf, [&](sc::beast::error_code e, std::size_t) {
        ec = e;
        done = true;
      });
      ioc_.restart();
      ioc_.run_for(60s);
      if (!done) throw std::runtime_error("DevTools: no answer to " + method);
      if (ec) throw boost::system::system_error(ec);
      const auto j = nlohmann::json::parse(sc::beast::buffers_to_string(buf.data()));
      if (j.value("id", 0) != id) continue;
      if (j.contains("error")) throw std::runtime_error("DevTools " + method + ": " + j["error"].dump());
      return j["result"];
    }
  }
  /// Evaluates a JavaScript expression in the page and returns its value.
  nlohmann::json eval(const std::string& expr) {
    const auto r = call("Runtime.evaluate", {{"expression", expr}, {"returnByValue", true}});
    return r.contains("result") && r["result"].contains("value") ? r["result"]["value"] : nlohmann::json();
  }
  /// One mouse event at (x, y) in CSS pixels.
  void mouse(const std::string& type, double x, double y, int buttons) {
    call("Input.dispatchMouseEvent",
         {{"type", type}, {"x", x}, {"y", y}, {"button", "left"}, {"buttons", buttons}, {"clickCount", 1}});
  }

 private:
  sc::net::io_context ioc_;
  sc::websocket::stream<sc::beast::tcp_stream> ws_;
  int id_ = 0;
};

}  // namespace

TEST_CASE(
    "browser: headless Chromium shows the liquid, a mouse drag is recorded as force, the record replays the live hashes") {
  const char* envExe = std::getenv("SPH2D_CHROMIUM");
  const std::string exe = envExe ? envExe : "/usr/bin/chromium";
  REQUIRE_MESSAGE(std::filesystem::exists(exe),
                  "Chromium is missing (" << exe
                                          << "): install Debian's chromium (apt-get install chromium; "
                                             "./test.sh installs it through .ci/setup.sh) or set SPH2D_CHROMIUM");
  const std::string dir = scratch("browser");
  const char* envScene = std::getenv("SPH2D_BROWSER_SCENE");
  const std::string scene = envScene ? envScene : asset("scenes/tests/small_dam_break.json");
  const std::string rec = dir + "/rec.jsonl";
  Server s(scene, {"--record", rec, "--threads", "1"}, dir + "/serve.log");
  REQUIRE_MESSAGE(s.port > 0, slurp(s.log));

  Chromium browser(exe, dir);
  REQUIRE_MESSAGE(browser.port > 0, slurp(dir + "/chromium.log"));
  const auto list =
      nlohmann::json::parse(sc::httpRequest("127.0.0.1", browser.port, sc::http::verb::get, "/json/list").body);
  std::string pagePath;
  for (const auto& t : list)
    if (t.value("type", "") == "page") {
      const std::string url = t.value("webSocketDebuggerUrl", "");
      pagePath = url.substr(url.find("/devtools/"));
      break;
    }
  REQUIRE(!pagePath.empty());
  Cdp cdp(browser.port, pagePath);
  cdp.call("Page.enable");
  cdp.call("Page.navigate", {{"url", "http://127.0.0.1:" + std::to_string(s.port) + "/"}});
  // The page is live once it has drawn frames (its `meta` is the last frame's overlay data).
  REQUIRE(waitFor([&] {
    const auto v = cdp.eval("typeof meta !== 'undefined' && meta && received > 5 ? meta.frame : -1");
    return v.is_number() && v.get<int>() > 0;
  }));
  // SPH2D_BROWSER_SETTLE: seconds more before the screenshot (for the documentation's picture).
  if (const char* settle = std::getenv("SPH2D_BROWSER_SETTLE"))
    std::this_thread::sleep_for(std::chrono::duration<double>(std::atof(settle)));
  const auto rect = cdp.eval("JSON.stringify(view.getBoundingClientRect())");
  REQUIRE(rect.is_string());
  const auto r = nlohmann::json::parse(rect.get<std::string>());
  const double cx = r["x"], cy = r["y"], cw = r["width"], ch = r["height"];
  CHECK(cw > 100);
  CHECK(cdp.eval("document.getElementById('overlay').textContent").get<std::string>().find("particles") !=
        std::string::npos);

  // The screenshot: the page, with the water's blue in the frame's rectangle.
  const auto shot = cdp.call("Page.captureScreenshot", {{"format", "png"}});
  int w = 0, h = 0;
  std::vector<std::uint8_t> rgba;
  decodePng(base64Decode(shot["data"].get<std::string>()), dir + "/screenshot.png", w, h, rgba);
  REQUIRE(w >= int(cx + cw));
  REQUIRE(h >= int(cy + ch));
  const double blue = blueFraction(rgba, w, int(cx), int(cy), int(cx + cw), int(cy + ch));
  MESSAGE("blue (water) fraction of the frame's rectangle in the screenshot: " << blue);
  CHECK(blue > 0.05);
  if (const char* copy = std::getenv("SPH2D_BROWSER_SHOT"))
    std::filesystem::copy_file(dir + "/screenshot.png", copy, std::filesystem::copy_options::overwrite_existing);

  // A synthetic drag across the lower half of the frame: mouse down, moves, up.
  const double y = cy + 0.75 * ch;
  cdp.mouse("mousePressed", cx + 0.2 * cw, y, 1);
  for (int i = 1; i <= 12; ++i) {
    cdp.mouse("mouseMoved", cx + (0.2 + 0.05 * i) * cw, y, 1);
    std::this_thread::sleep_for(40ms);
  }
  cdp.mouse("mouseReleased", cx + 0.8 * cw, y, 0);
  REQUIRE(waitFor([&] {
    const std::string t = slurp(rec);
    return t.find("\"type\":\"force\"") != std::string::npos && t.find("\"type\":\"release\"") != std::string::npos;
  }));
  CHECK(slurp(rec).find("\"source\":\"live\"") != std::string::npos);

  // A click without a drag drops water; the left arrow tilts gravity.
  const std::size_t before = s.state().value("particles", std::size_t(0));
  cdp.mouse("mousePressed", cx + 0.6 * cw, cy + 0.3 * ch, 1);
  cdp.mouse("mouseReleased", cx + 0.6 * cw, cy + 0.3 * ch, 0);
  cdp.call("Input.dispatchKeyEvent",
           {{"type", "keyDown"}, {"key", "ArrowLeft"}, {"code", "ArrowLeft"}, {"windowsVirtualKeyCode", 37}});
  cdp.call("Input.dispatchKeyEvent",
           {{"type", "keyUp"}, {"key", "ArrowLeft"}, {"code", "ArrowLeft"}, {"windowsVirtualKeyCode", 37}});
  REQUIRE(waitFor([&] {
    const std::string t = slurp(rec);
    return t.find("\"type\":\"drop\"") != std::string::npos && t.find("\"type\":\"gravity\"") != std::string::npos;
  }));
  CHECK(waitFor([&] { return s.state().value("particles", std::size_t(0)) > before; }));

  // Live frames after the drag, as a client receives them, then the replay of the record.
  sc::WsClient c("127.0.0.1", s.port);
  std::vector<nlohmann::json> live;
  while (live.size() < 10) {
    auto m = c.read(30000ms);
    REQUIRE(m);
    if (m->frame) live.push_back(m->header);
  }
  CHECK(s.stop() == 130);
  checkReplay(scene, rec, live, dir);
}
