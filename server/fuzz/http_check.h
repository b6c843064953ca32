#pragma once
// TEST ONLY: what the end-to-end fuzz targets check in everything the server sent on one
// connection: HTTP/1.x responses with a status from 200 to 599 and a Content-Length that fits
// (101 only when it switches to WebSocket), JSON bodies that parse, then unmasked WebSocket
// frames with known opcodes whose text messages parse as JSON. A violation prints what the
// server sent and aborts (libFuzzer then saves the input).

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace costar::server::fuzzing {

[[noreturn]] inline void fail(const char* what, std::string_view output) {
  std::fprintf(stderr, "http_fuzz: %s; the server sent %zu bytes:\n%.*s\n", what, output.size(),
               static_cast<int>(std::min<std::size_t>(output.size(), 2000)), output.data());
  std::abort();
}

/// WebSocket frames from the server: unmasked, known opcodes, text messages that are JSON.
inline void checkFrames(std::string_view data, std::string_view output) {
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
inline void checkOutput(std::string_view output) {
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

}  // namespace costar::server::fuzzing
