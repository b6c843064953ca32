#pragma once
// Lockstep with a simulated clock: a simulated cell whose components run in hosts elsewhere
// (docs/ARCHITECTURE.md, "Components in other processes"). The executor owns the simulation and
// its clock, which it publishes on rt/clock (rosgraph_msgs/msg/Clock, as ROS 2 does with
// simulated time); each call of a remote component (start, poll, cancel, report) is answered at
// once by its host at that simulated time, and the host's components reach the simulator's
// drivers (the gripper's fingers, the camera) through calls back to the executor, answered while
// it waits. Simulated time stands still while a call is out, so a run is the same whichever
// process its components run in, and the same for a seed.

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "core/clock.h"
#include "dds/remote_config.h"

namespace costar::dds {

/// A driver call's answer: JSON, and for a camera frame its points and colours.
struct DriverReply {
  nlohmann::json result;
  std::vector<float> floats;
  std::vector<std::uint8_t> bytes;
};

/// An arm's joints as ROS 2's sensor_msgs/msg/JointState carries them (rad, rad/s, N m).
struct JointStateSample {
  TimePoint stamp{};
  std::vector<std::string> names;
  std::vector<double> position;
  std::vector<double> velocity;
  std::vector<double> effort;
};

/// A wrist sensor's reading as geometry_msgs/msg/WrenchStamped carries it (N, N m, in `frame_id`).
struct WrenchSample {
  TimePoint stamp{};
  std::string frame_id;
  std::array<double, 3> force{};
  std::array<double, 3> torque{};
};

/// A camera image as ROS 2's sensor_msgs/msg/Image carries it: `encoding` "rgb8" (3 bytes a
/// pixel) or "32FC1" (a float a pixel, little-endian), rows of `step` bytes.
struct ImageSample {
  TimePoint stamp{};
  std::string frame_id;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::string encoding;
  std::uint32_t step = 0;
  std::vector<std::uint8_t> data;
};

/// The executor's side: answers `method` of `driver` with `args` (dds::RemoteClient calls it
/// while it waits for a host). Throws to answer with an error.
using DriverServer =
    std::function<DriverReply(const std::string& driver, const std::string& method, const nlohmann::json& args)>;

/// A driver's calls whose answer depends on the simulated time alone (a reading: it changes
/// nothing, and asked twice at one time answers the same). The executor answers them ahead with
/// a component call whose last one asked them first (a gripper's report reads its fingers), which
/// saves the host a round trip each; the host uses them while its component asks the same calls
/// in the same order, and asks for the rest.
struct DriverReading {
  std::string driver;
  std::string method;
  bool operator<(const DriverReading& other) const {
    return driver != other.driver ? driver < other.driver : method < other.method;
  }
};

/// A host's side: the simulated time on rt/clock and calls to the executor's drivers.
class SimulatorLink {
 public:
  /// A driver call the executor has not answered in this long fails (it died or hangs).
  static constexpr std::chrono::seconds kAnswerTimeout{5};

  /// Joins the domain and partition of `config`. @throws std::runtime_error.
  explicit SimulatorLink(const RemoteConfig& config);
  SimulatorLink(const SimulatorLink&) = delete;
  SimulatorLink& operator=(const SimulatorLink&) = delete;
  ~SimulatorLink();

  /// The executor whose simulator the calls go to (its RemoteClient's id): a new run.
  void setExecutor(std::uint64_t client);
  /// Whether an executor was set: before the first run, driver calls have no one to answer.
  bool hasExecutor() const;
  /// Which host asks (its replies are told apart from other hosts').
  void setHost(std::uint64_t host_id);
  /// Calls `method` of `driver`. @throws std::runtime_error naming them when the executor
  /// answers with an error or not within kAnswerTimeout.
  DriverReply call(const std::string& driver, const std::string& method, const nlohmann::json& args);

  /// The readings the executor answered ahead for the call about to be served (its
  /// prepared_json; empty: none), used by call() in order while they match.
  void prepare(const std::string& prepared_json);
  /// How many of them call() used since prepare(); forgets the rest.
  std::uint32_t preparedUsed();
  /// How many driver calls went to the executor (those answered ahead did not).
  std::uint64_t callsSent() const;

  /// Waits until rt/clock has reached `stamp_ns` and sets the clock to it.
  /// @throws std::runtime_error when it does not within kAnswerTimeout.
  void reachTime(std::int64_t stamp_ns);
  /// The simulated time of rt/clock, as the host's components read it: it moves only with the
  /// executor's clock (sleepUntil waits for it).
  Clock& clock();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace costar::dds
