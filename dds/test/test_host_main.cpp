// TEST ONLY: serves the test components (testing/test_components.h) named on the command
// line over DDS, for dds/test/remote_component_test.cpp, until SIGTERM or SIGINT.
//   dds_test_host PARTITION COMPONENT...   (test_actions, test_counter, test_logger, test_arm)
// or, for dds/test/lockstep_test.cpp, a probe named NAME in lockstep with an executor's clock:
//   dds_test_host --lockstep DOMAIN PARTITION NAME

#include <atomic>
#include <cctype>
#include <csignal>
#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include "dds/host.h"
#include "dds/lockstep.h"
#include "testing/test_components.h"

namespace {

std::atomic<bool> g_stop{false};

extern "C" void onSignal(int /*signal*/) { g_stop = true; }

/// A component whose operation (Read and its name: ReadNear for "near"), and whose report, ask the executor's "sensor"
/// driver for a reading (as a gripper reads its fingers), saying who asks; its report counts the readings.
class LockstepProbe final : public costar::component::Component {
 public:
  LockstepProbe(std::string name, costar::dds::SimulatorLink& link) : link_(link) {
    description_.name = std::move(name);
    description_.type = "Probe";
    description_.symbols = {{"reads", costar::world::SymbolKind::kNumber, "readings so far"}};
    std::string operation = "Read" + description_.name;
    operation[4] = static_cast<char>(std::toupper(static_cast<unsigned char>(operation[4])));
    description_.operations.push_back(
        {operation, "reads the sensor", {}, costar::component::OperationKind::kRobotAction, {}});
  }
  const costar::component::ComponentDescription& description() const override { return description_; }
  costar::component::OperationId start(const std::string&, const costar::component::ParamMap&) override {
    read();
    return reads_;
  }
  costar::component::OperationResult poll(costar::component::OperationId) override {
    return costar::component::OperationResult::success({{"reads", reads_}});
  }
  void cancel(costar::component::OperationId) override {}
  costar::world::Report report() const override {
    read();
    costar::world::Report report;
    report.symbols.push_back({"reads", "", {}, costar::world::NumberValue{static_cast<double>(reads_), ""}});
    return report;
  }

 private:
  void read() const {
    link_.call("sensor", "read", {{"who", description_.name}});
    ++reads_;
  }
  costar::dds::SimulatorLink& link_;
  costar::component::ComponentDescription description_;
  mutable int reads_ = 0;
};

int serveLockstep(const std::string& domain, const std::string& partition, const std::string& name) {
  costar::dds::RemoteConfig config;
  config.domain = static_cast<std::uint32_t>(std::stoul(domain));
  config.partition = partition;
  config.lockstep = true;
  costar::dds::SimulatorLink link(config);
  costar::dds::ComponentHost::Lockstep lockstep;
  lockstep.new_run = [&](std::uint64_t executor) {
    link.setExecutor(executor);
    return std::vector<std::shared_ptr<costar::component::Component>>{std::make_shared<LockstepProbe>(name, link)};
  };
  lockstep.reach_time = [&](std::int64_t stamp_ns) { link.reachTime(stamp_ns); };
  costar::dds::ComponentHost host(config, {std::make_shared<LockstepProbe>(name, link)}, lockstep);
  link.setHost(host.id());
  host.serve(g_stop);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 5 && std::string(argv[1]) == "--lockstep") {
    std::signal(SIGTERM, onSignal);
    std::signal(SIGINT, onSignal);
    try {
      return serveLockstep(argv[2], argv[3], argv[4]);
    } catch (const std::exception& error) {
      std::fprintf(stderr, "%s: %s\n", argv[0], error.what());
      return 1;
    }
  }
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s PARTITION COMPONENT...\n", argv[0]);
    return 2;
  }
  std::signal(SIGTERM, onSignal);
  std::signal(SIGINT, onSignal);
  const std::map<std::string, std::shared_ptr<costar::component::Component>> known = {
      {"test_actions", std::make_shared<costar::testing::TestActions>()},
      {"test_counter", std::make_shared<costar::testing::TestCounter>()},
      {"test_logger", std::make_shared<costar::testing::TestLogger>()},
      {"test_arm", std::make_shared<costar::testing::TestArm>()},
  };
  costar::dds::RemoteConfig config;
  config.partition = argv[1];
  std::vector<std::shared_ptr<costar::component::Component>> served;
  for (int i = 2; i < argc; ++i) {
    const auto it = known.find(argv[i]);
    if (it == known.end()) {
      std::fprintf(stderr, "%s: unknown test component '%s'\n", argv[0], argv[i]);
      return 2;
    }
    served.push_back(it->second);
  }
  try {
    costar::dds::ComponentHost host(config, served);
    host.serve(g_stop);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "%s: %s\n", argv[0], error.what());
    return 1;
  }
  return 0;
}
