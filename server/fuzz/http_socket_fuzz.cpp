// libFuzzer target, end to end over a real socket (the slower of the two; http_fuzz.cpp runs
// the same sessions in memory, ~100 times faster): any bytes sent over a loopback connection
// to the real server
// (Boost.Beast's HTTP parser, the Host and upgrade checks, the static files, the API's router
// and handlers, the error answers, and after an upgrade to /api/stream the WebSocket frames and
// their messages), then the connection is half-closed and everything the server sends is read.
// The server must never crash, hang or leak, and everything it sends must be well-formed:
// HTTP/1.x responses with a status from 200 to 599 and a Content-Length that fits (101 only
// when it switches to WebSocket), JSON bodies that parse, then unmasked WebSocket frames whose
// text messages parse as JSON.
//
// What only this target sees: TCP (the accept loop, the I/O thread, bytes cut where the kernel
// cuts them, the shutdown of a socket), and the stream's broadcaster on its timer.
//
// Run: build-fuzz/server/http_socket_fuzz -dict=server/fuzz/http.dict server/fuzz/http_corpus

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "server/api.h"
#include "server/fuzz/fuzz_backend.h"
#include "server/fuzz/http_check.h"
#include "server/http_server.h"
#include "server/store.h"

using namespace costar;
using costar::server::fuzzing::checkOutput;
using costar::server::fuzzing::fail;

namespace {

constexpr const char* kToken = "fuzz-token-0123456789abcdef";
constexpr int kTimeoutMs = 10'000;

/// A server on 127.0.0.1 with an in-memory store, one I/O thread (deterministic order).
struct Harness {
  server::fuzzing::FuzzBackend backend;
  std::unique_ptr<server::Store> store;
  std::unique_ptr<server::Api> api;
  std::unique_ptr<server::HttpServer> http;

  void restart() {
    http.reset();
    api.reset();
    store = std::make_unique<server::Store>(":memory:");
    api = std::make_unique<server::Api>(backend, *store, server::ApiOptions{.token = kToken, .test_endpoints = true});
    server::HttpServerOptions options;
    options.address = "127.0.0.1";
    options.port = 0;
    options.web_root = std::filesystem::path("/nonexistent-costar-web-root");
    options.threads = 1;
    options.stream_hz = 1000.0;
    options.max_body_bytes = 64 * 1024;
    http = std::make_unique<server::HttpServer>(*api, backend, options);
    http->start();
  }
};

/// Sends `input`, half-closes, and returns everything the server sent until it closed.
std::string exchange(std::uint16_t port, std::string_view input) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(port);
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (fd < 0 || ::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    fail("cannot connect to the server", {});
  }
  std::string output;
  char buffer[65536];
  std::size_t sent = 0;
  bool write_open = true;
  while (true) {
    pollfd pfd{fd, static_cast<short>(POLLIN | (write_open ? POLLOUT : 0)), 0};
    if (::poll(&pfd, 1, kTimeoutMs) <= 0) {
      fail("the server hung (no answer and no close within 10 s)", output);
    }
    if (write_open && (pfd.revents & POLLOUT) != 0) {
      if (sent < input.size()) {
        const ssize_t n = ::send(fd, input.data() + sent, input.size() - sent, MSG_NOSIGNAL);
        sent = n > 0 ? sent + static_cast<std::size_t>(n) : input.size();  // refused: the server closed
      }
      if (sent >= input.size()) {
        ::shutdown(fd, SHUT_WR);
        write_open = false;
      }
    }
    if ((pfd.revents & (POLLIN | POLLHUP | POLLERR)) != 0) {
      const ssize_t n = ::recv(fd, buffer, sizeof(buffer), 0);
      if (n <= 0) {
        break;  // closed (or reset)
      }
      output.append(buffer, static_cast<std::size_t>(n));
    }
  }
  ::close(fd);
  return output;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static Harness harness;
  static std::size_t inputs = 0;
  if (inputs++ % 2000 == 0) {  // a fresh store now and then keeps memory flat
    harness.restart();
  }
  const std::string output = exchange(harness.http->port(), {reinterpret_cast<const char*>(data), size});
  checkOutput(output);
  return 0;
}
