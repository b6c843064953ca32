// The end-to-end fuzz targets' judge (server/fuzz/http_check.h): what the server sends on one
// connection passes only as HTTP/1.x answers with a status from 200 to 599 (101 only before
// WebSocket frames), a Content-Length that fits and JSON that parses. A judge that let a bad
// answer through would make the fuzz runs' "0 crashes" mean nothing; these check that it fails.

#include "server/fuzz/http_check.h"

#include <gtest/gtest.h>

#include <string>

namespace costar::server::fuzzing {
namespace {

std::string answer(const std::string& status_line, const std::string& body,
                   const std::string& type = "application/json") {
  return status_line + "\r\nContent-Type: " + type + "\r\nContent-Length: " + std::to_string(body.size()) + "\r\n\r\n" +
         body;
}

/// An unmasked text frame with a short payload.
std::string textFrame(const std::string& payload) {
  return std::string{static_cast<char>(0x81), static_cast<char>(payload.size())} + payload;
}

TEST(HttpCheck, PassesValidAnswers) {
  checkOutput("");  // nothing sent (the client's bytes were no request)
  checkOutput(answer("HTTP/1.1 200 OK", R"({"ok":true})"));
  checkOutput(answer("HTTP/1.1 404 Not Found", R"({"error":"no such plan"})") +
              answer("HTTP/1.0 599 Whatever", "plain", "text/plain"));                        // pipelined
  checkOutput("HTTP/1.1 200 OK\r\nContent-Type: text/html\r\nContent-Length: 1234\r\n\r\n");  // a HEAD's answer
  checkOutput("HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\n\r\n" + textFrame(R"({"tick":1})") +
              std::string{static_cast<char>(0x88), 0});  // a close frame
}

TEST(HttpCheck, FailsAStatusOutside200To599) {
  EXPECT_DEATH(checkOutput(answer("HTTP/1.1 100 Continue", "{}")), "a status outside 200-599");
  EXPECT_DEATH(checkOutput(answer("HTTP/1.1 199 Odd", "{}")), "a status outside 200-599");
  EXPECT_DEATH(checkOutput(answer("HTTP/1.1 600 Odd", "{}")), "a status outside 200-599");
  EXPECT_DEATH(checkOutput(answer("HTTP/1.1 abc Odd", "{}")), "a status outside 200-599");
  // The second of two answers is judged as well.
  EXPECT_DEATH(checkOutput(answer("HTTP/1.1 200 OK", "{}") + answer("HTTP/1.1 700 Odd", "{}")),
               "a status outside 200-599");
}

TEST(HttpCheck, FailsWhatIsNotAnHttpAnswer) {
  EXPECT_DEATH(checkOutput("hello, this is not HTTP\r\n\r\n"), "not an HTTP/1.x status line");
  EXPECT_DEATH(checkOutput(answer("HTTP/2 200 OK", "{}")), "not an HTTP/1.x status line");
  EXPECT_DEATH(checkOutput("HTTP/1.1 200 OK\r\nContent-Length: 2\r\n"), "the response's header does not end");
  EXPECT_DEATH(checkOutput("HTTP/1.1 200 OK\r\nContent-Type: application/json\r\n\r\n{}"),
               "a response without Content-Length");
  EXPECT_DEATH(checkOutput("HTTP/1.1 200 OK\r\nContent-Length: 10\r\n\r\n{}"),
               "a body shorter than its Content-Length");
  EXPECT_DEATH(checkOutput(answer("HTTP/1.1 400 Bad Request", R"({"error":)")), "a JSON body that does not parse");
}

TEST(HttpCheck, FailsBadWebSocketFramesAfterAnUpgrade) {
  const std::string upgrade = "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\n\r\n";
  EXPECT_DEATH(checkOutput(upgrade + textFrame("not json")), "a WebSocket text message is not JSON");
  EXPECT_DEATH(checkOutput(upgrade + std::string{static_cast<char>(0x81), static_cast<char>(0x82), 'a', 'b'}),
               "reserved bits, a mask or an unknown opcode");  // masked: only clients mask
  EXPECT_DEATH(checkOutput(upgrade + std::string{static_cast<char>(0x81), 5, '{', '}'}),
               "a WebSocket frame is shorter than its length");
}

}  // namespace
}  // namespace costar::server::fuzzing
