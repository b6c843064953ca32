// SmartPush: when no grasp is feasible among crowded parts, the most crowded matching part is
// pushed `distance` along the direction that leaves it the most room (its centre farther from
// every other footprint, no gap shrinking below 5 mm), with the closed fingers: moved
// collision-free above its far side, down, across, up. The plan then looks again.

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

#include "smartmove/footprint.h"
#include "smartmove/script.h"
#include "smartmove/smartmove.h"

namespace costar::smartmove {

using component::RunningOperation;

std::unique_ptr<RunningOperation> SmartMoveComponent::beginPush(const component::ParamMap& params) {
  std::vector<predicator::Pattern> patterns;
  if (const auto problem = parsePredicates(params, patterns)) {
    return failed(*problem);
  }
  const std::string object_class = params.at("object_class").asString();
  const double distance = params.at("distance").asDouble();
  const double speed = params.at("speed").asDouble();
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
  const Eigen::Vector2d closed_half = fingers_.closedHalfExtent();
  const double half_x = closed_half.x();
  const double half_y = closed_half.y();
  const auto grasp = grasps_.defaultFor(object_class);
  // The most crowded part first.
  std::vector<std::pair<Room, std::pair<std::string, world::Pose>>> order;
  for (const auto& entry : matches.objects) {
    order.push_back({room(entry.first, entry.second), entry});
  }
  std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first.centre < b.first.centre; });
  // The candidate pushes are checked with the fingers closed, as they push.
  const gripper::FingerStance closed{.opening = 0.0};
  const arm::QueryScene clear = scene({}, closed);
  nlohmann::json tried = nlohmann::json::array();
  for (const auto& [room_now, entry] : order) {
    const std::string& object = entry.first;
    const world::Pose& pose = entry.second;
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
        const auto beside = motion_.firstFree(motion_.solutions(start, motion_.joints()), clear, reason);
        const auto top = beside ? motion_.firstFree(motion_.solutions(above, *beside), clear, reason) : std::nullopt;
        if (!beside || !top) {
          attempt["rejected"] =
              "no collision-free tool pose beside it: " + (reason.empty() ? "no IK solution" : reason);
          tried.push_back(attempt);
          continue;
        }
        const arm::MotionPlan descent = motion_.planLine(*top, start, config_.approach_speed, clear);
        if (!descent.ok()) {
          attempt["rejected"] = "no straight way down beside it: " + descent.failure;
          tried.push_back(attempt);
          continue;
        }
        const arm::MotionPlan push =
            motion_.planLine(descent.goal, end, config_.approach_speed, scene({object}, closed));
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
                           return std::make_unique<component::DelegatedOperation>(
                               gripper_, "Close", component::ParamMap{{"speed", 0.5}, {"force", 40.0}});
                         },
                         nullptr});
        steps.push_back({"move beside " + object,
                         [this, above, seed, speed] {
                           return moveToFreeConfiguration(above, seed, speed, "pre-push", "no collision-free pre-push");
                         },
                         nullptr});
        steps.push_back({"go down beside " + object,
                         [this, start] {
                           return follow(motion_.planLine(motion_.joints(), start, config_.approach_speed, scene()),
                                         "descent");
                         },
                         nullptr});
        steps.push_back(
            {"push " + object,
             [this, end, object] {
               return follow(motion_.planLine(motion_.joints(), end, config_.approach_speed, scene({object})), "push");
             },
             nullptr});
        steps.push_back({"lift clear",
                         [this, object] {
                           const arm::JointVector now = motion_.joints();
                           return follow(motion_.planLine(now, up(config_.retreat) * motion_.toolAt(now),
                                                          config_.approach_speed, scene({object})),
                                         "retreat");
                         },
                         nullptr});
        return std::make_unique<Script>(std::move(steps), data);
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
