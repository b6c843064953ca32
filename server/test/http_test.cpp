// A real server on loopback (HTTP + WebSocket through Boost.Beast), driven the way a browser
// drives it: tokens, limits, hostile requests, the live stream. The server keeps answering.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "server/auth.h"
#include "server/engine.h"
#include "server/http_server.h"
#include "server/serve.h"
#include "server/test/http_client.h"

namespace costar::server {
namespace {

using nlohmann::json;
using testing::Response;
using testing::WebSocket;

class HttpTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::filesystem::temp_directory_path() / ("costar_http_test_" + randomToken().substr(0, 8));
    std::filesystem::create_directories(dir_ / "web" / "assets");
    std::ofstream(dir_ / "web" / "index.html") << "<!doctype html><title>editor</title>";
    std::ofstream(dir_ / "web" / "assets" / "app.js") << "console.log('hi')";
    std::ofstream(dir_ / "secret.txt") << "secret";
    ServeOptions options;
    options.workcell.name = "test";
    options.workcell.memory_only = true;
    options.port = 0;
    options.store = dir_ / "editor.sqlite";
    options.web_root = dir_ / "web";
    options.pace = 1.0;
    server_ = new Server(options);
  }
  static void TearDownTestSuite() {
    delete server_;
    std::filesystem::remove_all(dir_);
  }
  void TearDown() override {
    // Whatever the test sent, the server still answers.
    EXPECT_EQ(testing::request(port(), "GET", "/api/info").status, 200);
  }
  static std::uint16_t port() { return server_->port(); }
  static const std::string& token() { return server_->token(); }

  static inline Server* server_ = nullptr;
  static inline std::filesystem::path dir_;
};

TEST_F(HttpTest, ServesThePageAndReadOnlyApi) {
  const Response page = testing::request(port(), "GET", "/");
  EXPECT_EQ(page.status, 200);
  EXPECT_NE(page.body.find("editor"), std::string::npos);
  EXPECT_NE(page.headers.at("content-security-policy").find("default-src 'self'"), std::string::npos);
  EXPECT_EQ(testing::request(port(), "GET", "/assets/app.js").headers["content-type"],
            "text/javascript; charset=utf-8");
  const Response info = testing::request(port(), "GET", "/api/info");
  ASSERT_EQ(info.status, 200);
  EXPECT_EQ(json::parse(info.body)["workcell"], "test");
  EXPECT_EQ(info.headers.at("cache-control"), "no-store");
}

TEST_F(HttpTest, ChangesNeedTheToken) {
  const std::string body =
      R"({"plan": {"main_tree": "main", "trees": [{"id": "main", "root": {"id": "AlwaysSuccess"}}]}})";
  EXPECT_EQ(testing::request(port(), "PUT", "/api/plans/p", body).status, 401);
  EXPECT_EQ(testing::request(port(), "PUT", "/api/plans/p", body, "wrong-token-123456").status, 401);
  EXPECT_EQ(testing::request(port(), "POST", "/api/operations", R"({"node": "TestLog"})").status, 401);
  const Response saved = testing::request(port(), "PUT", "/api/plans/p", body, token());
  EXPECT_EQ(saved.status, 201) << saved.body;
}

TEST_F(HttpTest, RefusesOversizeBodiesWithoutReadingThem) {
  testing::Socket socket(port());
  // Announce 2 MiB, send only the headers: the answer comes before the body.
  socket.send("PUT /api/plans/big HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer " + token() +
              "\r\nContent-Type: application/json\r\nContent-Length: 2097152\r\n\r\n{\"xml\": \"");
  std::string pending;
  EXPECT_EQ(testing::readResponse(socket, pending).status, 413);
}

TEST_F(HttpTest, AnswersMalformedRequestsWith400) {
  testing::Socket socket(port());
  socket.send("THIS IS NOT HTTP\r\n\r\n");
  std::string pending;
  EXPECT_EQ(testing::readResponse(socket, pending).status, 400);

  testing::Socket long_header(port());
  long_header.send("GET /api/info HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Long: " + std::string(20000, 'a') + "\r\n\r\n");
  pending.clear();
  EXPECT_EQ(testing::readResponse(long_header, pending).status, 400);
}

