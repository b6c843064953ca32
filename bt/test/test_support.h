#pragma once
// Test-only helpers for the engine: a scripted leaf that records what happens to it, a
// registry that knows it, and an observer that records transitions.

#include <memory>
#include <string>
#include <vector>

#include "bt/builder.h"
#include "bt/plan_xml.h"
#include "bt/registry.h"
#include "core/clock.h"

namespace costar::bt::testing {

/// Events in the order they happened, e.g. "a:start", "a:halt", "a:success", "b:failure".
struct EventLog {
  std::vector<std::string> events;
  void add(const std::string& event) { events.push_back(event); }
  int count(const std::string& event) const {
    int n = 0;
    for (const auto& e : events) {
      n += e == event ? 1 : 0;
    }
    return n;
  }
};

/// TestLeaf: each run stays RUNNING for `ticks` ticks, then returns `result` with `reason`.
/// Records start (first tick of a run), halt (cancelled while RUNNING) and its result.
/// `results` (optional, ';'-separated) gives the result of successive runs, e.g.
/// "failure;failure;success"; the last one repeats.
class TestLeaf final : public LeafNode {
 public:
  TestLeaf(std::string id, std::string name, int ticks, std::vector<Status> results, std::string reason, EventLog* log)
      : LeafNode(std::move(id), std::move(name)),
        ticks_(ticks),
        results_(std::move(results)),
        reason_(std::move(reason)),
        log_(log) {}

 private:
  Status onTick() override {
    if (!running_) {
      running_ = true;
      elapsed_ = 0;
      log_->add(name() + ":start");
    }
    if (elapsed_++ < ticks_) {
      return Status::kRunning;
    }
    running_ = false;
    const Status result = results_[std::min(run_, results_.size() - 1)];
    ++run_;
    log_->add(name() + (result == Status::kSuccess ? ":success" : ":failure"));
    return result == Status::kSuccess ? result : fail(reason_);
  }
  void onHalt() override {
    running_ = false;
    log_->add(name() + ":halt");
  }
  // No onReset(): the scripted results model the outside world, not memory of the node.

  int ticks_;
  std::vector<Status> results_;
  std::string reason_;
  EventLog* log_;
  bool running_ = false;
  int elapsed_ = 0;
  std::size_t run_ = 0;
};

inline NodeRegistry registryWithTestLeaf(EventLog& log) {
  NodeRegistry registry = builtinRegistry();
  NodeSpec spec;
  spec.id = "TestLeaf";
  spec.kind = NodeKind::kAction;
  spec.category = NodeCategory::kRobotAction;
  spec.asynchronous = true;
  spec.ports = {PortSpec::integer("ticks", "ticks spent RUNNING per run", "0", 0, 1000000),
                PortSpec::text("results", "results of successive runs, ';'-separated", "success"),
                PortSpec::text("reason", "failure reason", "scripted failure")};
  spec.build = [&log](const NodeArgs& args) {
    std::vector<Status> results;
    std::string text = args.get("results");
    std::size_t start = 0;
    while (start <= text.size()) {
      const std::size_t end = std::min(text.find(';', start), text.size());
      results.push_back(text.substr(start, end - start) == "failure" ? Status::kFailure : Status::kSuccess);
      start = end + 1;
    }
    return std::make_unique<TestLeaf>(args.spec().id, args.name(), static_cast<int>(args.getInt("ticks")),
                                      std::move(results), args.get("reason"), &log);
  };
  NodeSpec condition;
  condition.id = "TestCondition";
  condition.kind = NodeKind::kCondition;
  condition.category = NodeCategory::kKnowledge;
  condition.ports = spec.ports;
  condition.build = spec.build;
  registry.add(std::move(spec));
  registry.add(std::move(condition));
  return registry;
}

/// Records every transition as "path:FROM->TO".
class RecordingObserver final : public TreeObserver {
 public:
  void onTransition(TimePoint, const TreeNode& node, Status from, Status to) override {
    transitions.push_back(node.path() + ":" + toString(from) + "->" + toString(to));
    if (to == Status::kFailure) {
      reasons.push_back(std::string(node.failureReason()));
    }
  }
  std::vector<std::string> transitions;
  std::vector<std::string> reasons;
};

/// Wraps a tree body in a plan document with main tree "main".
inline std::string planXml(const std::string& body, const std::string& extra_trees = "") {
  return R"(<root BTCPP_format="4" main_tree_to_execute="main"><BehaviorTree ID="main">)" + body + "</BehaviorTree>" +
         extra_trees + "</root>";
}

/// The hostile shape of issue 27: a chain of `trees` SubTrees, each tree an Inverter over the
/// next one (`<BehaviorTree ID="T7"><Inverter><SubTree ID="T8"/></Inverter></BehaviorTree>`),
/// one tree a line; the last ends in AlwaysSuccess (or, with `loop`, uses T0 again).
/// 12,000 trees make about 950 KB.
inline std::string subTreeChainXml(int trees, bool loop = false) {
  std::string xml = "<root BTCPP_format=\"4\" main_tree_to_execute=\"T0\">\n";
  for (int i = 0; i < trees; ++i) {
    const std::string next = i + 1 < trees ? "<SubTree ID=\"T" + std::to_string(i + 1) + "\"/>"
                             : loop        ? "<SubTree ID=\"T0\"/>"
                                           : "<AlwaysSuccess/>";
    xml += "<BehaviorTree ID=\"T" + std::to_string(i) + "\"><Inverter>" + next + "</Inverter></BehaviorTree>\n";
  }
  return xml + "</root>\n";
}

/// A tree built from `body`, with the TestLeaf registry and `clock`.
struct TestTree {
  TestTree(const std::string& body, const std::string& extra_trees = "")
      : registry(registryWithTestLeaf(log)),
        tree(buildTree(loadPlanText(planXml(body, extra_trees), "test.xml"), registry, clock)) {}
  EventLog log;
  SimClock clock;
  NodeRegistry registry;
  Tree tree;
};

}  // namespace costar::bt::testing
