#pragma once
// A component host: serves components of this process to executors in others over DDS
// (`costar host`). A goal (an operation with its JSON parameters) is started and answered
// accepted or rejected with the reason; the host polls its running operations every
// millisecond and publishes a changed state as feedback and the end as a result; a cancel
// stops the operation. Each component's description and report are published (durable, so a
// proxy that joins later reads them), and a heartbeat every kHeartbeatPeriod.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "component/component.h"
#include "dds/remote_config.h"

namespace costar::dds {

class ComponentHost {
 public:
  /// Lockstep with the executor's simulated clock (dds/lockstep.h): the executor calls the
  /// components (start, poll, cancel, report) and each call is answered at once, at its
  /// simulated time; nothing is polled or published between calls.
  struct Lockstep {
    /// The components afresh for a new executor (a new run or trial: its client id), with the
    /// names of those given, so that each run starts from the state one process would.
    std::function<std::vector<std::shared_ptr<component::Component>>(std::uint64_t executor)> new_run;
    /// Brings the host's clock to a call's simulated time (SimulatorLink::reachTime).
    std::function<void(std::int64_t stamp_ns)> reach_time;
    /// The driver readings the executor answered ahead for the call about to be served
    /// (SimulatorLink::prepare), and after it how many were used (SimulatorLink::preparedUsed).
    std::function<void(const std::string& prepared_json)> prepare;
    std::function<std::uint32_t()> prepared_used;
  };

  /// Joins the DDS domain and partition of `config` and publishes the components'
  /// descriptions. The components are used from serve()'s thread only.
  /// @throws std::invalid_argument for no components or two with one name;
  /// std::runtime_error when DDS cannot be joined.
  ComponentHost(const RemoteConfig& config, std::vector<std::shared_ptr<component::Component>> components,
                std::optional<Lockstep> lockstep = std::nullopt);
  ComponentHost(const ComponentHost&) = delete;
  ComponentHost& operator=(const ComponentHost&) = delete;
  ~ComponentHost();

  /// Serves until `stop` is set (noticed within kHeartbeatPeriod). The heartbeat goes from a
  /// thread of its own, so a long operation step (a detection) does not silence it. `each_cycle` (if given) runs
  /// on this thread before the goals and running operations of each cycle are handled (a
  /// workcell refreshes its world and advances its clock there). Cancels the operations still
  /// running when it returns.
  void serve(const std::atomic<bool>& stop, const std::function<void()>& each_cycle = {});

  /// This host's identity on the wire (random, new for every host).
  std::uint64_t id() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace costar::dds
