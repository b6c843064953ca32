#include "smartmove/smartmove.h"

#include <numbers>

#include "smartmove/footprint.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>

namespace costar::smartmove {

using component::OperationResult;
using component::OperationState;
using component::ParamSpec;
using component::RunningOperation;
using component::ValueType;

namespace {

/// The gripper's declared defaults of `operation`'s parameters: its speeds are in its own units
/// (m/s for a 2-finger gripper, strokes/s for the adaptive one).
component::ParamMap gripperDefaults(const component::Component& gripper, const std::string& operation) {
  component::ParamMap params;
  if (const component::OperationSpec* spec = gripper.description().operation(operation)) {
    for (const ParamSpec& param : spec->params) {
      if (param.default_value) {
        params[param.name] = *param.default_value;
      }
    }
  }
  return params;
}

/// Close's parameters: the gripper's defaults with the grip force `force` (N).
component::ParamMap closeParams(const component::Component& gripper, double force) {
  component::ParamMap params = gripperDefaults(gripper, "Close");
  params["force"] = force;
  return params;
}

/// An operation of another component, started now, as a step.
class ComponentStep final : public RunningOperation {
 public:
  ComponentStep(component::Component& component, const std::string& operation, const component::ParamMap& params)
      : component_(component), id_(component.start(operation, params)) {}
  OperationResult poll() override { return component_.poll(id_); }
  void cancel() override { component_.cancel(id_); }

 private:
  component::Component& component_;
  component::OperationId id_;
};

/// A short script of steps, each an operation started when the previous one succeeded.
class Script final : public RunningOperation {
 public:
  struct Step {
    std::string what;
    std::function<std::unique_ptr<RunningOperation>()> start;
    /// Checks the step's result; empty when the script may go on.
    std::function<std::string(const OperationResult&)> check;
    /// A failure of this step is noted in the script's reason and the next step runs (a step
    /// of backing off that helps but is not needed, e.g. opening fingers that a part blocks).
    bool may_fail = false;
  };

  Script(std::vector<Step> steps, nlohmann::json data, std::function<void(bool)> on_end)
      : steps_(std::move(steps)), data_(std::move(data)), on_end_(std::move(on_end)) {}

  /// When a step from `from` to `to` fails, `backing_off` steps run before the failure is
  /// reported (e.g. the tool lifted clear of a part it missed), their outcome added to it.
  void backOff(std::size_t from, std::size_t to, std::vector<Step> backing_off, std::string done_note) {
    back_off_from_ = from;
    back_off_to_ = to;
    back_off_ = std::move(backing_off);
    back_off_note_ = std::move(done_note);
  }

  OperationResult poll() override {
    while (next_ < steps_.size() || current_) {
      if (!current_) {
        try {
          current_ = steps_[next_].start();
        } catch (const std::exception& e) {
          // A step that could not even start (a component that threw, a broken driver) is a
          // fault, not a miss: reported at once, without backing off (the arm stays at rest),
          // as when a poll throws.
          return fail(steps_[next_].what + ": " + e.what(), /*may_back_off=*/false);
        }
      }
      OperationResult result = current_->poll();
      if (result.state == OperationState::kRunning) {
        return OperationResult::running();
      }
      current_.reset();
      const Step& step = steps_[next_++];
      if (result.state == OperationState::kFailure && step.may_fail) {
        notes_ += "; " + step.what + " failed (" + result.reason + ")";
        continue;
      }
      if (result.state == OperationState::kFailure) {
        return fail(step.what + ": " + result.reason);
      }
      if (step.check) {
        if (const std::string problem = step.check(result); !problem.empty()) {
          return fail(step.what + ": " + problem);
        }
      }
    }
    return finish(OperationResult::success(data_));
  }

  void cancel() override {
    if (current_) {
      current_->cancel();
      current_.reset();
    }
    if (on_end_) {
      on_end_(false);
      on_end_ = nullptr;
    }
  }

 private:
  /// Steps that run once the script has failed (backing off), then the failure.
  OperationResult fail(std::string reason, bool may_back_off = true) {
    const std::size_t failed_step = next_ - 1;  // poll() has moved past it
    if (may_back_off && !failure_ && next_ > 0 && failed_step >= back_off_from_ && failed_step <= back_off_to_ &&
        !back_off_.empty()) {
      failure_ = std::move(reason);
      steps_ = std::move(back_off_);
      back_off_.clear();
      next_ = 0;
      return poll();
    }
    if (failure_) {  // backing off failed too: both reasons
      return finish(OperationResult::failure(*failure_ + "; backing off, " + reason, data_));
    }
    return finish(OperationResult::failure(std::move(reason), data_));
  }

  OperationResult finish(OperationResult result) {
    if (failure_ && result.state == OperationState::kSuccess) {
      result = OperationResult::failure(*failure_ + " (" + back_off_note_ + notes_ + ")", data_);
    }
    if (on_end_) {
      on_end_(result.state == OperationState::kSuccess);
      on_end_ = nullptr;
    }
    return result;
  }

  std::vector<Step> steps_;
  std::size_t next_ = 0;
  std::unique_ptr<RunningOperation> current_;
  nlohmann::json data_;
  std::function<void(bool)> on_end_;
  std::size_t back_off_from_ = 0;
  std::size_t back_off_to_ = 0;
  std::vector<Step> back_off_;
  std::string back_off_note_;
  std::optional<std::string> failure_;
  std::string notes_;  // failures of steps that may fail
};

std::unique_ptr<RunningOperation> failed(std::string reason, nlohmann::json data = {}) {
  return std::make_unique<component::FinishedOperation>(OperationResult::failure(std::move(reason), std::move(data)));
}

world::Pose up(double metres) { return world::Pose(Eigen::Translation3d(0, 0, metres)); }

}  // namespace

/// The fingers' shapes in the collision world put where a plan will have them (at the opening
/// of the grasp it checks), and back as they were once the plan is made.
class SmartMoveComponent::PlannedFingers {
 public:
  explicit PlannedFingers(SmartMoveComponent& self)
      : self_(self), modelled_(self_.config_.fingers || self_.config_.mode_fingers) {
    if (modelled_) {
      saved_ = self_.collisions_.linkShapes(self_.config_.finger_link);
    }
  }
  ~PlannedFingers() {
    if (modelled_) {
      self_.collisions_.setLinkShapes(self_.config_.finger_link, saved_);
    }
  }
  PlannedFingers(const PlannedFingers&) = delete;
  PlannedFingers& operator=(const PlannedFingers&) = delete;

  void at(double opening) const {
    if (self_.config_.fingers && opening != opening_) {
      self_.collisions_.setLinkShapes(self_.config_.finger_link, self_.fingerShapes(opening));
      opening_ = opening;
    }
  }

  /// The fingers of gripper mode `mode` at `position` (SmartGrasp turns the gripper to it first).
  void inMode(const std::string& mode, double position = 0.0) const { self_.fingersInMode(mode, position); }

