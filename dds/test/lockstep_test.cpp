// Lockstep with a simulated clock (dds/lockstep.h): the executor's side (a RemoteClient in
// lockstep that publishes rt/clock and answers driver calls) and a host's side (a ComponentHost
// in lockstep with a SimulatorLink) in one process, over DDS on loopback, in a domain of this
// test's own.

#include "dds/lockstep.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <thread>

#include "component/registry.h"
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

/// A component whose report is a gauge's level, read from the executor's "gauge" driver.
class Gauge final : public component::Component {
 public:
  Gauge(std::string name, SimulatorLink& link) : link_(link) {
    description_.name = std::move(name);
    description_.type = "Gauge";
    description_.symbols = {{"level", world::SymbolKind::kNumber, "the gauge's level"}};
  }
  const component::ComponentDescription& description() const override { return description_; }
  component::OperationId start(const std::string&, const component::ParamMap&) override { return 1; }
  component::OperationResult poll(component::OperationId) override { return component::OperationResult::success(); }
  void cancel(component::OperationId) override {}
  world::Report report() const override {
    const double level = link_.call("gauge", "read", {{"who", description_.name}}).result.get<double>();
    world::Report report;
    report.symbols.push_back({description_.name, "", {}, world::NumberValue{level, ""}});
    return report;
  }

 private:
  SimulatorLink& link_;
  component::ComponentDescription description_;
};

/// Gauges "left" and "right" in one lockstep host on a thread of its own; counts the calls it
/// answers.
class GaugeHost {
 public:
  explicit GaugeHost(const RemoteConfig& config) : link_(config) {
    const auto gauges = [this] {
      return std::vector<std::shared_ptr<component::Component>>{std::make_shared<Gauge>("left", link_),
                                                                std::make_shared<Gauge>("right", link_)};
    };
    ComponentHost::Lockstep lockstep;
    lockstep.new_run = [this, gauges](std::uint64_t executor) {
      link_.setExecutor(executor);
      return gauges();
    };
    lockstep.reach_time = [this](std::int64_t stamp_ns) {
      ++calls_;
      link_.reachTime(stamp_ns);
    };
    lockstep.prepare = [this](const std::string& prepared_json) { link_.prepare(prepared_json); };
    lockstep.prepared_used = [this] { return link_.preparedUsed(); };
    host_ = std::make_unique<ComponentHost>(config, gauges(), lockstep);
    link_.setHost(host_->id());
    thread_ = std::thread([this] { host_->serve(stop_); });
  }
  ~GaugeHost() {
    stop_ = true;
    thread_.join();
  }
  /// The executor's calls answered, and the driver calls sent to the executor.
  int calls() const { return calls_; }
  std::uint64_t driverCallsSent() const { return link_.callsSent(); }

 private:
  SimulatorLink link_;
  std::unique_ptr<ComponentHost> host_;
  std::atomic<bool> stop_{false};
  std::atomic<int> calls_{0};
  std::thread thread_;
};

/// The executor of the gauges: their levels are `levels` (by name) when read.
struct GaugeExecutor {
  GaugeExecutor(const RemoteConfig& config, bool readings_ahead) : client(RemoteClient::create(config)) {
    client->setDriverServer(
        [this](const std::string&, const std::string&, const nlohmann::json& args) {
          return DriverReply{levels.at(args.at("who").get<std::string>()), {}, {}};
        },
        readings_ahead ? std::vector<DriverReading>{{"gauge", "read"}} : std::vector<DriverReading>{});
    left = client->connect("left", seconds(10));
    right = client->connect("right", seconds(10));
  }
  static double level(const component::Component& gauge) {
    return std::get<world::NumberValue>(gauge.report().symbols.at(0).value).value;
  }
  std::map<std::string, double> levels = {{"left", 1.0}, {"right", 2.0}};
  std::shared_ptr<RemoteClient> client;
  std::shared_ptr<RemoteComponent> left, right;
};

RemoteConfig gaugeConfig(const std::string& name) {
  RemoteConfig config = lockstepConfig(name);
  config.components = {"left", "right"};
  return config;
}

