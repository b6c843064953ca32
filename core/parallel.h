#pragma once
// N independent, numbered runs (trials, fault-campaign runs) on J threads, with their results
// kept in index order whatever order they finish in. Used by trials/ and faults/.

#include <cstddef>
#include <functional>
#include <mutex>
#include <type_traits>
#include <utility>
#include <vector>

namespace costar {

/// Calls `body(i)` once for every i in [0, count) on `jobs` threads: the calling thread and
/// jobs - 1 others, each taking the next index not yet taken. The calling thread runs index 0
/// first (a run may need the thread that prepared it; OpenGL contexts are per thread).
/// If a body throws, no further index is started, the runs under way finish, and the first
/// exception is rethrown on the calling thread once every thread has been joined.
/// @pre jobs >= 1 (a smaller value runs on the calling thread alone).
void forEachIndex(std::size_t count, int jobs, const std::function<void(std::size_t)>& body);

/// forEachIndex that keeps what each run returns: result i is `run(i)`. `done(result, i,
/// finished)` is called as each run ends (in the order they end; `finished` counts them from 1),
/// one call at a time, so it may print or append to a file without a lock of its own.
/// @throws the first exception a run or `done` threw (see forEachIndex).
template <typename Run, typename Done>
auto runIndexed(std::size_t count, int jobs, Run&& run, Done&& done)
    -> std::vector<std::invoke_result_t<Run&, std::size_t>> {
  using Result = std::invoke_result_t<Run&, std::size_t>;
  std::vector<Result> results(count);
  std::mutex mutex;
  int finished = 0;
  forEachIndex(count, jobs, [&](std::size_t index) {
    Result result = run(index);
    std::lock_guard lock(mutex);
    results[index] = std::move(result);
    done(std::as_const(results[index]), index, ++finished);
  });
  return results;
}

/// runIndexed without a per-run callback.
template <typename Run>
auto runIndexed(std::size_t count, int jobs, Run&& run) {
  return runIndexed(count, jobs, std::forward<Run>(run), [](const auto&, std::size_t, int) {});
}

}  // namespace costar
