// What the browser sees of the engine: its runs (as run_state.h writes them), the snapshots of
// the cell (cell_state.h) and the stream's messages (hello, state, run events).

#include "server/engine_parts.h"

#include "server/cell_state.h"

namespace costar::server {

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
  json out = runJson(*run, controls_.paused(), true);
  out["statuses"] = statusesJson(*run, false)["nodes"];
  return out;
}

void Engine::takeSnapshot() {
  const auto begin = std::chrono::steady_clock::now();
  std::string text = jsonText(cellState(*cell_, active_run_.load(), controls_.paused()));
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
    out.push_back(jsonText(*statuses));
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
      json run = runJson(*current_, controls_.paused(), true);
      run["statuses"] = statusesJson(*current_, false)["nodes"];
      hello["run"] = std::move(run);
    } else {
      hello["run"] = nullptr;
    }
    state = state_json_;
  }
  std::string text = jsonText(hello);
  text.pop_back();  // '}'
  return text + ",\"state\":" + state + "}";
}

}  // namespace costar::server