 private:
  SmartMoveComponent& self_;
  bool modelled_;
  std::vector<planning::CollisionShape> saved_;
  mutable double opening_ = -1.0;
};

std::string partObstacle(const std::string& object) { return "part:" + object; }

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
      config_(std::move(config)) {
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
    const std::string& object_class = params.at("object_class").asString();
    const std::string& name = params.at("grasp").asString();
    if (name.empty() || grasps_.find(object_class, name)) {
      return {};
    }
    std::string taught;
    for (const auto& known : grasps_.forClass(object_class)) {
      taught += (taught.empty() ? "" : ", ") + known.name;
    }
    return "no grasp '" + name + "' is taught for class '" + object_class + "'" +
           (taught.empty() ? std::string(" (none is)") : " (taught: " + taught + ")");
  };
  const auto check_release = [](const component::ParamMap& params) -> std::string {
    const std::string& target_class = params.at("target_class").asString();
    const std::string& target = params.at("target").asString();
    if (target_class.empty() && target.empty()) {
      return "give target_class (put the part on such a part) or target (a frame, or 'table')";
    }
    if (!target_class.empty() && !target.empty()) {
      return "give target_class or target, not both (target '" + target + "' would be ignored)";
    }
    if (!target.empty() && target != "table" && !params.at("predicates").asString().empty()) {
      return "the conditions cannot apply: the part goes to frame '" + target +
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
                  {target_class, predicates, target, approach, speed},
                  component::OperationKind::kRobotAction,
                  check_release},
                 [this](const Params& params) { return beginRelease(params); });
  operations.add({"SmartPush",
                  "Pushes the most crowded part that satisfies the conditions where it gets more room, "
                  "with the closed gripper (when none can be grasped; look again after it).",
                  {object_class, predicates, push_distance, speed},
                  component::OperationKind::kRobotAction},
                 [this](const Params& params) { return beginPushOperation(params); });
  operations.add({"TeachGrasp",
                  "Saves how the gripper holds the nearest part of a class as a named grasp.",
                  {object_class, {"grasp", ValueType::kString, "name of the new grasp", {}}},
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
    if (std::any_of(put_->known.begin(), put_->known.end(), [&](const Eigen::Vector3d& known) {
          return (known - pose.translation()).norm() <= config_.misplaced_distance;
        })) {
      continue;
    }
    const double distance = (pose.translation() - put_->pose.translation()).norm();
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
  for (const auto& name : obstacles_) {
    if (std::find(present.begin(), present.end(), name) == present.end()) {
      collisions_.remove(name);
    }
  }
  obstacles_ = std::move(present);
}

arm::AllowedContacts SmartMoveComponent::touching(const std::vector<std::string>& objects) const {
  std::vector<std::string> obstacles;
  for (const std::string& object : objects) {
    obstacles.push_back(partObstacle(object));
  }
  return arm::AllowedContacts::between(config_.gripper_links, obstacles);
}

std::vector<planning::CollisionShape> SmartMoveComponent::fingerShapes(double opening) const {
  std::vector<planning::CollisionShape> shapes;
  for (const gripper::FingerBox& box : config_.fingers->at(opening)) {
    planning::CollisionShape shape;
    shape.kind = planning::CollisionShape::Kind::kBox;
    shape.size = box.size;
    shape.origin = world::Pose(Eigen::Translation3d(box.centre));
    shapes.push_back(shape);
  }
  return shapes;
}

void SmartMoveComponent::syncFingers(double opening) {
  // Every tick: new shapes only when the fingers moved (planning puts them back as they were).
  // An opening not known (a reading that is not a number) counts as the whole stroke.
  if (config_.fingers && !std::isfinite(opening)) {
    opening = config_.fingers->max_opening;
  }
  if (config_.fingers && std::abs(opening - synced_opening_) > 1e-4) {
    collisions_.setLinkShapes(config_.finger_link, fingerShapes(opening));
    synced_opening_ = opening;
  }
}

void SmartMoveComponent::fingersInMode(const std::string& mode, double position) {
  if (!config_.mode_fingers || mode.empty()) {
    return;
  }
  std::vector<planning::CollisionShape> shapes = config_.mode_fingers->shapes(mode, position);
  if (!shapes.empty()) {
    collisions_.setLinkShapes(config_.finger_link, std::move(shapes));
  }
}

double SmartMoveComponent::partHalfWidth(const world::Pose& tcp, const world::Pose& object,
                                         const world::ObjectClass& object_class) {
  // The part's bounding box in the tool's frame: its extent along y, either side of the TCP.
  const Eigen::AlignedBox3d bounds = object_class.bounds();
  const world::Pose part_in_tool = tcp.inverse() * object;
  double half = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p = part_in_tool * bounds.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner));
    half = std::max(half, std::abs(p.y()));
  }
  return half;
}

component::ParamMap SmartMoveComponent::openParams(double opening) const {
  component::ParamMap params = gripperDefaults(gripper_, "Open");  // fully, unless the fingers' geometry says how far
  if (config_.fingers && opening > 0.0) {
    params["opening"] = opening;
  }
  return params;
}

std::optional<double> SmartMoveComponent::graspOpening(const world::Pose& tcp, const world::Pose& object,
                                                       const world::ObjectClass& object_class) const {
  if (!config_.fingers) {
    return 0.0;
  }
  const double stroke = config_.fingers->max_opening;
  const double half = partHalfWidth(tcp, object, object_class);
  if (2.0 * half > stroke) {
    return std::nullopt;
  }
  return std::min(2.0 * half + config_.grasp_margin, stroke);
}

SmartMoveComponent::Matches SmartMoveComponent::matching(const std::string& object_class,
                                                         const std::vector<predicator::Pattern>& patterns,
                                                         const std::string& exclude) const {
  Matches matches;
  const std::vector<std::string> is_a{"?", object_class};
  for (const std::string& object : world_.match("is_a", is_a)) {
    const auto pose = world_.worldPose(object);
    if (object == exclude || !pose) {
      continue;
    }
    std::string failing;
    for (const auto& pattern : patterns) {
      std::vector<std::string> args = pattern.args;
      std::replace(args.begin(), args.end(), std::string("?"), object);
      if (!world_.holds(pattern.predicate, args)) {
        failing = world::predicateKey(pattern.predicate, args) + " is false";
        break;
      }
    }
    if (failing.empty()) {
      matches.objects.emplace_back(object, *pose);
    } else {
      matches.rejected.emplace_back(object, failing);
    }
  }
  return matches;
}

ArmModel SmartMoveComponent::armModel() const {
  const arm::JointVector now = motion_.joints();
  return {[this, now](const world::Pose& goal) { return motion_.solutions(goal, now); }, motion_.endpoint(), now};
}

namespace {

void addRejected(Selection& selection, const SmartMoveComponent::Matches& matches) {
  for (const auto& [object, reason] : matches.rejected) {
    Candidate candidate;
    candidate.object = object;
    candidate.symmetry = -1;
    candidate.rejected = "predicate false: " + reason;
    selection.candidates.push_back(std::move(candidate));
  }
  selection.summarizeFailure();
  if (!selection.ok() && selection.candidates.empty()) {
    selection.failure = "no part of the class is known (detect the parts first)";
  }
}

}  // namespace

