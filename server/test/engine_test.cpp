// The API and the engine together, in one process without the network: plans saved,
// validated, run and logged on the test workcell, and the "pick up node" plan run in the
// simulated UR5 cell, judged from the simulator's true state.

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "bt/builder.h"
#include "bt/plan_xml.h"
#include "core/paths.h"
#include "server/api.h"
#include "server/engine.h"
#include "server/plan_json.h"
#include "server/store.h"
#include "workcell/workcell.h"

namespace costar::server {
namespace {

using nlohmann::json;

constexpr const char* kToken = "test-token-0123456789";

/// A workcell, an in-memory store, the engine and the API.
class Harness {
 public:
  explicit Harness(workcell::WorkcellOptions options, double pace = 0.0, ApiOptions api_options = {}) {
    options.memory_only = true;
    cell_ = workcell::makeWorkcell(options);
    EngineOptions engine_options;
    engine_options.pace = pace;
    engine_options.grasp_defaults = dataRoot() / "data/grasps.json";
    engine_ = std::make_unique<Engine>(*cell_, &store_, engine_options);
    api_options.token = kToken;
    api_ = std::make_unique<Api>(*engine_, store_, api_options);
    engine_->startThread();
  }
  ~Harness() { engine_->shutdown(); }

  HttpResponse call(const std::string& method, const std::string& target, const json& body = nullptr,
                    bool with_token = true) {
    return api_->handle(
        {method, target, body.is_null() ? "" : body.dump(), with_token ? std::string("Bearer ") + kToken : ""});
  }
  HttpResponse api_call_raw(const std::string& method, const std::string& target, const std::string& body) {
    return api_->handle({method, target, body, std::string("Bearer ") + kToken});
  }
  json get(const std::string& target) {
    const HttpResponse response = call("GET", target);
    EXPECT_EQ(response.status, 200) << target << ": " << response.body;
    return json::parse(response.body);
  }
  /// Waits until the run has ended (a safety limit of 120 s of wall time, never expected).
  json waitForRun(std::int64_t id) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (std::chrono::steady_clock::now() < deadline) {
      const auto status = engine_->runStatus(id);
      if (status && !(*status)["active"].get<bool>()) {
        return *status;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    ADD_FAILURE() << "run " << id << " did not end";
    return {};
  }
  /// Waits until the engine thread has run `count` more before-tick hooks.
  void waitTicks(std::uint64_t count) {
    const std::uint64_t target = engine_->stats().ticks + count;
    while (engine_->stats().ticks < target) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }

  Engine& engine() { return *engine_; }
  Store& store() { return store_; }
  workcell::Workcell& cell() { return *cell_; }

 private:
  std::unique_ptr<workcell::Workcell> cell_;
  Store store_{":memory:"};
  std::unique_ptr<Engine> engine_;
  std::unique_ptr<Api> api_;
};

workcell::WorkcellOptions testCell() {
  workcell::WorkcellOptions options;
  options.name = "test";
  return options;
}

json node(const std::string& id, std::vector<std::pair<std::string, std::string>> attributes = {},
          std::vector<json> children = {}) {
  json attrs = json::array();
  for (auto& [key, value] : attributes) {
    attrs.push_back({key, value});
  }
  return {{"id", id}, {"attributes", attrs}, {"children", children}};
}

json plan(const json& root, const std::string& id = "main") {
  return {{"main_tree", id}, {"trees", {{{"id", id}, {"root", root}}}}};
}

TEST(Api, PaletteListsEveryNodeTypeWithItsCategory) {
  Harness h(testCell());
  const json nodes = h.get("/api/nodes");
  std::map<std::string, json> by_id;
  for (const auto& n : nodes) {
    by_id[n["id"]] = n;
  }
  ASSERT_TRUE(by_id.contains("TestAction"));
  EXPECT_EQ(by_id["TestAction"]["category"], "robot_action");
  EXPECT_EQ(by_id["TestAction"]["component"], "test_actions");
  EXPECT_EQ(by_id["Sequence"]["category"], "internal");
  EXPECT_EQ(by_id["CheckPredicate"]["category"], "knowledge");
  const json& result_port = by_id["TestAction"]["ports"][0];
  EXPECT_EQ(result_port["name"], "result");
  EXPECT_EQ(result_port["choices"], json({"success", "failure"}));
  EXPECT_EQ(h.get("/api/info")["workcell"], "test");
}

TEST(Api, ChangesNeedTheToken) {
  Harness h(testCell());
  const json body = {{"plan", plan(node("AlwaysSuccess"))}};
  EXPECT_EQ(h.call("PUT", "/api/plans/p", body, false).status, 401);
  EXPECT_EQ(h.call("POST", "/api/runs", body, false).status, 401);
  EXPECT_EQ(h.call("POST", "/api/operations", {{"node", "TestLog"}}, false).status, 401);
  EXPECT_EQ(h.call("POST", "/api/control", {{"action", "stop"}}, false).status, 401);
  EXPECT_EQ(h.call("DELETE", "/api/plans/p", nullptr, false).status, 401);
  Api wrong(h.engine(), h.store(), {.token = "another-token-abcdef"});
  EXPECT_EQ(wrong.handle({"PUT", "/api/plans/p", body.dump(), std::string("Bearer ") + kToken}).status, 401);
  EXPECT_EQ(h.engine().stats().runs, 0u);                              // nothing ran
  EXPECT_EQ(h.call("GET", "/api/plans", nullptr, false).status, 200);  // reads are open on loopback
  EXPECT_EQ(h.call("PUT", "/api/plans/p", body).status, 201);
}

TEST(Api, ReadsNeedTheTokenBeyondLoopback) {
  Harness h(testCell(), 0.0, {.reads_need_token = true});
  EXPECT_EQ(h.call("GET", "/api/state", nullptr, false).status, 401);
  EXPECT_EQ(h.call("GET", "/api/state").status, 200);
}

TEST(Api, SavesVersionsAndExportsTheXmlTheCliRuns) {
  Harness h(testCell());
  const json p = plan(node("Sequence", {{"name", "demo"}},
                           {node("TestLog", {{"message", "hello & <bye>"}}), node("TestAction", {{"polls", "2"}})}));
  HttpResponse saved = h.call("PUT", "/api/plans/demo", {{"plan", p}});
  ASSERT_EQ(saved.status, 201) << saved.body;
  EXPECT_EQ(json::parse(saved.body)["version"], 1);
  EXPECT_EQ(json::parse(h.call("PUT", "/api/plans/demo", {{"plan", p}}).body)["version"], 2);

  const json loaded = h.get("/api/plans/demo");
  EXPECT_EQ(loaded["version"], 2);
  EXPECT_EQ(loaded["plan"], p);
  EXPECT_EQ(h.get("/api/plans/demo?version=1")["version"], 1);
  EXPECT_EQ(h.get("/api/plans/demo/versions").size(), 2u);
  EXPECT_EQ(h.get("/api/plans")[0]["latest_version"], 2);

  const HttpResponse xml = h.call("GET", "/api/plans/demo/xml");
  EXPECT_EQ(xml.content_type, "application/xml");
  // The exported file is the one `costar run` reads: valid for the workcell, same plan.
  const bt::Plan exported = bt::loadPlanText(xml.body, "demo.xml");
  EXPECT_TRUE(bt::validatePlan(exported, h.cell().nodes()).empty());
  EXPECT_EQ(planFileToJson(exported.file), p);

  // Import of XML text gives the same plan.
  EXPECT_EQ(h.call("PUT", "/api/plans/imported", {{"xml", xml.body}}).status, 201);
  EXPECT_EQ(h.get("/api/plans/imported")["plan"], p);

  EXPECT_EQ(h.call("DELETE", "/api/plans/demo").status, 200);
  EXPECT_EQ(h.call("GET", "/api/plans/demo").status, 404);
}

TEST(Api, RefusesBadRequestsWithAMessage) {
  Harness h(testCell());
  const auto expect = [&](int status, const HttpResponse& response, const std::string& words) {
    EXPECT_EQ(response.status, status) << response.body;
    const json body = json::parse(response.body);
    EXPECT_NE(body["error"].get<std::string>().find(words), std::string::npos) << response.body;
  };
  expect(422, h.call("PUT", "/api/plans/p", {{"plan", plan(node("Sequense", {}, {node("AlwaysSuccess")}))}}),
         "did you mean 'Sequence'");
  const HttpResponse unknown = h.call("PUT", "/api/plans/p", {{"plan", plan(node("Sequence", {}, {node("Fly")}))}});
  ASSERT_EQ(unknown.status, 422);
  EXPECT_EQ(json::parse(unknown.body)["diagnostics"][0]["node"]["path"], json({0}));
  expect(422, h.call("PUT", "/api/plans/p", {{"plan", plan(node("TestLog"))}}), "message");  // missing parameter
  expect(422, h.call("PUT", "/api/plans/p", {{"plan", plan(node("TestAction", {{"polls", "many"}}))}}), "polls");
  expect(400, h.api_call_raw("PUT", "/api/plans/p", "{not json"), "not valid JSON");
  expect(400, h.api_call_raw("PUT", "/api/plans/p", std::string(5000, '[')), "nested");
  expect(400, h.call("PUT", "/api/plans/..%2F..%2Fetc", {{"plan", plan(node("AlwaysSuccess"))}}), "bad name");
  expect(400, h.call("PUT", "/api/plans/a.xml", {{"plan", plan(node("AlwaysSuccess"))}}), "bad name");
  expect(400, h.call("GET", "/api/plans/p?version=-1"), "version");
  expect(400, h.call("PUT", "/api/plans/p", {{"plan", 42}}), "object");
  expect(400, h.call("PUT", "/api/plans/p", {{"nothing", 1}}), "needs 'plan'");
  expect(422,
         h.call("PUT", "/api/plans/p",
                {{"xml",
                  "<root BTCPP_format=\"4\"><include path=\"/etc/passwd\"/>"
                  "<BehaviorTree ID=\"m\"><AlwaysSuccess/></BehaviorTree></root>"}}),
         "include");
  expect(422, h.call("PUT", "/api/subtrees/grasp", {{"plan", plan(node("AlwaysSuccess"), "other")}}), "its name");
  expect(413, h.api_call_raw("PUT", "/api/plans/p", std::string((1u << 20) + 1, ' ')), "larger");
  expect(404, h.call("GET", "/api/nothing"), "no such endpoint");
  expect(405, h.call("DELETE", "/api/nodes"), "not allowed");
  expect(400, h.call("POST", "/api/control", {{"action", "fly"}}), "unknown action");
  expect(409, h.call("POST", "/api/control", {{"action", "stop"}}), "nothing is running");
  expect(422, h.call("POST", "/api/operations", {{"node", "Sequence"}}), "one action or condition");
  expect(422, h.call("POST", "/api/operations", {{"node", "Teleport"}}), "unknown");
  expect(400, h.call("POST", "/api/operations", {{"node", "TestLog"}, {"attributes", {{"message", 5}}}}), "string");
  EXPECT_TRUE(h.store().list(DocumentKind::kPlan).empty());
  EXPECT_EQ(h.engine().stats().runs, 0u);
}

TEST(Engine, RunsAPlanAndLogsEveryTransition) {
  Harness h(testCell());
  const json p = plan(node("Sequence", {{"name", "demo"}},
                           {node("TestLog", {{"message", "start"}}), node("TestAction", {{"polls", "3"}}),
                            node("TestCount", {{"counter", "parts"}})}));
  ASSERT_EQ(h.call("PUT", "/api/plans/demo", {{"plan", p}}).status, 201);
  const HttpResponse started = h.call("POST", "/api/runs", {{"name", "demo"}});
  ASSERT_EQ(started.status, 202) << started.body;
  const std::int64_t id = json::parse(started.body)["run"];
  const json run = h.waitForRun(id);
  EXPECT_EQ(run["result"], "SUCCESS");
  EXPECT_EQ(run["plan"], "demo");
  ASSERT_EQ(run["nodes"].size(), 4u);
  for (const auto& status : run["statuses"]) {
    EXPECT_EQ(status["last"], "SUCCESS") << status.dump();
  }
  EXPECT_EQ(run["statuses"].size(), 4u);

  // The stream: the run started, statuses, the run ended, in this order.
  std::vector<std::string> types;
  for (const std::string& message : h.engine().drainStream()) {
    types.push_back(json::parse(message)["type"]);
  }
  const auto position = [&types](const std::string& type) {
    return std::find(types.begin(), types.end(), type) - types.begin();
  };
  ASSERT_LT(position("run_started"), static_cast<long>(types.size()));
  EXPECT_LT(position("run_started"), position("statuses"));
  EXPECT_LT(position("statuses"), position("run_ended"));

  // The run log reaches the store (written in batches by its own thread).
  std::optional<RunLog> log;
  for (int i = 0; i < 2000; ++i) {
    log = h.store().run(id);
    if (log && log->run.result == "SUCCESS") {
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(log);
  EXPECT_EQ(log->run.result, "SUCCESS");
  EXPECT_EQ(log->nodes.size(), 4u);
  EXPECT_EQ(log->transitions.size(), run["transitions"].get<std::size_t>());
  ASSERT_FALSE(log->transitions.empty());
  // A node's status is reported when its tick returns: the synchronous TestLog finishes first.
  EXPECT_EQ(log->transitions.front().uid, 1u);
  EXPECT_EQ(log->transitions.front().to, "SUCCESS");
  EXPECT_TRUE(std::any_of(log->transitions.begin(), log->transitions.end(),
                          [](const TransitionRecord& t) { return t.uid == 0 && t.to == "SUCCESS"; }));
  for (std::size_t i = 1; i < log->transitions.size(); ++i) {
    EXPECT_GE(log->transitions[i].t, log->transitions[i - 1].t);
    EXPECT_EQ(log->transitions[i].seq, log->transitions[i - 1].seq + 1);
  }
  const json listed = h.get("/api/runs");
  EXPECT_EQ(listed[0]["id"], id);
  const json replay = h.get("/api/runs/" + std::to_string(id));
  EXPECT_EQ(replay["transition_list"].size(), log->transitions.size());
  EXPECT_EQ(replay["plan_json"], p);
}

TEST(Engine, TheFailingNodeCarriesItsReason) {
  Harness h(testCell());
  const json p = plan(
      node("Sequence", {},
           {node("TestAction", {{"polls", "1"}}),
            node("TestAction", {{"name", "grasp"}, {"result", "failure"}, {"reason", "no reachable candidate"}})}));
  const HttpResponse started = h.call("POST", "/api/runs", {{"plan", p}});
  ASSERT_EQ(started.status, 202) << started.body;
  const json run = h.waitForRun(json::parse(started.body)["run"]);
  EXPECT_EQ(run["result"], "FAILURE");
  EXPECT_EQ(run["failure_reason"], "no reachable candidate");
  EXPECT_EQ(run["failure_path"], "main/Sequence[1]/TestAction \"grasp\"");
  bool found = false;
  for (const auto& status : run["statuses"]) {
    if (status["uid"] == 2) {
      found = true;
      EXPECT_EQ(status["last"], "FAILURE");
      EXPECT_EQ(status["reason"], "no reachable candidate");
    }
  }
  EXPECT_TRUE(found);
}

TEST(Engine, OneRunAtATimeAndStopHaltsIt) {
  Harness h(testCell(), 1.0);
  const json endless = plan(node("TestAction", {{"name", "forever"}, {"polls", "1000000000"}}));
  const HttpResponse first = h.call("POST", "/api/runs", {{"plan", endless}});
  ASSERT_EQ(first.status, 202) << first.body;
  const std::int64_t id = json::parse(first.body)["run"];
  EXPECT_EQ(h.call("POST", "/api/runs", {{"plan", endless}}).status, 409);
  EXPECT_EQ(h.call("POST", "/api/operations", {{"node", "TestLog"}, {"attributes", {{"message", "x"}}}}).status, 409);
  h.waitTicks(5);
  EXPECT_EQ(h.call("POST", "/api/control", {{"action", "stop"}}).status, 200);
  const json run = h.waitForRun(id);
  EXPECT_EQ(run["result"], "STOPPED");
  EXPECT_EQ(run["statuses"][0]["last"], "HALTED");
  EXPECT_EQ(h.call("POST", "/api/runs", {{"plan", plan(node("AlwaysSuccess"))}}).status, 202);
}

TEST(Engine, PausedRunsTickOnlyWhenStepped) {
  Harness h(testCell(), 1.0);
  const json p =
      plan(node("Sequence", {}, {node("TestAction", {{"polls", "2"}}), node("TestAction", {{"polls", "2"}})}));
  const HttpResponse started = h.call("POST", "/api/runs", {{"plan", p}, {"paused", true}});
  ASSERT_EQ(started.status, 202) << started.body;
  const std::int64_t id = json::parse(started.body)["run"];
  h.waitTicks(20);
  EXPECT_EQ((*h.engine().runStatus(id))["transitions"], 0);
  EXPECT_EQ(h.engine().state()["mode"], "paused");

  EXPECT_EQ(h.call("POST", "/api/control", {{"action", "step"}}).status, 200);
  h.waitTicks(20);
  json status = *h.engine().runStatus(id);
  EXPECT_TRUE(status["active"].get<bool>());
  EXPECT_EQ(status["transitions"], 2);  // one tick: the Sequence and its first child started
  h.waitTicks(20);
  EXPECT_EQ((*h.engine().runStatus(id))["transitions"], 2);

  EXPECT_EQ(h.call("POST", "/api/control", {{"action", "resume"}}).status, 200);
  EXPECT_EQ(h.waitForRun(id)["result"], "SUCCESS");
}

TEST(Engine, SingleOperationsRunAndAreNotLogged) {
  Harness h(testCell());
  const HttpResponse started =
      h.call("POST", "/api/operations", {{"node", "TestLog"}, {"attributes", {{"message", "hi"}}}});
  ASSERT_EQ(started.status, 202) << started.body;
  const std::int64_t id = json::parse(started.body)["run"];
  const json run = h.waitForRun(id);
  EXPECT_EQ(run["result"], "SUCCESS");
  EXPECT_EQ(run["kind"], "operation");
  EXPECT_EQ(h.get("/api/runs/" + std::to_string(id))["result"], "SUCCESS");
  EXPECT_TRUE(h.store().runs().empty());
}

// --- the simulated UR5 cell ---------------------------------------------------------------------

workcell::WorkcellOptions blindCell() {
  workcell::WorkcellOptions options;
  options.name = "ur5-sim";
  options.scene = dataRoot() / "sim/scenes/one_node.json";
  options.waypoints = dataRoot() / "examples/ur5/blind_waypoints.json";
  return options;
}

TEST(Ur5Cell, ChoicesComeFromWhatTheCellKnows) {
  Harness h(blindCell());
  const json choices = h.get("/api/choices");
  const auto has = [](const json& list, const std::string& value) {
    return std::find(list.begin(), list.end(), value) != list.end();
  };
  EXPECT_TRUE(has(choices["waypoint"], "above_pick"));
  EXPECT_TRUE(has(choices["waypoint"], "pick"));
  EXPECT_TRUE(has(choices["frame"], "table_center"));
  EXPECT_TRUE(has(choices["object_class"], "node"));
  EXPECT_TRUE(has(choices["grasp"]["node"], "top"));
  // The classes' shapes and colours, as the class files give them, for drawing the parts.
  const json& node_shape = choices["object_shape"]["node"];
  ASSERT_EQ(node_shape["boxes"].size(), 19u);
  EXPECT_DOUBLE_EQ(node_shape["boxes"][8]["half_size"][0].get<double>(), 0.025);
  ASSERT_EQ(node_shape["colors"].size(), 4u);
  bool red = false;
  for (const json& color : node_shape["colors"]) {
    red = red || (color["name"] == "red" && color["rgb"] == json::array({0.8, 0.1, 0.1}));
  }
  EXPECT_TRUE(red) << node_shape["colors"];
  bool holding = false;
  for (const auto& predicate : choices["predicate"]) {
    holding = holding || (predicate["name"] == "gripper_holding" && predicate["arity"] == 0);
  }
  EXPECT_TRUE(holding);

  json move;
  for (const auto& n : h.get("/api/nodes")) {
    if (n["id"] == "Move") {
      move = n;
    }
  }
  ASSERT_FALSE(move.is_null());
  EXPECT_EQ(move["ports"][0]["name"], "waypoint");
  EXPECT_EQ(move["ports"][0]["choices_from"], "waypoint");
  EXPECT_EQ(move["category"], "robot_action");

  const json state = h.get("/api/state");
  EXPECT_EQ(state["arm"]["joints"].size(), 6u);
  bool above_pick = false;
  for (const auto& waypoint : state["waypoints"]) {
    if (waypoint["name"] == "above_pick") {
      above_pick = true;
      EXPECT_NEAR(waypoint["p"][0].get<double>(), 0.45, 1e-6);
      EXPECT_NEAR(waypoint["p"][2].get<double>(), 0.15, 1e-6);
    }
  }
  EXPECT_TRUE(above_pick);
  EXPECT_TRUE(state["gripper"].contains("open"));
}

TEST(Ur5Cell, EveryPlaceIsOfferedAndDefaultsAreValidForTheClass) {
  Harness h(blindCell());
  json release;
  json grasp;
  for (const auto& n : h.get("/api/nodes")) {
    if (n["id"] == "SmartRelease") {
      release = n;
    }
    if (n["id"] == "SmartGrasp") {
      grasp = n;
    }
  }
  ASSERT_FALSE(release.is_null());
  ASSERT_FALSE(grasp.is_null());
  for (const auto& port : release["ports"]) {
    if (port["name"] == "target") {
      EXPECT_EQ(port["choices_from"], "frame");
      EXPECT_EQ(port["extra_choices"], json::array({"table"}));  // not a frame, but a place
      EXPECT_EQ(port["excludes"], json::array({"target_class"}));
    }
  }
  for (const auto& port : grasp["ports"]) {
    if (port["name"] == "grasp") {
      EXPECT_EQ(port["default"], "");  // the class's first taught grasp, valid for every class
    }
  }
}

// Check (POST /api/validate) catches what would fail at once, on the node it concerns.
TEST(Ur5Cell, CheckCatchesWhatWouldFailAtOnce) {
  Harness h(blindCell());
  const auto check = [&](const std::string& node) {
    const std::string xml = R"(<root BTCPP_format="4"><BehaviorTree ID="main"><Sequence><Open/>)" + node +
                            R"(</Sequence></BehaviorTree></root>)";
    const HttpResponse response = h.call("POST", "/api/validate", {{"xml", xml}});
    EXPECT_EQ(response.status, 200) << response.body;
    return json::parse(response.body);
  };
  const auto firstProblem = [](const json& result) {
    return result["diagnostics"].empty() ? std::string() : result["diagnostics"][0]["message"].get<std::string>();
  };

  json result = check(R"x(<SmartGrasp object_class="link" grasp="top"/>)x");
  EXPECT_FALSE(result["valid"]) << result.dump();
  EXPECT_NE(firstProblem(result).find("no grasp 'top' is taught for class 'link' (taught: middle)"), std::string::npos)
      << firstProblem(result);
  EXPECT_EQ(result["diagnostics"][0]["node"]["path"], json::array({1}));
  EXPECT_TRUE(check(R"x(<SmartGrasp object_class="link"/>)x")["valid"]);  // the default grasp fits any class
  EXPECT_TRUE(check(R"x(<SmartGrasp object_class="link" grasp="middle"/>)x")["valid"]);

  result = check(R"x(<SmartRelease predicates="left_of(table_center)"/>)x");
  EXPECT_FALSE(result["valid"]) << result.dump();
  EXPECT_NE(firstProblem(result).find("give target_class"), std::string::npos) << firstProblem(result);
  result = check(R"x(<SmartRelease target="table_center" predicates="left_of(table_center)"/>)x");
  EXPECT_FALSE(result["valid"]) << result.dump();
  EXPECT_NE(firstProblem(result).find("the conditions cannot apply"), std::string::npos) << firstProblem(result);
  result = check(R"x(<SmartRelease target="table" target_class="node"/>)x");
  EXPECT_FALSE(result["valid"]) << result.dump();
  EXPECT_NE(firstProblem(result).find("not both"), std::string::npos) << firstProblem(result);
  EXPECT_TRUE(check(R"x(<SmartRelease target="table" predicates="left_of(table_center)"/>)x")["valid"]);
  EXPECT_TRUE(check(R"x(<SmartRelease target_class="node" predicates="left_of(table_center)"/>)x")["valid"]);
  EXPECT_TRUE(check(R"x(<SmartRelease target="table_center"/>)x")["valid"]);
}

// The state the page draws from: after DetectObjects each object carries the colour perception
// saw on it, near the red node's material (0.8, 0.1, 0.1) and nearer to red than to the class's
// other colours (the page names it so).
TEST(Ur5Cell, TheStateCarriesEachPartsSeenColour) {
  Harness h(blindCell());
  EXPECT_TRUE(h.get("/api/state")["objects"].empty());
  const HttpResponse started = h.call("POST", "/api/operations", {{"node", "DetectObjects"}});
  ASSERT_EQ(started.status, 202) << started.body;
  ASSERT_EQ(h.waitForRun(json::parse(started.body)["run"])["result"], "SUCCESS");
  h.waitTicks(2);  // the next snapshot
  const json objects = h.get("/api/state")["objects"];
  ASSERT_EQ(objects.size(), 1u) << objects.dump();
  const json& node = objects[0];
  EXPECT_EQ(node["class"], "node");
  ASSERT_TRUE(node.contains("color")) << node.dump();
  ASSERT_EQ(node["color"].size(), 3u);
  const Eigen::Vector3d seen(node["color"][0].get<double>(), node["color"][1].get<double>(),
                             node["color"][2].get<double>());
  EXPECT_LT((seen - Eigen::Vector3d(0.8, 0.1, 0.1)).cwiseAbs().maxCoeff(), 0.2) << seen.transpose();
  const json choices = h.get("/api/choices");
  std::string nearest;
  double nearest_distance = 1e9;
  for (const json& color : choices["object_shape"]["node"]["colors"]) {
    const Eigen::Vector3d rgb(color["rgb"][0].get<double>(), color["rgb"][1].get<double>(),
                              color["rgb"][2].get<double>());
    if ((rgb - seen).norm() < nearest_distance) {
      nearest_distance = (rgb - seen).norm();
      nearest = color["name"];
    }
  }
  EXPECT_EQ(nearest, "red") << seen.transpose();
}

TEST(Ur5Cell, GroundTruthIsOnlyForTests) {
  Harness h(blindCell());
  EXPECT_EQ(h.call("GET", "/api/test/ground_truth").status, 404);
}

TEST(Ur5Cell, ThePickUpPlanLiftsTheNode) {
  Harness h(blindCell(), 0.0, {.test_endpoints = true});
  EXPECT_EQ(h.call("GET", "/api/test/ground_truth", nullptr, false).status, 401);
  const json before = h.get("/api/test/ground_truth");
  ASSERT_EQ(before["parts"].size(), 1u);
  const double z0 = before["parts"][0]["p"][2];

  // The plan a user builds by clicks: Open, Move above_pick, Move pick, Close, Move above_pick.
  const json p =
      plan(node("Sequence", {},
                {node("Open"), node("Move", {{"waypoint", "above_pick"}}), node("Move", {{"waypoint", "pick"}}),
                 node("Close"), node("Move", {{"waypoint", "above_pick"}})}));
  ASSERT_EQ(h.call("PUT", "/api/plans/pick_up", {{"plan", p}}).status, 201);
  const HttpResponse started = h.call("POST", "/api/runs", {{"name", "pick_up"}});
  ASSERT_EQ(started.status, 202) << started.body;
  const json run = h.waitForRun(json::parse(started.body)["run"]);
  EXPECT_EQ(run["result"], "SUCCESS") << run.dump();
  for (const auto& status : run["statuses"]) {
    EXPECT_EQ(status["last"], "SUCCESS");
  }
  const json after = h.get("/api/test/ground_truth");
  const double z1 = after["parts"][0]["p"][2];
  EXPECT_GT(z1 - z0, 0.08) << "the node was not lifted: z " << z0 << " -> " << z1;
  EXPECT_TRUE(h.get("/api/state")["gripper"]["holding"].get<bool>());
}

TEST(Ur5Cell, StopHaltsTheRunAndStopsTheArm) {
  Harness h(blindCell(), 1.0);  // real time: the motion takes seconds, the stop milliseconds
  const HttpResponse started =
      h.call("POST", "/api/operations", {{"node", "Move"}, {"attributes", {{"waypoint", "above_place"}}}});
  ASSERT_EQ(started.status, 202) << started.body;
  const std::int64_t id = json::parse(started.body)["run"];
  while (!h.engine().state()["arm"]["moving"].get<bool>()) {
    h.waitTicks(1);
  }
  EXPECT_EQ(h.call("POST", "/api/control", {{"action", "stop"}}).status, 200);
  EXPECT_EQ(h.waitForRun(id)["result"], "STOPPED");
  h.waitTicks(150);  // 1.5 s of clock time: the arm has decelerated and stands still
  const json state = h.get("/api/state");
  EXPECT_FALSE(state["arm"]["moving"].get<bool>());
  const double y = state["arm"]["endpoint"]["p"][1];
  EXPECT_LT(y, 0.24) << "the arm went on to the waypoint (y 0.25) instead of stopping";
}

}  // namespace
}  // namespace costar::server
