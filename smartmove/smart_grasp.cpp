// SmartMove and SmartGrasp (the paper's Sec. IV-C): the chosen grasp's script. SmartMove moves
// the tool to the goal; SmartGrasp opens the gripper (turned to the grasp's mode, closed part
// way where the open fingers do not fit), comes down straight from a pre-grasp, closes, checks
// the part is held, optionally squares it up a quarter turn round, and lifts; a grasp that
// misses backs off straight up before it fails.

#include <numbers>

#include "smartmove/script.h"
#include "smartmove/smartmove.h"

namespace costar::smartmove {

using component::OperationResult;
using component::RunningOperation;

std::optional<SmartMoveComponent::Centring> SmartMoveComponent::planCentring(const Candidate& chosen,
                                                                             const world::Pose& object_pose,
                                                                             const world::ObjectClass& object_class,
                                                                             std::string& why) {
  const std::optional<double> stroke = fingers_.stroke();
  if (!stroke) {
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
  // It goes down round the part fully open.
  const arm::QueryScene around = scene({chosen.object}, {.opening = *stroke});
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
    std::string reason;
    const auto down = motion_.firstFree(motion_.solutions(turned, chosen.solutions.front()), around, reason);
    const auto above =
        down ? motion_.firstFree(motion_.solutions(up(rise) * turned, *down), around, reason) : std::nullopt;
    if (down && above) {
      return centring;
    }
    why = "turned a quarter the fingers would touch a neighbour: " + (reason.empty() ? "no IK solution" : reason);
  }
  return std::nullopt;
}

std::unique_ptr<RunningOperation> SmartMoveComponent::beginMoveOrGrasp(bool grasping,
                                                                       const component::ParamMap& params) {
  const auto text = [&params](const char* name) { return params.at(name).asString(); };
  std::vector<predicator::Pattern> patterns;
  if (const auto problem = parsePredicates(params, patterns)) {
    return failed(*problem);
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
                                     const arm::QueryScene moving = scene();
                                     std::string reason;
                                     const arm::JointVector now = motion_.joints();
                                     const auto goal =
                                         motion_.firstFree(motion_.solutions(chosen.goal, now), moving, reason);
                                     return follow(
                                         goal ? motion_.planToJoints(now, *goal, speed, moving)
                                              : arm::MotionPlan::failed({}, "collision at the goal: " + reason),
                                         "SmartMove");
                                   },
                                   nullptr}},
        data);
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
  steps.push_back({"open the gripper", [this, opening] { return openGripper({.opening = opening}); }, nullptr});
  if (!grasp->mode.empty()) {
    // The grasp was taught in this mode: the fingers are open now, the only time it can change.
    steps.push_back({"set the gripper to " + grasp->mode + " mode",
                     [this, mode = grasp->mode] {
                       return std::make_unique<component::DelegatedOperation>(gripper_, "SetMode",
                                                                              component::ParamMap{{"mode", mode}});
                     },
                     nullptr});
  }
  // How the fingers stand from here on: in the grasp's mode, closed part way where the chosen
  // grasp needs it (the cell's own reading follows once the gripper reports the mode).
  const gripper::FingerStance down{.mode = grasp->mode, .position = chosen.finger_position};
  // Released with the fingers only as far open as they need to clear the part (a fingertip
  // mode), so that the place is chosen, and left, with the fingers as they will be.
  const double release_position = fingers_.fingertipPosition(
      grasp->mode, partHalfWidth(chosen.goal, object_pose, *objectClass(object_class)) + 0.5 * config_.grasp_margin);
  if (down.position > 0.0) {
    steps.push_back({"close the fingers part way, to clear the neighbours",
                     [this, down] { return openGripper({.position = down.position}); }, nullptr});
  }
  steps.push_back({"move above " + object,
                   [this, pregrasp, chosen, speed, down] {
                     return moveToFreeConfiguration(pregrasp, chosen.solutions.front(), speed, "pre-grasp",
                                                    "no collision-free pre-grasp", down);
                   },
                   nullptr});
  const std::size_t approach_step = steps.size();
  steps.push_back({"approach " + object,
                   [this, chosen, object, down] {
                     return follow(
                         motion_.planLine(motion_.joints(), chosen.goal, config_.approach_speed, scene({object}, down)),
                         "approach");
                   },
                   nullptr});
  steps.push_back({"close on " + object, [this] { return closeGripper(40.0); },
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
                     return {};
                   }});
  if (centring) {
    // The fingers centred the part across them and turned it square with the pads; along the
    // pads it may sit anywhere they still touch it. Closing again a quarter turn round centres
    // it that way too: then it sits where the grasp was planned, wherever it was.
    const auto line = [this, object](std::function<world::Pose(const world::Pose&)> to, const char* what) {
      return [this, object, to = std::move(to), what] {
        const arm::JointVector now = motion_.joints();
        return follow(motion_.planLine(now, to(motion_.toolAt(now)), config_.approach_speed, scene({object})), what);
      };
    };
    const double rise = centring->rise;
    const world::Pose turn = centring->turn;
    const double stroke = *fingers_.stroke();
    // Let go only as far as the grasp opened (wider, a finger could push a neighbour), rise
    // clear, then open fully: the part may sit up to the pads' half-width plus its own off
    // their centre.
    steps.push_back({"let go of " + object + " to square it up",
                     [this, opening] { return openGripper({.opening = opening}); }, nullptr});
    steps.push_back(
        {"rise above " + object, line([rise](const world::Pose& tcp) { return up(rise) * tcp; }, "rise"), nullptr});
    steps.push_back(
        {"open fully above " + object, [this, stroke] { return openGripper({.opening = stroke}); }, nullptr});
    steps.push_back({"turn a quarter above " + object,
                     line([turn](const world::Pose& tcp) { return tcp * turn; }, "turn"), nullptr});
    steps.push_back({"go down round " + object,
                     line([rise](const world::Pose& tcp) { return up(-rise) * tcp; }, "approach"), nullptr});
    steps.push_back(
        {"close again on " + object, [this] { return closeGripper(40.0); },
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
           return {};
         }});
  }
  const std::size_t last_close = steps.size() - 1;
  steps.push_back({"lift " + object,
                   [this, object] {
                     const arm::JointVector now = motion_.joints();
                     return follow(motion_.planLine(now, up(config_.retreat) * motion_.toolAt(now),
                                                    config_.approach_speed, scene({object})),
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
  auto script = std::make_unique<Script>(std::move(steps), data);
  script->backOff(
      approach_step, last_close,
      {{"open the gripper", [this, opening] { return openGripper({.opening = opening}); }, nullptr, true},
       {"lift clear",
        [this, object] {
          // Straight up from wherever the miss left the fingers, even beside a neighbour (a
          // part moved or caught by the fingers): up is away from every part on the table.
          std::vector<std::string> obstacles = obstacles_;
          obstacles.push_back(partObstacle(object));
          arm::QueryScene clear = scene();
          clear.allowed = arm::AllowedContacts::between(config_.gripper_links, obstacles);
          const arm::JointVector now = motion_.joints();
          return follow(motion_.planLine(now, up(config_.retreat) * motion_.toolAt(now), config_.approach_speed, clear),
                        "back off");
        },
        nullptr}},
      "the tool backed off up");
  return script;
}

}  // namespace costar::smartmove
