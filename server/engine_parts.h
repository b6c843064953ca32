#pragma once
// Private to the Engine's parts (engine.cpp, engine_lists.cpp, engine_views.cpp,
// engine_sim_views.cpp): the state of one run as the browser sees it, the tree observer, and
// Engine::call, which hands a task to the engine thread and waits for its answer. Not for
// other parts of the server.

#include <time.h>

#include <cmath>
#include <span>

#include "bt/executor.h"
#include "server/engine.h"
#include "world/pose.h"

namespace costar::server::engine_detail {

using nlohmann::json;

inline double rounded(double value, double scale = 1e5) { return std::round(value * scale) / scale; }

inline json poseJson(const world::Pose& pose) {
  const Eigen::Vector3d& p = pose.translation();
  const Eigen::Quaterniond q(pose.linear());
  // three.js order: x, y, z, w.
  return {{"p", {rounded(p.x()), rounded(p.y()), rounded(p.z())}},
          {"q", {rounded(q.x()), rounded(q.y()), rounded(q.z()), rounded(q.w())}}};
}

inline const std::span<const std::string> kNoArgs{};

/// CPU time of the calling thread, seconds.
inline double threadCpuSeconds() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

}  // namespace costar::server::engine_detail

namespace costar::server {

using engine_detail::kNoArgs;
using engine_detail::poseJson;
using engine_detail::rounded;
using engine_detail::threadCpuSeconds;
using nlohmann::json;

// One run (a plan or a single operation) as the browser sees it.
struct Engine::RunState {
  struct Node {
    bt::Status current = bt::Status::kIdle;
    std::string last = "IDLE";  // last status other than IDLE; HALTED when stopped while RUNNING
    std::string reason;
    std::string origin;
    json data;  // an operation's result data (SmartMove candidates, ...)
    bool dirty = false;
  };
  std::int64_t id = 0;
  bool operation = false;
  std::string plan_name;
  int version = 0;
  std::string label;  // the main tree's ID, or the operation's node type
  std::string workcell;
  std::string xml;
  json plan_json;  // a plan run's plan as the editor's JSON (any page can show what runs)
  std::vector<RunNode> nodes;
  std::vector<Node> statuses;
  std::vector<std::uint32_t> dirty;
  bool active = true;
  bool stopped = false;
  std::string result;
  std::string failure_path;
  std::string failure_reason;
  double started_at = 0;
  double clock_seconds = 0;
  double wall_seconds = 0;
  double cpu_seconds = 0;  // the engine thread's CPU time during the run
  TimePoint start_time{};
  std::uint64_t transitions = 0;
  bool truncated = false;
};

class Engine::Observer final : public bt::TreeObserver {
 public:
  explicit Observer(Engine& engine) : engine_(engine) {}
  void onTransition(TimePoint time, const bt::TreeNode& node, bt::Status from, bt::Status to) override {
    engine_.onTransition(time, node, from, to);
  }

 private:
  Engine& engine_;
};

template <typename F>
auto Engine::call(F task) -> decltype(task()) {
  return tasks_.call(std::move(task), options_.call_timeout);
}

}  // namespace costar::server
