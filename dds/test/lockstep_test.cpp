// Lockstep with a simulated clock (dds/lockstep.h): the executor's side (a RemoteClient in
// lockstep that publishes rt/clock and answers driver calls) and a host's side (a ComponentHost
// in lockstep with a SimulatorLink) in one process, over DDS on loopback, in a domain of this
// test's own.

#include "dds/lockstep.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <thread>

#include "dds/bus.h"
#include "dds/host.h"
#include "dds/remote_component.h"

namespace costar::dds {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

/// This test's DDS domain: no other test of the project uses it.
constexpr std::uint32_t kDomain = 72;

RemoteConfig lockstepConfig(const std::string& name) {
  RemoteConfig config;
  config.domain = kDomain;
  config.partition = "costar-lockstep-" + std::to_string(::getpid()) + "-" + name;
  config.components = {"probe"};
  config.lockstep = true;
  return config;
}

/// A component whose operation Read asks the executor's "sensor" driver for its value when it
/// starts and ends at its next poll with that value and the host's simulated time then; its
/// report is the number of reads (made afresh for each run).
class Probe final : public component::Component {
 public:
  explicit Probe(SimulatorLink& link) : link_(link) {
    description_.name = "probe";
    description_.type = "Probe";
    description_.symbols = {{"reads", world::SymbolKind::kNumber, "reads so far"}};
    description_.operations.push_back({"Read", "reads the sensor", {}, component::OperationKind::kRobotAction, {}});
  }
  const component::ComponentDescription& description() const override { return description_; }
  component::OperationId start(const std::string&, const component::ParamMap&) override {
    value_ = link_.call("sensor", "read", {{"scale", 2}}).result.at("value").get<double>();
    ++reads_;
    return static_cast<component::OperationId>(reads_);
  }
  component::OperationResult poll(component::OperationId) override {
    return component::OperationResult::success(
        {{"value", value_}, {"time_ns", link_.clock().now().time_since_epoch().count()}});
  }
  void cancel(component::OperationId) override {}
  world::Report report() const override {
    world::Report report;
    report.symbols.push_back({"reads", "", {}, world::NumberValue{static_cast<double>(reads_), ""}});
    return report;
  }

 private:
  SimulatorLink& link_;
  component::ComponentDescription description_;
  double value_ = 0;
  int reads_ = 0;
};

/// A lockstep host of a Probe on a thread of its own, for the life of the object.
class LockstepHost {
 public:
  explicit LockstepHost(const RemoteConfig& config) : link_(config) {
    ComponentHost::Lockstep lockstep;
    lockstep.new_run = [this](std::uint64_t executor) {
      link_.setExecutor(executor);
      ++runs_;
      return std::vector<std::shared_ptr<component::Component>>{std::make_shared<Probe>(link_)};
    };
    lockstep.reach_time = [this](std::int64_t stamp_ns) { link_.reachTime(stamp_ns); };
    host_ = std::make_unique<ComponentHost>(
        config, std::vector<std::shared_ptr<component::Component>>{std::make_shared<Probe>(link_)}, lockstep);
    link_.setHost(host_->id());
    thread_ = std::thread([this] { host_->serve(stop_); });
  }
  ~LockstepHost() {
    stop_ = true;
    thread_.join();
  }
  int runs() const { return runs_; }