Selection SmartMoveComponent::selectGrasp(const std::string& object_class,
                                          const std::vector<predicator::Pattern>& patterns, const world::Pose& grasp,
                                          double approach, double speed, const std::string& mode) {
  const bool with_approach = approach > 0.0;
  const world::ObjectClass* object = objectClass(object_class);
  if (object == nullptr) {
    Selection none;
    none.failure = "unknown object class '" + object_class + "'";
    return none;
  }
  syncObstacles();
  const Matches matches = matching(object_class, patterns);
  const arm::JointVector now = motion_.joints();
  const PlannedFingers fingers(*this);
  const bool in_mode = with_approach && !mode.empty() && config_.mode_fingers;
  if (in_mode) {
    fingers.inMode(mode);
  }
  const FeasibilityCheck check = [&](Candidate& candidate) -> std::string {
    const auto object_pose = world_.worldPose(candidate.object);
    const auto opening = graspOpening(candidate.goal, *object_pose, *object);
    if (!opening) {
      return "too wide for the fingers";
    }
    if (with_approach) {
      fingers.at(*opening);  // SmartGrasp opens them this far first; SmartMove leaves them
    }
    // The fingers may touch the part they are to grasp, in these queries only.
    const arm::AllowedContacts allowed = touching({candidate.object});
    std::string reason;
    const auto goal = motion_.firstFree(candidate.solutions, allowed, reason);
    if (!goal) {
      return "collision at the goal: " + reason;
    }
    if (!with_approach) {
      const arm::MotionPlan path = motion_.planToJoints(now, *goal, speed, allowed);
      return path.ok() ? std::string() : "no path: " + path.failure;
    }
    const world::Pose pregrasp = candidate.goal * world::Pose(Eigen::Translation3d(0, 0, -approach));
    const auto pre = motion_.firstFree(motion_.solutions(pregrasp, *goal), allowed, reason);
    if (!pre) {
      return "no reachable, collision-free pre-grasp: " + (reason.empty() ? "no IK solution" : reason);
    }
    const arm::MotionPlan line = motion_.planLine(*pre, candidate.goal, config_.approach_speed, allowed);
    if (!line.ok()) {
      return "no straight approach: " + line.failure;
    }
    const arm::MotionPlan retreat =
        motion_.planLine(line.goal, up(config_.retreat) * candidate.goal, config_.approach_speed, allowed);
    if (!retreat.ok()) {
      return "no straight retreat: " + retreat.failure;
    }
    const arm::MotionPlan path = motion_.planToJoints(now, *pre, speed, allowed);
    return path.ok() ? std::string() : "no path to the pre-grasp: " + path.failure;
  };
  // In a mode whose fingers can close part way: a candidate the open fingers do not fit is
  // checked again with them closed as far as the part allows (beside a neighbour that the
  // open fingers, leaning out, would reach).
  // The fingers closing from `from` onto the part, at the goal: they sweep the space between,
  // which must be free of neighbours (a part lying against it would be caught too).
  const auto closingClear = [&](const Candidate& candidate, double from) -> std::string {
    const world::Pose object_pose = *world_.worldPose(candidate.object);
    const double contact =
        config_.mode_fingers->position_for(mode, partHalfWidth(candidate.goal, object_pose, *object));
    const arm::AllowedContacts allowed = touching({candidate.object});
    std::string reason;
    const auto goal = motion_.firstFree(candidate.solutions, allowed, reason);
    std::string blocked;
    for (double position = from + 0.05; blocked.empty() && position < contact + 0.025; position += 0.05) {
      fingers.inMode(mode, std::min(position, contact));
      if (const auto touch = goal ? motion_.collision(*goal, allowed) : std::nullopt) {
        blocked = "the closing fingers would touch " + touch->str();
      }
    }
    fingers.inMode(mode);
    return blocked;
  };
  const FeasibilityCheck feasible = [&](Candidate& candidate) -> std::string {
    candidate.finger_position = 0.0;
    const std::string open = check(candidate);
    if (!in_mode || open.starts_with("too wide")) {
      return open;
    }
    if (open.empty()) {
      return closingClear(candidate, 0.0);
    }
    const world::Pose object_pose = *world_.worldPose(candidate.object);
    const double half = partHalfWidth(candidate.goal, object_pose, *object) + 0.5 * config_.grasp_margin;
    const double position = config_.mode_fingers->position_for(mode, half);
    if (position <= 0.0) {
      return open;
    }
    fingers.inMode(mode, position);
    const std::string part_way = check(candidate);
    fingers.inMode(mode);
    if (!part_way.empty()) {
      return open + "; with the fingers closed part way: " + part_way;
    }
    if (std::string blocked = closingClear(candidate, position); !blocked.empty()) {
      return blocked;
    }
    candidate.finger_position = position;
    return {};
  };
  Selection selection = selectGoal(matches.objects, *object, grasp, armModel(), config_.weights, feasible);
  if (!selection.ok() && with_approach) {
    if (const auto reach = fingerReachAcross(mode)) {
      selection = withShiftedGrasps(std::move(selection), *object, *reach, feasible);
    }
  }
  addRejected(selection, matches);
  return selection;
}

std::optional<double> SmartMoveComponent::fingerReachAcross(const std::string& mode) const {
  if (config_.fingers) {
    double pad = 0.0;
    for (const gripper::FingerBox& box : config_.fingers->closed) {
      pad = std::max(pad, std::abs(box.centre.x()) + 0.5 * box.size.x());
    }
    return pad;
  }
  if (config_.mode_fingers && config_.mode_fingers->reach_across && !mode.empty()) {
    if (const double reach = config_.mode_fingers->reach_across(mode); reach > 0.0) {
      return reach;
    }
  }
  return std::nullopt;
}

std::vector<double> SmartMoveComponent::graspShifts(const world::Pose& tcp, const world::Pose& object,
                                                    const world::ObjectClass& object_class, double reach) const {
  // The part's extent along the tool's x (across the fingers); the fingers reach `reach` either side.
  const Eigen::AlignedBox3d bounds = object_class.bounds();
  const world::Pose part_in_tool = tcp.inverse() * object;
  double low = 0.0;
  double high = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p = part_in_tool * bounds.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner));
    low = std::min(low, p.x());
    high = std::max(high, p.x());
  }
  const double keep = config_.grasp_shift_keep;
  std::vector<double> shifts;
  for (int k = 1; k * config_.grasp_shift_step <= config_.grasp_shift_max + 1e-9; ++k) {
    const double shift = k * config_.grasp_shift_step;
    for (const double d : {shift, -shift}) {
      const double limited = d > 0 ? std::min(d, high - reach - keep) : std::max(d, low + reach + keep);
      if (limited * d > 1e-6 &&
          std::none_of(shifts.begin(), shifts.end(), [&](double s) { return std::abs(s - limited) < 1e-6; })) {
        shifts.push_back(limited);
      }
    }
  }
  return shifts;
}

