// Overhead of a component in another process over DDS on loopback (dds/), against the same
// component in this process, in the same run: an operation's round trip (start, then poll
// until it ends), a cancel's round trip (cancel until the host confirms it stopped), one poll,
// and how long a killed host takes to be noticed; in lockstep (a simulated cell's hosts), a
// report's and an operation's calls. Figures: docs/BENCHMARKS.md.
//   build/bench/dds_bench [ROUND_TRIPS=2000] [KILLS=5]

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "dds/host.h"
#include "dds/lockstep.h"
#include "dds/remote_component.h"
#include "testing/test_components.h"

namespace {

using costar::component::Component;
using costar::component::OperationState;
using costar::component::ParamMap;
using Clock = std::chrono::steady_clock;

std::atomic<bool> g_stop{false};
extern "C" void onTerm(int /*signal*/) { g_stop = true; }

/// `dds_bench --host PARTITION`: serves the test components until SIGTERM.
int serveTestComponents(const std::string& partition) {
  std::signal(SIGTERM, onTerm);
  costar::dds::RemoteConfig config;
  config.partition = partition;
  costar::dds::ComponentHost host(
      config, {std::make_shared<costar::testing::TestLogger>(), std::make_shared<costar::testing::TestActions>()});
  host.serve(g_stop);
  return 0;
}

/// `dds_bench --lockstep-host PARTITION`: serves the test logger in lockstep with an executor's
/// simulated clock (as a simulated cell's hosts do) until SIGTERM.
int serveLockstep(const std::string& partition) {
  std::signal(SIGTERM, onTerm);
  costar::dds::RemoteConfig config;
  config.partition = partition;
  config.lockstep = true;
  costar::dds::SimulatorLink link(config);
  costar::dds::ComponentHost::Lockstep lockstep;
  lockstep.new_run = [&](std::uint64_t executor) {
    link.setExecutor(executor);
    return std::vector<std::shared_ptr<Component>>{std::make_shared<costar::testing::TestLogger>()};
  };
  lockstep.reach_time = [&](std::int64_t stamp_ns) { link.reachTime(stamp_ns); };
  lockstep.prepare = [&](const std::string& prepared_json) { link.prepare(prepared_json); };
  lockstep.prepared_used = [&] { return link.preparedUsed(); };
  costar::dds::ComponentHost host(config, {std::make_shared<costar::testing::TestLogger>()}, lockstep);
  link.setHost(host.id());
  host.serve(g_stop);
  return 0;
}

/// This executable again, as a host in a child process (exec: the fork of a process that uses
/// DDS cannot use DDS); `flag` --host or --lockstep-host.
pid_t startHost(const costar::dds::RemoteConfig& config, std::string flag = "--host") {
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::string self = "/proc/self/exe", partition = config.partition;
    char* argv[] = {self.data(), flag.data(), partition.data(), nullptr};
    ::execv(argv[0], argv);
    ::_exit(127);
  }
  return pid;
}

double micros(Clock::duration d) { return std::chrono::duration<double, std::micro>(d).count(); }

struct Stats {
  double median, p99, max;
};

Stats stats(std::vector<double> samples) {
  std::sort(samples.begin(), samples.end());
  const auto at = [&](double q) {
    return samples[static_cast<std::size_t>(q * static_cast<double>(samples.size() - 1))];
  };
  return {at(0.5), at(0.99), samples.back()};
}

void print(const char* what, const Stats& local, const Stats& remote) {
  std::printf("%-44s in-process %8.2f / %8.2f / %8.2f us   remote %8.2f / %8.2f / %8.2f us\n", what, local.median,
              local.p99, local.max, remote.median, remote.p99, remote.max);
}

/// start(operation) then poll until it ends: the wall time of each, in µs.
std::vector<double> roundTrips(Component& component, const std::string& operation, const ParamMap& params, int count) {
  std::vector<double> samples;
  for (int i = 0; i < count; ++i) {
    const auto begin = Clock::now();
    const auto id = component.start(operation, params);
    while (component.poll(id).state == OperationState::kRunning) {
      std::this_thread::yield();
    }
    samples.push_back(micros(Clock::now() - begin));
  }
  return samples;
}

