#include "core/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace costar {
namespace {

TEST(RunIndexed, KeepsResultsInIndexOrderAndRunsEachIndexOnce) {
  for (const int jobs : {1, 2, 5}) {
    std::vector<std::atomic<int>> calls(200);
    const std::vector<std::string> results = runIndexed(calls.size(), jobs, [&](std::size_t i) {
      ++calls[i];
      return "run " + std::to_string(i);
    });
    ASSERT_EQ(results.size(), calls.size());
    for (std::size_t i = 0; i < calls.size(); ++i) {
      EXPECT_EQ(results[i], "run " + std::to_string(i)) << "jobs " << jobs;
      EXPECT_EQ(calls[i].load(), 1) << "index " << i << ", jobs " << jobs;
    }
  }
}

TEST(RunIndexed, ReportsEachRunOnceAndOneAtATime) {
  std::atomic<int> inside{0};
  bool overlapped = false;
  std::vector<int> finished_seen;
  std::set<std::size_t> indices;
  const auto results = runIndexed(
      64, 4, [](std::size_t i) { return static_cast<int>(i) * 3; },
      [&](const int& result, std::size_t index, int finished) {
        overlapped |= ++inside > 1;
        EXPECT_EQ(result, static_cast<int>(index) * 3);  // the stored result, already in its slot
        finished_seen.push_back(finished);
        indices.insert(index);
        std::this_thread::sleep_for(std::chrono::microseconds(50));
        --inside;
      });
  EXPECT_FALSE(overlapped);
  ASSERT_EQ(finished_seen.size(), 64u);
  for (std::size_t k = 0; k < finished_seen.size(); ++k) {
    EXPECT_EQ(finished_seen[k], static_cast<int>(k) + 1);
  }
  EXPECT_EQ(indices.size(), 64u);
  EXPECT_EQ(results[63], 189);
}

TEST(ForEachIndex, TheCallingThreadRunsIndexZero) {
  const auto caller = std::this_thread::get_id();
  for (const int jobs : {1, 3, 8}) {
    std::thread::id ran_zero;
    forEachIndex(8, jobs, [&](std::size_t i) {
      if (i == 0) {
        ran_zero = std::this_thread::get_id();
      }
    });
    EXPECT_EQ(ran_zero, caller) << "jobs " << jobs;
  }
}

TEST(ForEachIndex, RunsJobsAtOnce) {
  // Three runs that each wait until all three have started: only three threads finish them.
  std::mutex mutex;
  std::condition_variable all_in;
  int started = 0;
  bool timed_out = false;
  std::set<std::thread::id> threads;
  forEachIndex(3, 3, [&](std::size_t) {
    std::unique_lock lock(mutex);
    threads.insert(std::this_thread::get_id());
    ++started;
    all_in.notify_all();
    if (!all_in.wait_for(lock, std::chrono::seconds(20), [&] { return started == 3; })) {
      timed_out = true;
    }
  });
  EXPECT_FALSE(timed_out);
  EXPECT_EQ(threads.size(), 3u);
}

TEST(ForEachIndex, OneJobOrFewerRunsInOrderOnTheCallingThread) {
  const auto caller = std::this_thread::get_id();
  for (const int jobs : {1, 0, -3}) {
    std::vector<std::size_t> order;
    forEachIndex(5, jobs, [&](std::size_t i) {
      EXPECT_EQ(std::this_thread::get_id(), caller);
      order.push_back(i);
    });
    EXPECT_EQ(order, (std::vector<std::size_t>{0, 1, 2, 3, 4})) << "jobs " << jobs;
  }
}

TEST(ForEachIndex, NothingToRunCallsNothing) {
  int calls = 0;
  forEachIndex(0, 4, [&](std::size_t) { ++calls; });
  EXPECT_EQ(calls, 0);
  EXPECT_TRUE(runIndexed(0, 2, [](std::size_t) { return 1; }).empty());
}

TEST(ForEachIndex, AFailingRunStopsTheRestAndItsErrorReachesTheCaller) {
  // One thread: the runs after the failing one never start.
  std::vector<std::size_t> ran;
  try {
    forEachIndex(10, 1, [&](std::size_t i) {
      ran.push_back(i);
      if (i == 3) {
        throw std::runtime_error("run 3 broke");
      }
    });
    ADD_FAILURE() << "the error was swallowed";
  } catch (const std::runtime_error& error) {
    EXPECT_STREQ(error.what(), "run 3 broke");
  }
  EXPECT_EQ(ran, (std::vector<std::size_t>{0, 1, 2, 3}));

  // Several threads: the error is rethrown after every thread has stopped (before this helper, an
  // exception on a worker thread ended the process), and not every run was started.
  std::atomic<int> started{0};
  std::atomic<bool> thrown{false};
  EXPECT_THROW(forEachIndex(1000, 4,
                            [&](std::size_t i) {
                              ++started;
                              if (i == 1) {
                                thrown = true;
                                throw std::invalid_argument("bad run");
                              }
                              while (!thrown) {
                                std::this_thread::yield();
                              }
                              std::this_thread::sleep_for(std::chrono::milliseconds(1));
                            }),
               std::invalid_argument);
  EXPECT_LT(started.load(), 1000);
}

}  // namespace
}  // namespace costar