Selection SmartMoveComponent::withShiftedGrasps(Selection centred, const world::ObjectClass& object_class, double reach,
                                                const FeasibilityCheck& feasible) {
  // Grasps shifted across the fingers, nearest the centre first, of the centred candidates
  // that failed for something in the way (not reach, not width).
  std::map<double, std::vector<Candidate>> by_shift;
  for (const Candidate& candidate : centred.candidates) {
    if (candidate.symmetry < 0 || candidate.rejected.starts_with("no IK solution") ||
        candidate.rejected.starts_with("too wide")) {
      continue;
    }
    const auto pose = world_.worldPose(candidate.object);
    for (const double shift : graspShifts(candidate.goal, *pose, object_class, reach)) {
      Candidate shifted;
      shifted.object = candidate.object;
      shifted.symmetry = candidate.symmetry;
      shifted.goal = candidate.goal * Eigen::Translation3d(shift, 0, 0);
      by_shift[std::abs(shift)].push_back(std::move(shifted));
    }
  }
  Selection merged = std::move(centred);
  for (auto& [shift, candidates] : by_shift) {
    Selection selection = selectAmong(std::move(candidates), armModel(), config_.weights, feasible);
    const std::size_t offset = merged.candidates.size();
    for (Candidate& candidate : selection.candidates) {
      merged.candidates.push_back(std::move(candidate));
    }
    merged.seconds += selection.seconds;
    if (selection.chosen) {
      merged.chosen = offset + *selection.chosen;
      break;
    }
  }
  if (merged.chosen) {
    merged.failure.clear();
  } else {
    merged.summarizeFailure();
  }
  return merged;
}

std::string SmartMoveComponent::spotFailsPattern(const Eigen::Vector3d& spot,
                                                 const predicator::Pattern& pattern) const {
  const auto relation = predicator::relationFromName(pattern.predicate);
  const bool usable = relation && *relation != predicator::Relation::kOn && *relation != predicator::Relation::kAbove &&
                      *relation != predicator::Relation::kBelow;
  if (!usable || pattern.args.size() != 2 || pattern.args[0] != "?") {
    return "only left_of, right_of, in_front_of, behind, near(?, frame) can choose a spot on the table: " +
           pattern.predicate;
  }
  const auto reference = world_.worldPose(pattern.args[1]);
  if (!reference) {
    return "unknown frame '" + pattern.args[1] + "'";
  }
  const auto viewpoint = world_.worldPose("table_center");
  const Eigen::Matrix3d axes = viewpoint ? Eigen::Matrix3d(viewpoint->linear()) : Eigen::Matrix3d::Identity();
  const bool holds = predicator::relationHolds(*relation, {spot, {}}, {reference->translation(), {}}, axes, {});
  return holds ? std::string() : pattern.predicate + " is false there";
}

std::unique_ptr<RunningOperation> SmartMoveComponent::moveToFreeConfiguration(const world::Pose& pose,
                                                                              const arm::JointVector& seed,
                                                                              double speed, const std::string& what,
                                                                              const std::string& none) {
  std::string reason;
  const auto configuration = motion_.firstFree(motion_.solutions(pose, seed), {}, reason);
  return follow(configuration ? motion_.planToJoints(motion_.joints(), *configuration, speed)
                              : arm::MotionPlan::failed({}, none + ": " + reason),
                what);
}

std::optional<SmartMoveComponent::Centring> SmartMoveComponent::planCentring(const Candidate& chosen,
                                                                             const world::Pose& object_pose,
                                                                             const world::ObjectClass& object_class,
                                                                             std::string& why) {
  if (!config_.fingers) {
    why = "the fingers are not modelled";
    return std::nullopt;
  }
  // Only a grasp on the part's centre line: a shifted grasp would be undone by squaring up.
  const Eigen::Vector3d centre = chosen.goal.inverse() * object_pose * object_class.bounds().center();
  if (centre.head<2>().norm() > 0.001) {
    why = "the grasp is off the part's centre (no room there)";
    return std::nullopt;
  }
  // How far the pads rise to clear the part's top: the part's extent toward the gripper
  // above the tool centre, the pads' reach below it, a margin.
  double top = 0.0;
  const Eigen::AlignedBox3d box = object_class.bounds();
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d point = box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner));
    top = std::max(top, -(chosen.goal.inverse() * object_pose * point).z());
  }
  const double rise = top + config_.finger_reach + 0.01;
  syncObstacles();
  const PlannedFingers fingers(*this);
  const arm::AllowedContacts allowed = touching({chosen.object});
  for (const double degrees : {90.0, -90.0}) {
    Centring centring;
    centring.turn = world::Pose(Eigen::AngleAxisd(degrees * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()));
    centring.rise = rise;
    const world::Pose turned = chosen.goal * centring.turn;
    const auto opening = graspOpening(turned, object_pose, object_class);
    if (!opening) {
      why = "the part is too wide for the fingers turned a quarter";
      return std::nullopt;
    }
    centring.opening = *opening;
    fingers.at(config_.fingers->max_opening);  // it goes down round the part fully open
    std::string reason;
    const auto down = motion_.firstFree(motion_.solutions(turned, chosen.solutions.front()), allowed, reason);
    const auto above =
        down ? motion_.firstFree(motion_.solutions(up(rise) * turned, *down), allowed, reason) : std::nullopt;
    if (down && above) {
      return centring;
    }
    why = "turned a quarter the fingers would touch a neighbour: " + (reason.empty() ? "no IK solution" : reason);
  }
  return std::nullopt;
}

std::unique_ptr<RunningOperation> SmartMoveComponent::follow(const arm::MotionPlan& plan, const std::string& what) {
  if (!plan.ok()) {
    return failed(what + ": " + plan.failure);
  }
  return std::make_unique<ComponentStep>(arm_, std::string(arm::kFollowJointPath), arm::followParams(plan, what));
}

std::unique_ptr<RunningOperation> SmartMoveComponent::beginPushOperation(const component::ParamMap& params) {
  const auto text = [&params](const char* name) { return params.at(name).asString(); };
  std::vector<predicator::Pattern> patterns;
  try {
    patterns = parsePredicateList(text("predicates"));
  } catch (const std::invalid_argument& e) {
    return failed(std::string("predicates: ") + e.what());
  }
  const double speed = params.at("speed").asDouble();
  return beginPush(text("object_class"), patterns, params.at("distance").asDouble(), speed);
}

