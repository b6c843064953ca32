#pragma once
// Private to the Engine's parts (engine.cpp, engine_lists.cpp, engine_views.cpp,
// engine_sim_views.cpp, cell_state.cpp): JSON of poses, the engine thread's CPU time, and
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

template <typename F>
auto Engine::call(F task) -> decltype(task()) {
  return tasks_.call(std::move(task), options_.call_timeout);
}

}  // namespace costar::server
