// What the editor offers: the workcell's info (the palette's, with the engine's pace, active
// run and counters), the choice lists read from what the cell knows now (waypoints, frames,
// object classes, predicates, the grasps of the cell's gripper per class, each with the tool
// centre point in the part's frame and its mode, for drawing it on the parts), and each object
// class's shape and colours (for drawing the parts).

#include "server/engine_parts.h"

#include <algorithm>
#include <functional>
#include <set>
#include <string_view>

#include <Eigen/Geometry>

#include "arm/arm_component.h"
#include "server/cell_state.h"
#include "sim/simulation.h"
#include "smartmove/grasps.h"
#include "workcell/workcell.h"
#include "world/object_class.h"

namespace costar::server {

namespace {

/// The names of a list parameter ("a;b; c"), trimmed, empty ones left out.
std::vector<std::string> splitList(std::string_view text) {
  std::vector<std::string> names;
  for (std::size_t start = 0; start <= text.size();) {
    const std::size_t end = std::min(text.find(';', start), text.size());
    std::string_view name = text.substr(start, end - start);
    name.remove_prefix(std::min(name.find_first_not_of(' '), name.size()));
    name.remove_suffix(name.size() - std::min(name.find_last_not_of(' ') + 1, name.size()));
    if (!name.empty()) {
      names.emplace_back(name);
    }
    start = end + 1;
  }
  return names;
}

/// A class as the 3D view draws it: its boxes (object frame, metres) and its named colours
/// (RGB in [0, 1], ordered by name as the simulator numbers them).
json classShape(const world::ObjectClass& object_class) {
  json boxes = json::array();
  for (const world::Box& box : object_class.boxes) {
    boxes.push_back({{"center", {box.center.x(), box.center.y(), box.center.z()}},
                     {"half_size", {box.half_size.x(), box.half_size.y(), box.half_size.z()}}});
  }
  json colors = json::array();
  for (const auto& [name, rgb] : object_class.colors) {
    colors.push_back({{"name", name}, {"rgb", {rgb.x(), rgb.y(), rgb.z()}}});
  }
  return {{"boxes", std::move(boxes)}, {"colors", std::move(colors)}};
}

/// The names a plan may use of what the cell knows now (engine thread).
struct Known {
  std::set<std::string> waypoints;
  std::set<std::string> trajectories;
  std::set<std::string> frames = {"world"};
  std::set<std::string> classes;
};

Known knownNow(workcell::Workcell& cell) {
  Known known;
  const world::WorldState& world = cell.components().world();
  const WaypointFinder waypoints_of_arms(cell);
  for (const world::Symbol* symbol : world.symbols()) {
    if (symbol->frame() != nullptr) {
      known.frames.insert(symbol->name);
    }
    if (waypoints_of_arms.isWaypoint(*symbol)) {
      known.waypoints.insert(symbol->name);
    }
  }
  for (const world::Predicate* predicate : world.predicates("is_a")) {
    if (predicate->args.size() == 2) {
      known.classes.insert(predicate->args[1]);
    }
  }
  if (sim::Simulation* simulation = cell.simulation()) {
    for (const auto& object_class : simulation->objectClasses()) {
      known.classes.insert(object_class.name);
    }
  }
  if (const auto* arm = dynamic_cast<const arm::ArmComponent*>(cell.components().provider("FollowTrajectory"))) {
    for (const arm::RecordedTrajectory& trajectory : arm->waypoints().trajectories()) {
      known.trajectories.insert(trajectory.name);
    }
  }
  return known;
}

/// The recorded trajectories as the 3D view draws them: each pose kept, in the world (through
/// its frame as the world has it now; none when the frame is unknown now).
json trajectoryLines(workcell::Workcell& cell) {
  json lines = json::object();
  const auto* arm = dynamic_cast<const arm::ArmComponent*>(cell.components().provider("FollowTrajectory"));
  if (arm == nullptr) {
    return lines;
  }
  for (const arm::RecordedTrajectory& trajectory : arm->waypoints().trajectories()) {
    const std::optional<world::Pose> frame = trajectory.frame == "world"
                                                 ? std::optional<world::Pose>(world::Pose::Identity())
                                                 : cell.components().world().worldPose(trajectory.frame);
    json points = json::array();
    if (frame) {
      for (const world::Pose& pose : trajectory.poses) {
        const Eigen::Vector3d p = *frame * pose.translation();
        points.push_back({p.x(), p.y(), p.z()});
      }
    }
    lines[trajectory.name] = {{"frame", trajectory.frame}, {"points", std::move(points)}};
  }
  return lines;
}

std::string listed(const std::set<std::string>& names) {
  std::string out;
  for (const std::string& name : names) {
    out += (out.empty() ? "" : ", ") + name;
  }
  return out.empty() ? "none" : out;
}

void visit(const bt::PlanNode& node, const std::function<void(const bt::PlanNode&)>& f) {
  f(node);
  for (const bt::PlanNode& child : node.children) {
    visit(child, f);
  }
}

}  // namespace

std::vector<bt::Diagnostic> Engine::checkAgainstCell(const bt::Plan& plan) {
  // What the plan itself makes known before it uses it: waypoints it teaches or renames to,
  // and parts a detection finds (then frames of parts cannot be known beforehand).
  std::set<std::string> taught;
  bool detects = false;
  for (const bt::PlanTree& tree : plan.file.trees) {
    visit(tree.root, [&](const bt::PlanNode& node) {
      if (node.id == "Teach") {
        taught.insert(node.attribute("waypoint").value_or(""));
      } else if (node.id == "RenameWaypoint") {
        taught.insert(node.attribute("new_name").value_or(""));
      } else if (node.id == "DetectObjects") {
        detects = true;
      }
    });
  }
  const Known known = knownNow(*cell_);
  std::vector<bt::Diagnostic> out;
  for (const bt::PlanTree& tree : plan.file.trees) {
    visit(tree.root, [&](const bt::PlanNode& node) {
      const component::Component* provider = cell_->components().provider(node.id);
      const component::OperationSpec* operation =
          provider != nullptr ? provider->description().operation(node.id) : nullptr;
      if (operation == nullptr) {
        return;
      }
      for (const auto& [name, value] : node.attributes) {
        const component::ParamSpec* param = operation->param(name);
        if (param == nullptr || value.empty() || (node.id == "Teach" && name == "waypoint")) {
          continue;
        }
        const auto extra = [&] {
          return std::find(param->extra_choices.begin(), param->extra_choices.end(), value) !=
                 param->extra_choices.end();
        };
        std::string problem;
        if (param->choices_from == "trajectory" && !known.trajectories.contains(value)) {
          problem =
              "no trajectory '" + value + "' recorded in this cell; its trajectories: " + listed(known.trajectories);
        } else if (param->choices_from == "waypoint") {
          // A list of waypoints (PressAndFollow's path, "row1_start;row1_end") names each one.
          for (const std::string& waypoint :
               param->type == component::ValueType::kStringList ? splitList(value) : std::vector{value}) {
            if (!known.waypoints.contains(waypoint) && !taught.contains(waypoint)) {
              problem = "no waypoint '" + waypoint +
                        "' in this cell now (renamed or deleted?); its waypoints: " + listed(known.waypoints);
              break;
            }
          }
        } else if (param->choices_from == "frame" && !detects && !extra() && !known.frames.contains(value) &&
                   !known.waypoints.contains(value) && !taught.contains(value)) {
          problem = "no frame '" + value + "' in this cell now; its frames: " + listed(known.frames);
        } else if (param->choices_from == "object_class" && !known.classes.empty() && !extra() &&
                   !known.classes.contains(value)) {
          problem = "no object class '" + value + "' in this cell; its classes: " + listed(known.classes);
        }
        if (!problem.empty()) {
          out.push_back({node.location, node.id + ": " + name + ": " + problem});
        }
      }
    });
  }
  return out;
}

std::optional<json> Engine::robot() {
  return call([this]() -> std::optional<json> {
    json drawing = cell_->robotDrawing();
    if (drawing.is_null()) {
      return std::nullopt;
    }
    return drawing;
  });
}

json Engine::info() {
  json out = palette_.info;
  const std::lock_guard lock(mutex_);
  out["pace"] = pace_.pace();
  out["active_run"] = active_run_.load();
  if (!last_error_.empty()) {
    out["last_error"] = last_error_;
  }
  out["stats"] = {{"ticks", stats_.ticks},
                  {"snapshots", stats_.snapshots},
                  {"snapshot_seconds", stats_.snapshot_seconds},
                  {"paced_wait_seconds", stats_.paced_wait_seconds},
                  {"runs", stats_.runs}};
  return out;
}

json Engine::choices() {
  return call([this] {
    const Known known = knownNow(*cell_);
    const std::set<std::string>& classes = known.classes;
    json shapes = json::object();
    if (sim::Simulation* simulation = cell_->simulation()) {
      for (const auto& object_class : simulation->objectClasses()) {
        shapes[object_class.name] = classShape(object_class);
      }
    }
    json predicates = json::array();
    for (const auto& [name, decl] : cell_->components().predicates()) {
      predicates.push_back({{"name", name}, {"arity", decl.arity}, {"description", decl.description}});
    }
    json grasps = json::object();
    json grasp_poses = json::object();
    try {
      if (!options_.grasp_defaults.empty() && std::filesystem::exists(options_.grasp_defaults)) {
        const smartmove::GraspLibrary library(options_.grasp_defaults, options_.grasp_taught, grasp_gripper_);
        for (const std::string& object_class : classes) {
          json names = json::array();
          json poses = json::object();
          for (const auto& grasp : library.forClass(object_class)) {
            names.push_back(grasp.name);
            const Eigen::Vector3d& p = grasp.tcp_in_object.translation();
            const Eigen::Quaterniond q(grasp.tcp_in_object.linear());
            poses[grasp.name] = {
                {"p", {p.x(), p.y(), p.z()}}, {"q", {q.x(), q.y(), q.z(), q.w()}}, {"mode", grasp.mode}};
          }
          grasps[object_class] = std::move(names);
          grasp_poses[object_class] = std::move(poses);
        }
      }
    } catch (const std::exception&) {
      // An unreadable grasp file: SmartMove reports it when it runs; offer no list.
    }
    return json{{"waypoint", known.waypoints},
                {"trajectory", known.trajectories},
                {"trajectory_line", trajectoryLines(*cell_)},
                {"frame", known.frames},
                {"object_class", classes},
                {"predicate", std::move(predicates)},
                {"grasp", std::move(grasps)},
                {"grasp_pose", std::move(grasp_poses)},
                {"object_shape", std::move(shapes)}};
  });
}

}  // namespace costar::server
