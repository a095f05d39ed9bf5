// app/serve/serve_server.cpp — Boost.Beast HTTP + WebSocket server of `sph2d serve`; see
// serve_server.hpp for the threads and the frame slots. Every handler runs on the one
// io thread; the encoder thread hands its messages over with net::post.
#include "serve/serve_server.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

namespace sph2d::cli {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

namespace {

/// A WebSocket message longer than this closes the connection (Beast: close code 1009);
/// between maxEventBytes and this, the client gets an error reply and stays.
constexpr std::size_t kHardMessageMax = std::size_t(1) << 20;
/// Replies to a client's own messages waiting to be written; one more and it is dropped.
constexpr std::size_t kMaxReplies = 32;
/// A frame write that has not completed after this long drops the client (it stopped reading).
constexpr auto kWriteStall = std::chrono::seconds(10);
/// HTTP connections at once (besides the WebSocket clients).
constexpr int kMaxHttp = 16;

std::string errorJson(const std::string& why) { return nlohmann::json{{"error", why}}.dump(); }
/// A refused event's reply: the error and its HTTP status.
std::string errorJson(const EventReply& r) { return nlohmann::json{{"error", r.error}, {"status", r.status}}.dump(); }

}  // namespace

class WsSession;

struct ServeServer::Impl {
  ServeConfig cfg;
  std::string page;
  ServeEventHandler onEvent;
  ServeStateFn state;
  std::optional<tcp::acceptor> acceptor;
  int boundPort = 0;
  std::thread ioThread, encoderThread;
  std::atomic<bool> stopped{false};

  // io thread only
  std::set<std::shared_ptr<WsSession>> clients;
  std::shared_ptr<const std::string> latest;  ///< the newest frame message
  std::uint64_t latestSeq = 0;
  int httpCount = 0;
  std::uint64_t pngSeq = 0;  ///< the raw frame the cached snapshot PNG shows
  std::string png;
  int nextClient = 0;

  // the raw frame slot (loop thread writes; encoder and io threads copy)
  std::mutex rawMutex;
  std::condition_variable rawCv;
  Frame raw;
  nlohmann::json rawMeta;
  std::uint64_t rawSeq = 0;
  bool stopping = false;
  std::atomic<int> wsCount{0};

  mutable std::mutex countMutex;
  ServeCounters counts;
  // Last: destroyed first, so the sessions its pending handlers hold die while the
  // members they touch (httpCount, the counters) still live. stop() drops the acceptor
  // and the clients before.
  net::io_context ioc{1};

  void accept();
  void encoderLoop();
  void deliver(std::shared_ptr<const std::string> msg, std::uint64_t seq);
  void wake() {
    { std::lock_guard<std::mutex> lock(rawMutex); }
    rawCv.notify_all();
  }
  void count(std::uint64_t ServeCounters::*field) {
    std::lock_guard<std::mutex> lock(countMutex);
    ++(counts.*field);
  }
  /// The latest frame as a PNG ("" when none was published yet).
  const std::string& snapshot();
};

/// One WebSocket client: reads events, writes replies and the newest frame, one write at a time.
class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(tcp::socket&& socket, ServeServer::Impl& s)
      : ws_(std::move(socket)), s_(s), stall_(s.ioc), name_("ws client " + std::to_string(++s.nextClient)) {}