// The registry asks each component's report in turn every tick: a host's components answer in
// one call a tick (the first asked brings the others'), each at that tick's time.
TEST(Lockstep, AHostsReportsComeInOneCallATick) {
  const RemoteConfig config = gaugeConfig("reports");
  GaugeHost host(config);
  GaugeExecutor executor(config, false);
  for (int tick = 1; tick <= 3; ++tick) {
    executor.levels = {{"left", 10.0 * tick}, {"right", 10.0 * tick + 1}};
    executor.client->publishClock(TimePoint(milliseconds(10 * tick)));
    EXPECT_EQ(GaugeExecutor::level(*executor.left), 10.0 * tick);
    EXPECT_EQ(GaugeExecutor::level(*executor.right), 10.0 * tick + 1);
    EXPECT_EQ(host.calls(), tick);
  }
  // Asked again at the same time, a report is asked again (the one brought along was used).
  EXPECT_EQ(GaugeExecutor::level(*executor.right), 31.0);
  EXPECT_EQ(host.calls(), 4);
}

// The readings a host's report asked for at the last tick are read by the executor and sent with
// the next tick's call: the host asks nothing more, and reads the levels of the new tick.
TEST(Lockstep, TheReadingsTheLastCallAskedAreAnsweredAheadWithTheNext) {
  for (const bool ahead : {true, false}) {
    const RemoteConfig config = gaugeConfig(ahead ? "ahead" : "asked");
    GaugeHost host(config);
    GaugeExecutor executor(config, ahead);
    for (int tick = 1; tick <= 3; ++tick) {
      executor.levels = {{"left", 5.0 * tick}, {"right", -5.0 * tick}};
      executor.client->publishClock(TimePoint(milliseconds(10 * tick)));
      EXPECT_EQ(GaugeExecutor::level(*executor.left), 5.0 * tick);
      EXPECT_EQ(GaugeExecutor::level(*executor.right), -5.0 * tick);
    }
    // The first tick's two readings were asked by the host; then none (ahead) or two a tick.
    EXPECT_EQ(host.driverCallsSent(), ahead ? 2U : 6U) << (ahead ? "answered ahead" : "no readings declared");
  }
}

/// A lockstep host of a probe named `name` in a child process (dds_test_host --lockstep): its
/// operation (ReadNear for "near") and its report each ask the executor's "sensor" driver; SIGKILLed when destroyed.
class ProbeProcess {
 public:
  ProbeProcess(const RemoteConfig& config, const std::string& name) {
    std::vector<std::string> args = {COSTAR_DDS_TEST_HOST, "--lockstep", std::to_string(config.domain),
                                     config.partition, name};
    pid_ = ::fork();
    if (pid_ == 0) {
      std::vector<char*> argv;
      for (auto& arg : args) {
        argv.push_back(arg.data());
      }
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
  }
  ProbeProcess(const ProbeProcess&) = delete;
  ProbeProcess& operator=(const ProbeProcess&) = delete;
  ~ProbeProcess() { kill(); }
  void kill() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
      pid_ = -1;
    }
  }

 private:
  pid_t pid_ = -1;
};

// Two hosts, one component each; the host of 'far' dies while the executor answers its driver
// call with a camera frame's worth of data (640 x 480 points and colours), which it never takes.
// The other host's component keeps answering (its driver calls answered at once, not held up
// behind the frame the dead host left unread), and only 'far' is named: before, the next driver
// reply to 'near' waited 1 s behind the frame and failed ("DDS: write failed: Timeout"), and that
// failure was reported as component 'near''s.
TEST(Lockstep, AHostThatDiesIsNamedAloneAndTheOtherHostsComponentsKeepAnswering) {
  RemoteConfig config = lockstepConfig("two-hosts");
  config.components = {"near", "far"};
  ProbeProcess near_host(config, "near");
  ProbeProcess far_host(config, "far");
  const auto client = RemoteClient::create(config);
  client->setDriverServer([&](const std::string&, const std::string&, const nlohmann::json& args) {
    DriverReply reply{{{"value", 1.0}}, {}, {}};
    if (args.at("who") == "far") {
      far_host.kill();
      reply.floats.assign(640 * 480 * 3, 0.5F);
      reply.bytes.assign(640 * 480 * 3, 7);
    }
    return reply;
  });
  const auto near = client->connect("near", seconds(20));
  const auto far = client->connect("far", seconds(20));
  client->publishClock(TimePoint(milliseconds(10)));
  ASSERT_EQ(near->report().symbols.size(), 1U);
  try {
    far->start("ReadFar", {});
    ADD_FAILURE() << "far started on a host that was killed";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("component 'far' stopped answering"), std::string::npos) << error.what();
  }

  client->publishClock(TimePoint(milliseconds(20)));
  component::ComponentRegistry registry;
  registry.add(near);
  registry.add(far);
  registry.refreshWorld();
  EXPECT_NE(registry.stopReason().find("component 'far' stopped answering"), std::string::npos)
      << registry.stopReason();
  EXPECT_EQ(registry.stopReason().find("near"), std::string::npos) << registry.stopReason();
  const component::OperationResult read = near->poll(near->start("ReadNear", {}));
  EXPECT_EQ(read.state, component::OperationState::kSuccess) << read.reason;
}

