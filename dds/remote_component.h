#pragma once
// The executor's side: a Component whose operations run in a component host elsewhere
// (dds/host.h). start() sends the goal and returns at once; poll() returns the latest state
// received, so a tick never waits on the network; a rejected goal ends as FAILURE with the
// host's reason. When the component's host has sent nothing for kHostTimeout (it died, hangs
// or its network is gone), running operations end as FAILURE and report() throws, both naming
// the component (the registry then stops the cell). A restarted host is used again at once.
// In lockstep (RemoteConfig::lockstep, dds/lockstep.h) every call is answered by the host at
// once at the executor's simulated time instead.

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "component/component.h"
#include "dds/lockstep.h"
#include "dds/remote_config.h"

namespace costar::dds {

class RemoteClient;

class RemoteComponent final : public component::Component {
 public:
  /// Use RemoteClient::connect.
  RemoteComponent(std::shared_ptr<RemoteClient> client, component::ComponentDescription description);

  const component::ComponentDescription& description() const override { return description_; }
  /// Sends the goal. @throws std::runtime_error when the component's host is gone.
  component::OperationId start(const std::string& operation, const component::ParamMap& params) override;
  component::OperationResult poll(component::OperationId id) override;
  void cancel(component::OperationId id) override;
  world::Report report() const override;

  /// Whether the host has confirmed that `id`, cancelled here, has stopped.
  bool cancelConfirmed(component::OperationId id) const;

 private:
  std::shared_ptr<RemoteClient> client_;
  component::ComponentDescription description_;
};

/// One per executor process and RemoteConfig: the DDS reader side shared by its proxies.
class RemoteClient : public std::enable_shared_from_this<RemoteClient> {
 public:
  /// Joins the domain and partition of `config`. @throws std::runtime_error.
  static std::shared_ptr<RemoteClient> create(const RemoteConfig& config);
  RemoteClient(const RemoteClient&) = delete;
  RemoteClient& operator=(const RemoteClient&) = delete;
  ~RemoteClient();

  /// A proxy of `component`, once a host serving it has been heard and can receive goals.
  /// @throws std::runtime_error naming the component, the domain and the partition when no
  /// host serves it within `timeout`.
  std::shared_ptr<RemoteComponent> connect(const std::string& component, std::chrono::milliseconds timeout);

  /// Lockstep: answers the hosts' driver calls with `server` while a call waits for its host;
  /// `readings` are answered ahead with a call whose last one asked them first (DriverReading).
  void setDriverServer(DriverServer server, std::vector<DriverReading> readings = {});
  /// Lockstep: publishes the simulated time on rt/clock; the calls after it carry it.
  void publishClock(TimePoint now);
  /// Lockstep: publishes the arm's joints on rt/joint_states (sensor_msgs/msg/JointState) and the
  /// wrist's wrench on rt/wrench (geometry_msgs/msg/WrenchStamped), for ROS 2 tools on the domain.
  void publishJointState(const JointStateSample& joints);
  void publishWrench(const WrenchSample& wrench);
  /// Lockstep: publishes a camera frame's colour image on rt/camera/color/image_raw and its depth
  /// on rt/camera/depth/image_raw (sensor_msgs/msg/Image; either may be empty: not sent).
  void publishImages(const ImageSample& color, const ImageSample& depth);

 private:
  friend class RemoteComponent;
  struct State;
  explicit RemoteClient(const RemoteConfig& config);

  std::unique_ptr<State> state_;
};

}  // namespace costar::dds
