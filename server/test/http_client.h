#pragma once
// TEST ONLY: a minimal blocking HTTP/1.1 and WebSocket client over POSIX sockets, so the tests
// talk to the server the way a browser does without linking a second network library.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>

namespace costar::server::testing {

/// A connected TCP socket to 127.0.0.1:port, closed on destruction.
class Socket {
 public:
  explicit Socket(std::uint16_t port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(port);
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd_ < 0 || ::connect(fd_, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
      if (fd_ >= 0) {
        ::close(fd_);
      }
      throw std::runtime_error("cannot connect to port " + std::to_string(port));
    }
    const int one = 1;
    ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
  }
  ~Socket() { ::close(fd_); }
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;

  /// Sends everything; false if the peer closed.
  bool send(const std::string& data) {
    std::size_t sent = 0;
    while (sent < data.size()) {
      const ssize_t n = ::send(fd_, data.data() + sent, data.size() - sent, MSG_NOSIGNAL);
      if (n <= 0) {
        return false;
      }
      sent += static_cast<std::size_t>(n);
    }
    return true;
  }
  /// Reads what is there (waiting up to `timeout`); empty when closed or timed out.
  std::string receive(std::chrono::milliseconds timeout = std::chrono::seconds(30)) {
    pollfd pfd{fd_, POLLIN, 0};
    if (::poll(&pfd, 1, static_cast<int>(timeout.count())) <= 0) {
      return {};
    }
    char buffer[65536];
    const ssize_t n = ::recv(fd_, buffer, sizeof(buffer), 0);
    return n > 0 ? std::string(buffer, static_cast<std::size_t>(n)) : std::string();
  }
  int fd() const { return fd_; }

 private:
  int fd_ = -1;
};

struct Response {
  int status = 0;                              // 0: no response (connection closed)
  std::map<std::string, std::string> headers;  // names in lower case
  std::string body;
};

/// Reads one HTTP response from `socket`, using `pending` for bytes already read.
inline Response readResponse(Socket& socket, std::string& pending) {
  Response response;
  while (pending.find("\r\n\r\n") == std::string::npos) {
    const std::string more = socket.receive();
    if (more.empty()) {
      return response;
    }
    pending += more;
  }
  const std::size_t header_end = pending.find("\r\n\r\n");
  const std::string head = pending.substr(0, header_end);
  pending.erase(0, header_end + 4);
  std::size_t line_end = head.find("\r\n");
  const std::string status_line = head.substr(0, line_end);
  response.status = std::stoi(status_line.substr(status_line.find(' ') + 1, 3));
  while (line_end != std::string::npos) {
    const std::size_t next = head.find("\r\n", line_end + 2);
    const std::string line =
        head.substr(line_end + 2, next == std::string::npos ? std::string::npos : next - line_end - 2);
    const auto colon = line.find(':');
    if (colon != std::string::npos) {
      std::string name = line.substr(0, colon);
      for (char& c : name) {
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      }
      std::string value = line.substr(colon + 1);
      value.erase(0, value.find_first_not_of(' '));
      response.headers[name] = value;
    }
    line_end = next;
  }
  const std::size_t length =
      response.headers.contains("content-length") ? std::stoul(response.headers["content-length"]) : 0;
  while (pending.size() < length) {
    const std::string more = socket.receive();
    if (more.empty()) {
      break;
    }
    pending += more;
  }
  response.body = pending.substr(0, length);
  pending.erase(0, std::min(length, pending.size()));
  return response;
}

/// One request on a fresh connection.
inline Response request(std::uint16_t port, const std::string& method, const std::string& target,
                        const std::string& body = {}, const std::string& token = {},
                        const std::string& host = "127.0.0.1") {
  Socket socket(port);
  std::string text = method + " " + target + " HTTP/1.1\r\nHost: " + host + "\r\nConnection: close\r\n";
  if (!token.empty()) {
    text += "Authorization: Bearer " + token + "\r\n";
  }
  if (!body.empty() || method == "POST" || method == "PUT") {
    text += "Content-Type: application/json\r\nContent-Length: " + std::to_string(body.size()) + "\r\n";
  }
  text += "\r\n" + body;
  if (!socket.send(text)) {
    return {};
  }
  std::string pending;
  return readResponse(socket, pending);
}

/// A WebSocket client (RFC 6455), text messages only.
class WebSocket {
 public:
  /// Connects to ws://127.0.0.1:port/target (saying `host` in Host, `origin` in Origin when not
  /// empty); `status` is the handshake's HTTP status.
  WebSocket(std::uint16_t port, const std::string& target = "/api/stream", const std::string& origin = {},
            const std::string& host = "127.0.0.1")
      : socket_(port) {
    std::string text = "GET " + target + " HTTP/1.1\r\nHost: " + host +
                       "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                       "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n";
    if (!origin.empty()) {
      text += "Origin: " + origin + "\r\n";
    }
    socket_.send(text + "\r\n");
    status = readResponse(socket_, pending_).status;
  }

  int status = 0;

  /// The next text message, or nullopt when closed or nothing came within `timeout`.
  std::optional<std::string> read(std::chrono::milliseconds timeout = std::chrono::seconds(30)) {
    std::string message;
    while (true) {
      while (pending_.size() < 2) {
        if (!fill(timeout)) {
          return std::nullopt;
        }
      }
      const auto byte = [this](std::size_t i) { return static_cast<std::uint8_t>(pending_[i]); };
      const bool fin = (byte(0) & 0x80) != 0;
      const int opcode = byte(0) & 0x0F;
      std::uint64_t length = byte(1) & 0x7F;
      std::size_t header = 2;
      if (length == 126) {
        while (pending_.size() < 4) {
          if (!fill(timeout)) return std::nullopt;
        }
        length = (std::uint64_t{byte(2)} << 8) | byte(3);
        header = 4;
      } else if (length == 127) {
        while (pending_.size() < 10) {
          if (!fill(timeout)) return std::nullopt;
        }
        length = 0;
        for (int i = 0; i < 8; ++i) {
          length = (length << 8) | byte(2 + static_cast<std::size_t>(i));
        }
        header = 10;
      }
      while (pending_.size() < header + length) {
        if (!fill(timeout)) return std::nullopt;
      }
      const std::string payload = pending_.substr(header, length);
      pending_.erase(0, header + length);
      if (opcode == 0x8) {
        return std::nullopt;  // close
      }
      if (opcode == 0x9 || opcode == 0xA) {
        continue;  // ping / pong
      }
      message += payload;
      if (fin) {
        return message;
      }
    }
  }

  /// Sends a masked text frame.
  bool send(const std::string& text) {
    std::string frame;
    frame += static_cast<char>(0x81);
    if (text.size() < 126) {
      frame += static_cast<char>(0x80 | text.size());
    } else {
      frame += static_cast<char>(0x80 | 126);
      frame += static_cast<char>((text.size() >> 8) & 0xFF);
      frame += static_cast<char>(text.size() & 0xFF);
    }
    const char mask[4] = {0x12, 0x34, 0x56, 0x78};
    frame.append(mask, 4);
    for (std::size_t i = 0; i < text.size(); ++i) {
      frame += static_cast<char>(text[i] ^ mask[i % 4]);
    }
    return socket_.send(frame);
  }

 private:
  bool fill(std::chrono::milliseconds timeout) {
    const std::string more = socket_.receive(timeout);
    pending_ += more;
    return !more.empty();
  }
  Socket socket_;
  std::string pending_;
};

}  // namespace costar::server::testing
