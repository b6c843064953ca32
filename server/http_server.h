#pragma once
// The network side of `costar serve`, on Boost.Beast (kept inside http_server.cpp): HTTP/1.1
// for the page's files and the API, and a WebSocket at /api/stream for the live stream.
//
// Requests are read with limits (1 MiB bodies, 8 KiB headers, 30 s per request); a body over
// the limit is answered 413 without being read, a malformed request 400, a request whose Host
// is not this machine 421 when listening on loopback (DNS rebinding: http_session.h says which
// Hosts and WebSocket Origins pass). API requests go to Api::handle on the I/O threads, but long
// reads (Api::isBulkRead: run logs, read in pages, the run list, the point cloud) on a thread
// of their own, one at a time, so that however many arrive, the stream and commands such as
// stop are not held up. Nothing here touches the workcell.
//
// No exception ends a thread here: one thrown while answering a request becomes a 500 answer,
// one thrown anywhere else (the stream, the accept loop, the broadcaster) is logged and the
// connection concerned is closed; the I/O threads and the broadcaster go on (guard.h).
//
// WebSocket: the server sends "hello" (the active run with each node's status, and the latest
// state), then every 1/(2 stream_hz) s the messages of Backend::drainStream() (so each snapshot
// goes out within half a period of being taken). A client sends
// {"type":"auth","token":T} to be allowed commands ({"type":"control","action":"pause" |
// "resume" | "step" | "stop"}); when reads need the token, nothing is sent before it.
// A client that falls 256 messages behind is disconnected (it reconnects and gets a fresh hello).

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

namespace costar::server {

class Api;
class Backend;

struct HttpServerOptions {
  std::string address = "127.0.0.1";
  /// 0: any free port (see HttpServer::port()).
  std::uint16_t port = 8080;
  /// The built page (web/dist); missing: a page saying how to build it.
  std::filesystem::path web_root;
  int threads = 2;
  double stream_hz = 20.0;
  std::size_t max_body_bytes = 1u << 20;
};

class HttpServer {
 public:
  /// `api` and `backend` (the stream's source, and run control from WebSocket commands) must
  /// outlive the server. Binds at once.
  /// @throws std::runtime_error when the address cannot be bound.
  HttpServer(Api& api, Backend& backend, HttpServerOptions options);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  /// Starts the I/O threads and the stream's broadcaster.
  void start();
  /// Closes every connection and joins the threads. Idempotent.
  void stop();
  /// The port it listens on.
  std::uint16_t port() const;
  /// WebSocket clients connected now.
  std::size_t streamClients() const;
  /// Stream messages sent (all clients together).
  std::uint64_t streamMessagesSent() const;

  /// True for 127.0.0.0/8, ::1 and "localhost".
  static bool isLoopback(const std::string& address);

  /// The Beast side (http_server.cpp only).
  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace costar::server