/// A reader of its own on `topic_name`, as a ROS 2 node would read it (no costar code): checks
/// its type's name on the wire and the first sample that `publish` (called until one arrives)
/// sends; whether one arrived.
template <typename T>
bool readAsRos2(const RemoteConfig& config, const dds_topic_descriptor_t* type, const char* topic_name,
                const char* expected_type, const std::function<void()>& publish,
                const std::function<void(const T&)>& check) {
  const dds_entity_t participant = dds_create_participant(kDomain, nullptr, nullptr);
  EXPECT_GT(participant, 0);
  const dds_entity_t topic = dds_create_topic(participant, type, topic_name, nullptr, nullptr);
  EXPECT_GT(topic, 0);
  char type_name[128] = {};
  EXPECT_GE(dds_get_type_name(topic, type_name, sizeof(type_name)), 0);
  EXPECT_STREQ(type_name, expected_type);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_partition1(qos, config.partition.c_str());
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  const dds_entity_t subscriber = dds_create_subscriber(participant, qos, nullptr);
  const dds_entity_t reader = dds_create_reader(subscriber, topic, qos, nullptr);
  dds_delete_qos(qos);
  EXPECT_GT(reader, 0);
  // Published until the reader has one (discovery takes a moment; no result depends on how long).
  bool got = false;
  const auto guard = std::chrono::steady_clock::now() + seconds(20);
  while (!got && std::chrono::steady_clock::now() < guard) {
    publish();
    std::this_thread::sleep_for(milliseconds(10));
    Bus::takeAll<T>(reader, [&](const T& sample) {
      if (!got) {
        check(sample);
        got = true;
      }
    });
  }
  dds_delete(participant);
  return got;
}