  void run(http::request<http::string_body> req) {
    beast::get_lowest_layer(ws_).expires_never();  // the websocket's own timeouts from here
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.read_message_max(kHardMessageMax);
    ws_.auto_fragment(false);
    // Registered at once: the client counts against --max-clients from its upgrade on.
    s_.clients.insert(shared_from_this());
    ++s_.wsCount;
    s_.count(&ServeCounters::clients);
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return self->close();
      self->accepted_ = true;
      self->s_.wake();  // the encoder compresses the newest frame for it (even while paused)
      self->read();
      self->pump();
    });
  }

  /// A newer frame is there: sends it unless a write is under way (then after it).
  void offer() { pump(); }

  void close() {
    if (closed_) return;
    closed_ = true;
    stall_.cancel();
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ec);
    beast::get_lowest_layer(ws_).close();
    --s_.wsCount;
    s_.clients.erase(shared_from_this());
  }

 private:
  void read() {
    ws_.async_read(buf_, [self = shared_from_this()](beast::error_code ec, std::size_t n) { self->onRead(ec, n); });
  }

  void onRead(beast::error_code ec, std::size_t n) {
    if (ec) return close();  // closed, vanished, or over kHardMessageMax (Beast sent close 1009)
    std::string reply;
    if (!ws_.got_text()) {
      reply = errorJson("binary messages are not events: send one event as JSON text (docs/SCENES.md)");
    } else if (n > s_.cfg.maxEventBytes) {
      reply = errorJson("message of " + std::to_string(n) + " bytes is over the limit of " +
                        std::to_string(s_.cfg.maxEventBytes) + " bytes; nothing applied");
    } else {
      const std::string text = beast::buffers_to_string(buf_.data());
      const EventReply r = s_.onEvent(text, name_);
      reply = r.error.empty() ? std::string("{\"ok\":true}") : errorJson(r);
    }
    buf_.consume(buf_.size());
    if (buf_.capacity() > s_.cfg.maxEventBytes) buf_.shrink_to_fit();  // keep no oversized message's memory
    if (reply.rfind("{\"error\"", 0) == 0) s_.count(&ServeCounters::rejected);
    if (replies_.size() >= kMaxReplies) return close();  // it sends but never reads
    replies_.push_back(std::move(reply));
    pump();
    if (!closed_) read();
  }

  void pump() {
    if (writing_ || closed_ || !accepted_) return;
    std::shared_ptr<const std::string> msg;
    if (!replies_.empty()) {
      msg = std::make_shared<const std::string>(std::move(replies_.front()));
      replies_.pop_front();
      ws_.text(true);
    } else if (s_.latest && s_.latestSeq > sentSeq_) {
      msg = s_.latest;
      sentSeq_ = s_.latestSeq;
      ws_.binary(true);
      frame_ = true;
    } else {
      return;
    }
    writing_ = true;
    stall_.expires_after(kWriteStall);
    stall_.async_wait([w = weak_from_this()](beast::error_code ec) {
      if (ec) return;  // cancelled: the write completed
      if (auto self = w.lock()) self->close();
    });
    ws_.async_write(net::buffer(*msg), [self = shared_from_this(), msg](beast::error_code ec, std::size_t) {
      self->writing_ = false;
      self->stall_.cancel();
      if (ec) return self->close();
      if (self->frame_) self->s_.count(&ServeCounters::sent);
      self->frame_ = false;
      self->pump();
    });
  }

  websocket::stream<beast::tcp_stream> ws_;
  ServeServer::Impl& s_;
  net::steady_timer stall_;
  std::string name_;
  beast::flat_buffer buf_;
  std::deque<std::string> replies_;
  std::uint64_t sentSeq_ = 0;
  bool writing_ = false, frame_ = false, closed_ = false, accepted_ = false;
};