std::unique_ptr<RunningOperation> SmartMoveComponent::beginMoveOrGrasp(bool grasping,
                                                                       const component::ParamMap& params) {
  const auto text = [&params](const char* name) { return params.at(name).asString(); };
  std::vector<predicator::Pattern> patterns;
  try {
    patterns = parsePredicateList(text("predicates"));
  } catch (const std::invalid_argument& e) {
    return failed(std::string("predicates: ") + e.what());
  }
  const double speed = params.at("speed").asDouble();
  const std::string object_class = text("object_class");
  const auto grasp =
      text("grasp").empty() ? grasps_.defaultFor(object_class) : grasps_.find(object_class, text("grasp"));
  if (!grasp && text("grasp").empty()) {
    return failed("no grasp is taught for class '" + object_class + "'");
  }
  if (!grasp) {
    return failed("no grasp '" + text("grasp") + "' is taught for class '" + object_class + "'");
  }
  if (grasping && held_ && world_.holds("gripper_holding", {})) {
    return failed("the gripper already holds " + *held_ + ": release it first");
  }
  const double approach = grasping ? params.at("approach").asDouble() : 0.0;
  Selection selection =
      selectGrasp(object_class, patterns, grasp->tcp_in_object, approach, speed, grasping ? grasp->mode : "");
  nlohmann::json data = selection.toJson();
  if (!selection.ok()) {
    return failed("no feasible " + object_class + ": " + selection.failure, data);
  }
  const Candidate chosen = selection.best();
  const world::Pose object_pose = *world_.worldPose(chosen.object);
  const double opening = graspOpening(chosen.goal, object_pose, *objectClass(object_class)).value_or(0.0);
  if (!grasping) {
    return std::make_unique<Script>(
        std::vector<Script::Step>{{"move to " + chosen.object,
                                   [this, chosen, speed] {
                                     std::string reason;
                                     const arm::JointVector now = motion_.joints();
                                     const auto goal =
                                         motion_.firstFree(motion_.solutions(chosen.goal, now), {}, reason);
                                     return follow(
                                         goal ? motion_.planToJoints(now, *goal, speed)
                                              : arm::MotionPlan::failed({}, "collision at the goal: " + reason),
                                         "SmartMove");
                                   },
                                   nullptr}},
        data, nullptr);
  }
  const world::Pose pregrasp = chosen.goal * world::Pose(Eigen::Translation3d(0, 0, -approach));
  const std::string object = chosen.object;
  std::optional<Centring> centring;
  if (params.at("centre").asBool()) {
    std::string why;
    centring = planCentring(chosen, object_pose, *objectClass(object_class), why);
    data["centring"] = centring ? "squared up a quarter turn" : "skipped: " + why;
  }
  std::vector<Script::Step> steps;
  steps.push_back({"open the gripper",
                   [this, opening] { return std::make_unique<ComponentStep>(gripper_, "Open", openParams(opening)); },
                   nullptr});
  if (!grasp->mode.empty()) {
    // The grasp was taught in this mode: the fingers are open now, the only time it can change.
    steps.push_back({"set the gripper to " + grasp->mode + " mode",
                     [this, mode = grasp->mode] {
                       component::ParamMap params;
                       params["mode"] = mode;
                       return std::make_unique<ComponentStep>(gripper_, "SetMode", params);
                     },
                     nullptr});
  }
  const double finger_position = chosen.finger_position;
  // Released with the fingers only as far open as they need to clear the part (a fingertip
  // mode), so that the place is chosen, and left, with the fingers as they will be.
  const double release_position =
      grasp->mode.empty() || !config_.mode_fingers
          ? 0.0
          : config_.mode_fingers->position_for(
                grasp->mode,
                partHalfWidth(chosen.goal, object_pose, *objectClass(object_class)) + 0.5 * config_.grasp_margin);
  if (finger_position > 0.0) {
    steps.push_back({"close the fingers part way, to clear the neighbours",
                     [this, finger_position] {
                       component::ParamMap params = gripperDefaults(gripper_, "Open");
                       params["position"] = finger_position;
                       return std::make_unique<ComponentStep>(gripper_, "Open", params);
                     },
                     nullptr});
  }
  // The fingers are planned in the grasp's mode from here on (the cell's own sync follows once
  // the gripper reports the mode).
  steps.push_back({"move above " + object,
                   [this, pregrasp, chosen, speed, mode = grasp->mode, finger_position] {
                     fingersInMode(mode, finger_position);
                     return moveToFreeConfiguration(pregrasp, chosen.solutions.front(), speed, "pre-grasp",
                                                    "no collision-free pre-grasp");
                   },
                   nullptr});
  const std::size_t approach_step = steps.size();
  steps.push_back({"approach " + object,
                   [this, chosen, object, mode = grasp->mode, finger_position] {
                     fingersInMode(mode, finger_position);
                     return follow(
                         motion_.planLine(motion_.joints(), chosen.goal, config_.approach_speed, touching({object})),
                         "approach");
                   },
                   nullptr});
  steps.push_back({"close on " + object,
                   [this] { return std::make_unique<ComponentStep>(gripper_, "Close", closeParams(gripper_, 40.0)); },
                   [this, object, object_class, object_pose, chosen, opening, centring, mode = grasp->mode,
                    release_position](const OperationResult& result) -> std::string {
                     if (!result.data.value("holding", false)) {
                       return "the fingers closed on nothing: " + object + " was not where it was seen";
                     }
                     if (centring) {
                       return {};  // held once squared up
                     }
                     held_ = object;
                     put_.reset();
                     held_class_ = object_class;
                     held_grasp_ = object_pose.inverse() * chosen.goal;
                     held_opening_ = opening;
                     held_mode_ = mode;
                     held_finger_position_ = release_position;
                     collisions_.remove(partObstacle(object));
                     return {};
                   }});
  if (centring) {
    // The fingers centred the part across them and turned it square with the pads; along the
    // pads it may sit anywhere they still touch it. Closing again a quarter turn round centres
    // it that way too: then it sits where the grasp was planned, wherever it was.
    const auto line = [this, object](std::function<world::Pose(const world::Pose&)> to, const char* what) {
      return [this, object, to = std::move(to), what] {
        const arm::JointVector now = motion_.joints();
        return follow(motion_.planLine(now, to(motion_.toolAt(now)), config_.approach_speed, touching({object})), what);
      };
    };
    const double rise = centring->rise;
    const world::Pose turn = centring->turn;
    // Let go only as far as the grasp opened (wider, a finger could push a neighbour), rise
    // clear, then open fully: the part may sit up to the pads' half-width plus its own off
    // their centre.
    steps.push_back({"let go of " + object + " to square it up",
                     [this, opening] { return std::make_unique<ComponentStep>(gripper_, "Open", openParams(opening)); },
                     nullptr});
    steps.push_back(
        {"rise above " + object, line([rise](const world::Pose& tcp) { return up(rise) * tcp; }, "rise"), nullptr});
    steps.push_back(
        {"open fully above " + object,
         [this] { return std::make_unique<ComponentStep>(gripper_, "Open", openParams(config_.fingers->max_opening)); },
         nullptr});
    steps.push_back({"turn a quarter above " + object,
                     line([turn](const world::Pose& tcp) { return tcp * turn; }, "turn"), nullptr});
    steps.push_back({"go down round " + object,
                     line([rise](const world::Pose& tcp) { return up(-rise) * tcp; }, "approach"), nullptr});
    steps.push_back(
        {"close again on " + object,
         [this] { return std::make_unique<ComponentStep>(gripper_, "Close", closeParams(gripper_, 40.0)); },
         [this, object, object_class, object_pose, chosen, centring](const OperationResult& result) -> std::string {
           if (!result.data.value("holding", false)) {
             return "the fingers closed on nothing: " + object + " was lost while squaring it up";
           }
           held_ = object;
           put_.reset();
           held_class_ = object_class;
           // Centred both ways and square with the pads: as planned, turned.
           held_grasp_ = object_pose.inverse() * chosen.goal * centring->turn;
           held_opening_ = centring->opening;
           held_mode_.clear();
           held_finger_position_ = 0.0;
           collisions_.remove(partObstacle(object));
           return {};
         }});
  }
  const std::size_t last_close = steps.size() - 1;
  steps.push_back({"lift " + object,
                   [this, object] {
                     const arm::JointVector now = motion_.joints();
                     return follow(motion_.planLine(now, up(config_.retreat) * motion_.toolAt(now),
                                                    config_.approach_speed, touching({object})),
                                   "retreat");
                   },
                   [this](const OperationResult&) -> std::string {
                     return world_.holds("gripper_holding", {}) || !held_ ? std::string() : "the part slipped out";
                   }});
  // A grasp that fails once the tool went down (it closed on nothing, or on the part's top
  // because the part moved) opens and lifts straight up before it reports the failure, so
  // that the tool is clear of where the part was seen and a plan that looks again can go on
  // (from down there every motion would start in collision with the part as it was seen).
  // Opening may fail (a finger that landed on the moved part, pressed against it); lifting
  // straight up is what gets the tool clear, so it runs all the same.
  auto script = std::make_unique<Script>(std::move(steps), data, nullptr);
  script->backOff(
      approach_step, last_close,
      {{"open the gripper",
        [this, opening] { return std::make_unique<ComponentStep>(gripper_, "Open", openParams(opening)); }, nullptr,
        true},
       {"lift clear",
        [this, object] {
          // Straight up from wherever the miss left the fingers, even beside a neighbour (a
          // part moved or caught by the fingers): up is away from every part on the table.
          std::vector<std::string> obstacles = obstacles_;
          obstacles.push_back(partObstacle(object));
          const arm::AllowedContacts allowed = arm::AllowedContacts::between(config_.gripper_links, obstacles);
          const arm::JointVector now = motion_.joints();
          return follow(
              motion_.planLine(now, up(config_.retreat) * motion_.toolAt(now), config_.approach_speed, allowed),
              "back off");
        },
        nullptr}},
      "the tool backed off up");
  return script;
}