/// One poll of a running operation, in µs (the median of 1000 in a row, per sample).
std::vector<double> polls(Component& component, int count) {
  std::vector<double> samples;
  const auto id = component.start("TestAction", {{"result", "success"}, {"polls", 1000000000LL}, {"reason", ""}});
  for (int i = 0; i < count; ++i) {
    const auto begin = Clock::now();
    for (int k = 0; k < 1000; ++k) {
      (void)component.poll(id);
    }
    samples.push_back(micros(Clock::now() - begin) / 1000.0);
  }
  component.cancel(id);
  return samples;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::string(argv[1]) == "--host") {
    return serveTestComponents(argv[2]);
  }
  if (argc == 3 && std::string(argv[1]) == "--lockstep-host") {
    return serveLockstep(argv[2]);
  }
  const int count = argc > 1 ? std::atoi(argv[1]) : 2000;
  const int kills = argc > 2 ? std::atoi(argv[2]) : 5;
  if (count < 10 || kills < 0) {
    std::fprintf(stderr, "usage: %s [ROUND_TRIPS>=10] [KILLS>=0]\n", argv[0]);
    return 2;
  }
  costar::dds::RemoteConfig config;
  config.partition = "costar-bench-" + std::to_string(::getpid());
  pid_t host = startHost(config);
  const auto client = costar::dds::RemoteClient::create(config);
  const auto remote_logger = client->connect("test_logger", std::chrono::seconds(20));
  const auto remote_actions = client->connect("test_actions", std::chrono::seconds(20));
  costar::testing::TestLogger local_logger;
  costar::testing::TestActions local_actions;
  const ParamMap log{{"message", "m"}};
  // Warm up both paths.
  roundTrips(*remote_logger, "TestLog", log, 100);
  roundTrips(local_logger, "TestLog", log, 100);

  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  std::printf("dds_bench: %d round trips each, loopback, one host process; median / p99 / max\n", count);
  print("operation round trip (TestLog: start..SUCCESS)", stats(roundTrips(local_logger, "TestLog", log, count)),
        stats(roundTrips(*remote_logger, "TestLog", log, count)));
  print("one poll of a running operation", stats(polls(local_actions, count / 10)),
        stats(polls(*remote_actions, count / 10)));

  std::vector<double> local_cancels, remote_cancels;
  const ParamMap forever{{"result", "success"}, {"polls", 1000000000LL}, {"reason", ""}};
  for (int i = 0; i < count; ++i) {
    auto id = local_actions.start("TestAction", forever);
    auto begin = Clock::now();
    local_actions.cancel(id);
    local_cancels.push_back(micros(Clock::now() - begin));
    id = remote_actions->start("TestAction", forever);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));  // started on the host by now
    begin = Clock::now();
    remote_actions->cancel(id);
    while (!remote_actions->cancelConfirmed(id)) {
      std::this_thread::yield();
    }
    remote_cancels.push_back(micros(Clock::now() - begin));
  }
  print("cancel round trip (cancel..host confirms)", stats(local_cancels), stats(remote_cancels));

  // Lockstep (a simulated cell's hosts): each call answered at once at the executor's simulated
  // time; a report at a new time is one call, an operation (start, then poll) two.
  {
    costar::dds::RemoteConfig lockstep_config;
    lockstep_config.partition = config.partition + "-lockstep";
    lockstep_config.lockstep = true;
    const pid_t lockstep_host = startHost(lockstep_config, "--lockstep-host");
    const auto lockstep_client = costar::dds::RemoteClient::create(lockstep_config);
    const auto lockstep_logger = lockstep_client->connect("test_logger", std::chrono::seconds(20));
    std::int64_t tick = 0;
    const auto nextTick = [&] {
      lockstep_client->publishClock(costar::TimePoint(std::chrono::milliseconds(10 * ++tick)));
    };
    const auto reports = [&](Component& component, int n) {
      std::vector<double> samples;
      for (int i = 0; i < n; ++i) {
        nextTick();
        const auto begin = Clock::now();
        (void)component.report();
        samples.push_back(micros(Clock::now() - begin));
      }
      return samples;
    };
    reports(*lockstep_logger, 100);  // warm up
    print("lockstep: a report at a new simulated time", stats(reports(local_logger, count)),
          stats(reports(*lockstep_logger, count)));
    std::vector<double> local_operations, remote_operations;
    for (int i = 0; i < count; ++i) {
      nextTick();
      local_operations.push_back(roundTrips(local_logger, "TestLog", log, 1).front());
      remote_operations.push_back(roundTrips(*lockstep_logger, "TestLog", log, 1).front());
    }
    print("lockstep: an operation (start, poll)", stats(local_operations), stats(remote_operations));
    ::kill(lockstep_host, SIGTERM);
    ::waitpid(lockstep_host, nullptr, 0);
  }

  // A host killed with SIGKILL in the middle of an operation: time until poll says FAILURE.
  std::vector<double> noticed;
  for (int i = 0; i < kills; ++i) {
    const auto id = remote_actions->start("TestAction", forever);
    std::this_thread::sleep_for(std::chrono::milliseconds(50 + 37 * i));  // somewhere between heartbeats
    ::kill(host, SIGKILL);
    const auto killed = Clock::now();
    ::waitpid(host, nullptr, 0);
    while (remote_actions->poll(id).state == OperationState::kRunning) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    noticed.push_back(micros(Clock::now() - killed) / 1000.0);
    host = startHost(config);
    // The restarted host is used again by the same proxies.
    const auto give_up = Clock::now() + std::chrono::seconds(30);
    for (;;) {
      if (Clock::now() > give_up) {
        std::fprintf(stderr, "dds_bench: the restarted host was not heard within 30 s\n");
        ::kill(host, SIGKILL);
        return 1;
      }
      try {
        roundTrips(*remote_actions, "TestAction", {{"result", "success"}, {"polls", 0LL}, {"reason", ""}}, 1);
        break;
      } catch (const std::exception&) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    }
  }
  if (kills > 0) {
    const Stats kill_stats = stats(noticed);
    std::printf("host killed (SIGKILL) until poll FAILURE, %d kills: median %.0f ms, max %.0f ms\n", kills,
                kill_stats.median, kill_stats.max);
  }
  ::kill(host, SIGTERM);
  ::waitpid(host, nullptr, 0);
  return 0;
}
