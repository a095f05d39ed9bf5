// app/serve/serve_client.hpp — a small synchronous client of `sph2d serve` (Boost.Beast): one
// HTTP request, or a WebSocket that reads frame messages and sends events.
//
// Design: header-only, used by `sph2d bench serve` and by the serve and browser tests,
// so that both speak the server's protocol through the same code: a frame message is
// 4 bytes (big-endian) of header length, the header (JSON overlay data), the image.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

namespace sph2d::serveclient {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

/// An HTTP answer.
struct HttpResult {
  int status = 0;           ///< the status code (0: no answer)
  std::string body;         ///< the body
  std::string contentType;  ///< the Content-Type header
  std::string retryAfter;   ///< the Retry-After header ("" when absent)
};

/// One HTTP/1.1 request to host:port (a new connection), waiting at most `timeout`. Throws
/// boost::system::system_error when the connection fails.
inline HttpResult httpRequest(const std::string& host, int port, http::verb method, const std::string& target,
                              const std::string& body = "", std::chrono::seconds timeout = std::chrono::seconds(30)) {
  net::io_context ioc;
  beast::tcp_stream stream(ioc);
  tcp::resolver resolver(ioc);
  stream.expires_after(timeout);
  stream.connect(resolver.resolve(host, std::to_string(port)));
  http::request<http::string_body> req{method, target, 11};
  req.set(http::field::host, host);
  if (!body.empty() || method == http::verb::post) {
    req.set(http::field::content_type, "application/json");
    req.body() = body;
    req.prepare_payload();
  }
  stream.expires_after(timeout);
  http::write(stream, req);
  beast::flat_buffer buf;
  http::response_parser<http::string_body> parser;
  parser.body_limit(64u << 20);
  parser.skip(method == http::verb::head);  // a HEAD answer has headers only
  http::read(stream, buf, parser);
  HttpResult r;
  r.status = int(parser.get().result_int());
  r.body = parser.get().body();
  r.contentType = std::string(parser.get()[http::field::content_type]);
  r.retryAfter = std::string(parser.get()[http::field::retry_after]);
  beast::error_code ec;
  stream.socket().shutdown(tcp::socket::shutdown_both, ec);
  return r;
}

/// A message from the server: a frame (header + image) or a text reply.
struct ServeMessage {
  bool frame = false;                        ///< a binary frame message (else a text reply)
  nlohmann::json header;                     ///< the frame's overlay data, or the parsed reply
  std::string image;                         ///< the frame's JPEG or PNG bytes
  std::string text;                          ///< the reply's text
  std::chrono::steady_clock::time_point at;  ///< when it was read
};

/// A WebSocket client of /ws.
class WsClient {
 public:
  /// Connects to ws://host:port/ws. Throws on failure (e.g. 503 when the server has
  /// --max-clients clients already).
  WsClient(const std::string& host, int port) : ws_(ioc_) {
    tcp::resolver resolver(ioc_);
    beast::get_lowest_layer(ws_).expires_after(std::chrono::seconds(30));
    beast::get_lowest_layer(ws_).connect(resolver.resolve(host, std::to_string(port)));
    ws_.handshake(host + ":" + std::to_string(port), "/ws");
    beast::get_lowest_layer(ws_).expires_never();
    ws_.read_message_max(64u << 20);
  }
  /// Sends one text message (an event as JSON).
  void send(const std::string& text) {
    ws_.text(true);
    ws_.write(net::buffer(text));
  }
  /// Reads the next message, waiting at most `timeout`; nullopt on timeout (the connection
  /// is then unusable). Throws when the server closed the connection.
  std::optional<ServeMessage> read(std::chrono::milliseconds timeout = std::chrono::milliseconds(30000)) {
    beast::flat_buffer buf;
    beast::error_code ec;
    bool done = false;
    ws_.async_read(buf, [&](beast::error_code e, std::size_t) {
      ec = e;
      done = true;
    });
    ioc_.restart();
    ioc_.run_for(timeout);
    if (!done) {
      beast::get_lowest_layer(ws_).close();
      ioc_.restart();
      ioc_.run();
      return std::nullopt;
    }
    if (ec) throw boost::system::system_error(ec);
    ServeMessage m;
    m.at = std::chrono::steady_clock::now();
    const std::string data = beast::buffers_to_string(buf.data());
    if (ws_.got_text()) {
      m.text = data;
      m.header = nlohmann::json::parse(data, nullptr, false);
      return m;
    }
    m.frame = true;
    if (data.size() < 4) throw std::runtime_error("frame message shorter than its length prefix");
    const std::uint32_t n = (std::uint32_t(std::uint8_t(data[0])) << 24) |
                            (std::uint32_t(std::uint8_t(data[1])) << 16) | (std::uint32_t(std::uint8_t(data[2])) << 8) |
                            std::uint32_t(std::uint8_t(data[3]));
    if (4 + std::size_t(n) > data.size()) throw std::runtime_error("frame header longer than the message");
    m.header = nlohmann::json::parse(data.substr(4, n));
    m.image = data.substr(4 + n);
    return m;
  }
  /// Reads until a text reply arrives (frames meanwhile are skipped); nullopt on timeout.
  std::optional<ServeMessage> readReply(std::chrono::milliseconds timeout = std::chrono::milliseconds(30000)) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now());
      if (left.count() <= 0) return std::nullopt;
      auto m = read(left);
      if (!m || !m->frame) return m;
    }
  }
  /// Closes the connection abruptly (no close handshake).
  void drop() {
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().close(ec);
  }

 private:
  net::io_context ioc_;
  websocket::stream<beast::tcp_stream> ws_;
};

}  // namespace sph2d::serveclient
