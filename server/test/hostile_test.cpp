// A hostile stranger with a valid token (and one without): cut UTF-8 in every field of every
// route, huge bodies, odd paths, methods and headers, WebSocket messages that are not what the
// page sends, slow partial requests. The server never dies, answers 4xx with a message (never
// 500 for what a request holds), and without the token accepts no motion. Then a backend that
// throws where nothing expects it: the server logs it and goes on (guard.h).

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>
#include <vector>

#include "server/api.h"
#include "server/auth.h"
#include "server/backend.h"
#include "server/http_server.h"
#include "server/serve.h"
#include "server/store.h"
#include "server/test/http_client.h"

namespace costar::server {
namespace {

using nlohmann::json;
using testing::Response;
using testing::WebSocket;

// 'a' and 19 times 'é' (2 bytes each): the API quotes at most 32 bytes of an action, which
// cuts the 16th 'é' in half.
const std::string kLongAccents =
    "a\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9"
    "\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9";
// Cut UTF-8: the first byte of a 2-, 3- and 4-byte character, and bytes that are never UTF-8.
const std::vector<std::string> kCuts = {"\xc3",     "x\xe2\x82",  "\xf0\x9f\x98",
                                        "\xff\xfe", kLongAccents, std::string(300, 'a') + "\xc3"};

/// The answer is well-formed: a status, a JSON body with an "error" for 4xx.
void expectClientError(const Response& response, const std::string& what) {
  EXPECT_GE(response.status, 400) << what << ": " << response.body;
  EXPECT_LT(response.status, 500) << what << ": " << response.body;
  const json body = json::parse(response.body, nullptr, false);
  ASSERT_FALSE(body.is_discarded()) << what << ": " << response.body;
  EXPECT_TRUE(body.contains("error") && body["error"].is_string() && !body["error"].get<std::string>().empty()) << what;
}

class HostileTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::filesystem::temp_directory_path() / ("costar_hostile_test_" + randomToken().substr(0, 8));
    std::filesystem::create_directories(dir_);
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

TEST_F(HostileTest, TheIssueReproducerIsAnswered400) {
  // Was: json type_error 316 thrown while answering, std::terminate.
  const Response response =
      testing::request(port(), "POST", "/api/control", json{{"action", kLongAccents}}.dump(), token());
  expectClientError(response, "control");
  EXPECT_NE(json::parse(response.body)["error"].get<std::string>().find("unknown action"), std::string::npos);
  // Without the token, a path with bytes that are not UTF-8 is not found (was: 500).
  EXPECT_EQ(testing::request(port(), "GET", "/api/no\xff\xfesuch").status, 404);
}

TEST_F(HostileTest, CutUtf8InEveryFieldOfEveryRoute) {
  const auto plan = [](const std::string& tree, const std::string& node, const std::string& key,
                       const std::string& value) {
    return json{{"plan",
                 {{"main_tree", tree},
                  {"trees", json::array({json{{"id", tree},
                                              {"root",
                                               {{"id", node},
                                                {"attributes", json::array({json::array({key, value})})},
                                                {"children", json::array()}}}}})}}}};
  };
  for (const std::string& cut : kCuts) {
    // The body as text with raw bytes (json::dump would refuse them): built by hand.
    const auto raw = [&cut](const std::string& before, const std::string& after) { return before + cut + after; };
    struct Case {
      std::string method, target, body;
    };
    std::vector<Case> cases = {
        {"POST", "/api/control", raw(R"({"action":")", R"("})")},
        {"POST", "/api/operations", raw(R"({"node":")", R"("})")},
        {"POST", "/api/operations", raw(R"({"node":"TestLog","attributes":{")", R"(":"x"}})")},
        {"POST", "/api/operations", raw(R"({"node":"TestLog","attributes":{"message":")", R"("}})")},
        {"POST", "/api/operations", raw(R"({"node":"TestLog","attributes":{"message":1,")", R"(":2}})")},
        {"POST", "/api/validate", raw(R"({"xml":")", R"("})")},
        {"POST", "/api/validate", raw(R"({"xml":"<root BTCPP_format=\"4\"><BehaviorTree ID=\")", R"(\"/></root>"})")},
        {"POST", "/api/runs", raw(R"({"name":")", R"("})")},
        {"POST", "/api/runs", raw(R"({"xml":"<root><)", R"(/></root>"})")},
        {"PUT", "/api/plans/p", raw(R"({"xml":"<)", R"("})")},
        {"PUT", "/api/plans/" + cut, R"({"xml":"<root/>"})"},
        {"PUT", "/api/subtrees/" + cut, R"({"xml":"<root/>"})"},
        {"DELETE", "/api/plans/" + cut, ""},
        {"POST", "/api/control", raw(R"({"action":)", "}")},  // bad JSON: the parser quotes the bytes
        {"POST", "/api/runs", raw("", "")},
        {"POST", "/api/" + cut, "{}"},
        {"PUT", "/api/plans/p?version=" + cut, "{}"},
        {cut.substr(0, 1) == "a" ? "POST" : "PATCH", "/api/runs", "{}"},
    };
    // Bodies json::dump can build: the plan's every field.
    for (int field = 0; field < 4; ++field) {
      const std::string good[] = {"main", "TestLog", "message", "hello"};
      std::string parts[4] = {good[0], good[1], good[2], good[3]};
      parts[field] = parts[field] + cut;
      const json body = plan(parts[0], parts[1], parts[2], parts[3]);
      const std::string text = body.dump(-1, ' ', false, json::error_handler_t::ignore);
      // (ignore drops the cut bytes; send them raw instead)
      std::string with_cut = json{{"plan", body["plan"]}}.dump(-1, ' ', false, json::error_handler_t::replace);
      const std::string marker = "\xef\xbf\xbd";  // what replace wrote for the cut
      for (std::size_t at = with_cut.find(marker); at != std::string::npos; at = with_cut.find(marker)) {
        with_cut.replace(at, marker.size(), "\xc3");
      }
      cases.push_back({"POST", "/api/validate", with_cut});
      cases.push_back({"PUT", "/api/plans/p", with_cut});
      cases.push_back({"POST", "/api/runs", with_cut});
      cases.push_back({"POST", "/api/validate", text});
    }
    for (const Case& c : cases) {
      const Response response = testing::request(port(), c.method, c.target, c.body, token());
      const std::string what = c.method + " " + c.target + " " + c.body.substr(0, 80);
      ASSERT_NE(response.status, 0) << what << ": no answer";
      EXPECT_LT(response.status, 500) << what << ": " << response.body;
      EXPECT_FALSE(json::parse(response.body, nullptr, false).is_discarded()) << what << ": " << response.body;
      if (response.status == 202) {  // a run started (a valid plan with an odd value): let it end
        testing::request(port(), "POST", "/api/control", R"({"action":"stop"})", token());
        for (int i = 0; i < 200 && testing::request(port(), "GET", "/api/runs/active").body.find("\"active\":true") !=
                                       std::string::npos;
             ++i) {
          std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
      }
    }
  }
}

TEST_F(HostileTest, OddPathsMethodsAndHeaders) {
  const auto raw = [](const std::string& text) {
    testing::Socket socket(port());
    socket.send(text);
    std::string pending;
    return testing::readResponse(socket, pending);
  };
  const std::string auth = "Authorization: Bearer " + token() + "\r\n";
  // Odd paths.
  for (const std::string& target : std::vector<std::string>{
           "//api//info", "/api/../api/info", "/api/plans/%2e%2e", "/api/runs/99999999999999999999", "/api/runs/-1",
           "/api/runs/0x10", "/api/plans/a?version=0", "/api/plans/a?version=99999999999", "/api/pointcloud?max=-1",
           "/api/runs?limit=1e9", "/api?", "/api/plans/a/versions/extra", "/api/plans/" + std::string(5000, 'a')}) {
    const Response response = raw("GET " + target + " HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n");
    ASSERT_NE(response.status, 0) << target;
    EXPECT_LT(response.status, 500) << target << ": " << response.body;
  }
  expectClientError(raw("GET " + std::string(20000, '/') + " HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"), "long target");
  EXPECT_EQ(raw("GET * HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n").status, 404);
  expectClientError(raw("GET http://127.0.0.1/api/info HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"), "absolute form");
  // Odd methods, with the token.
  for (const std::string& method :
       std::vector<std::string>{"BREW", "get", "OPTIONS", "TRACE", "CONNECT", "PATCH", "PROPFIND"}) {
    const Response response = raw(method + " /api/runs HTTP/1.1\r\nHost: 127.0.0.1\r\n" + auth + "\r\n");
    ASSERT_NE(response.status, 0) << method;
    EXPECT_GE(response.status, 400) << method;
    EXPECT_LT(response.status, 500) << method << ": " << response.body;
  }
  // Odd headers.
  const std::string body = R"({"action":"stop"})";
  for (const std::string& headers : std::vector<std::string>{
           "Content-Length: -5\r\n", "Content-Length: 5\r\nContent-Length: 6\r\n",
           "Transfer-Encoding: chunked\r\nContent-Length: 17\r\n", "Content-Length: 99999999999999999999999\r\n",
           "Authorization: Bearer \xc3\r\n", "Authorization: Bearer\r\n", "Authorization: Basic Zm9vOmJhcg==\r\n",
           "Host: 127.0.0.1\r\n", "X-\xff\xfe: \xc3\r\n", "Expect: 100-continue\r\nContent-Length: 17\r\n"}) {
    const Response response =
        raw("POST /api/control HTTP/1.1\r\nHost: 127.0.0.1\r\n" + headers + "Connection: close\r\n\r\n" + body);
    ASSERT_NE(response.status, 0) << headers;
    EXPECT_GE(response.status, 400) << headers;
    EXPECT_LT(response.status, 500) << headers << ": " << response.body;
  }
}

TEST_F(HostileTest, HugeBodiesAreRefused) {
  // Sent in full (not only announced): 413, or the connection closed after the answer.
  const std::string huge = "{\"xml\":\"" + std::string(3u << 20, 'a') + "\"}";
  testing::Socket socket(port());
  socket.send("PUT /api/plans/big HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer " + token() +
              "\r\nContent-Length: " + std::to_string(huge.size()) + "\r\n\r\n");
  socket.send(huge);  // may fail half-way: the server closed after answering
  std::string pending;
  EXPECT_EQ(testing::readResponse(socket, pending).status, 413);
  // Chunked, without announcing a length.
  testing::Socket chunked(port());
  chunked.send("PUT /api/plans/big HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer " + token() +
               "\r\nTransfer-Encoding: chunked\r\n\r\n");
  for (int i = 0; i < 40 && chunked.send("10000\r\n" + std::string(0x10000, 'a') + "\r\n"); ++i) {
  }
  pending.clear();
  EXPECT_EQ(testing::readResponse(chunked, pending).status, 413);
}

/// Issue 27's hostile shape: a chain of `trees` SubTrees, each an Inverter over the next, a
/// tree a line (the first on line 2).
std::string subTreeChain(int trees) {
  std::string xml = "<root BTCPP_format=\"4\" main_tree_to_execute=\"T0\">\n";
  for (int i = 0; i < trees; ++i) {
    xml += "<BehaviorTree ID=\"T" + std::to_string(i) + "\"><Inverter>" +
           (i + 1 < trees ? "<SubTree ID=\"T" + std::to_string(i + 1) + "\"/>" : "<AlwaysSuccess/>") +
           "</Inverter></BehaviorTree>\n";
  }
  return xml + "</root>\n";
}

TEST_F(HostileTest, AChainOfThousandsOfSubTreesIsRefusedNotACrash) {
  // Issue 27: one authenticated request of ~950 KB overflowed the stack in the validator's
  // depth measurement, killing the server (and so the arm's run) with nothing printed.
  const std::string xml = json{{"xml", subTreeChain(11000)}}.dump();
  ASSERT_GT(xml.size(), 900'000u);
  ASSERT_LT(xml.size(), 1u << 20);
  const Response validated = testing::request(port(), "POST", "/api/validate", xml, token());
  ASSERT_EQ(validated.status, 200) << validated.body.substr(0, 300);
  const json body = json::parse(validated.body);
  EXPECT_FALSE(body["valid"].get<bool>());
  ASSERT_EQ(body["diagnostics"].size(), 1u);
  EXPECT_TRUE(body["diagnostics"][0]["where"].get<std::string>().starts_with("plan:"));
  EXPECT_EQ(body["diagnostics"][0]["message"],
            "the plan nests deeper than 1000 levels once its subtrees are instantiated");
  EXPECT_EQ(body["diagnostics"][0]["node"]["tree"], "T500");  // the editor's node
  for (const auto& [method, target] :
       std::vector<std::pair<std::string, std::string>>{{"PUT", "/api/plans/deep"}, {"POST", "/api/runs"}}) {
    const Response refused = testing::request(port(), method, target, xml, token());
    EXPECT_EQ(refused.status, 422) << target << ": " << refused.body.substr(0, 300);
    EXPECT_NE(refused.body.find("nests deeper than 1000 levels"), std::string::npos) << target;
  }
  EXPECT_EQ(testing::request(port(), "GET", "/api/plans/deep").status, 404);
  // The same chain as the editor's JSON.
  json trees = json::array();
  for (int i = 0; i < 6000; ++i) {
    const json leaf =
        i + 1 < 6000
            ? json{{"id", "SubTree"}, {"attributes", json::array({json::array({"ID", "T" + std::to_string(i + 1)})})}}
            : json{{"id", "AlwaysSuccess"}};
    trees.push_back({{"id", "T" + std::to_string(i)}, {"root", {{"id", "Inverter"}, {"children", {leaf}}}}});
  }
  const std::string editor = json{{"plan", {{"main_tree", "T0"}, {"trees", trees}}}}.dump();
  ASSERT_LT(editor.size(), 1u << 20);
  const Response from_editor = testing::request(port(), "POST", "/api/validate", editor, token());
  ASSERT_EQ(from_editor.status, 200) << from_editor.body.substr(0, 300);
  EXPECT_NE(from_editor.body.find("nests deeper than 1000 levels"), std::string::npos);
}

TEST_F(HostileTest, SurrogateReferencesAndBytesThatAreNotUtf8AreRefusedInPlans) {
  // Issue 27: `&#xD800;` in a name became bytes that are not UTF-8; the plan validated, saved
  // and ran, and broke every JSON that later held the name.
  const auto planWith = [](const std::string& name) {
    return json{{"xml", "<root BTCPP_format=\"4\"><BehaviorTree ID=\"m\"><TestLog name=\"" + name +
                            "\" message=\"x\"/></BehaviorTree></root>"}}
        .dump();
  };
  for (const auto& [method, target] : std::vector<std::pair<std::string, std::string>>{
           {"POST", "/api/validate"}, {"PUT", "/api/plans/surrogate"}, {"POST", "/api/runs"}}) {
    const Response refused = testing::request(port(), method, target, planWith("a&#xD800;b"), token());
    EXPECT_EQ(refused.status, 422) << target << ": " << refused.body;
    EXPECT_NE(refused.body.find("column 61: the character reference '&#xD800;' is not a character XML allows"),
              std::string::npos)
        << refused.body;
  }
  EXPECT_EQ(testing::request(port(), "GET", "/api/plans/surrogate").status, 404);
  // As a JSON escape: not JSON at all (a lone surrogate).
  expectClientError(
      testing::request(
          port(), "POST", "/api/validate",
          R"({"xml":"<root BTCPP_format=\"4\"><BehaviorTree ID=\"m\"><TestLog name=\"\ud800\" message=\"x\"/></BehaviorTree></root>"})",
          token()),
      "a lone surrogate escape");
}

TEST_F(HostileTest, ALongRunLogIsReadInBoundedPages) {
  // Issue 27: one unauthenticated GET of a 120,000-transition log took 7 s of CPU and hundreds
  // of MB; six at once stalled the server. A log is read in pages now.
  const std::int64_t id = 1'000'000;  // far beyond what the engine numbers runs
  RunRecord record;
  record.id = id;
  record.xml = "<root BTCPP_format=\"4\"><BehaviorTree ID=\"m\"><AlwaysSuccess/></BehaviorTree></root>";
  record.started_at = 1;
  server_->store().beginRun(record, {{0, -1, "AlwaysSuccess", "", "m/AlwaysSuccess[1]"}});
  std::vector<TransitionRecord> transitions;
  for (std::uint64_t seq = 1; seq <= 12'001; ++seq) {
    transitions.push_back({seq, 0.01 * static_cast<double>(seq), 0, "IDLE", "RUNNING", "", "", R"({"n":1})"});
  }
  server_->store().appendTransitions(id, transitions);
  record.result = "SUCCESS";
  record.transitions = 12'001;
  server_->store().endRun(record);

  const Response first = testing::request(port(), "GET", "/api/runs/" + std::to_string(id));
  ASSERT_EQ(first.status, 200);
  const json head = json::parse(first.body);
  ASSERT_EQ(head["transition_list"].size(), 5000u);
  EXPECT_EQ(head["next_from"], 5001);
  EXPECT_EQ(head["nodes"].size(), 1u);
  EXPECT_EQ(head["transitions"], 12'001);
  std::uint64_t expected = 1;
  for (const json& t : head["transition_list"]) {
    EXPECT_EQ(t["seq"], expected++);
  }
  for (json next = head["next_from"]; !next.is_null();) {
    const Response page = testing::request(
        port(), "GET", "/api/runs/" + std::to_string(id) + "/transitions?from=" + next.dump() + "&limit=3000");
    ASSERT_EQ(page.status, 200);
    const json body = json::parse(page.body);
    EXPECT_LE(body["transition_list"].size(), 3000u);
    EXPECT_FALSE(body.contains("nodes"));
    for (const json& t : body["transition_list"]) {
      EXPECT_EQ(t["seq"], expected++);
      EXPECT_EQ(t["data"]["n"], 1);
    }
    next = body["next_from"];
  }
  EXPECT_EQ(expected, 12'002u);  // every transition, once, in order
  for (const char* bad : {"?from=0", "?from=x", "?limit=0", "?limit=5001", "?limit=-1", "?from=1&limit=1e3"}) {
    expectClientError(testing::request(port(), "GET", "/api/runs/" + std::to_string(id) + bad), bad);
  }
  expectClientError(testing::request(port(), "GET", "/api/runs/abc/transitions"), "not an id");
  expectClientError(testing::request(port(), "GET", "/api/runs/999999/transitions"), "no such run");
  expectClientError(testing::request(port(), "POST", "/api/runs/1/transitions", "{}", token()), "not GET");
}

TEST_F(HostileTest, NoMotionWithoutTheToken) {
  const std::string body = R"({"node":"TestLog","attributes":{"message":"hi"}})";
  const std::string plan =
      R"({"plan":{"main_tree":"main","trees":[{"id":"main","root":{"id":"TestLog","attributes":[["message","x"]]}}]}})";
  const auto lastRun = [] {
    const Response active = testing::request(port(), "GET", "/api/runs/active");
    return active.status == 200 ? json::parse(active.body)["id"].get<long long>() : 0;
  };
  const long long last_run = lastRun();
  for (const std::string& bad_token :
       std::vector<std::string>{"", "wrong-token-123456", "\xc3", token() + "x", token().substr(1)}) {
    EXPECT_EQ(testing::request(port(), "POST", "/api/operations", body, bad_token).status, 401) << bad_token;
    EXPECT_EQ(testing::request(port(), "POST", "/api/runs", plan, bad_token).status, 401) << bad_token;
    EXPECT_EQ(testing::request(port(), "POST", "/api/control", R"({"action":"resume"})", bad_token).status, 401);
    WebSocket ws(port());
    ASSERT_EQ(ws.status, 101);
    ASSERT_TRUE(ws.read());  // hello
    ws.send(R"({"type":"auth","token":")" + bad_token + R"("})");
    ws.send(R"({"type":"control","action":"step"})");
    for (int i = 0; i < 50; ++i) {  // the answers come between state snapshots
      const auto message = ws.read(std::chrono::seconds(5));
      if (bad_token == "\xc3") {  // a text frame that is not UTF-8: closed (RFC 6455, 1007)
        if (!message) {
          break;
        }
        EXPECT_EQ(json::parse(*message)["type"], "state") << *message;
        continue;
      }
      ASSERT_TRUE(message);
      const json parsed = json::parse(*message, nullptr, false);
      ASSERT_FALSE(parsed.is_discarded()) << *message;
      if (parsed["type"] == "error") {
        EXPECT_NE(parsed["error"].get<std::string>().find("token"), std::string::npos);
        break;
      }
      EXPECT_NE(parsed["type"], "control") << *message;
    }
  }
  // Nothing ran.
  EXPECT_EQ(lastRun(), last_run);
}

TEST_F(HostileTest, WebSocketMessagesThatAreNotThePages) {
  // Text frames that are not UTF-8: the connection is closed (RFC 6455, 1007), nothing else.
  for (const std::string& text : std::vector<std::string>{"{\"type\":\"\xc3\"}", "\xc3", "\xff\xfe",
                                                          "{\"type\":\"auth\",\"token\":\"\xe2\x82\"}"}) {
    WebSocket ws(port());
    ASSERT_EQ(ws.status, 101);
    ASSERT_TRUE(ws.read());  // hello
    ASSERT_TRUE(ws.send(text));
    std::optional<std::string> message;
    for (int i = 0; i < 200 && (message = ws.read(std::chrono::seconds(5))); ++i) {
      EXPECT_EQ(json::parse(*message)["type"], "state") << *message;
    }
    EXPECT_FALSE(message);
  }
  // UTF-8 that is not what the page sends: an error (or a refused auth) each, then the pong.
  WebSocket ws(port());
  ASSERT_EQ(ws.status, 101);
  ASSERT_TRUE(ws.read());  // hello
  const std::vector<std::string> odd = {"[1,2",
                                        std::string(20000, '['),
                                        "{\"type\":\"" + kLongAccents + "\"}",
                                        "{\"type\":\"control\",\"action\":\"" + kLongAccents + "\"}",
                                        "{\"type\":\"auth\",\"token\":[]}",
                                        "{\"type\":7}",
                                        "null"};
  for (const std::string& text : odd) {
    ASSERT_TRUE(ws.send(text));
  }
  ASSERT_TRUE(ws.send(R"({"type":"ping"})"));
  int errors = 0;
  for (int i = 0; i < 200; ++i) {
    const auto message = ws.read(std::chrono::seconds(5));
    ASSERT_TRUE(message) << "the stream closed";
    const json parsed = json::parse(*message, nullptr, false);
    ASSERT_FALSE(parsed.is_discarded()) << *message;
    errors += parsed["type"] == "error" || (parsed["type"] == "auth" && parsed["ok"] == false) ? 1 : 0;
    if (parsed["type"] == "pong") {
      EXPECT_EQ(errors, static_cast<int>(odd.size()));
      return;
    }
  }
  FAIL() << "no pong";
}

TEST_F(HostileTest, SlowPartialRequestsDoNotHoldOthersUp) {
  // 64 connections that send a request's start and then nothing (bounded: they are closed at
  // the end of the test): the others are answered at once.
  std::vector<std::unique_ptr<testing::Socket>> slow;
  for (int i = 0; i < 64; ++i) {
    slow.push_back(std::make_unique<testing::Socket>(port()));
    slow.back()->send(i % 2 == 0 ? "GET /api/info HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: "
                                 : "PUT /api/plans/x HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 100\r\n\r\n{");
  }
  for (int i = 0; i < 10; ++i) {
    const auto start = std::chrono::steady_clock::now();
    EXPECT_EQ(testing::request(port(), "GET", "/api/info").status, 200);
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
    for (auto& socket : slow) {
      socket->send("a");  // a byte now and then, as slowloris does
    }
  }
}

/// A backend that throws where nothing expects it: the stream's hello and drain.
class ThrowingBackend final : public Backend {
 public:
  json info() override { return {{"workcell", "throwing"}}; }
  const std::string& nodesJson() override { return nodes_; }
  json choices() override { throw std::runtime_error("choices failed"); }
  std::vector<bt::Diagnostic> validate(const bt::Plan&) override { return {}; }
  StartResult start(RunRequest) override { throw std::logic_error("start failed"); }
  bool control(RunControl) override { throw std::runtime_error("control failed"); }
  json state() override { return {{"type", "state"}}; }
  std::optional<json> runStatus(std::optional<std::int64_t>) override { return std::nullopt; }
  std::optional<json> groundTruth() override { return std::nullopt; }
  std::optional<json> pointCloud(std::size_t) override { throw 42; }  // not even a std::exception
  std::vector<std::string> drainStream() override {
    ++drains;
    throw std::runtime_error("drain failed");
  }
  std::string helloMessage() override { throw std::runtime_error("hello failed"); }
  std::atomic<int> drains{0};

 private:
  std::string nodes_ = "[]";
};

TEST(ServerGuards, ExceptionsOnServerThreadsBecomeAnswersOrLoggedErrors) {
  ThrowingBackend backend;
  Store store(":memory:");
  Api api(backend, store, ApiOptions{.token = "guard-token-0123456789"});
  HttpServerOptions options;
  options.port = 0;
  options.threads = 2;
  options.stream_hz = 100;
  HttpServer http(api, backend, options);
  http.start();
  // Handlers that throw: 500 with a message.
  EXPECT_EQ(testing::request(http.port(), "GET", "/api/choices").status, 500);
  EXPECT_EQ(testing::request(http.port(), "GET", "/api/pointcloud").status, 500);
  EXPECT_EQ(
      testing::request(http.port(), "POST", "/api/control", R"({"action":"stop"})", "guard-token-0123456789").status,
      500);
  // The stream's hello throws: that client is closed, the server goes on.
  {
    WebSocket ws(http.port());
    EXPECT_EQ(ws.status, 101);
    EXPECT_FALSE(ws.read(std::chrono::seconds(5)));
  }
  // The broadcaster's drain throws every round: it keeps going (logged each time).
  const int drains = backend.drains.load();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_GT(backend.drains.load(), drains + 5);
  EXPECT_EQ(testing::request(http.port(), "GET", "/api/info").status, 200);
  http.stop();
}

}  // namespace
}  // namespace costar::server