/// One HTTP connection: the page, the snapshot, the state, POST /event, or the upgrade to a WebSocket.
class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket&& socket, ServeServer::Impl& s) : stream_(std::move(socket)), s_(s) { ++s_.httpCount; }
  ~HttpSession() { --s_.httpCount; }

  void read() {
    parser_.emplace();
    parser_->header_limit(8192);
    parser_->body_limit(s_.cfg.maxEventBytes);
    stream_.expires_after(std::chrono::seconds(30));
    http::async_read(stream_, buf_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) { self->onRead(ec); });
  }

 private:
  using Response = http::response<http::string_body>;

  void onRead(beast::error_code ec) {
    if (ec == http::error::body_limit)
      return send(make(http::status::payload_too_large, "application/json",
                       errorJson("request body over the limit of " + std::to_string(s_.cfg.maxEventBytes) +
                                 " bytes; nothing applied")),
                  true);
    if (ec == http::error::header_limit)
      return send(make(http::status::request_header_fields_too_large, "application/json",
                       errorJson("request header over 8192 bytes")),
                  true);
    if (ec) return shutdown();
    http::request<http::string_body> req = parser_->release();
    std::string target(req.target());
    target = target.substr(0, target.find('?'));
    if (websocket::is_upgrade(req)) {
      if (target != "/ws")
        return send(make(http::status::not_found, "application/json", errorJson("WebSocket at /ws only")), true);
      if (s_.wsCount.load() >= s_.cfg.maxClients) {
        s_.count(&ServeCounters::refused);
        return send(make(http::status::service_unavailable, "application/json",
                         errorJson("too many clients: at most " + std::to_string(s_.cfg.maxClients) +
                                   " at once (--max-clients)")),
                    true);
      }
      std::make_shared<WsSession>(stream_.release_socket(), s_)->run(std::move(req));
      return;
    }
    Response res = handle(req, target);
    if (req.method() == http::verb::head) {  // GET's headers, without the body
      const std::size_t n = res.body().size();
      res.body().clear();
      res.content_length(n);
    }
    send(std::move(res), !req.keep_alive());
  }

  Response make(http::status status, const char* type, std::string body) {
    Response res{status, 11};
    res.set(http::field::server, "sph2d serve");
    res.set(http::field::content_type, type);
    res.set(http::field::cache_control, "no-store");
    res.body() = std::move(body);
    res.prepare_payload();
    return res;
  }

  Response handle(const http::request<http::string_body>& req, const std::string& target) {
    const auto method = req.method();
    const bool get = method == http::verb::get || method == http::verb::head;
    auto wrongMethod = [&](const char* allowed) {
      Response r = make(http::status::method_not_allowed, "application/json", errorJson(target + " allows " + allowed));
      r.set(http::field::allow, allowed);
      return r;
    };
    if (target == "/" || target == "/index.html") {
      if (!get) return wrongMethod("GET");
      return make(http::status::ok, "text/html; charset=utf-8", s_.page);
    }
    if (target == "/snapshot.png") {
      if (!get) return wrongMethod("GET");
      const std::string& png = s_.snapshot();
      if (png.empty())
        return make(http::status::service_unavailable, "application/json", errorJson("no frame rendered yet"));
      return make(http::status::ok, "image/png", png);
    }
    if (target == "/state") {
      if (!get) return wrongMethod("GET");
      return make(http::status::ok, "application/json", s_.state().dump());
    }
    if (target == "/event") {
      if (method != http::verb::post) return wrongMethod("POST");
      const EventReply r = s_.onEvent(req.body(), "POST /event");
      if (!r.error.empty()) {
        s_.count(&ServeCounters::rejected);
        const int code = r.status >= 400 && r.status < 500 ? r.status : 400;
        Response res = make(http::int_to_status(unsigned(code)), "application/json", errorJson(r));
        if (code == 429) res.set(http::field::retry_after, std::to_string(std::max(1L, long(std::ceil(r.retryAfter)))));
        return res;
      }
      return make(http::status::ok, "application/json", "{\"ok\":true}");
    }
    return make(http::status::not_found, "application/json",
                errorJson("not found: this server has /, /ws, /snapshot.png, /state and POST /event"));
  }

  void send(Response res, bool close) {
    auto sp = std::make_shared<Response>(std::move(res));
    sp->keep_alive(!close);
    http::async_write(stream_, *sp, [self = shared_from_this(), sp, close](beast::error_code ec, std::size_t) {
      if (ec || close) return self->shutdown();
      self->read();
    });
  }

  void shutdown() {
    beast::error_code ec;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
  }

  beast::tcp_stream stream_;
  ServeServer::Impl& s_;
  beast::flat_buffer buf_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

void ServeServer::Impl::accept() {
  acceptor->async_accept(net::make_strand(ioc), [this](beast::error_code ec, tcp::socket socket) {
    if (ec) {
      if (ec == net::error::operation_aborted || !acceptor->is_open()) return;
    } else if (httpCount >= kMaxHttp + cfg.maxClients) {
      count(&ServeCounters::refused);
      beast::error_code ignored;
      socket.close(ignored);
    } else {
      std::make_shared<HttpSession>(std::move(socket), *this)->read();
    }
    accept();
  });
}

const std::string& ServeServer::Impl::snapshot() {
  Frame copy;
  std::uint64_t seq;
  {
    std::lock_guard<std::mutex> lock(rawMutex);
    seq = rawSeq;
    if (seq == 0 || seq == pngSeq) return png;
    copy = raw;
  }
  png.clear();
  appendPng(copy.width, copy.height, copy.rgba.data(), png);
  pngSeq = seq;
  return png;
}