TEST(Lockstep, TheClockIsRos2sOnTheWire) {
  const RemoteConfig config = lockstepConfig("clock");
  const auto client = RemoteClient::create(config);
  // Read with rosgraph_msgs::msg::dds_::Clock_ from the IDL written from ROS 2's Clock.msg and Time.msg.
  const auto got = readAsRos2<rosgraph_msgs_msg_dds__Clock_>(
      config, &rosgraph_msgs_msg_dds__Clock__desc, "rt/clock", "rosgraph_msgs::msg::dds_::Clock_",
      [&] { client->publishClock(TimePoint(std::chrono::nanoseconds(12'345'000'678))); },
      [](const rosgraph_msgs_msg_dds__Clock_& clock) {
        EXPECT_EQ(clock.clock.sec, 12);
        EXPECT_EQ(clock.clock.nanosec, 345'000'678U);
      });
  EXPECT_TRUE(got);
}

TEST(Lockstep, JointStatesAndTheWrenchAreRos2sOnTheWire) {
  const RemoteConfig config = lockstepConfig("robot");
  const auto client = RemoteClient::create(config);
  JointStateSample joints;
  joints.stamp = TimePoint(milliseconds(2500));
  joints.names = {"shoulder_pan_joint", "shoulder_lift_joint"};
  joints.position = {0.5, -1.25};
  joints.velocity = {0.0, 0.125};
  const auto got_joints = readAsRos2<sensor_msgs_msg_dds__JointState_>(
      config, &sensor_msgs_msg_dds__JointState__desc, "rt/joint_states", "sensor_msgs::msg::dds_::JointState_",
      [&] { client->publishJointState(joints); },
      [](const sensor_msgs_msg_dds__JointState_& state) {
        EXPECT_EQ(state.header.stamp.sec, 2);
        EXPECT_EQ(state.header.stamp.nanosec, 500'000'000U);
        ASSERT_EQ(state.name._length, 2U);
        EXPECT_STREQ(state.name._buffer[1], "shoulder_lift_joint");
        ASSERT_EQ(state.position._length, 2U);
        EXPECT_EQ(state.position._buffer[1], -1.25);
        ASSERT_EQ(state.velocity._length, 2U);
        EXPECT_EQ(state.velocity._buffer[1], 0.125);
        EXPECT_EQ(state.effort._length, 0U);
      });
  EXPECT_TRUE(got_joints);
  WrenchSample wrench;
  wrench.stamp = TimePoint(milliseconds(2510));
  wrench.frame_id = "tool0";
  wrench.force = {1.5, -2.0, 10.25};
  wrench.torque = {0.0, 0.5, -0.125};
  const auto got_wrench = readAsRos2<geometry_msgs_msg_dds__WrenchStamped_>(
      config, &geometry_msgs_msg_dds__WrenchStamped__desc, "rt/wrench", "geometry_msgs::msg::dds_::WrenchStamped_",
      [&] { client->publishWrench(wrench); },
      [](const geometry_msgs_msg_dds__WrenchStamped_& stamped) {
        EXPECT_EQ(stamped.header.stamp.nanosec, 510'000'000U);
        EXPECT_STREQ(stamped.header.frame_id, "tool0");
        EXPECT_EQ(stamped.wrench.force.z, 10.25);
        EXPECT_EQ(stamped.wrench.torque.z, -0.125);
      });
  EXPECT_TRUE(got_wrench);
}

TEST(Lockstep, CameraImagesAreRos2sOnTheWire) {
  const RemoteConfig config = lockstepConfig("images");
  const auto client = RemoteClient::create(config);
  ImageSample color;
  color.stamp = TimePoint(milliseconds(3040));
  color.frame_id = "camera_optical_frame";
  color.width = 2;
  color.height = 1;
  color.encoding = "rgb8";
  color.step = 6;
  color.data = {255, 0, 0, 10, 20, 30};
  ImageSample depth = color;
  depth.encoding = "32FC1";
  depth.step = 8;
  const float metres[2] = {0.75F, std::numeric_limits<float>::quiet_NaN()};
  depth.data.resize(sizeof(metres));
  std::memcpy(depth.data.data(), metres, sizeof(metres));
  const auto got_color = readAsRos2<sensor_msgs_msg_dds__Image_>(
      config, &sensor_msgs_msg_dds__Image__desc, "rt/camera/color/image_raw", "sensor_msgs::msg::dds_::Image_",
      [&] { client->publishImages(color, depth); },
      [](const sensor_msgs_msg_dds__Image_& image) {
        EXPECT_EQ(image.header.stamp.sec, 3);
        EXPECT_EQ(image.header.stamp.nanosec, 40'000'000U);
        EXPECT_STREQ(image.header.frame_id, "camera_optical_frame");
        EXPECT_EQ(image.width, 2U);
        EXPECT_EQ(image.height, 1U);
        EXPECT_STREQ(image.encoding, "rgb8");
        EXPECT_EQ(image.step, 6U);
        ASSERT_EQ(image.data._length, 6U);
        EXPECT_EQ(image.data._buffer[3], 10);
        EXPECT_EQ(image.data._buffer[5], 30);
      });
  EXPECT_TRUE(got_color);
  const auto got_depth = readAsRos2<sensor_msgs_msg_dds__Image_>(
      config, &sensor_msgs_msg_dds__Image__desc, "rt/camera/depth/image_raw", "sensor_msgs::msg::dds_::Image_",
      [&] { client->publishImages(color, depth); },
      [](const sensor_msgs_msg_dds__Image_& image) {
        EXPECT_STREQ(image.encoding, "32FC1");
        EXPECT_EQ(image.is_bigendian, 0);
        ASSERT_EQ(image.data._length, 8U);
        float read[2] = {};
        std::memcpy(read, image.data._buffer, sizeof(read));
        EXPECT_EQ(read[0], 0.75F);
        EXPECT_TRUE(std::isnan(read[1]));
      });
  EXPECT_TRUE(got_depth);
}

}  // namespace
}  // namespace costar::dds