TEST_F(HttpTest, RefusesOtherHostsOnLoopback) {
  // Issue 27: any Host starting with "127." passed (a DNS-rebinding site's name can). Only a
  // loopback literal or localhost, with an optional port.
  struct Case {
    std::string host;
    int status;
  };
  const std::string own = std::to_string(port());
  const std::vector<Case> cases = {
      {"127.0.0.1", 200},
      {"127.0.0.1:" + own, 200},
      {"localhost", 200},
      {"LocalHost:8080", 200},
      {"127.1.2.3:1", 200},
      {"127.255.255.254:65535", 200},
      {"[::1]", 200},
      {"[::1]:" + own, 200},
      {"[0:0:0:0:0:0:0:1]:80", 200},
      {"evil.example.com", 421},
      {"127.attacker.example", 421},
      {"127.0.0.1.nip.io", 421},
      {"127.0.0.1.nip", 421},
      {"127.0.0.1evil", 421},
      {"127.0.0.1evil:" + own, 421},
      {"[::1].evil.com", 421},
      {"[::1]evil", 421},
      {"[::1]:", 421},
      {"[::1", 421},
      {"[::1%lo]", 421},
      {"[::ffff:127.0.0.1]", 421},
      {"[::2]", 421},
      {"localhost.evil.com", 421},
      {"localhost.", 421},
      {"localhostevil", 421},
      {"127.0.0.1:", 421},
      {"127.0.0.1:0", 421},
      {"127.0.0.1:65536", 421},
      {"127.0.0.1:99999999999", 421},
      {"127.0.0.1:80:80", 421},
      {"127.0.0.1:8o", 421},
      {"127.00.0.1", 421},
      {"0177.0.0.1", 421},
      {"127.1", 421},
      {"127.0.0.256", 421},
      {"127.0.0.1.", 421},
      {"user@127.0.0.1", 421},
      {"128.0.0.1", 421},
      {"0.0.0.0", 421},
      {"", 421},
  };
  for (const Case& c : cases) {
    const testing::Response response = testing::request(port(), "GET", "/api/info", {}, {}, c.host);
    EXPECT_EQ(response.status, c.status) << "Host: " << c.host;
    if (c.status == 421) {
      EXPECT_NE(response.body.find("whose Host is localhost, 127.x.y.z or [::1]"), std::string::npos) << response.body;
    }
  }
}

TEST_F(HttpTest, StaticFilesStayInsideTheWebRoot) {
  EXPECT_EQ(testing::request(port(), "GET", "/../secret.txt").status, 404);
  EXPECT_EQ(testing::request(port(), "GET", "/%2e%2e/secret.txt").status, 404);
  EXPECT_EQ(testing::request(port(), "GET", "/assets/../../secret.txt").status, 404);
  EXPECT_EQ(testing::request(port(), "POST", "/index.html", "{}", token()).status, 405);
}

TEST_F(HttpTest, KeepsConnectionsAlive) {
  testing::Socket socket(port());
  std::string pending;
  for (int i = 0; i < 3; ++i) {
    socket.send("GET /api/info HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n");
    EXPECT_EQ(testing::readResponse(socket, pending).status, 200);
  }
}

TEST_F(HttpTest, StreamSendsHelloThenStateSnapshots) {
  WebSocket ws(port());
  ASSERT_EQ(ws.status, 101);
  const auto hello = ws.read();
  ASSERT_TRUE(hello);
  const json first = json::parse(*hello);
  EXPECT_EQ(first["type"], "hello");
  EXPECT_EQ(first["info"]["workcell"], "test");
  EXPECT_EQ(first["state"]["type"], "state");
  double last_t = -1;
  int states = 0;
  while (states < 5) {
    const auto message = ws.read();
    ASSERT_TRUE(message);
    const json m = json::parse(*message);
    if (m["type"] == "state") {
      EXPECT_GT(m["t"].get<double>(), last_t);  // fresh snapshots: simulated time goes on
      last_t = m["t"];
      ++states;
    }
  }
}

TEST_F(HttpTest, StreamCommandsNeedTheToken) {
  WebSocket ws(port());
  ASSERT_EQ(ws.status, 101);
  const auto next = [&ws](const std::string& type) {
    while (auto message = ws.read()) {
      json m = json::parse(*message);
      if (m["type"] == type || m["type"] == "error") {
        return m;
      }
    }
    return json();
  };
  ws.send(R"({"type": "control", "action": "stop"})");
  EXPECT_EQ(next("control")["type"], "error");
  ws.send(R"({"type": "auth", "token": "not-the-token-1234"})");
  EXPECT_FALSE(next("auth")["ok"].get<bool>());
  ws.send("{broken json");
  EXPECT_EQ(next("nothing")["type"], "error");
  ws.send(R"({"type": "auth", "token": ")" + token() + "\"}");
  EXPECT_TRUE(next("auth")["ok"].get<bool>());
  ws.send(R"({"type": "control", "action": "stop"})");
  const json answer = next("control");
  EXPECT_EQ(answer["type"], "control");
  EXPECT_FALSE(answer["ok"].get<bool>());  // nothing runs
  // A hostile tester: a wrong token after the right one left the stream authenticated.
  ws.send(R"({"type": "auth", "token": "not-the-token-1234"})");
  EXPECT_FALSE(next("auth")["ok"].get<bool>());
  ws.send(R"({"type": "control", "action": "stop"})");
  EXPECT_EQ(next("control")["type"], "error");
}

