// libFuzzer target, end to end: any bytes sent over a loopback connection to the real server
// (Boost.Beast's HTTP parser, the Host and upgrade checks, the static files, the API's router
// and handlers, the error answers, and after an upgrade to /api/stream the WebSocket frames and
// their messages), then the connection is half-closed and everything the server sends is read.
// The server must never crash, hang or leak, and everything it sends must be well-formed:
// HTTP/1.x responses with a status from 200 to 599 and a Content-Length that fits (101 only
// when it switches to WebSocket), JSON bodies that parse, then unmasked WebSocket frames whose
// text messages parse as JSON.
//
// Run: build-fuzz/server/http_fuzz -dict=server/fuzz/http.dict server/fuzz/http_corpus

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
#include "server/http_server.h"
#include "server/store.h"

using namespace costar;

namespace {

constexpr const char* kToken = "fuzz-token-0123456789abcdef";
constexpr int kTimeoutMs = 10'000;

[[noreturn]] void fail(const char* what, std::string_view output) {
  std::fprintf(stderr, "http_fuzz: %s; the server sent %zu bytes:\n%.*s\n", what, output.size(),
               static_cast<int>(std::min<std::size_t>(output.size(), 2000)), output.data());
  std::abort();
}

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

/// WebSocket frames from the server: unmasked, known opcodes, text messages that are JSON.
void checkFrames(std::string_view data, std::string_view output) {
  std::string message;
  std::size_t at = 0;
  while (at < data.size()) {
    if (data.size() - at < 2) {
      fail("a WebSocket frame is cut", output);
    }
    const auto byte = [&](std::size_t i) { return static_cast<std::uint8_t>(data[at + i]); };
    const bool fin = (byte(0) & 0x80) != 0;
    const int opcode = byte(0) & 0x0F;
    if ((byte(0) & 0x70) != 0 || (byte(1) & 0x80) != 0 || (opcode > 2 && opcode < 8) || opcode > 10) {
      fail("a WebSocket frame from the server has reserved bits, a mask or an unknown opcode", output);
    }
    std::uint64_t length = byte(1) & 0x7F;
    std::size_t header = 2;
    if (length == 126 || length == 127) {
      header = length == 126 ? 4 : 10;
      if (data.size() - at < header) {
        fail("a WebSocket frame header is cut", output);
      }
      length = 0;
      for (std::size_t i = 2; i < header; ++i) {
        length = (length << 8) | byte(i);
      }
    }
    if (data.size() - at - header < length) {
      fail("a WebSocket frame is shorter than its length", output);
    }
    const std::string_view payload = data.substr(at + header, length);
    at += header + length;
    if (opcode == 1 || opcode == 0) {
      message += payload;
      if (fin) {
        if (nlohmann::json::parse(message, nullptr, false).is_discarded()) {
          fail("a WebSocket text message is not JSON", output);
        }
        message.clear();
      }
    }
  }
}

/// HTTP responses, in order; after a 101 the rest is WebSocket frames.
void checkOutput(std::string_view output) {
  std::size_t at = 0;
  while (at < output.size()) {
    const std::string_view rest = output.substr(at);
    if (rest.size() < 13 || !rest.starts_with("HTTP/") || !std::isdigit(static_cast<unsigned char>(rest[5])) ||
        rest[6] != '.' || !std::isdigit(static_cast<unsigned char>(rest[7])) || rest[8] != ' ') {
      fail("not an HTTP/1.x status line", output);
    }
    const int status = std::atoi(std::string(rest.substr(9, 3)).c_str());
    const auto head_end = rest.find("\r\n\r\n");
    if (head_end == std::string_view::npos) {
      fail("the response's header does not end", output);
    }
    const std::string_view head = rest.substr(0, head_end);
    if (status == 101) {
      checkFrames(rest.substr(head_end + 4), output);
      return;
    }
    if (status < 200 || status > 599) {
      fail("a status outside 200-599", output);
    }
    const auto length_at = head.find("\r\nContent-Length: ");
    if (length_at == std::string_view::npos) {
      fail("a response without Content-Length", output);
    }
    const std::size_t length = std::strtoull(std::string(head.substr(length_at + 18, 20)).c_str(), nullptr, 10);
    const std::string_view after = rest.substr(head_end + 4);
    if (after.empty() || (length > 0 && after.starts_with("HTTP/"))) {
      at += head_end + 4;  // the answer to a HEAD: no body
      continue;
    }
    if (after.size() < length) {
      fail("a body shorter than its Content-Length", output);
    }
    const std::string_view body = after.substr(0, length);
    if (head.find("\r\nContent-Type: application/json") != std::string_view::npos &&
        nlohmann::json::parse(body, nullptr, false).is_discarded()) {
      fail("a JSON body that does not parse", output);
    }
    at += head_end + 4 + length;
  }
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
