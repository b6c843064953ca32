// TeachGrasp: how the gripper holds the nearest part of a class now, saved as a named grasp
// (snapped to the class's canonical frame; with the mode chosen, or the gripper's, for a gripper
// with modes).

#include <algorithm>

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
  const std::vector<std::string> modes = fingers_.modes();
  const std::string chosen = text("mode");
  if (!chosen.empty() && std::find(modes.begin(), modes.end(), chosen) == modes.end()) {
    std::string listed;
    for (const std::string& mode : modes) {
      listed += (listed.empty() ? "" : ", ") + mode;
    }
    return failed("mode: '" + chosen + "' is not a mode of this gripper" +
                  (modes.empty() ? std::string(" (it has none)") : " (" + listed + ")"));
  }
  const world::Pose relative = snapToCanonical(nearest->second.inverse() * tool, *object);
  Grasp taught{object_class, text("grasp"), relative, {}, chosen};
  // A gripper with modes: the grasp needs the one chosen, else the one it was taught in.
  for (const std::string& mode : modes) {
    if (chosen.empty() && world_.holds("gripper_mode", std::vector<std::string>{mode})) {
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
