#pragma once
// A simulated cell's components served by a host (`costar host gripper perception -w ur5-sim`)
// in lockstep with the executor that owns the simulation (dds/lockstep.h). The executor answers
// its hosts' driver calls from its simulator (simDriverServer); a host builds the components on
// drivers that call it (RemoteSimComponents). The gripper (2-finger or 3-finger adaptive) and
// perception can be remote: the others share the cell's planner, world or simulation in the
// executor.

#include <memory>
#include <string>
#include <vector>

#include "camera/rgbd.h"
#include "component/component.h"
#include "dds/lockstep.h"
#include "gripper/adaptive_gripper_driver.h"
#include "gripper/gripper_driver.h"

namespace costar::dds {
class RemoteClient;
}  // namespace costar::dds

namespace costar::workcell {

/// The components of a simulated cell that a host may serve.
const std::vector<std::string>& remotableSimComponents();

/// The executor's answers to its hosts' driver calls: `gripper` (read, command, max_opening) on
/// the cell's 2-finger driver, `adaptive_gripper` (read, command_fingers, command_mode) on its
/// 3-finger one (either may be null: the cell has none), `camera` (info, capture,
/// capture_depth, stream_status) with the frames seen from `camera_pose()` (the calibrated pose,
/// as perception in the executor's process sees them).
dds::DriverServer simDriverServer(gripper::GripperDriver* gripper, gripper::AdaptiveGripperDriver* adaptive,
                                  camera::RgbdCamera& camera, std::function<world::Pose()> camera_pose);

/// The calls of simDriverServer that are readings (dds::DriverReading): the fingers' reading and
/// opening, the camera's description and stream status.
const std::vector<dds::DriverReading>& simDriverReadings();

/// `camera`, whose frames, as they are taken, are also published for ROS 2 tools on the domain:
/// the colour image on rt/camera/color/image_raw (rgb8) and the depth on rt/camera/depth/image_raw
/// (32FC1, metres along the optical axis, NaN where there is none), in frame `frame_id`.
std::unique_ptr<camera::RgbdCamera> imagePublishingCamera(camera::RgbdCamera& camera, dds::RemoteClient& client,
                                                          std::string frame_id);

/// A host's components of simulated cell `cell` on drivers that call the executor through
/// `link`, and what they need kept alive.
class RemoteSimComponents {
 public:
  /// @throws std::invalid_argument naming a component that cannot be remote; std::runtime_error
  /// for an unreadable cell.
  RemoteSimComponents(const std::string& cell, const std::vector<std::string>& names, dds::SimulatorLink& link);
  ~RemoteSimComponents();
  RemoteSimComponents(const RemoteSimComponents&) = delete;
  RemoteSimComponents& operator=(const RemoteSimComponents&) = delete;

  /// The components afresh (a new run), in the order of `names`.
  std::vector<std::shared_ptr<component::Component>> make();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace costar::workcell