 private:
  SimulatorLink link_;
  std::unique_ptr<ComponentHost> host_;
  std::atomic<bool> stop_{false};
  std::atomic<int> runs_{0};
  std::thread thread_;
};

/// The executor's side: a proxy of the probe whose driver calls are answered with 21 x scale.
struct Executor {
  explicit Executor(const RemoteConfig& config) : client(RemoteClient::create(config)) {
    client->setDriverServer([this](const std::string& driver, const std::string& method, const nlohmann::json& args) {
      ++driver_calls;
      if (driver != "sensor" || method != "read") {
        throw std::invalid_argument("no driver call " + driver + " " + method);
      }
      return DriverReply{{{"value", 21.0 * args.at("scale").get<double>()}}, {}, {}};
    });
    probe = client->connect("probe", seconds(10));
  }
  std::shared_ptr<RemoteClient> client;
  std::shared_ptr<RemoteComponent> probe;
  int driver_calls = 0;
};

TEST(Lockstep, ACallIsAnsweredAtTheExecutorsSimulatedTimeWithItsDriversAnsweringTheHost) {
  const RemoteConfig config = lockstepConfig("call");
  LockstepHost host(config);
  Executor executor(config);
  executor.client->publishClock(TimePoint(milliseconds(1250)));
  const component::OperationId id = executor.probe->start("Read", {});
  EXPECT_EQ(executor.driver_calls, 1);  // answered while the start waited for its host
  const component::OperationResult result = executor.probe->poll(id);
  ASSERT_EQ(result.state, component::OperationState::kSuccess) << result.reason;
  EXPECT_EQ(result.data.at("value").get<double>(), 42.0);
  EXPECT_EQ(result.data.at("time_ns").get<std::int64_t>(), 1'250'000'000);
  executor.client->publishClock(TimePoint(milliseconds(1260)));
  const world::Report report = executor.probe->report();
  ASSERT_EQ(report.symbols.size(), 1U);
  EXPECT_EQ(std::get<world::NumberValue>(report.symbols[0].value).value, 1.0);
}

TEST(Lockstep, EachNewExecutorGetsTheComponentsAfresh) {
  const RemoteConfig config = lockstepConfig("afresh");
  LockstepHost host(config);
  for (int run = 1; run <= 2; ++run) {
    Executor executor(config);
    executor.client->publishClock(TimePoint(milliseconds(10)));
    executor.probe->poll(executor.probe->start("Read", {}));
    const world::Report report = executor.probe->report();
    ASSERT_EQ(report.symbols.size(), 1U);
    EXPECT_EQ(std::get<world::NumberValue>(report.symbols[0].value).value, 1.0) << "run " << run;
    EXPECT_EQ(host.runs(), run);
  }
}

TEST(Lockstep, TheClockIsRos2sOnTheWire) {
  RemoteConfig config = lockstepConfig("clock");
  const auto client = RemoteClient::create(config);
  // A reader of its own, as a ROS 2 node would read /clock: topic rt/clock, type
  // rosgraph_msgs::msg::dds_::Clock_ from the IDL written from ROS 2's Clock.msg and Time.msg.
  const dds_entity_t participant = dds_create_participant(kDomain, nullptr, nullptr);
  ASSERT_GT(participant, 0);
  const dds_entity_t topic =
      dds_create_topic(participant, &rosgraph_msgs_msg_dds__Clock__desc, "rt/clock", nullptr, nullptr);
  ASSERT_GT(topic, 0);
  char type_name[128] = {};
  ASSERT_GE(dds_get_type_name(topic, type_name, sizeof(type_name)), 0);
  EXPECT_STREQ(type_name, "rosgraph_msgs::msg::dds_::Clock_");
  dds_qos_t* qos = dds_create_qos();
  dds_qset_partition1(qos, config.partition.c_str());
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  const dds_entity_t subscriber = dds_create_subscriber(participant, qos, nullptr);
  const dds_entity_t reader = dds_create_reader(subscriber, topic, qos, nullptr);
  dds_delete_qos(qos);
  ASSERT_GT(reader, 0);
  // Published until the reader has it (discovery takes a moment; no result depends on how long).
  std::optional<rosgraph_msgs_msg_dds__Clock_> got;
  const auto guard = std::chrono::steady_clock::now() + seconds(20);
  while (!got && std::chrono::steady_clock::now() < guard) {
    client->publishClock(TimePoint(std::chrono::nanoseconds(12'345'000'678)));
    std::this_thread::sleep_for(milliseconds(10));
    Bus::takeAll<rosgraph_msgs_msg_dds__Clock_>(reader,
                                                [&](const rosgraph_msgs_msg_dds__Clock_& clock) { got = clock; });
  }
  dds_delete(participant);
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->clock.sec, 12);
  EXPECT_EQ(got->clock.nanosec, 345'000'678U);
}

}  // namespace
}  // namespace costar::dds
