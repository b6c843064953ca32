#include "server/cell_state.h"

#include <algorithm>
#include <set>

#include "arm/motion_service.h"
#include "server/engine_parts.h"
#include "workcell/workcell.h"

namespace costar::server {

WaypointFinder::WaypointFinder(workcell::Workcell& cell) {
  for (const auto& component : cell.components().components()) {
    const auto& description = component->description();
    if (std::find(description.implements.begin(), description.implements.end(), "Arm") !=
        description.implements.end()) {
      arm_sources_.insert(description.name);
    }
    for (const auto& symbol : description.symbols) {
      declared_.insert(symbol.name);
    }
  }
}

bool WaypointFinder::isWaypoint(const world::Symbol& symbol) const {
  return arm_sources_.contains(symbol.source) && !declared_.contains(symbol.name);
}

json cellState(workcell::Workcell& cell, std::int64_t active, bool paused) {
  const world::WorldState& world = cell.components().world();
  json state = {{"type", "state"}, {"t", rounded(toSeconds(cell.clock().now()), 1e4)}};
  state["run"] = active;
  state["mode"] = active == 0 ? "idle" : (paused ? "paused" : "running");

  const WaypointFinder waypoints_of_arms(cell);

  json arm_json = json::object();
  if (const auto endpoint = world.worldPose("endpoint")) {
    arm_json["endpoint"] = poseJson(*endpoint);
  }
  // A joint waypoint is drawn where the cell's motion service puts the tool at its joints.
  const arm::MotionService* motion = cell.motion();
  std::size_t arm_joint_count = 0;
  if (const world::Symbol* joints = world.symbol("arm_joints"); joints != nullptr && joints->joints() != nullptr) {
    arm_joint_count = joints->joints()->positions.size();
    json positions = json::array();
    for (const double q : joints->joints()->positions) {
      positions.push_back(rounded(q));
    }
    arm_json["joints"] = std::move(positions);
  }
  arm_json["moving"] = world.holds("arm_moving", kNoArgs);
  // The wrist sensor's wrench (what the tool pushes with, in the tool frame): the page shows
  // the force while a plan presses.
  if (const world::Symbol* symbol = world.symbol("wrench"); symbol != nullptr && symbol->wrench() != nullptr) {
    const world::WrenchValue& wrench = *symbol->wrench();
    const auto triple = [](const Eigen::Vector3d& v) {
      return json::array({rounded(v.x(), 1e3), rounded(v.y(), 1e3), rounded(v.z(), 1e3)});
    };
    arm_json["wrench"] = {{"frame", wrench.frame}, {"force", triple(wrench.force)}, {"torque", triple(wrench.torque)}};
    arm_json["in_contact"] = world.holds("in_contact", kNoArgs);
  }
  state["arm"] = std::move(arm_json);

  // The power tool (its component's symbol and predicates), when the cell has one.
  if (const world::Symbol* speed = world.symbol("tool_speed"); speed != nullptr && speed->number() != nullptr) {
    state["tool"] = {
        {"speed", rounded(speed->number()->value, 10)}, {"unit", speed->number()->unit},
        {"on", world.holds("tool_on", kNoArgs)},        {"at_speed", world.holds("tool_at_speed", kNoArgs)},
        {"held", world.holds("tool_held", kNoArgs)},    {"docked", world.holds("tool_docked", kNoArgs)}};
  }

  // The speed and separation monitor (the safety component, docs/PERSON.md), when the scene has
  // a person: the page shows the separation and the speed override live over the 3D view.
  const auto number = [&world](const char* name) -> const world::NumberValue* {
    const world::Symbol* symbol = world.symbol(name);
    return symbol == nullptr ? nullptr : symbol->number();
  };
  if (const world::NumberValue* separation = number("person_separation")) {
    const world::NumberValue* protective = number("protective_distance");
    const world::NumberValue* scale = number("arm_speed_scale");
    state["safety"] = {{"separation", rounded(separation->value, 1e3)},
                       {"protective_distance", protective != nullptr ? rounded(protective->value, 1e3) : 0.0},
                       {"speed_scale", scale != nullptr ? rounded(scale->value, 1e3) : 0.0},
                       {"slowed", world.holds("arm_slowed_for_person", kNoArgs)},
                       {"stopped", world.holds("arm_stopped_for_person", kNoArgs)},
                       {"collaborative", world.holds("arm_collaborative", kNoArgs)}};
  }

  json gripper = {{"open", world.holds("gripper_open", kNoArgs)},
                  {"closed", world.holds("gripper_closed", kNoArgs)},
                  {"holding", world.holds("gripper_holding", kNoArgs)}};
  for (const world::Predicate* predicate : world.predicates("gripper_mode")) {
    if (predicate->value && !predicate->args.empty()) {
      gripper["mode"] = predicate->args.front();
    }
  }
  // The fingers' reading (the gripper's own symbol): the page draws the fingers from it.
  if (const world::Symbol* fingers = world.symbol("gripper_fingers");
      fingers != nullptr && fingers->joints() != nullptr) {
    json positions = json::array();
    for (const double value : fingers->joints()->positions) {
      positions.push_back(rounded(value));
    }
    gripper["reading"] = {{"names", fingers->joints()->joint_names}, {"positions", std::move(positions)}};
  }
  state["gripper"] = std::move(gripper);

  std::set<std::string> objects;
  json objects_json = json::array();
  for (const world::Predicate* predicate : world.predicates("is_a")) {
    if (!predicate->value || predicate->args.size() != 2 || objects.contains(predicate->args[0])) {
      continue;
    }
    const auto pose = world.worldPose(predicate->args[0]);
    if (!pose) {
      continue;
    }
    objects.insert(predicate->args[0]);
    json item = poseJson(*pose);
    item["name"] = predicate->args[0];
    item["class"] = predicate->args[1];
    item["source"] = predicate->source;
    if (const world::Symbol* symbol = world.symbol(predicate->args[0]); symbol != nullptr && symbol->color) {
      const Eigen::Vector3d& rgb = *symbol->color;
      item["color"] = {rounded(rgb.x(), 1e3), rounded(rgb.y(), 1e3), rounded(rgb.z(), 1e3)};
    }
    objects_json.push_back(std::move(item));
  }
  state["objects"] = std::move(objects_json);

  json waypoints = json::array();
  json frames = json::array();
  for (const world::Symbol* symbol : world.symbols()) {
    if (waypoints_of_arms.isWaypoint(*symbol)) {
      json item = {{"name", symbol->name}};
      if (const world::FrameValue* frame = symbol->frame()) {
        item["kind"] = "pose";
        item["frame"] = frame->parent;
        if (const auto pose = world.worldPose(symbol->name)) {
          item.update(poseJson(*pose));
        }
      } else if (const world::JointsValue* joints = symbol->joints()) {
        item["kind"] = "joints";
        if (motion != nullptr && joints->positions.size() == arm_joint_count) {
          const arm::JointVector q = arm::JointVector::fromEigen(
              Eigen::Map<const Eigen::VectorXd>(joints->positions.data(), static_cast<Eigen::Index>(arm_joint_count)));
          item.update(poseJson(motion->toolAt(q)));
        }
      }
      waypoints.push_back(std::move(item));
    } else if (symbol->frame() != nullptr && !objects.contains(symbol->name) && symbol->name != "endpoint") {
      json item = {{"name", symbol->name}, {"parent", symbol->frame()->parent}};
      if (const auto pose = world.worldPose(symbol->name)) {
        item.update(poseJson(*pose));
      }
      frames.push_back(std::move(item));
    }
  }
  state["waypoints"] = std::move(waypoints);
  state["frames"] = std::move(frames);

  json predicates = json::array();
  for (const world::Predicate* predicate : world.predicates()) {
    if (predicate->value && predicate->name != "is_a") {
      predicates.push_back(predicate->str());
      if (predicates.size() >= 2000) {
        break;
      }
    }
  }
  state["predicates"] = std::move(predicates);
  return state;
}

}  // namespace costar::server
