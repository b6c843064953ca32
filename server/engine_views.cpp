// What the browser sees of the engine: snapshots of the cell (joints, gripper, objects,
// waypoints, frames, predicates), each run as JSON with its nodes' statuses, and the stream's
// messages (hello, state, run events).

#include "server/engine_parts.h"

#include <algorithm>
#include <set>
#include "arm/motion_service.h"
#include "workcell/workcell.h"

namespace costar::server {

json Engine::statusesJson(RunState& run, bool dirty_only) {
  json nodes = json::array();
  const auto add = [&](std::uint32_t uid) {
    const RunState::Node& state = run.statuses[uid];
    json item = {{"uid", uid}, {"status", bt::toString(state.current)}, {"last", state.last}};
    if (!state.reason.empty()) {
      item["reason"] = state.reason;
      item["origin"] = state.origin;
    }
    if (!state.data.is_null()) {
      item["data"] = state.data;
    }
    nodes.push_back(std::move(item));
  };
  if (dirty_only) {
    for (const std::uint32_t uid : run.dirty) {
      run.statuses[uid].dirty = false;
      add(uid);
    }
    run.dirty.clear();
  } else {
    for (std::uint32_t uid = 0; uid < run.statuses.size(); ++uid) {
      if (run.statuses[uid].last != "IDLE" || run.statuses[uid].current != bt::Status::kIdle) {
        add(uid);
      }
    }
  }
  return {{"type", "statuses"}, {"run", run.id}, {"nodes", std::move(nodes)}};
}

json Engine::runJson(const RunState& run, bool with_nodes) const {
  json out = {{"id", run.id},
              {"kind", run.operation ? "operation" : "plan"},
              {"plan", run.plan_name},
              {"version", run.version},
              {"label", run.label},
              {"workcell", run.workcell},
              {"active", run.active},
              {"paused", run.active && paused_.load()},
              {"started_at", run.started_at},
              {"result", run.result},
              {"clock_seconds", run.clock_seconds},
              {"wall_seconds", run.wall_seconds},
              {"cpu_seconds", run.cpu_seconds},
              {"transitions", run.transitions}};
  if (!run.failure_reason.empty()) {
    out["failure_path"] = run.failure_path;
    out["failure_reason"] = run.failure_reason;
  }
  if (run.stopped) {
    out["stopped"] = true;
  }
  if (with_nodes) {
    json nodes = json::array();
    for (const RunNode& node : run.nodes) {
      nodes.push_back(
          {{"uid", node.uid}, {"parent", node.parent}, {"id", node.id}, {"name", node.name}, {"path", node.path}});
    }
    out["nodes"] = std::move(nodes);
    if (!run.plan_json.is_null()) {
      out["plan_json"] = run.plan_json;
    }
  }
  return out;
}

json Engine::state() {
  const std::lock_guard lock(mutex_);
  return json::parse(state_json_);
}

std::optional<json> Engine::runStatus(std::optional<std::int64_t> id) {
  const std::lock_guard lock(mutex_);
  std::shared_ptr<RunState> run;
  if (!id) {
    run = current_;
  } else if (current_ && current_->id == *id) {
    run = current_;
  } else {
    for (const auto& finished : finished_) {
      if (finished->id == *id) {
        run = finished;
        break;
      }
    }
  }
  if (!run) {
    return std::nullopt;
  }
  json out = runJson(*run, true);
  out["statuses"] = statusesJson(*run, false)["nodes"];
  return out;
}

json Engine::buildState() const {
  const world::WorldState& world = cell_->components().world();
  json state = {{"type", "state"}, {"t", rounded(toSeconds(cell_->clock().now()), 1e4)}};
  const std::int64_t active = active_run_.load();
  state["run"] = active;
  state["mode"] = active == 0 ? "idle" : (paused_ ? "paused" : "running");

  std::set<std::string> arm_sources;
  std::set<std::string> declared;
  for (const auto& component : cell_->components().components()) {
    const auto& description = component->description();
    if (std::find(description.implements.begin(), description.implements.end(), "Arm") !=
        description.implements.end()) {
      arm_sources.insert(description.name);
    }
    for (const auto& symbol : description.symbols) {
      declared.insert(symbol.name);
    }
  }

  json arm_json = json::object();
  if (const auto endpoint = world.worldPose("endpoint")) {
    arm_json["endpoint"] = poseJson(*endpoint);
  }
  // A joint waypoint is drawn where the cell's motion service puts the tool at its joints.
  const arm::MotionService* motion = cell_->motion();
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
  state["arm"] = std::move(arm_json);

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
    if (arm_sources.contains(symbol->source) && !declared.contains(symbol->name)) {
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

void Engine::takeSnapshot() {
  const auto begin = std::chrono::steady_clock::now();
  std::string text = buildState().dump(-1, ' ', false, json::error_handler_t::replace);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  const std::lock_guard lock(mutex_);
  state_json_ = std::move(text);
  ++state_version_;
  ++stats_.snapshots;
  stats_.snapshot_seconds += seconds;
}

std::vector<std::string> Engine::drainStream() {
  std::vector<std::string> out;
  std::optional<json> statuses;
  std::string state;
  {
    const std::lock_guard lock(mutex_);
    out.swap(events_);
    if (current_ && current_->active && !current_->dirty.empty()) {
      statuses = statusesJson(*current_, true);
    }
    if (state_version_ != drained_state_version_) {
      drained_state_version_ = state_version_;
      state = state_json_;
    }
  }
  if (statuses) {
    out.push_back(statuses->dump(-1, ' ', false, json::error_handler_t::replace));
  }
  if (!state.empty()) {
    out.push_back(std::move(state));
  }
  return out;
}

std::string Engine::helloMessage() {
  json hello = {{"type", "hello"}, {"info", info()}};
  std::string state;
  {
    const std::lock_guard lock(mutex_);
    if (current_) {
      json run = runJson(*current_, true);
      run["statuses"] = statusesJson(*current_, false)["nodes"];
      hello["run"] = std::move(run);
    } else {
      hello["run"] = nullptr;
    }
    state = state_json_;
  }
  std::string text = hello.dump(-1, ' ', false, json::error_handler_t::replace);
  text.pop_back();  // '}'
  return text + ",\"state\":" + state + "}";
}

}  // namespace costar::server
