#include "smartmove/smartmove.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "smartmove/script.h"

namespace costar::smartmove {

using component::OperationResult;
using component::ParamSpec;
using component::RunningOperation;
using component::ValueType;

std::string partObstacle(const std::string& object) { return "part:" + object; }

std::vector<planning::CollisionShape> fingerShapes(const std::vector<gripper::OrientedBox>& boxes) {
  std::vector<planning::CollisionShape> shapes;
  for (const gripper::OrientedBox& box : boxes) {
    planning::CollisionShape shape;
    shape.kind = planning::CollisionShape::Kind::kBox;
    shape.size = box.size;
    shape.origin = box.pose;
    shapes.push_back(shape);
  }
  return shapes;
}

SmartMoveComponent::SmartMoveComponent(const arm::MotionService& motion, component::Component& arm,
                                       component::Component& gripper, world::WorldState& world,
                                       planning::CollisionWorld& collisions, std::vector<world::ObjectClass> classes,
                                       GraspLibrary& grasps, SmartMoveConfig config)
    : motion_(motion),
      arm_(arm),
      gripper_(gripper),
      world_(world),
      collisions_(collisions),
      classes_(std::move(classes)),
      grasps_(grasps),
      config_(std::move(config)),
      fingers_(config_.gripper ? *config_.gripper
                               : throw std::invalid_argument("SmartMove '" + config_.name + "': no gripper geometry")) {
  component::ComponentDescription description;
  description.name = config_.name;
  description.type = "SmartMove";
  std::vector<std::string> class_names;
  for (const auto& object : classes_) {
    class_names.push_back(object.name);
  }
  ParamSpec object_class{"object_class", ValueType::kString, "class of the part", {}, class_names};
  object_class.choices_from = "object_class";
  ParamSpec predicates{"predicates", ValueType::kString,
                       "conditions on the part, e.g. right_of(table_center); near(node_1)", std::string()};
  predicates.choices_from = "predicate";
  predicates.validate = [check = pattern_check_](std::string_view text) {
    return predicator::checkPatternList(text, *check);
  };
  ParamSpec grasp{"grasp", ValueType::kString,
                  "a grasp taught for the class (default: the first taught for it, e.g. 'top' for a node)",
                  std::string()};
  grasp.choices_from = "grasp";
  ParamSpec approach{"approach", ValueType::kDouble, "distance of the straight approach and retreat (m)",
                     config_.approach};
  approach.min = 0.02;
  approach.max = 0.3;
  ParamSpec drop{"drop", ValueType::kDouble,
                 "let the part go this far above where it would rest (m): 0 sets it down; a little above 0 drops it "
                 "onto a hand held open under it (target hand_1)",
                 0.0};
  drop.min = 0.0;
  drop.max = 0.05;
  ParamSpec speed{"speed", ValueType::kDouble, "fraction of the arm's top speed", config_.default_speed};
  speed.min = 0.01;
  speed.max = 1.0;
  ParamSpec centre{"centre", ValueType::kBool,
                   "after closing, square the part up between the fingers both ways (let go, rise, open fully, turn a "
                   "quarter, go down, close again), so that where it sits in the hand is known even if it moved after "
                   "it was seen; for parts that fit the fingers both ways (a node), else skipped",
                   false};
  ParamSpec push_distance{"distance", ValueType::kDouble, "how far the part is pushed (m)", 0.03};
  push_distance.min = 0.01;
  push_distance.max = 0.1;
  std::vector<std::string> optional_classes = class_names;
  optional_classes.insert(optional_classes.begin(), "");
  ParamSpec target_class{"target_class", ValueType::kString, "put the part on a part of this class", std::string(),
                         optional_classes};
  ParamSpec target{"target", ValueType::kString,
                   "or put it down at a frame (e.g. a taught waypoint), or 'table': a free spot on the table that "
                   "satisfies the predicates",
                   std::string()};
  target.choices_from = "frame";
  target.extra_choices = {"table"};
  target.excludes = {"target_class"};
  target_class.excludes = {"target"};
  // What would fail at once, caught when the plan is checked (the editor's Check, costar run).
  const auto check_grasp = [this](const component::ParamMap& params) -> std::string {
    const std::string& class_name = params.at("object_class").asString();
    const std::string& name = params.at("grasp").asString();
    if (name.empty() || grasps_.find(class_name, name)) {
      return {};
    }
    std::string taught;
    for (const auto& known : grasps_.forClass(class_name)) {
      taught += (taught.empty() ? "" : ", ") + known.name;
    }
    return "no grasp '" + name + "' is taught for class '" + class_name + "'" +
           (taught.empty() ? std::string(" (none is)") : " (taught: " + taught + ")");
  };
  const auto check_release = [](const component::ParamMap& params) -> std::string {
    const std::string& on_class = params.at("target_class").asString();
    const std::string& at = params.at("target").asString();
    if (on_class.empty() && at.empty()) {
      return "give target_class (put the part on such a part) or target (a frame, or 'table')";
    }
    if (!on_class.empty() && !at.empty()) {
      return "give target_class or target, not both (target '" + at + "' would be ignored)";
    }
    if (!at.empty() && at != "table" && !params.at("predicates").asString().empty()) {
      return "the conditions cannot apply: the part goes to frame '" + at +
             "' itself (conditions choose among parts with target_class, or spots with target 'table')";
    }
    return {};
  };
  using Params = component::ParamMap;
  component::OperationTable operations;
  operations.add({"SmartMove",
                  "Moves the tool to the best reachable part that satisfies the conditions.",
                  {object_class, predicates, grasp, speed},
                  component::OperationKind::kRobotAction,
                  check_grasp},
                 [this](const Params& params) { return beginMoveOrGrasp(false, params); });
  operations.add({"SmartGrasp",
                  "Picks up the best reachable part that satisfies the conditions.",
                  {object_class, predicates, grasp, approach, speed, centre},
                  component::OperationKind::kRobotAction,
                  check_grasp},
                 [this](const Params& params) { return beginMoveOrGrasp(true, params); });
  operations.add({"SmartRelease",
                  "Puts the part held on a part that satisfies the conditions, or at a frame.",
                  {target_class, predicates, target, approach, speed, drop},
                  component::OperationKind::kRobotAction,
                  check_release},
                 [this](const Params& params) { return beginRelease(params); });
  operations.add({"SmartPush",
                  "Pushes the most crowded part that satisfies the conditions where it gets more room, "
                  "with the closed gripper (when none can be grasped; look again after it).",
                  {object_class, predicates, push_distance, speed},
                  component::OperationKind::kRobotAction},
                 [this](const Params& params) { return beginPush(params); });
  // A gripper with modes (the 3-finger gripper's basic, pinch, wide, scissor): the mode the taught
  // grasp needs, chosen when it is taught; empty: the mode the gripper is in.
  ParamSpec teach_mode{"mode", ValueType::kString,
                       "the gripper mode the grasp needs, for a gripper with modes (empty: the mode it is in now)",
                       std::string()};
  if (!fingers_.modes().empty()) {
    teach_mode.choices = fingers_.modes();
    teach_mode.choices.insert(teach_mode.choices.begin(), "");
  }
  operations.add({"TeachGrasp",
                  "Saves how the gripper holds the nearest part of a class as a named grasp.",
                  {object_class, {"grasp", ValueType::kString, "name of the new grasp", {}}, teach_mode},
                  component::OperationKind::kKnowledge},
                 [this](const Params& params) { return beginTeachGrasp(params); });
  description.predicates = {{"holding", 1, "holding(o): the gripper holds part o"},
                            {"misplaced", 1,
                             "misplaced(o): o, the part put down last, is seen more than " +
                                 std::to_string(static_cast<int>(std::lround(config_.misplaced_distance * 1000.0))) +
                                 " mm from where it was put (look again, then grasp it and put it again)"}};
  declare(std::move(description), std::move(operations));
}

const world::ObjectClass* SmartMoveComponent::objectClass(const std::string& name) const {
  for (const auto& object : classes_) {
    if (object.name == name) {
      return &object;
    }
  }
  return nullptr;
}

world::Report SmartMoveComponent::report() const {
  world::Report report;
  if (held_ && world_.holds("gripper_holding", {})) {
    report.predicates.push_back({"holding", {*held_}, true, ""});
  }
  if (const auto misplaced = misplacedPart()) {
    report.predicates.push_back({"misplaced", {*misplaced}, true, ""});
  }
  return report;
}

std::optional<std::string> SmartMoveComponent::misplacedPart() const {
  if (!put_) {
    return std::nullopt;
  }
  // Perception renames a part that moved farther than it tracks, so the part put down is found
  // by where it is: the nearest of its class to where it was put, among those seen where none was.
  std::optional<std::pair<std::string, double>> nearest;
  for (const auto& [object, pose] : matching(put_->object_class, {}).objects) {
    const Eigen::Vector3d seen = pose.translation();
    if (std::any_of(put_->known.begin(), put_->known.end(), [&](const Eigen::Vector3d& known) {
          return (known - seen).norm() <= config_.misplaced_distance;
        })) {
      continue;
    }
    const double distance = (seen - put_->pose.translation()).norm();
    if (!nearest || distance < nearest->second) {
      nearest = {object, distance};
    }
  }
  if (!nearest || nearest->second <= config_.misplaced_distance || nearest->second > config_.misplaced_search) {
    return std::nullopt;
  }
  return nearest->first;
}

void SmartMoveComponent::syncObstacles() {
  std::vector<std::string> present;
  for (const world::Predicate* is_a : world_.predicates("is_a")) {
    if (is_a->args.size() != 2 || (held_ && is_a->args[0] == *held_)) {
      continue;
    }
    const world::ObjectClass* object = objectClass(is_a->args[1]);
    const auto pose = world_.worldPose(is_a->args[0]);
    if (object == nullptr || !pose) {
      continue;
    }
    const Eigen::AlignedBox3d bounds = object->bounds();
    collisions_.setBox(partObstacle(is_a->args[0]), *pose * Eigen::Translation3d(bounds.center()), bounds.sizes());
    present.push_back(partObstacle(is_a->args[0]));
  }
  // The person's hand and forearm where the camera sees the hand: never planned through.
  for (const std::string& frame : config_.person_frames) {
    const auto pose = world_.worldPose(frame);
    if (!pose) {
      continue;
    }
    const double wrist = -config_.hand_size.x() / 2;
    collisions_.setBox(partObstacle(frame), *pose, config_.hand_size);
    collisions_.setBox(partObstacle(frame) + ":forearm",
                       *pose * Eigen::Translation3d(wrist - config_.forearm_size.x() / 2, 0, 0), config_.forearm_size);
    present.push_back(partObstacle(frame));
    present.push_back(partObstacle(frame) + ":forearm");
  }
  for (const auto& name : obstacles_) {
    if (std::find(present.begin(), present.end(), name) == present.end()) {
      collisions_.remove(name);
    }
  }
  obstacles_ = std::move(present);
}

arm::QueryScene SmartMoveComponent::scene(const std::vector<std::string>& objects,
                                          const gripper::FingerStance& stance) const {
  arm::QueryScene query;
  std::vector<std::string> obstacles;
  for (const std::string& object : objects) {
    obstacles.push_back(partObstacle(object));
  }
  query.allowed = arm::AllowedContacts::between(config_.gripper_links, obstacles);
  if (const auto boxes = fingers_.fingerBoxes(stance)) {
    query.link_shapes.emplace_back(config_.finger_link, fingerShapes(*boxes));
  }
  // The part held moves with the gripper: not an obstacle (syncObstacles leaves it out of the
  // cell's world from the next tick on; a query in between leaves it out here).
  if (held_) {
    query.removed.push_back(partObstacle(*held_));
  }
  return query;
}

ArmModel SmartMoveComponent::armModel() const {
  const arm::JointVector now = motion_.joints();
  return {[this, now](const world::Pose& goal) { return motion_.solutions(goal, now); }, motion_.endpoint(), now};
}

std::unique_ptr<RunningOperation> SmartMoveComponent::follow(const arm::MotionPlan& plan, const std::string& what) {
  if (!plan.ok()) {
    return failed(what + ": " + plan.failure);
  }
  return std::make_unique<component::DelegatedOperation>(arm_, std::string(arm::kFollowJointPath),
                                                         arm::followParams(plan, what));
}

std::unique_ptr<RunningOperation> SmartMoveComponent::moveToFreeConfiguration(const world::Pose& pose,
                                                                              const arm::JointVector& seed,
                                                                              double speed, const std::string& what,
                                                                              const std::string& none,
                                                                              const gripper::FingerStance& stance) {
  const arm::QueryScene moving = scene({}, stance);
  std::string reason;
  const auto configuration = motion_.firstFree(motion_.solutions(pose, seed), moving, reason);
  return follow(configuration ? motion_.planToJoints(motion_.joints(), *configuration, speed, moving)
                              : arm::MotionPlan::failed({}, none + ": " + reason),
                what);
}

std::unique_ptr<RunningOperation> SmartMoveComponent::openGripper(const gripper::FingerStance& stance) {
  component::ParamMap params = declaredDefaults(gripper_, "Open");
  fingers_.openTo(stance, params);
  return std::make_unique<component::DelegatedOperation>(gripper_, "Open", params);
}

std::unique_ptr<RunningOperation> SmartMoveComponent::closeGripper(double force) {
  component::ParamMap params = declaredDefaults(gripper_, "Close");
  params["force"] = force;
  return std::make_unique<component::DelegatedOperation>(gripper_, "Close", params);
}

}  // namespace costar::smartmove
