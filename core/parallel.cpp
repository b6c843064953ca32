#include "core/parallel.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <system_error>
#include <thread>

namespace costar {

void forEachIndex(std::size_t count, int jobs, const std::function<void(std::size_t)>& body) {
  // Index 0 is the calling thread's; the others take the next free index until none is left
  // or a run has failed.
  std::atomic<std::size_t> next{1};
  std::atomic<bool> failed{false};
  std::exception_ptr first_error;
  std::mutex error_mutex;
  const auto worker = [&](std::size_t index) {
    for (; index < count && !failed; index = next++) {
      try {
        body(index);
      } catch (...) {
        std::lock_guard lock(error_mutex);
        if (!first_error) {
          first_error = std::current_exception();
        }
        failed = true;
      }
    }
  };

  // Never more threads than runs; a thread the system refuses leaves the work to the others.
  const std::size_t helpers = std::min<std::size_t>(count > 0 ? count - 1 : 0, jobs > 1 ? jobs - 1 : 0);
  std::vector<std::thread> threads;
  threads.reserve(helpers);
  for (std::size_t j = 0; j < helpers; ++j) {
    try {
      threads.emplace_back([&worker, &next] { worker(next++); });
    } catch (const std::system_error&) {
      break;
    }
  }
  worker(0);
  for (std::thread& thread : threads) {
    thread.join();
  }
  if (first_error) {
    std::rethrow_exception(first_error);
  }
}

}  // namespace costar
