// The in-memory connection (http_memory.h) that the end-to-end fuzz target drives: it runs the
// server's own sessions, so for the same bytes it must answer byte for byte what the server
// answers over TCP, close when the client has closed, and carry the WebSocket stream.

#include <gtest/gtest.h>
#include <sys/socket.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "server/api.h"
#include "server/fuzz/fuzz_backend.h"
#include "server/http_memory.h"
#include "server/http_server.h"
#include "server/store.h"
#include "server/test/http_client.h"

namespace costar::server {
namespace {

constexpr const char* kToken = "memory-test-token-0123456789";

HttpServerOptions options() {
  HttpServerOptions options;
  options.address = "127.0.0.1";
  options.port = 0;
  options.threads = 1;
  options.web_root = "/nonexistent-costar-web-root";
  options.max_body_bytes = 4096;
  return options;
}

/// A server's API on the fuzz backend (built-in nodes) and an in-memory store.
struct ApiStack {
  fuzzing::FuzzBackend backend;
  Store store{":memory:"};
  Api api{backend, store, ApiOptions{.token = kToken, .max_body_bytes = 4096}};
};

/// Sends `input` over TCP, half-closes, and reads until the server closes.
std::string socketExchange(std::uint16_t port, const std::string& input) {
  testing::Socket socket(port);
  EXPECT_TRUE(socket.send(input));
  ::shutdown(socket.fd(), SHUT_WR);
  std::string output;
  for (std::string more = socket.receive(); !more.empty(); more = socket.receive()) {
    output += more;
  }
  return output;
}

const std::string kAuth = std::string("Authorization: Bearer ") + kToken + "\r\n";

/// Requests that reach every kind of answer: the API's, the page's, the parser's errors, the
/// Host check, a body over the limit, keep-alive and pipelining, HTTP/1.0, a cut request.
const std::vector<std::string> kConnections = {
    "GET /api/info HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n",
    "HEAD / HTTP/1.1\r\nHost: localhost\r\n\r\n",
    "GET /api/no\xff\xfesuch HTTP/1.1\r\nHost: localhost\r\n\r\n",
    "GET /api/info HTTP/1.1\r\nHost: evil.example\r\n\r\n",
    "GET /api/state HTTP/1.0\r\n\r\n",
    "NONSENSE\r\n\r\n",
    "POST /api/control HTTP/1.1\r\nHost: 127.0.0.1\r\n" + kAuth +
        "Content-Length: 54\r\n\r\n{\"action\":\"a\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3"
        "\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\"}",
    "POST /api/runs HTTP/1.1\r\nHost: 127.0.0.1\r\n" + kAuth +
        "Content-Length: "
        "98\r\n\r\n{\"plan\":{\"main_tree\":\"main\",\"trees\":[{\"id\":\"main\",\"root\":{\"id\":\"Sequence\","
        "\"children\":[]}}]}}",
    "PUT /api/plans/pick HTTP/1.1\r\nHost: 127.0.0.1\r\n" + kAuth + "Content-Length: 5000\r\n\r\n{}",
    "GET /api/info HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\nGET /api/plans HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"
    "DELETE /api/plans/x HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\nGET /api/info HTTP/1.1\r\n\r\n",
    "POST /api/validate HTTP/1.1\r\nHost: 127.0.0.1\r\n" + kAuth +
        "Transfer-Encoding: chunked\r\n\r\n5\r\n{\"xml\r\n0\r\n\r\n",
    "GET /api/info HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 10\r\n\r\nabc",
    "",
};

TEST(MemoryHttpServer, AnswersByteForByteAsTheServerDoesOverTcp) {
  ApiStack tcp_stack;
  HttpServer tcp(tcp_stack.api, tcp_stack.backend, options());
  tcp.start();
  ApiStack memory_stack;
  MemoryHttpServer memory(memory_stack.api, memory_stack.backend, options());
  for (std::size_t read_size : {0u, 7u}) {
    for (const std::string& input : kConnections) {
      const MemoryHttpServer::Exchange in_memory = memory.exchange(input, read_size);
      EXPECT_TRUE(in_memory.closed) << input;
      EXPECT_EQ(in_memory.output, socketExchange(tcp.port(), input)) << "read size " << read_size << ": " << input;
    }
  }
  // The answers are the real ones (not two empty strings).
  const std::string info = memory.exchange(kConnections[0]).output;
  EXPECT_TRUE(info.starts_with("HTTP/1.1 200 OK\r\n")) << info;
  EXPECT_NE(info.find("\"workcell\":\"fuzz\""), std::string::npos) << info;
  EXPECT_TRUE(memory.exchange(kConnections[3]).output.starts_with("HTTP/1.1 421 ")) << "the Host check";
}

/// A client frame: FIN, `opcode`, masked with `mask` as RFC 6455 requires of clients.
std::string clientFrame(int opcode, const std::string& payload, std::uint32_t mask = 0x12345678) {
  std::string frame;
  frame += static_cast<char>(0x80 | opcode);
  frame += static_cast<char>(0x80 | payload.size());  // payloads under 126 bytes here
  const char key[4] = {static_cast<char>(mask >> 24), static_cast<char>(mask >> 16), static_cast<char>(mask >> 8),
                       static_cast<char>(mask)};
  frame.append(key, 4);
  for (std::size_t i = 0; i < payload.size(); ++i) {
    frame += static_cast<char>(payload[i] ^ key[i % 4]);
  }
  return frame;
}

/// The text messages in the server's frames (unmasked, payloads under 64 KiB).
std::vector<nlohmann::json> serverMessages(const std::string& data) {
  std::vector<nlohmann::json> messages;
  std::size_t at = 0;
  while (at + 2 <= data.size()) {
    const int opcode = data[at] & 0x0F;
    std::size_t length = static_cast<unsigned char>(data[at + 1]) & 0x7F;
    std::size_t header = 2;
    if (length == 126) {
      length = (static_cast<unsigned char>(data[at + 2]) << 8) | static_cast<unsigned char>(data[at + 3]);
      header = 4;
    }
    if (opcode == 1) {
      messages.push_back(nlohmann::json::parse(data.substr(at + header, length)));
    }
    at += header + length;
  }
  EXPECT_EQ(at, data.size()) << "the frames end where the output ends";
  return messages;
}

TEST(MemoryHttpServer, CarriesTheWebSocketStream) {
  ApiStack stack;
  MemoryHttpServer memory(stack.api, stack.backend, options());
  const std::string upgrade =
      "GET /api/stream HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
      "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";
  const std::string frames = clientFrame(1, R"({"type":"ping"})") +
                             clientFrame(1, R"({"type":"control","action":"stop"})") +
                             clientFrame(1, R"({"type":"auth","token":"wrong"})") + clientFrame(1, "not json");
  // One byte per read: the HTTP parser reads nothing past the upgrade request, so the frames
  // reach the WebSocket (a client must wait for the 101 before sending frames; see the docs).
  const MemoryHttpServer::Exchange exchange = memory.exchange(upgrade + frames, 1);
  EXPECT_TRUE(exchange.closed);
  EXPECT_EQ(memory.streamClients(), 0u) << "the session ended with the connection";
  ASSERT_TRUE(exchange.output.starts_with("HTTP/1.1 101 Switching Protocols\r\n")) << exchange.output;
  const std::size_t head_end = exchange.output.find("\r\n\r\n");
  ASSERT_NE(head_end, std::string::npos);
  const std::vector<nlohmann::json> messages = serverMessages(exchange.output.substr(head_end + 4));
  std::vector<std::string> answers;  // what the client's messages got, in order (no broadcasts)
  bool broadcast = false;
  for (const auto& message : messages) {
    if (message["type"] == "state") {
      broadcast = true;
    } else {
      answers.push_back(message.dump());
    }
  }
  ASSERT_EQ(answers.size(), 5u) << exchange.output;
  EXPECT_EQ(messages.front()["type"], "hello");
  EXPECT_EQ(answers[1], R"({"type":"pong"})");
  EXPECT_NE(answers[2].find("commands need the token"), std::string::npos) << answers[2];
  EXPECT_EQ(answers[3], R"({"ok":false,"type":"auth"})");
  EXPECT_NE(answers[4].find("\"type\":\"error\""), std::string::npos) << answers[4];
  EXPECT_TRUE(broadcast) << "the stream's snapshots go out between the answers";
}

}  // namespace
}  // namespace costar::server
