// TeachGrasp: how the gripper holds the nearest part of a class now, saved as a named grasp
// (snapped to the class's canonical frame; with the gripper's mode, for a gripper with modes).

#include "smartmove/script.h"
#include "smartmove/smartmove.h"

namespace costar::smartmove {

using component::OperationResult;
using component::RunningOperation;

std::unique_ptr<RunningOperation> SmartMoveComponent::beginTeachGrasp(const component::ParamMap& params) {
  const auto text = [&params](const char* name) { return params.at(name).asString(); };
  const std::string object_class = text("object_class");
  const world::ObjectClass* object = objectClass(object_class);
  const world::Pose tool = motion_.endpoint();
  std::optional<std::pair<std::string, world::Pose>> nearest;
  for (const auto& [name, pose] : matching(object_class, {}).objects) {
    if ((pose.translation() - tool.translation()).norm() < 0.1 &&
        (!nearest || (pose.translation() - tool.translation()).norm() <
                         (nearest->second.translation() - tool.translation()).norm())) {
      nearest = {name, pose};
    }
  }
  if (object == nullptr || !nearest) {
    return failed("no " + object_class +
                  " within 10 cm of the gripper: detect the parts, then put the gripper "
                  "around one");
  }
  const world::Pose relative = snapToCanonical(nearest->second.inverse() * tool, *object);
  Grasp taught{object_class, text("grasp"), relative, {}, {}};
  // A gripper with modes: the grasp needs the one it was taught in.
  for (const std::string& mode : fingers_.modes()) {
    if (world_.holds("gripper_mode", std::vector<std::string>{mode})) {
      taught.mode = mode;
    }
  }
  try {
    grasps_.teach(taught);
  } catch (const std::exception& e) {
    return failed(std::string("cannot save the grasp: ") + e.what());
  }
  const Eigen::Vector3d& p = relative.translation();
  return std::make_unique<component::FinishedOperation>(
      OperationResult::success({{"object", nearest->first}, {"position", {p.x(), p.y(), p.z()}}}));
}

}  // namespace costar::smartmove
