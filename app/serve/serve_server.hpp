// app/serve/serve_server.hpp — the HTTP and WebSocket side of `sph2d serve`.
//
//   GameLoop ─ frame() ─> publish(): copy into the raw slot (one frame, overwritten)
//                              │
//   encoder thread: newest raw frame ─> JPEG/PNG ─> "latest" message (one slot, overwritten)
//                                                        │
//   io thread (asio): each WebSocket client sends "latest" when its previous write
//                     completed (skipping the frames it missed); HTTP: the page,
//                     /snapshot.png, /state, POST /event; events ─> EventHandler
//
// Design: HTTP parsing and WebSocket framing are Boost.Beast's (libboost-dev). One
// io thread runs every socket, so the sessions need no locks; the encoder thread
// compresses only the newest frame and only while a client is connected. Nothing
// queues per client but a few replies to its own messages (a client that stops
// reading them is dropped): a slow or vanished client never slows the loop, which
// only copies its frame into the slot. Every message and body has a size cap, and
// no path of a request reaches the file system: the server knows the embedded page,
// the snapshot, the state and the event endpoint, nothing else.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "serve/serve_encode.hpp"
#include "sph2d/render/image.hpp"

namespace sph2d::cli {

/// How the server listens and what it sends.
struct ServeConfig {
  std::string bind = "127.0.0.1";          ///< the address to listen on
  int port = 8080;                         ///< the TCP port (0: any free port; port() says which)
  int maxClients = 4;                      ///< WebSocket clients at once (more are answered 503)
  std::size_t maxEventBytes = 16384;       ///< an event (POST body, WebSocket message) at most this long
  ImageFormat format = ImageFormat::Jpeg;  ///< the live frames' format
  int jpegQuality = 80;                    ///< JPEG quality 1..100
};

/// Counters of the server's work (for the summary; read from any thread).
struct ServeCounters {
  std::uint64_t encoded = 0;   ///< frames compressed for the clients
  std::uint64_t sent = 0;      ///< frame messages written to clients
  std::uint64_t clients = 0;   ///< WebSocket clients accepted so far
  std::uint64_t refused = 0;   ///< connections refused (too many clients)
  std::uint64_t rejected = 0;  ///< messages answered with an error
  double encodeSeconds = 0;    ///< wall seconds compressing frames
};

/// The answer to a client's event: accepted (`error` empty), or refused with why (sent back
/// to the client) and the HTTP status that says so (400 a malformed or invalid event; 422, 429
/// or 409 an event over live input's caps, event_intake.hpp's LiveRefusal).
struct EventReply {
  int status = 200;
  std::string error;
  double retryAfter = 0;  ///< with 429: seconds until it would be taken (the Retry-After header, rounded up)
};

/// An event from a client: its text (at most maxEventBytes) and who sent it ("ws client 3",
/// "POST /event"). Called on the io thread.
using ServeEventHandler = std::function<EventReply(const std::string& text, const std::string& where)>;
/// The overlay data of the moment (GET /state). Called on the io thread.
using ServeStateFn = std::function<nlohmann::json()>;

/// The HTTP/WebSocket server of `sph2d serve`.
class ServeServer {
 public:
  /// A server serving `page` at / (nothing listens before start()).
  ServeServer(ServeConfig config, std::string page, ServeEventHandler onEvent, ServeStateFn state);
  /// Stops the threads (stop()).
  ~ServeServer();
  ServeServer(const ServeServer&) = delete;
  ServeServer& operator=(const ServeServer&) = delete;
  /// Binds, listens and starts the io and encoder threads. Throws std::runtime_error saying
  /// which address could not be used and why.
  void start();
  /// The port listened on (after start()).
  int port() const;
  /// Hands the newest frame and its overlay data (`meta`, sent with it) to the clients: copies
  /// it into the frame slot and returns at once (called by the loop's thread).
  void publish(const Frame& image, const nlohmann::json& meta);
  /// Closes every connection and joins the threads (idempotent).
  void stop();
  /// The counters so far.
  ServeCounters counters() const;
  /// WebSocket clients connected now.
  int clients() const;

  /// The sockets, threads and slots (serve_server.cpp).
  struct Impl;

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace sph2d::cli
