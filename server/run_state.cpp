#include "server/run_state.h"

namespace costar::server {

using nlohmann::json;

json runJson(const RunState& run, bool paused, bool with_nodes) {
  json out = {{"id", run.id},
              {"kind", run.operation ? "operation" : "plan"},
              {"plan", run.plan_name},
              {"version", run.version},
              {"label", run.label},
              {"workcell", run.workcell},
              {"active", run.active},
              {"paused", run.active && paused},
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

json statusesJson(RunState& run, bool dirty_only) {
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

std::string jsonText(const json& value) { return value.dump(-1, ' ', false, json::error_handler_t::replace); }

}  // namespace costar::server
