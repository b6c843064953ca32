#pragma once
// One run (a plan or a single operation) as the browser sees it: its nodes, each node's last
// status, its result and times, and that as the JSON of the stream's run_started, statuses and
// run_ended messages, GET /api/runs/{id} and the hello. The engine thread writes a run and
// network threads read it, both under the Engine's mutex.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bt/node.h"
#include "core/clock.h"
#include "server/store.h"

namespace costar::server {

struct RunState {
  struct Node {
    bt::Status current = bt::Status::kIdle;
    std::string last = "IDLE";  // last status other than IDLE; HALTED when stopped while RUNNING
    std::string reason;
    std::string origin;
    nlohmann::json data;  // an operation's result data (SmartMove candidates, ...)
    bool dirty = false;
  };
  std::int64_t id = 0;
  bool operation = false;
  std::string plan_name;
  int version = 0;
  std::string label;  // the main tree's ID, or the operation's node type
  std::string workcell;
  std::string xml;
  nlohmann::json plan_json;  // a plan run's plan as the editor's JSON (any page can show what runs)
  std::vector<RunNode> nodes;
  std::vector<Node> statuses;
  std::vector<std::uint32_t> dirty;  // nodes whose status changed since the stream last read them
  bool active = true;
  bool stopped = false;
  std::string result;
  std::string failure_path;
  std::string failure_reason;
  double started_at = 0;  // Unix seconds
  double ended_at = 0;
  double clock_seconds = 0;
  double wall_seconds = 0;
  double cpu_seconds = 0;  // the engine thread's CPU time during the run
  TimePoint start_time{};
  std::uint64_t transitions = 0;
  bool truncated = false;
};

/// {id, kind (plan, operation), plan, version, label, workcell, active, paused (`paused` while
/// active), started_at, result, clock_seconds, wall_seconds, cpu_seconds, transitions,
/// failure_path and failure_reason (when it failed with a reason), stopped (when stopped)};
/// `with_nodes`: also nodes [{uid, parent, id, name, path}] and plan_json (a plan run's).
nlohmann::json runJson(const RunState& run, bool paused, bool with_nodes);

/// {type: "statuses", run, nodes [{uid, status, last, reason and origin (a failure's), data}]}:
/// `dirty_only`: the nodes changed since the last such call (which it marks as read), else
/// every node that has left IDLE.
nlohmann::json statusesJson(RunState& run, bool dirty_only);

/// `value` as the stream sends it and the run log keeps it: compact, invalid UTF-8 replaced.
std::string jsonText(const nlohmann::json& value);

}  // namespace costar::server