void ServeServer::Impl::encoderLoop() {
  std::uint64_t done = 0;
  Frame frame;
  nlohmann::json meta;
  for (;;) {
    std::uint64_t seq;
    {
      std::unique_lock<std::mutex> lock(rawMutex);
      rawCv.wait(lock, [&] { return stopping || (rawSeq != done && wsCount.load() > 0); });
      if (stopping) return;
      seq = rawSeq;
      frame.width = raw.width;
      frame.height = raw.height;
      frame.rgba.assign(raw.rgba.begin(), raw.rgba.end());
      meta = rawMeta;
    }
    const auto t0 = std::chrono::steady_clock::now();
    // One binary message: 4 bytes (big-endian) of header length, the header (the frame's
    // overlay data as JSON), then the image.
    meta["seq"] = seq;
    meta["format"] = imageFormatName(cfg.format);
    const std::string header = meta.dump();
    auto msg = std::make_shared<std::string>();
    msg->reserve(header.size() + 4 + frame.rgba.size() / 8);
    const std::uint32_t n = std::uint32_t(header.size());
    const char len[4] = {char(n >> 24), char(n >> 16), char(n >> 8), char(n)};
    msg->append(len, 4);
    msg->append(header);
    try {
      appendImage(cfg.format, frame.width, frame.height, frame.rgba.data(), cfg.jpegQuality, *msg);
    } catch (const std::exception&) {
      done = seq;  // a frame that cannot be encoded is skipped; the next one is tried
      continue;
    }
    {
      std::lock_guard<std::mutex> lock(countMutex);
      ++counts.encoded;
      counts.encodeSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    done = seq;
    net::post(ioc, [this, m = std::shared_ptr<const std::string>(std::move(msg)), seq] { deliver(m, seq); });
  }
}

void ServeServer::Impl::deliver(std::shared_ptr<const std::string> msg, std::uint64_t seq) {
  if (seq <= latestSeq) return;
  latest = std::move(msg);
  latestSeq = seq;
  const std::vector<std::shared_ptr<WsSession>> now(clients.begin(), clients.end());
  for (const auto& c : now) c->offer();
}

ServeServer::ServeServer(ServeConfig config, std::string page, ServeEventHandler onEvent, ServeStateFn state)
    : impl_(std::make_shared<Impl>()) {
  impl_->cfg = std::move(config);
  impl_->page = std::move(page);
  impl_->onEvent = std::move(onEvent);
  impl_->state = std::move(state);
}

ServeServer::~ServeServer() { stop(); }

void ServeServer::start() {
  Impl& s = *impl_;
  beast::error_code ec;
  const auto address = net::ip::make_address(s.cfg.bind, ec);
  if (ec) throw std::runtime_error("--bind expects an IP address (127.0.0.1, 0.0.0.0, ::1), got '" + s.cfg.bind + "'");
  const tcp::endpoint endpoint(address, static_cast<unsigned short>(s.cfg.port));
  const std::string where = s.cfg.bind + ":" + std::to_string(s.cfg.port);
  s.acceptor.emplace(s.ioc);
  auto check = [&](const char* what) {
    if (ec) throw std::runtime_error("cannot listen on " + where + " (" + what + "): " + ec.message());
  };
  s.acceptor->open(endpoint.protocol(), ec);
  check("open");
  s.acceptor->set_option(net::socket_base::reuse_address(true), ec);
  check("reuse_address");
  s.acceptor->bind(endpoint, ec);
  check("bind");
  s.acceptor->listen(net::socket_base::max_listen_connections, ec);
  check("listen");
  s.boundPort = s.acceptor->local_endpoint().port();
  s.accept();
  s.ioThread = std::thread([&s] {
    for (;;) {
      try {
        s.ioc.run();
        return;
      } catch (const std::exception&) {
        // A handler threw (e.g. bad_alloc on one connection): keep serving the others.
      }
    }
  });
  s.encoderThread = std::thread([&s] { s.encoderLoop(); });
}

int ServeServer::port() const { return impl_->boundPort; }

void ServeServer::publish(const Frame& image, const nlohmann::json& meta) {
  Impl& s = *impl_;
  {
    std::lock_guard<std::mutex> lock(s.rawMutex);
    s.raw.width = image.width;
    s.raw.height = image.height;
    s.raw.rgba.assign(image.rgba.begin(), image.rgba.end());
    s.rawMeta = meta;
    ++s.rawSeq;
  }
  s.rawCv.notify_all();
}

void ServeServer::stop() {
  Impl& s = *impl_;
  if (s.stopped.exchange(true)) return;
  {
    std::lock_guard<std::mutex> lock(s.rawMutex);
    s.stopping = true;
  }
  s.rawCv.notify_all();
  if (s.encoderThread.joinable()) s.encoderThread.join();
  s.ioc.stop();
  if (s.ioThread.joinable()) s.ioThread.join();
  s.acceptor.reset();
  s.clients.clear();
}

ServeCounters ServeServer::counters() const {
  std::lock_guard<std::mutex> lock(impl_->countMutex);
  return impl_->counts;
}

int ServeServer::clients() const { return impl_->wsCount.load(); }

}  // namespace sph2d::cli
