// The API and the engine together, in one process without the network: plans saved,
// validated, run and logged on the test workcell, and the "pick up node" plan run in the
// simulated UR5 cell, judged from the simulator's true state.

#include <gtest/gtest.h>

#include <chrono>
#include <map>
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
  /// `resettable`: the engine can build the cell again ("Reset scene"), as `costar serve` does.
  explicit Harness(workcell::WorkcellOptions options, double pace = 0.0, ApiOptions api_options = {},
                   bool resettable = false) {
    options.memory_only = true;
    cell_ = workcell::makeWorkcell(options);
    EngineOptions engine_options;
    engine_options.pace = pace;
    engine_options.grasp_defaults = dataRoot() / "data/grasps.json";
    if (resettable) {
      engine_options.make_cell = [options] { return workcell::makeWorkcell(options); };
    }
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
  const HttpResponse refused = h.call("PUT", "/api/plans/p", body, false);
  EXPECT_EQ(refused.status, 401);
  // In a technician's words, not the header's.
  EXPECT_EQ(json::parse(refused.body)["error"].get<std::string>().rfind("sign in to change plans or move the robot", 0),
            0u)
      << refused.body;
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

  // A hostile tester: DELETE ...?version=1 removed every version, and a run of version 99
  // answered "no plan" of a plan that exists.
  const HttpResponse one_version = h.call("DELETE", "/api/plans/demo?version=1");
  EXPECT_EQ(one_version.status, 400) << one_version.body;
  EXPECT_NE(one_version.body.find("one version cannot be deleted"), std::string::npos) << one_version.body;
  EXPECT_EQ(h.get("/api/plans/demo/versions").size(), 2u);
  const HttpResponse missing_version = h.call("POST", "/api/runs", {{"name", "demo"}, {"version", 99}});
  EXPECT_EQ(missing_version.status, 404);
  EXPECT_NE(missing_version.body.find("no plan 'demo' with version 99 (its latest is version 2)"), std::string::npos)
      << missing_version.body;

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
  // The message names the plan, not a file the user never saw.
  const std::string message = json::parse(unknown.body)["error"];
  EXPECT_EQ(message.rfind("plan 'p' has 1 problem: ", 0), 0u) << message;
  EXPECT_EQ(message.find(".xml"), std::string::npos) << message;
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

// The route table's data: a command's body is small (16 KiB), a plan's may be 1 MiB; a bad
// name in the path comes before a wrong method; long reads are the routes marked so.
TEST(Api, TheRouteTableLimitsBodiesAndMarksLongReads) {
  Harness h(testCell());
  const auto expect = [](int status, const HttpResponse& response, const std::string& words) {
    EXPECT_EQ(response.status, status) << response.body;
    EXPECT_NE(json::parse(response.body)["error"].get<std::string>().find(words), std::string::npos) << response.body;
  };
  expect(413, h.api_call_raw("POST", "/api/control", std::string((16u << 10) + 1, ' ')), "16384 bytes");
  expect(400, h.api_call_raw("POST", "/api/control", std::string(16u << 10, ' ')), "not valid JSON");
  expect(400, h.call("POST", "/api/plans/a.b"), "bad name");
  expect(405, h.call("POST", "/api/plans/ab"), "not allowed");
  const auto bulk = [](const std::string& method, const std::string& target) {
    return Api::isBulkRead({.method = method, .target = target});
  };
  EXPECT_TRUE(bulk("GET", "/api/runs"));
  EXPECT_TRUE(bulk("GET", "/api/runs/"));
  EXPECT_TRUE(bulk("HEAD", "/api/runs/3?from=10"));
  EXPECT_TRUE(bulk("GET", "/api/runs/3/transitions"));
  EXPECT_TRUE(bulk("GET", "/api/runs/3/states"));
  EXPECT_TRUE(bulk("GET", "/api/pointcloud?max=10"));
  EXPECT_FALSE(bulk("POST", "/api/runs"));
  EXPECT_FALSE(bulk("GET", "/api/info"));
  EXPECT_FALSE(bulk("GET", "/api/plans/runs"));
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

TEST(Engine, PausingHoldsTheClockAndAStepLetsOneTickPeriodPass) {
  Harness h(testCell(), 0.0);  // unpaced: a running clock would race ahead while paused
  const HttpResponse started =
      h.call("POST", "/api/runs", {{"plan", plan(node("TestAction", {{"polls", "1000000"}}))}, {"paused", true}});
  ASSERT_EQ(started.status, 202) << started.body;
  h.waitTicks(5);
  const double t0 = h.engine().state()["t"];
  h.waitTicks(50);  // 50 held periods: the clock stands still
  EXPECT_DOUBLE_EQ(h.engine().state()["t"].get<double>(), t0);
  EXPECT_EQ(h.engine().state()["mode"], "paused");
  EXPECT_EQ(h.call("POST", "/api/control", {{"action", "step"}}).status, 200);
  h.waitTicks(20);
  const double t1 = h.engine().state()["t"];
  EXPECT_NEAR(t1 - t0, 0.01, 1e-9);  // one tick period (10 ms) and no more
  h.waitTicks(20);
  EXPECT_DOUBLE_EQ(h.engine().state()["t"].get<double>(), t1);
  EXPECT_EQ(h.call("POST", "/api/control", {{"action", "stop"}}).status, 200);
}

// Any page (a reload, a second browser) learns the running plan from the stream's hello: which
// plan, its version, its cell and the plan itself, whatever the page had open.
TEST(Engine, TheHelloCarriesTheRunningPlan) {
  Harness h(testCell(), 1.0);
  const json endless = plan(node("Repeat", {{"num_cycles", "-1"}}, {node("TestAction", {{"polls", "3"}})}));
  ASSERT_EQ(h.call("PUT", "/api/plans/forever", {{"plan", endless}}).status, 201);
  const HttpResponse started = h.call("POST", "/api/runs", {{"name", "forever"}});
  ASSERT_EQ(started.status, 202) << started.body;
  while (h.engine().state()["mode"] != "running") {  // the next snapshot
    h.waitTicks(1);
  }
  const json hello = json::parse(h.engine().helloMessage());
  const json& run = hello["run"];
  EXPECT_TRUE(run["active"].get<bool>());
  EXPECT_EQ(run["plan"], "forever");
  EXPECT_EQ(run["version"], 1);
  EXPECT_EQ(run["workcell"], "test");
  EXPECT_EQ(run["plan_json"]["trees"][0]["root"]["id"], "Repeat");
  EXPECT_EQ(hello["state"]["mode"], "running");
  EXPECT_EQ(h.call("POST", "/api/control", {{"action", "stop"}}).status, 200);
  EXPECT_EQ(h.waitForRun(run["id"])["result"], "STOPPED");
}

// A plan run's log keeps snapshots of the cell (replay draws the arm and the parts from them)
// and names the cell it ran on.
TEST(Engine, TheRunLogKeepsSnapshotsOfTheCellAndItsName) {
  Harness h(testCell(), 0.0);
  const HttpResponse started = h.call("POST", "/api/runs", {{"plan", plan(node("TestAction", {{"polls", "120"}}))}});
  ASSERT_EQ(started.status, 202) << started.body;
  const std::int64_t id = json::parse(started.body)["run"];
  EXPECT_EQ(h.waitForRun(id)["result"], "SUCCESS");
  // The log writer writes in batches: the run's end comes after its snapshots.
  for (int attempt = 0; attempt < 500 && (h.store().runs().empty() || h.store().runs().front().result.empty());
       ++attempt) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const json states = h.get("/api/runs/" + std::to_string(id) + "/states")["states"];
  // 1.2 s of clock time at 5 snapshots a second, the first and the last: 7.
  ASSERT_GE(states.size(), 6u) << states.dump();
  for (std::size_t i = 1; i < states.size(); ++i) {
    EXPECT_GE(states[i]["t"].get<double>(), states[i - 1]["t"].get<double>());
  }
  EXPECT_TRUE(states[0]["state"].contains("objects"));
  EXPECT_FALSE(states[0]["state"].contains("waypoints"));
  EXPECT_EQ(h.get("/api/runs")[0]["workcell"], "test");
  EXPECT_EQ(h.call("GET", "/api/runs/999/states").status, 404);
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
  EXPECT_FALSE(has(choices["grasp"]["node"], "pinch"));  // the 3-finger gripper's
  // Each grasp's tool centre point in the part's frame (data/grasps.json: 5 mm above a node's
  // centre, the tool pointing down), drawn on the parts by the page.
  const json& top = choices["grasp_pose"]["node"]["top"];
  EXPECT_NEAR(top["p"][2].get<double>(), 0.005, 1e-9);
  EXPECT_NEAR(std::abs(top["q"][0].get<double>()), 1.0, 1e-9);  // 180 degrees about x
  EXPECT_EQ(top["mode"], "");
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

// A joint waypoint is drawn where its joints put the tool (the cell's motion service, not the
// arm's class): taught where the arm stands, it is drawn at the endpoint.
TEST(Ur5Cell, AJointWaypointIsDrawnWhereItsJointsPutTheTool) {
  Harness h(blindCell());
  const HttpResponse taught = h.call("POST", "/api/operations",
                                     {{"node", "Teach"}, {"attributes", {{"waypoint", "here"}, {"kind", "joints"}}}});
  ASSERT_EQ(taught.status, 202) << taught.body;
  ASSERT_EQ(h.waitForRun(json::parse(taught.body)["run"])["result"], "SUCCESS");
  h.waitTicks(2);  // the next snapshot
  const json state = h.get("/api/state");
  const json* here = nullptr;
  for (const json& waypoint : state["waypoints"]) {
    if (waypoint["name"] == "here") {
      here = &waypoint;
    }
  }
  ASSERT_NE(here, nullptr) << state["waypoints"].dump();
  EXPECT_EQ((*here)["kind"], "joints");
  ASSERT_TRUE(here->contains("p")) << here->dump();
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR((*here)["p"][i].get<double>(), state["arm"]["endpoint"]["p"][i].get<double>(), 1e-4) << i;
  }
}

// Stepping through a SmartGrasp ends as a normal run does: while paused the simulated cell
// stands still, so no time limit (the fingers settling, the motion) runs out between steps.
TEST(Ur5Cell, SteppingThroughASmartGraspSucceeds) {
  workcell::WorkcellOptions options = blindCell();
  options.test_oracle_perception = true;  // the part's pose without a detection
  Harness h(options, 0.0);
  const json p = plan(node("Sequence", {}, {node("Open"), node("SmartGrasp", {{"object_class", "node"}})}));
  const HttpResponse started = h.call("POST", "/api/runs", {{"plan", p}, {"paused", true}});
  ASSERT_EQ(started.status, 202) << started.body;
  const std::int64_t id = json::parse(started.body)["run"];
  int steps = 0;
  while ((*h.engine().runStatus(id))["active"].get<bool>() && steps < 20000) {
    h.call("POST", "/api/control", {{"action", "step"}});
    ++steps;
    // Wall time between steps, as a person clicking leaves, now and then long: a clock that
    // ran on while paused (unpaced here: tens of simulated seconds) would pass every time limit
    // of an operation under way (the fingers settling: 3 s).
    std::this_thread::sleep_for(std::chrono::milliseconds(steps % 20 == 0 ? 300 : 1));
  }
  const json run = h.waitForRun(id);
  EXPECT_EQ(run["result"], "SUCCESS") << run.dump();
  EXPECT_GT(steps, 50);
  // One tick period of simulated time per step taken, however long the waits between them (the
  // last few steps asked for may come after the step that ended the run).
  EXPECT_LE(run["clock_seconds"].get<double>(), 0.01 * steps + 1e-9) << steps << " steps";
  EXPECT_GE(run["clock_seconds"].get<double>(), 0.01 * (steps - 10)) << steps << " steps";
  EXPECT_TRUE(h.get("/api/state")["gripper"]["holding"].get<bool>());
}

// Check knows the cell: waypoints (a renamed one is flagged, one the plan teaches first is not),
// the gripper's modes (a 2-finger gripper has only Pinch), the object classes.
TEST(Ur5Cell, CheckValidatesAgainstTheCell) {
  Harness h(blindCell());
  const auto check = [&](const std::string& body) {
    const std::string xml =
        R"(<root BTCPP_format="4"><BehaviorTree ID="main"><Sequence>)" + body + R"(</Sequence></BehaviorTree></root>)";
    const HttpResponse response = h.call("POST", "/api/validate", {{"xml", xml}, {"name", "shift_plan"}});
    EXPECT_EQ(response.status, 200) << response.body;
    return json::parse(response.body);
  };
  json result = check(R"(<Open/><Move waypoint="over_left"/>)");
  ASSERT_FALSE(result["valid"]) << result.dump();
  const std::string message = result["diagnostics"][0]["message"];
  EXPECT_NE(message.find("no waypoint 'over_left' in this cell now"), std::string::npos) << message;
  EXPECT_NE(message.find("above_pick"), std::string::npos) << message;  // what it has
  EXPECT_EQ(result["diagnostics"][0]["node"]["path"], json::array({1}));
  EXPECT_EQ(result["diagnostics"][0]["where"].get<std::string>().rfind("shift_plan:", 0), 0u);
  EXPECT_TRUE(check(R"(<Move waypoint="above_pick"/>)")["valid"]);
  EXPECT_TRUE(check(R"(<Teach waypoint="here"/><Move waypoint="here"/>)")["valid"]);  // taught first

  result = check(R"(<Open/><ScissorMode/>)");
  ASSERT_FALSE(result["valid"]) << result.dump();
  EXPECT_NE(result["diagnostics"][0]["message"].get<std::string>().find("has only Pinch mode"), std::string::npos)
      << result.dump();
  EXPECT_FALSE(check(R"(<SetMode mode="wide"/>)")["valid"]);
  EXPECT_TRUE(check(R"(<PinchMode/><SetMode mode="pinch"/>)")["valid"]);

  result = check(R"(<SmartGrasp object_class="gear"/>)");
  EXPECT_FALSE(result["valid"]) << result.dump();

  // Saving it is not refused (the waypoint may be taught later); running it is, at once,
  // naming the plan and the problem.
  EXPECT_EQ(
      h.call("PUT", "/api/plans/later",
             {{"xml",
               R"(<root BTCPP_format="4"><BehaviorTree ID="main"><Move waypoint="over_left"/></BehaviorTree></root>)"}})
          .status,
      201);
  const HttpResponse run = h.call(
      "POST", "/api/runs",
      {{"xml",
        R"(<root BTCPP_format="4"><BehaviorTree ID="main"><Move waypoint="over_left"/></BehaviorTree></root>)"}});
  EXPECT_EQ(run.status, 422) << run.body;
  EXPECT_EQ(json::parse(run.body)["error"].get<std::string>().rfind("this plan has 1 problem: Move: waypoint:", 0), 0u)
      << run.body;
}

// The palette offers the modes the cell's gripper has: a 2-finger gripper's Basic, Wide and
// Scissor modes are marked unavailable with the reason (the editor leaves them out); Check
// still names them in a plan.
TEST(Ur5Cell, ThePaletteMarksTheModesTheGripperLacks) {
  Harness h(blindCell());
  std::map<std::string, json> nodes;
  for (const json& node : h.get("/api/nodes")) {
    nodes[node["id"]] = node;
  }
  for (const char* mode : {"BasicMode", "WideMode", "ScissorMode"}) {
    ASSERT_TRUE(nodes[mode].contains("unavailable")) << mode;
    EXPECT_NE(nodes[mode]["unavailable"].get<std::string>().find("has only Pinch mode"), std::string::npos) << mode;
  }
  for (const char* available : {"PinchMode", "Open", "Close", "SetMode", "Move"}) {
    EXPECT_FALSE(nodes[available].contains("unavailable")) << available;
  }
}

// The editor offered the 2-finger gripper's grasps on the 3-finger cell: its grasp lists read
// data/grasps.json for parallel-2f whatever the cell's gripper, so SmartGrasp's list lacked
// basic, pinch, wide and scissor (which the plan may name) and no grasp carried its mode.
TEST(ThreeFingerCell, TheGraspsOfferedAreTheThreeFingerGrippersOwnWithTheirModes) {
  workcell::WorkcellOptions options;
  options.name = "iiwa-3f-sim";
  Harness h(options);
  const json choices = h.get("/api/choices");
  std::vector<std::string> node;
  for (const auto& name : choices["grasp"]["node"]) {
    node.push_back(name.get<std::string>());
  }
  std::sort(node.begin(), node.end());
  EXPECT_EQ(node, (std::vector<std::string>{"basic", "pinch", "scissor", "top", "wide"}));
  const json& wide = choices["grasp_pose"]["node"]["wide"];
  EXPECT_EQ(wide["mode"], "wide");
  EXPECT_NEAR(wide["p"][1].get<double>(), -0.006, 1e-9);
  EXPECT_EQ(choices["grasp_pose"]["node"]["top"]["mode"], "pinch");
  EXPECT_EQ(choices["grasp_pose"]["link"]["scissor"]["mode"], "scissor");
}

// --- the iiwa with the power tool (iiwa-3f-sim, the polishing scene) ---------------------------

workcell::WorkcellOptions polishingCell() {
  workcell::WorkcellOptions options;
  options.name = "iiwa-3f-sim";
  options.scene = dataRoot() / "sim/scenes/polishing.json";
  options.waypoints = dataRoot() / "examples/iiwa/polishing_waypoints.json";
  return options;
}

// A path of waypoints (PressAndFollow's "row1_start;row1_end") is checked waypoint by waypoint:
// the whole text was looked up as one waypoint's name, so Check and Run refused every path
// built in the editor ("no waypoint 'row1_start;row1_end'") and examples/iiwa/polishing.xml.
TEST(PolishingCell, APathIsCheckedWaypointByWaypoint) {
  Harness h(polishingCell());
  const auto check = [&](const std::string& body) {
    const std::string xml =
        R"(<root BTCPP_format="4"><BehaviorTree ID="main"><Sequence>)" + body + R"(</Sequence></BehaviorTree></root>)";
    const HttpResponse response = h.call("POST", "/api/validate", {{"xml", xml}});
    EXPECT_EQ(response.status, 200) << response.body;
    return json::parse(response.body);
  };
  EXPECT_TRUE(check(R"(<PressAndFollow path="row1_start;row1_end"/>)")["valid"]);
  EXPECT_TRUE(check(R"(<PressAndFollow path=" row1_start ; row1_end;row2_start "/>)")["valid"]);
  const json result = check(R"(<PressAndFollow path="row1_start;row9_end"/>)");
  ASSERT_FALSE(result["valid"]) << result.dump();
  const std::string message = result["diagnostics"][0]["message"];
  EXPECT_NE(message.find("path: no waypoint 'row9_end' in this cell now"), std::string::npos) << message;
}

// The state the page shows while force is used: the wrist sensor's wrench and whether it
// touches, the power tool's speed and where it is; the test endpoint has the tool's true state.
TEST(PolishingCell, TheStateCarriesTheWrenchAndTheTool) {
  ApiOptions api_options;
  api_options.test_endpoints = true;
  Harness h(polishingCell(), 0.0, api_options);
  h.waitTicks(5);
  const json state = h.get("/api/state");
  ASSERT_TRUE(state["arm"].contains("wrench")) << state.dump();
  EXPECT_EQ(state["arm"]["wrench"]["frame"], "tool");
  EXPECT_EQ(state["arm"]["wrench"]["force"].size(), 3u);
  EXPECT_FALSE(state["arm"]["in_contact"].get<bool>()) << state["arm"].dump();  // tared at rest, nothing touched
  ASSERT_TRUE(state.contains("tool")) << state.dump();
  EXPECT_FALSE(state["tool"]["on"].get<bool>());
  EXPECT_TRUE(state["tool"]["docked"].get<bool>());
  EXPECT_FALSE(state["tool"]["held"].get<bool>());
  EXPECT_EQ(state["tool"]["unit"], "opm");
  const json truth = h.get("/api/test/ground_truth");
  ASSERT_TRUE(truth.contains("power_tool")) << truth.dump();
  EXPECT_TRUE(truth["power_tool"]["docked"].get<bool>());
  EXPECT_FALSE(truth["power_tool"]["powered"].get<bool>());
  EXPECT_EQ(truth["power_tool"]["coverage"].get<double>(), 0.0);
  EXPECT_EQ(truth["power_tool"]["arm_workpiece_steps"].get<int>(), 0);
}

// The state the page shows over the 3D view when a person is in the cell: the speed and
// separation monitor's reading (docs/PERSON.md). Without a person there is none to show.
TEST(PersonCell, TheStateCarriesTheSeparationAndTheSpeedScale) {
  workcell::WorkcellOptions away;
  away.name = "iiwa-3f-sim";
  away.scene = dataRoot() / "sim/scenes/person_away.json";
  Harness h(away);
  h.waitTicks(5);
  const json state = h.get("/api/state");
  ASSERT_TRUE(state.contains("safety")) << state.dump().substr(0, 400);
  const json& safety = state["safety"];
  EXPECT_GT(safety["separation"].get<double>(), 1.0) << safety.dump();                     // walked away from the table
  EXPECT_NEAR(safety["protective_distance"].get<double>(), 0.501, 0.01) << safety.dump();  // the arm at rest
  EXPECT_DOUBLE_EQ(safety["speed_scale"].get<double>(), 1.0);
  EXPECT_FALSE(safety["stopped"].get<bool>());
  EXPECT_FALSE(safety["slowed"].get<bool>());
  EXPECT_FALSE(safety["collaborative"].get<bool>());
  // The test endpoint has what the separation judge recorded (nothing near the person here).
  ApiOptions test_endpoints;
  test_endpoints.test_endpoints = true;
  Harness truth_of(away, 0.0, test_endpoints);
  truth_of.waitTicks(5);
  const json truth = truth_of.get("/api/test/ground_truth");
  ASSERT_TRUE(truth.contains("separation")) << truth.dump().substr(0, 400);
  EXPECT_EQ(truth["separation"]["violation_steps"].get<int>(), 0);
  EXPECT_EQ(truth["separation"]["contact_steps"].get<int>(), 0);
  workcell::WorkcellOptions none;
  none.name = "iiwa-3f-sim";
  none.scene = dataRoot() / "sim/scenes/one_node.json";
  Harness without(none);
  without.waitTicks(5);
  EXPECT_FALSE(without.get("/api/state").contains("safety"));
}

// GET /api/robot on a cell with a power tool: its shape in the tool frame and where it sits in
// the hand (the tool frame in the tool centre point's, from the grasp SmartGrasp takes it by:
// the knob's, the pad 10.7 cm beyond the tool centre point, the tool pointing along its z), so
// the page draws the sander in the gripper while the state reads it held.
TEST(PolishingCell, TheRobotDescriptionCarriesThePowerToolAndWhereItSitsInTheHand) {
  Harness h(polishingCell());
  const json robot = h.get("/api/robot");
  ASSERT_TRUE(robot.contains("power_tool")) << robot.dump().substr(0, 400);
  const json& tool = robot["power_tool"];
  EXPECT_EQ(tool["name"], "orbital_sander");
  EXPECT_EQ(tool["grasp"], "knob");
  ASSERT_EQ(tool["boxes"].size(), 3u);                                // pad, housing, knob
  EXPECT_NEAR(tool["boxes"][0]["size"][0].get<double>(), 0.1, 1e-9);  // the pad, 10 cm square
  EXPECT_NEAR(tool["boxes"][0]["centre"][2].get<double>(), 0.006, 1e-9);
  const json& held = tool["held_in_tcp"];
  EXPECT_NEAR(held["p"][0].get<double>(), 0.0, 1e-9);
  EXPECT_NEAR(held["p"][2].get<double>(), 0.107, 1e-9);
  const Eigen::Quaterniond q(held["q"][3].get<double>(), held["q"][0].get<double>(), held["q"][1].get<double>(),
                             held["q"][2].get<double>());
  EXPECT_NEAR((q * Eigen::Vector3d::UnitZ() - Eigen::Vector3d(0, 0, -1)).norm(), 0.0, 1e-9);  // the knob up the arm
  // The UR5 cell has the sander too, held by its knob between the two pads, 1 cm lower in the
  // hand (its gripper's body clears the knob's top).
  Harness ur5(blindCell());
  const json ur5_robot = ur5.get("/api/robot");
  ASSERT_TRUE(ur5_robot.contains("power_tool"));
  EXPECT_EQ(ur5_robot["power_tool"]["grasp"], "knob");
  EXPECT_NEAR(ur5_robot["power_tool"]["held_in_tcp"]["p"][2].get<double>(), 0.117, 1e-9);
  workcell::WorkcellOptions without = blindCell();
  without.name = "iiwa-sim";  // no power tool in this cell
  Harness iiwa(without);
  EXPECT_FALSE(iiwa.get("/api/robot").contains("power_tool"));
}

// GET /api/robot: the robot as the planner models it (the arm's URDF with the gripper's on its
// flange), where it stands, its joints, its gripper; the state carries the fingers' reading.
TEST(Ur5Cell, TheRobotIsDescribedByThePlannersUrdf) {
  Harness h(blindCell());
  const json robot = h.get("/api/robot");
  EXPECT_EQ(robot["joints"].size(), 6u);
  EXPECT_EQ(robot["joints"][0]["name"], "shoulder_pan_joint");
  EXPECT_EQ(robot["flange_link"], "tool0");
  EXPECT_EQ(robot["tcp_link"], "tcp");
  const std::string urdf = robot["urdf"];
  EXPECT_NE(urdf.find("<link name=\"tcp\""), std::string::npos);
  EXPECT_NE(urdf.find("<joint name=\"tool_centre_point\""), std::string::npos);
  EXPECT_EQ(robot["gripper"]["kind"], "parallel");
  EXPECT_EQ(robot["gripper"]["finger_boxes"].size(), 2u);
  EXPECT_DOUBLE_EQ(robot["base_in_world"]["q"][2].get<double>(), 1.0);  // turned half a turn about z
  const json gripper = h.get("/api/state")["gripper"];
  ASSERT_TRUE(gripper.contains("reading")) << gripper.dump();
  EXPECT_EQ(gripper["reading"]["names"], json::array({"opening"}));
  EXPECT_GT(gripper["reading"]["positions"][0].get<double>(), 0.0);
}

// Reset scene builds the cell again from its scene file and seed: a part that was moved is
// back, the arm at home; refused while something runs.
TEST(Ur5Cell, ResetSceneBuildsTheSceneAgain) {
  Harness h(blindCell(), 0.0, {.test_endpoints = true}, /*resettable=*/true);
  const json before = h.get("/api/test/ground_truth");
  const json p =
      plan(node("Sequence", {},
                {node("Open"), node("Move", {{"waypoint", "above_pick"}}), node("Move", {{"waypoint", "pick"}}),
                 node("Close"), node("Move", {{"waypoint", "above_pick"}})}));
  const HttpResponse started = h.call("POST", "/api/runs", {{"plan", p}});
  ASSERT_EQ(started.status, 202) << started.body;
  EXPECT_EQ(h.call("POST", "/api/scene/reset").status, 409);  // not while it runs
  ASSERT_EQ(h.waitForRun(json::parse(started.body)["run"])["result"], "SUCCESS");
  const json lifted = h.get("/api/test/ground_truth");
  ASSERT_GT(lifted["parts"][0]["p"][2].get<double>() - before["parts"][0]["p"][2].get<double>(), 0.08);

  const HttpResponse reset = h.call("POST", "/api/scene/reset");
  ASSERT_EQ(reset.status, 200) << reset.body;
  const json after = h.get("/api/test/ground_truth");
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(after["parts"][0]["p"][i].get<double>(), before["parts"][0]["p"][i].get<double>(), 1e-3);
    EXPECT_NEAR(after["tcp"]["p"][i].get<double>(), before["tcp"]["p"][i].get<double>(), 1e-3);
  }
  EXPECT_FALSE(h.get("/api/state")["gripper"]["holding"].get<bool>());
  // The cell works after the reset.
  const HttpResponse again = h.call("POST", "/api/operations", {{"node", "Home"}});
  ASSERT_EQ(again.status, 202) << again.body;
  EXPECT_EQ(h.waitForRun(json::parse(again.body)["run"])["result"], "SUCCESS");
  // A cell made without a way to make it again cannot reset.
  Harness fixed(blindCell());
  EXPECT_EQ(fixed.call("POST", "/api/scene/reset").status, 404);
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

// Free-drive from the page (docs/TEACHING.md): POST /api/drag pushes the tool and holds the
// dead-man while FreeDrive runs; when the stream of drags stops, the arm stops and holds.
TEST(Ur5Cell, DraggingTheToolGuidesTheArmWhileHeldAndItStopsWhenTheDragsStop) {
  Harness h(blindCell(), 1.0);  // real time: the page's drags come every 50 ms of wall time
  const json push = {{"force", {0.0, 25.0, 0.0}}, {"torque", {0.0, 0.0, 0.0}}};
  const HttpResponse off = h.call("POST", "/api/drag", push);
  EXPECT_EQ(off.status, 409);
  EXPECT_NE(off.body.find("free-drive is off"), std::string::npos) << off.body;
  EXPECT_EQ(h.call("POST", "/api/drag", push, /*with_token=*/false).status, 401);
  EXPECT_EQ(h.call("POST", "/api/drag", {{"force", {0.0, 100.0, 0.0}}}).status, 400);
  EXPECT_EQ(h.call("POST", "/api/drag", {{"force", {0.0, 1.0}}}).status, 400);
  EXPECT_EQ(h.call("POST", "/api/drag", {{"hand", 1}}).status, 400);

  const double y0 = h.get("/api/state")["arm"]["endpoint"]["p"][1];
  const HttpResponse started =
      h.call("POST", "/api/operations", {{"node", "FreeDrive"}, {"attributes", {{"mode", "translation"}}}});
  ASSERT_EQ(started.status, 202) << started.body;
  const std::int64_t id = json::parse(started.body)["run"];
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(1200);
  int held = 0;
  while (std::chrono::steady_clock::now() < until) {
    held += h.call("POST", "/api/drag", push).status == 200 ? 1 : 0;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_GT(held, 10);
  // The drags stop: the dead-man lapses, the operation ends and the arm stands still.
  const json ended = h.waitForRun(id);
  EXPECT_EQ(ended["result"], "SUCCESS") << ended.dump();
  h.waitTicks(50);
  const json state = h.get("/api/state");
  EXPECT_FALSE(state["arm"]["moving"].get<bool>());
  const double y1 = state["arm"]["endpoint"]["p"][1];
  EXPECT_GT(y1 - y0, 0.05) << "the push along y did not move the tool";
  h.waitTicks(50);
  EXPECT_NEAR(h.get("/api/state")["arm"]["endpoint"]["p"][1].get<double>(), y1, 0.002) << "it did not hold";
  EXPECT_EQ(h.call("POST", "/api/drag", push).status, 409);  // no FreeDrive runs now

  // Refused while something else runs, with the reason.
  const HttpResponse moving =
      h.call("POST", "/api/operations", {{"node", "Move"}, {"attributes", {{"waypoint", "above_place"}}}});
  ASSERT_EQ(moving.status, 202) << moving.body;
  const HttpResponse refused =
      h.call("POST", "/api/operations", {{"node", "FreeDrive"}, {"attributes", json::object()}});
  EXPECT_EQ(refused.status, 409);
  EXPECT_NE(refused.body.find("is active"), std::string::npos) << refused.body;
  h.waitForRun(json::parse(moving.body)["run"]);
}

TEST(Ur5Cell, APageThatStallsKeepsFreeDriveHeldWhileTheArmStandsAndMovesAgainOnTheNextPush) {
  Harness h(blindCell(), 1.0);
  const json push = {{"force", {0.0, 25.0, 0.0}}, {"torque", {0.0, 0.0, 0.0}}};
  const HttpResponse started =
      h.call("POST", "/api/operations", {{"node", "FreeDrive"}, {"attributes", {{"mode", "translation"}}}});
  ASSERT_EQ(started.status, 202) << started.body;
  const std::int64_t id = json::parse(started.body)["run"];
  // The operation begins on the engine's next tick: until then a push finds free-drive off.
  for (int tries = 0; tries < 100 && h.call("POST", "/api/drag", push).status != 200; ++tries) {
    h.waitTicks(1);
  }
  const auto pushFor = [&](int ticks) {
    const std::uint64_t target = h.engine().stats().ticks + static_cast<std::uint64_t>(ticks);
    while (h.engine().stats().ticks < target) {
      ASSERT_EQ(h.call("POST", "/api/drag", push).status, 200);
      h.waitTicks(5);  // the page's 50 ms
    }
  };
  pushFor(60);
  // The page stalls for 1 s of the cell's time (a loaded machine): the push ends after 0.25 s
  // and the arm stands; the dead-man (2 s) stays held.
  h.waitTicks(40);
  const double stalled = h.get("/api/state")["arm"]["endpoint"]["p"][1];
  h.waitTicks(60);
  const double still = h.get("/api/state")["arm"]["endpoint"]["p"][1];
  EXPECT_NEAR(still, stalled, 0.002) << "the arm moved on a push older than 0.25 s";
  // The next push finds free-drive on, and the arm moves again.
  pushFor(60);
  const double moved = h.get("/api/state")["arm"]["endpoint"]["p"][1];
  EXPECT_GT(moved - still, 0.02);
  EXPECT_EQ(h.call("POST", "/api/drag", {{"release", true}}).status, 200);
  EXPECT_EQ(h.waitForRun(id)["result"], "SUCCESS");
}

TEST(Ur5Cell, EachPushIsAnsweredWithWhyFreeDriveHeldBackAndItsSpeed) {
  // Pushed down onto the table: the page is told the reference's speed while it moves, and why
  // the arm stopped short of the table when it does (what the page shows the person guiding).
  Harness h(blindCell(), 1.0);
  const json down = {{"force", {0.0, 0.0, -40.0}}, {"torque", {0.0, 0.0, 0.0}}};
  const HttpResponse started =
      h.call("POST", "/api/operations", {{"node", "FreeDrive"}, {"attributes", {{"mode", "translation"}}}});
  ASSERT_EQ(started.status, 202) << started.body;
  const std::int64_t id = json::parse(started.body)["run"];
  double fastest = 0.0;
  std::string blocked;
  const std::uint64_t end = h.engine().stats().ticks + 600;
  while (h.engine().stats().ticks < end && blocked.find("table") == std::string::npos) {
    const HttpResponse pushed = h.call("POST", "/api/drag", down);
    if (pushed.status == 200) {
      const json answer = json::parse(pushed.body);
      EXPECT_EQ(answer["ok"], "held");
      fastest = std::max(fastest, answer["speed"].get<double>());
      blocked = answer["blocked"].get<std::string>();
    }
    h.waitTicks(5);
  }
  EXPECT_GT(fastest, 0.05);
  EXPECT_NE(blocked.find("would touch table"), std::string::npos) << blocked;
  const HttpResponse released = h.call("POST", "/api/drag", {{"release", true}});
  EXPECT_EQ(json::parse(released.body), json({{"ok", "released"}}));
  EXPECT_EQ(h.waitForRun(id)["result"], "SUCCESS");
}

}  // namespace
}  // namespace costar::server
