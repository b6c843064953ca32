// libFuzzer target: any bytes as an HTTP request to the editor's API (method, token or not,
// target, body). Handling must never crash, hang or leak, and must always answer a status
// between 200 and 599 with a JSON body that parses (unless it is an XML export).
//
// Input layout: byte 0 picks the method, byte 1 the Authorization (none, right, wrong), then
// the target up to the first '\n', then the body.

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <string_view>

#include "bt/builder.h"
#include "server/api.h"
#include "server/backend.h"
#include "server/store.h"

using namespace costar;

namespace {

constexpr const char* kToken = "fuzz-token-0123456789abcdef";

/// The API's backend without a workcell: plans are validated against the built-in nodes and
/// "started" without running.
class FuzzBackend final : public server::Backend {
 public:
  nlohmann::json info() override { return {{"workcell", "fuzz"}}; }
  const std::string& nodesJson() override { return nodes_; }
  nlohmann::json choices() override { return nlohmann::json::object(); }
  std::vector<bt::Diagnostic> validate(const bt::Plan& plan) override {
    return bt::validatePlan(plan, registry_, limits_);
  }
  server::StartResult start(server::RunRequest request) override {
    server::StartResult result;
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
  bool control(server::RunControl) override { return false; }
  nlohmann::json state() override { return {{"type", "state"}}; }
  std::optional<nlohmann::json> runStatus(std::optional<std::int64_t> id) override {
    if (!id || *id > runs_) {
      return std::nullopt;
    }
    return nlohmann::json{{"id", *id}, {"active", false}};
  }
  std::optional<nlohmann::json> groundTruth() override { return std::nullopt; }
  std::optional<nlohmann::json> pointCloud(std::size_t) override { return std::nullopt; }

 private:
  bt::NodeRegistry registry_ = bt::builtinRegistry();
  bt::BuildLimits limits_{.max_nodes = 20'000, .max_depth = 300};
  std::string nodes_ = "[]";
  std::int64_t runs_ = 0;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static FuzzBackend backend;
  static std::unique_ptr<server::Store> store;
  static std::unique_ptr<server::Api> api;
  static std::size_t inputs = 0;
  if (inputs++ % 2000 == 0) {  // a fresh in-memory store now and then keeps memory flat
    api.reset();
    store = std::make_unique<server::Store>(":memory:");
    api = std::make_unique<server::Api>(backend, *store, server::ApiOptions{.token = kToken, .test_endpoints = true});
  }
  if (size < 2) {
    return 0;
  }
  static constexpr const char* kMethods[] = {"GET", "PUT", "POST", "DELETE", "HEAD", "PATCH", "OPTIONS", "get"};
  server::HttpRequest request;
  request.method = kMethods[data[0] % 8];
  request.authorization = data[1] % 3 == 0 ? "" : (data[1] % 3 == 1 ? std::string("Bearer ") + kToken : "Bearer nope");
  const std::string_view rest(reinterpret_cast<const char*>(data + 2), size - 2);
  const auto newline = rest.find('\n');
  request.target = std::string(rest.substr(0, newline));
  request.body = newline == std::string_view::npos ? std::string() : std::string(rest.substr(newline + 1));

  const server::HttpResponse response = api->handle(request);
  if (response.status < 200 || response.status > 599) {
    std::abort();
  }
  if (response.content_type == "application/json" &&
      nlohmann::json::parse(response.body, nullptr, /*allow_exceptions=*/false).is_discarded()) {
    std::abort();
  }
  return 0;
}
