// What the browser sees of the engine: each run as JSON with its nodes' statuses, the
// snapshots of the cell (cell_state.h) and the stream's messages (hello, state, run events).

#include "server/engine_parts.h"

#include "server/cell_state.h"

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

void Engine::takeSnapshot() {
  const auto begin = std::chrono::steady_clock::now();
  std::string text =
      cellState(*cell_, active_run_.load(), paused_).dump(-1, ' ', false, json::error_handler_t::replace);
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
