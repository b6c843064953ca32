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
#include <vector>

#include "component/component.h"
#include "dds/remote_config.h"

namespace costar::dds {

class ComponentHost {
 public:
  /// Joins the DDS domain and partition of `config` and publishes the components'
  /// descriptions. The components are used from serve()'s thread only.
  /// @throws std::invalid_argument for no components or two with one name;
  /// std::runtime_error when DDS cannot be joined.
  ComponentHost(const RemoteConfig& config, std::vector<std::shared_ptr<component::Component>> components);
  ComponentHost(const ComponentHost&) = delete;
  ComponentHost& operator=(const ComponentHost&) = delete;
  ~ComponentHost();

  /// Serves until `stop` is set (noticed within kHeartbeatPeriod). `each_cycle` (if given) runs
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