std::unique_ptr<RunningOperation> SmartMoveComponent::beginRelease(const component::ParamMap& params) {
  const auto text = [&params](const char* name) { return params.at(name).asString(); };
  std::vector<predicator::Pattern> patterns;
  try {
    patterns = parsePredicateList(text("predicates"));
  } catch (const std::invalid_argument& e) {
    return failed(std::string("predicates: ") + e.what());
  }
  const double speed = params.at("speed").asDouble();
  if (!held_) {
    return failed("nothing to release: no part was grasped with SmartGrasp");
  }
  const world::ObjectClass* held_object = objectClass(held_class_);
  const std::string target_class = text("target_class");
  const std::string target = text("target");
  if (target_class.empty() == target.empty()) {
    return failed("give either target_class (put the part on such a part) or target (put it at a frame)");
  }
  syncObstacles();
  // Candidate poses of the held part: on top of each matching part, every symmetric way.
  std::vector<Candidate> candidates;
  Matches matches;
  const auto addPlacements = [&](const std::string& name, const world::Pose& support, double lift) {
    for (std::size_t h = 0; h < held_object->symmetries.size(); ++h) {
      world::Pose held_symmetry = world::Pose::Identity();
      held_symmetry.linear() = held_object->symmetries[h];
      Candidate candidate;
      candidate.object = name;
      candidate.symmetry = static_cast<int>(h);
      candidate.goal = support * up(lift) * held_symmetry * held_grasp_;
      candidates.push_back(std::move(candidate));
    }
  };
  if (target == "table") {
    // Free spots on the table that satisfy the predicates, clear of every known part.
    const std::vector<std::pair<std::string, world::Pose>> others = [&] {
      std::vector<std::pair<std::string, world::Pose>> parts;
      for (const auto& object : classes_) {
        for (const auto& entry : matching(object.name, {}, *held_).objects) {
          parts.push_back(entry);
        }
      }
      return parts;
    }();
    for (const auto& pattern : patterns) {
      const std::string problem = spotFailsPattern(Eigen::Vector3d::Zero(), pattern);
      if (problem.rfind("only ", 0) == 0 || problem.rfind("unknown frame", 0) == 0) {
        return failed(problem);
      }
    }
    const double held_radius = 0.5 * held_object->bounds().sizes().head<2>().norm();
    const double step = config_.table_spot_step;
    for (double x = config_.table_min.x(); x <= config_.table_max.x() + 1e-9; x += step) {
      for (double y = config_.table_min.y(); y <= config_.table_max.y() + 1e-9; y += step) {
        const Eigen::Vector3d spot(x, y, 0.0);
        const bool clear =
            std::all_of(others.begin(), others.end(), [&](const std::pair<std::string, world::Pose>& other) {
              const world::ObjectClass* c = nullptr;
              for (const auto& object : classes_) {
                if (world_.holds("is_a", std::vector<std::string>{other.first, object.name})) {
                  c = &object;
                }
              }
              const double radius = c != nullptr ? 0.5 * c->bounds().sizes().head<2>().norm() : 0.05;
              return (other.second.translation().head<2>() - spot.head<2>()).norm() > held_radius + radius + 0.02;
            });
        std::string failing;
        const double m = config_.table_spot_margin;
        for (const auto& pattern : patterns) {
          for (const Eigen::Vector3d& shift :
               {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(m, 0, 0), Eigen::Vector3d(-m, 0, 0), Eigen::Vector3d(0, m, 0),
                Eigen::Vector3d(0, -m, 0)}) {
            failing = spotFailsPattern(spot + shift, pattern);
            if (!failing.empty()) {
              break;
            }
          }
          if (!failing.empty()) {
            break;
          }
        }
        if (!clear || !failing.empty()) {
          continue;
        }
        char name[48];
        std::snprintf(name, sizeof name, "table(%.2f,%.2f)", x, y);
        world::Pose frame = world::Pose::Identity();
        frame.translation() = spot;
        addPlacements(name, frame, held_object->rest_height + config_.place_clearance);
      }
    }
    // Keep the held part's placements that rest it as it rests canonically (its z up).
    std::erase_if(candidates, [this](const Candidate& candidate) {
      const world::Pose part = candidate.goal * held_grasp_.inverse();
      return part.linear().col(2).z() < 0.98;
    });
    if (candidates.empty()) {
      return failed("no free spot on the table satisfies " + text("predicates"));
    }
  } else if (!target.empty()) {
    const auto frame = world_.worldPose(target);
    if (!frame) {
      return failed("unknown frame '" + target + "'");
    }
    addPlacements(target, *frame, held_object->rest_height + config_.place_clearance);
  } else {
    const world::ObjectClass* support = objectClass(target_class);
    matches = matching(target_class, patterns, *held_);
    for (const auto& [name, pose] : matches.objects) {
      for (const Eigen::Matrix3d& symmetry : support->symmetries) {
        world::Pose frame = pose;
        frame.linear() = pose.linear() * symmetry;
        if (frame.linear().col(2).z() < 0.98) {
          continue;  // only the part's top side faces up
        }
        addPlacements(name, frame,
                      support->bounds().max().z() - held_object->bounds().min().z() + config_.place_clearance);
      }
    }
  }
  // Checked with the fingers at the opening they release to: wider than they hold.
  const PlannedFingers fingers(*this);
  fingers.at(held_opening_ > 0.0 ? held_opening_ : config_.fingers ? config_.fingers->max_opening : 0.0);
  fingers.inMode(held_mode_, held_finger_position_);
  const FeasibilityCheck feasible = [&](Candidate& candidate) -> std::string {
    // The part held may touch its support, in these queries only.
    const arm::AllowedContacts allowed = touching({candidate.object});
    std::string reason;
    const auto goal = motion_.firstFree(candidate.solutions, allowed, reason);
    if (!goal) {
      return "collision at the goal: " + reason;
    }
    const world::Pose above = up(params.at("approach").asDouble()) * candidate.goal;
    const auto pre = motion_.firstFree(motion_.solutions(above, *goal), allowed, reason);
    if (!pre) {
      return "no reachable, collision-free point above: " + (reason.empty() ? "no IK solution" : reason);
    }
    const arm::MotionPlan line = motion_.planLine(*pre, candidate.goal, config_.approach_speed, allowed);
    if (!line.ok()) {
      return "no straight way down: " + line.failure;
    }
    const arm::MotionPlan path = motion_.planToJoints(motion_.joints(), *pre, speed, allowed);
    return path.ok() ? std::string() : "no path: " + path.failure;
  };
  Selection selection = selectAmong(std::move(candidates), armModel(), config_.weights, feasible);
  addRejected(selection, matches);
  nlohmann::json data = selection.toJson();
  if (!selection.ok()) {
    return failed("no feasible place for " + *held_ + ": " + selection.failure, data);
  }
  const Candidate chosen = selection.best();
  const double approach = params.at("approach").asDouble();
  const std::string released = *held_;
  const std::string support_object = chosen.object;
  std::vector<Script::Step> steps;
  steps.push_back({"move above " + support_object,
                   [this, chosen, approach, speed] {
                     return moveToFreeConfiguration(up(approach) * chosen.goal, chosen.solutions.front(), speed,
                                                    "above the place", "no collision-free point above");
                   },
                   nullptr});
  steps.push_back({"lower onto " + support_object,
                   [this, chosen, support_object] {
                     return follow(motion_.planLine(motion_.joints(), chosen.goal, config_.approach_speed,
                                                    touching({support_object})),
                                   "lower");
                   },
                   nullptr});
  steps.push_back({"release " + released,
                   [this, opening = held_opening_, position = held_finger_position_] {
                     if (position > 0.0) {  // a fingertip mode: as far as the part needs
                       component::ParamMap params = gripperDefaults(gripper_, "Open");
                       params["position"] = position;
                       return std::make_unique<ComponentStep>(gripper_, "Open", params);
                     }
                     return std::make_unique<ComponentStep>(gripper_, "Open", openParams(opening));
                   },
                   [this, part = chosen.goal * held_grasp_.inverse()](const OperationResult&) -> std::string {
                     put_ = PutDown{held_class_, part, {}};
                     for (const auto& [object, pose] : matching(held_class_, {}).objects) {
                       put_->known.push_back(pose.translation());
                     }
                     held_.reset();
                     return {};
                   }});
  steps.push_back({"lift away",
                   [this, approach, support_object, mode = held_mode_, position = held_finger_position_] {
                     fingersInMode(mode, position);
                     const arm::JointVector now = motion_.joints();
                     return follow(motion_.planLine(now, up(approach) * motion_.toolAt(now), config_.approach_speed,
                                                    touching({support_object})),
                                   "retreat");
                   },
                   nullptr});
  return std::make_unique<Script>(std::move(steps), data, nullptr);
}

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
  if (grasps_.gripper() != kParallelGripper) {  // a gripper with modes: the grasp needs the one it was taught in
    for (const char* mode : {"basic", "pinch", "wide", "scissor"}) {
      const std::string args[] = {mode};
      if (world_.holds("gripper_mode", args)) {
        taught.mode = mode;
      }
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

std::unique_ptr<RunningOperation> SmartMoveComponent::beginPush(const std::string& object_class,
                                                                const std::vector<predicator::Pattern>& patterns,
                                                                double distance, double speed) {
  constexpr int kDirections = 16;
  constexpr double kStartGap = 0.012;  // m between the fingers and the part before the push
  constexpr double kKeepGap = 0.005;   // m: a push leaves the part at least this far from others
  if (held_ && world_.holds("gripper_holding", {})) {
    return failed("the gripper holds " + *held_ + ": release it first");
  }
  const world::ObjectClass* pushed_class = objectClass(object_class);
  if (pushed_class == nullptr) {
    return failed("unknown object class '" + object_class + "'");
  }
  syncObstacles();
  const Matches matches = matching(object_class, patterns);
  if (matches.objects.empty()) {
    return failed(matches.rejected.empty()
                      ? "no part of the class is known (detect the parts first)"
                      : "no " + object_class + " satisfies the conditions (" + matches.rejected.front().first + ": " +
                            matches.rejected.front().second + ")");
  }
  // Every known part, to measure the room around the pushed one.
  struct Known {
    std::string name;
    const world::ObjectClass* object_class;
    world::Pose pose;
  };
  std::vector<Known> known;
  for (const world::Predicate* is_a : world_.predicates("is_a")) {
    const world::ObjectClass* c = is_a->args.size() == 2 ? objectClass(is_a->args[1]) : nullptr;
    const auto pose = c != nullptr ? world_.worldPose(is_a->args[0]) : std::nullopt;
    if (pose) {
      known.push_back({is_a->args[0], c, *pose});
    }
  }
  // The room a part has: the gap between its footprint and the nearest other part's (it must
  // not shrink below kKeepGap), and the distance from its centre to the nearest other
  // footprint (which a push should increase: a link slid along a parallel neighbour until its
  // middle is past the neighbour's end can be taken by the middle).
  struct Room {
    double gap = 1.0;
    double centre = 1.0;
  };
  const auto room = [&](const std::string& name, const world::Pose& pose) {
    Room r;
    for (const Known& other : known) {
      if (other.name != name) {
        r.gap = std::min(r.gap, footprintGap(*pushed_class, pose, *other.object_class, other.pose));
        r.centre =
            std::min(r.centre, distanceToFootprint(pose.translation().head<2>(), *other.object_class, other.pose));
      }
    }
    return r;
  };
  // The closed fingers lead the push with their narrower side across it: the tool's x or y
  // along the push, whichever leaves the fingers less wide across; their half length along it.
  double half_x = 0.015;
  double half_y = 0.015;
  if (config_.fingers) {
    half_x = half_y = 0.0;
    for (const gripper::FingerBox& box : config_.fingers->at(0.0)) {
      half_x = std::max(half_x, std::abs(box.centre.x()) + 0.5 * box.size.x());
      half_y = std::max(half_y, std::abs(box.centre.y()) + 0.5 * box.size.y());
    }
  }
  const auto grasp = grasps_.defaultFor(object_class);
  // The most crowded part first.
  std::vector<std::pair<Room, std::pair<std::string, world::Pose>>> order;
  for (const auto& entry : matches.objects) {
    order.push_back({room(entry.first, entry.second), entry});
  }
  std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first.centre < b.first.centre; });
  const PlannedFingers fingers(*this);
  fingers.at(0.0);
  nlohmann::json tried = nlohmann::json::array();
  for (const auto& [room_now, entry] : order) {
    const auto& [object, pose] = entry;
    std::vector<std::pair<Room, double>> directions;  // room after the push, angle
    for (int k = 0; k < kDirections; ++k) {
      const double angle = 2.0 * std::numbers::pi * k / kDirections;
      world::Pose moved = pose;
      moved.translation() += distance * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0);
      const Room after = room(object, moved);
      if (after.gap >= std::min(room_now.gap, kKeepGap) && after.centre > room_now.centre + 0.002) {
        directions.emplace_back(after, angle);
      }
    }
    std::sort(directions.begin(), directions.end(),
              [](const auto& a, const auto& b) { return a.first.centre > b.first.centre; });
    for (const auto& [room_after, angle] : directions) {
      const Eigen::Vector3d direction(std::cos(angle), std::sin(angle), 0.0);
      const Eigen::AlignedBox3d bounds = pushed_class->bounds();
      double half = 0.0;
      for (int i = 0; i < 8; ++i) {
        const Eigen::Vector3d corner = pose * bounds.corner(static_cast<Eigen::AlignedBox3d::CornerType>(i));
        half = std::max(half, direction.dot(corner - pose.translation()));
      }
      // The tool pointing down, its x or y along the push (the narrower way across first), at
      // the height it grasps the part.
      for (const bool x_leads : {half_y <= half_x, half_y > half_x}) {
        const double finger_half = x_leads ? half_x : half_y;
        world::Pose start = world::Pose::Identity();
        const Eigen::Vector3d down = -Eigen::Vector3d::UnitZ();
        start.linear().col(2) = down;
        if (x_leads) {
          start.linear().col(0) = direction;
          start.linear().col(1) = down.cross(direction);
        } else {
          start.linear().col(1) = direction;
          start.linear().col(0) = direction.cross(down);
        }
        const double height = grasp ? (pose * grasp->tcp_in_object).translation().z() : pose.translation().z();
        start.translation() = pose.translation() - (half + finger_half + kStartGap) * direction;
        start.translation().z() = height;
        world::Pose end = start;
        end.translation() += (distance + kStartGap) * direction;
        const world::Pose above = up(config_.approach) * start;
        nlohmann::json attempt = {{"object", object},
                                  {"direction_deg", angle * 180.0 / std::numbers::pi},
                                  {"leading_tool_axis", x_leads ? "x" : "y"},
                                  {"centre_room_before", room_now.centre},
                                  {"centre_room_after", room_after.centre}};
        std::string reason;
        const auto beside = motion_.firstFree(motion_.solutions(start, motion_.joints()), {}, reason);
        const auto top = beside ? motion_.firstFree(motion_.solutions(above, *beside), {}, reason) : std::nullopt;
        if (!beside || !top) {
          attempt["rejected"] =
              "no collision-free tool pose beside it: " + (reason.empty() ? "no IK solution" : reason);
          tried.push_back(attempt);
          continue;
        }
        const arm::MotionPlan descent = motion_.planLine(*top, start, config_.approach_speed);
        if (!descent.ok()) {
          attempt["rejected"] = "no straight way down beside it: " + descent.failure;
          tried.push_back(attempt);
          continue;
        }
        const arm::MotionPlan push = motion_.planLine(descent.goal, end, config_.approach_speed, touching({object}));
        if (!push.ok()) {
          attempt["rejected"] = "the push is blocked: " + push.failure;
          tried.push_back(attempt);
          continue;
        }
        nlohmann::json data = {{"object", object},
                               {"direction_deg", angle * 180.0 / std::numbers::pi},
                               {"distance", distance},
                               {"centre_room_before", room_now.centre},
                               {"centre_room_after", room_after.centre},
                               {"tried", tried}};
        const arm::JointVector seed = *top;
        std::vector<Script::Step> steps;
        steps.push_back({"close the gripper",
                         [this] {
                           return std::make_unique<ComponentStep>(gripper_, "Close",
                                                                  component::ParamMap{{"speed", 0.5}, {"force", 40.0}});
                         },
                         nullptr});
        steps.push_back({"move beside " + object,
                         [this, above, seed, speed] {
                           return moveToFreeConfiguration(above, seed, speed, "pre-push", "no collision-free pre-push");
                         },
                         nullptr});
        steps.push_back({"go down beside " + object,
                         [this, start] {
                           return follow(motion_.planLine(motion_.joints(), start, config_.approach_speed), "descent");
                         },
                         nullptr});
        steps.push_back({"push " + object,
                         [this, end, object] {
                           return follow(
                               motion_.planLine(motion_.joints(), end, config_.approach_speed, touching({object})),
                               "push");
                         },
                         nullptr});
        steps.push_back({"lift clear",
                         [this, object] {
                           const arm::JointVector now = motion_.joints();
                           return follow(motion_.planLine(now, up(config_.retreat) * motion_.toolAt(now),
                                                          config_.approach_speed, touching({object})),
                                         "retreat");
                         },
                         nullptr});
        return std::make_unique<Script>(std::move(steps), data, nullptr);
      }
    }
  }
  std::map<std::string, int> reasons;  // why the pushes were not made, by kind
  for (const auto& attempt : tried) {
    const std::string reason = attempt.value("rejected", "");
    ++reasons[reason.substr(0, reason.find(':'))];
  }
  std::string why;
  for (const auto& [reason, count] : reasons) {
    why += (why.empty() ? "" : ", ") + std::to_string(count) + " " + reason;
  }
  return failed("no " + object_class + " can be pushed where it gets more room (" + std::to_string(tried.size()) +
                    " pushes that would give it more room, none possible" + (why.empty() ? "" : ": " + why) + ")",
                {{"tried", tried}});
}

}  // namespace costar::smartmove
