#pragma once
// TEST ONLY (the end-to-end fuzz target and the server's tests): the server's HTTP and
// WebSocket sessions, the same code HttpServer runs on TCP sockets (http_session.h), driven
// through an in-memory connection on the calling thread. One connection costs microseconds
// instead of a socket, an accept and a thread hop, so a fuzzer can afford millions: the same
// Boost.Beast parser, Host and upgrade checks, router, API handlers, error answers, WebSocket
// frames and stream broadcasts. What it cannot show is what only sockets do (timeouts, the
// accept loop, the I/O threads, a peer that resets); the socket target covers those.

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>

#include "server/http_server.h"

namespace costar::server {

class MemoryHttpServer {
 public:
  /// `api` and `backend` must outlive it. options.address decides the Host checks (loopback or
  /// not); the port, threads and stream_hz are not used (nothing listens, one thread runs it).
  MemoryHttpServer(Api& api, Backend& backend, HttpServerOptions options);
  ~MemoryHttpServer();
  MemoryHttpServer(const MemoryHttpServer&) = delete;
  MemoryHttpServer& operator=(const MemoryHttpServer&) = delete;

  struct Exchange {
    /// Everything the server sent on the connection.
    std::string output;
    /// The server closed its side once it had read everything and the client's end (it must:
    /// false means a session still waits for something that will never come).
    bool closed = false;
  };

  /// One connection: the client sends `input` and closes its side; the server reads it in
  /// pieces of at most `read_size` bytes (0: as much as it asks for), as TCP may cut it
  /// anywhere. Every handler that is ready runs on this thread until none is; after every
  /// 16th, while a WebSocket client is connected, the stream's broadcaster runs once (as its
  /// timer would), so snapshots interleave with answers.
  Exchange exchange(std::string_view input, std::size_t read_size = 0);

  /// WebSocket clients connected now (0 between exchanges unless one never ended).
  std::size_t streamClients() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace costar::server
