#pragma once
// TEST ONLY: the API's backend without a workcell, for the fuzz targets: plans are validated
// against the built-in nodes and "started" by ticking them a few times on a simulated clock.
// Thread-safe (the end-to-end target calls it from the server's I/O threads).

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "bt/builder.h"
#include "server/backend.h"

namespace costar::server::fuzzing {

class FuzzBackend final : public Backend {
 public:
  nlohmann::json info() override { return {{"workcell", "fuzz"}}; }
  const std::string& nodesJson() override { return nodes_; }
  nlohmann::json choices() override { return nlohmann::json::object(); }
  std::vector<bt::Diagnostic> validate(const bt::Plan& plan) override {
    return bt::validatePlan(plan, registry_, limits_);
  }
  StartResult start(RunRequest request) override {
    StartResult result;
    auto diagnostics = validate(request.plan);
    if (!diagnostics.empty()) {
      result.status = 422;
      result.diagnostics = std::move(diagnostics);
      return result;
    }
    SimClock clock;
    bt::Tree tree = bt::buildTree(request.plan, registry_, clock, {}, limits_);
    for (int tick = 0; tick < 8 && tree.tick() == bt::Status::kRunning; ++tick) {
      clock.advanceBy(std::chrono::milliseconds(10));
    }
    tree.halt();
    result.run_id = ++runs_;
    return result;
  }
  bool control(RunControl) override { return false; }
  nlohmann::json state() override { return {{"type", "state"}}; }
  std::optional<nlohmann::json> runStatus(std::optional<std::int64_t> id) override {
    if (!id || *id > runs_) {
      return std::nullopt;
    }
    return nlohmann::json{{"id", *id}, {"active", false}};
  }
  std::optional<nlohmann::json> groundTruth() override { return std::nullopt; }
  std::optional<nlohmann::json> pointCloud(std::size_t) override { return std::nullopt; }
  /// A state snapshot every other call, so the stream has something to send.
  std::vector<std::string> drainStream() override {
    if (++drains_ % 2 == 0) {
      return {R"({"type":"state","joints":[0,0,0,0,0,0]})"};
    }
    return {};
  }
  std::string helloMessage() override { return R"({"type":"hello","info":{"workcell":"fuzz"},"run":null})"; }

 private:
  bt::NodeRegistry registry_ = bt::builtinRegistry();
  bt::BuildLimits limits_{.max_nodes = 20'000, .max_depth = 300};
  std::string nodes_ = "[]";
  std::atomic<std::int64_t> runs_{0};
  std::atomic<std::uint64_t> drains_{0};
};

}  // namespace costar::server::fuzzing