TEST_F(HttpTest, StreamShowsARunAndStopHaltsIt) {
  WebSocket ws(port());
  ASSERT_EQ(ws.status, 101);
  const std::string body =
      R"({"plan": {"main_tree": "main", "trees": [{"id": "main", "root": {"id": "TestAction", "attributes": [["polls", "100000000"]]}}]}})";
  const Response started = testing::request(port(), "POST", "/api/runs", body, token());
  ASSERT_EQ(started.status, 202) << started.body;
  const std::int64_t id = json::parse(started.body)["run"];
  bool running = false;
  while (!running) {
    const auto message = ws.read();
    ASSERT_TRUE(message);
    const json m = json::parse(*message);
    if (m["type"] == "statuses" && m["run"] == id) {
      for (const auto& n : m["nodes"]) {
        running = running || n["status"] == "RUNNING";
      }
    }
  }
  ws.send(R"({"type": "auth", "token": ")" + token() + "\"}");
  ws.send(R"({"type": "control", "action": "stop"})");
  json ended;
  while (ended.is_null()) {
    const auto message = ws.read();
    ASSERT_TRUE(message);
    const json m = json::parse(*message);
    if (m["type"] == "run_ended") {
      ended = m;
    }
  }
  EXPECT_EQ(ended["run"]["id"], id);
  EXPECT_EQ(ended["run"]["result"], "STOPPED");
}

TEST_F(HttpTest, RefusesWebSocketsFromOtherSites) {
  // Issue 27: any Origin whose host started with "127." opened the stream, and so did a page on
  // another port of this machine. Only the page's own origin does now.
  struct Case {
    std::string origin;
    std::string host;
    int status;
  };
  const std::string own = std::to_string(port());
  const std::string here = "127.0.0.1:" + own;
  const std::vector<Case> cases = {
      {"", here, 101},  // not a browser
      {"http://127.0.0.1:" + own, here, 101},
      {"HTTP://127.0.0.1:" + own, here, 101},
      {"https://127.0.0.1:" + own, here, 101},
      {"http://localhost:" + own, "localhost:" + own, 101},
      {"http://[::1]:" + own, "[::1]:" + own, 101},
      {"http://127.0.0.1", "127.0.0.1", 101},            // both on port 80
      {"https://127.0.0.1", "127.0.0.1:443", 101},       // both on port 443
      {"http://localhost:5173", "localhost:5173", 101},  // the page's development server, a proxy
      {"http://localhost:5173", here, 403},              // another port of this machine
      {"http://127.0.0.1:5173", here, 403},
      {"http://127.0.0.1", here, 403},
      {"http://localhost:" + own, here, 403},  // another origin, though the same machine
      {"http://evil.example.com", here, 403},
      {"http://127.evil.example:" + own, here, 403},
      {"http://127.0.0.1.nip.io:" + own, here, 403},
      {"http://127.0.0.1evil:" + own, here, 403},
      {"http://[::1].evil.com:" + own, here, 403},
      {"http://127.0.0.1:" + own + "/", here, 403},
      {"http://127.0.0.1:" + own + "@evil.example.com", here, 403},
      {"ws://127.0.0.1:" + own, here, 403},
      {"file://", here, 403},
      {"null", here, 403},
      {"127.0.0.1:" + own, here, 403},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(WebSocket(port(), "/api/stream", c.origin, c.host).status, c.status)
        << "Origin: " << c.origin << ", Host: " << c.host;
  }
  EXPECT_EQ(WebSocket(port(), "/api/other").status, 404);
  const testing::Response refused = [&] {
    testing::Socket socket(port());
    socket.send("GET /api/stream HTTP/1.1\r\nHost: " + here +
                "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                "Sec-WebSocket-Version: 13\r\nOrigin: http://127.evil.example\r\n\r\n");
    std::string pending;
    return testing::readResponse(socket, pending);
  }();
  EXPECT_NE(refused.body.find("its Origin is not this server's page"), std::string::npos) << refused.body;
}

}  // namespace
}  // namespace costar::server
