// Operations of the test components through a component host in a child process (the
// dds_test_host executable), over DDS on loopback, each test in a partition of its own.

#include "dds/remote_component.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <thread>

#include "component/registry.h"
#include "dds/host.h"
#include "testing/test_components.h"

namespace costar::dds {
namespace {

using component::OperationResult;
using component::OperationState;
using std::chrono::milliseconds;
using std::chrono::seconds;

/// Only to keep a broken test from hanging: no result depends on it.
constexpr auto kHangGuard = seconds(20);

std::string uniquePartition() {
  static int count = 0;
  return "costar-test-" + std::to_string(::getpid()) + "-" + std::to_string(++count);
}

/// A dds_test_host child serving `components` in `partition`; killed when destroyed.
class HostProcess {
 public:
  HostProcess(const std::string& partition, std::vector<std::string> components) {
    std::vector<std::string> args = {COSTAR_DDS_TEST_HOST, partition};
    args.insert(args.end(), components.begin(), components.end());
    pid_ = ::fork();
    if (pid_ == 0) {
      std::vector<char*> argv;
      for (auto& arg : args) {
        argv.push_back(arg.data());
      }
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
  }
  HostProcess(const HostProcess&) = delete;
  HostProcess& operator=(const HostProcess&) = delete;
  ~HostProcess() { kill(SIGKILL); }

  void kill(int signal) {
    if (pid_ > 0) {
      ::kill(pid_, signal);
      ::waitpid(pid_, nullptr, 0);
      pid_ = -1;
    }
  }

 private:
  pid_t pid_ = -1;
};

/// Polls `id` until it ends (or the hang guard).
OperationResult pollToEnd(component::Component& component, component::OperationId id) {
  const auto deadline = std::chrono::steady_clock::now() + kHangGuard;
  while (std::chrono::steady_clock::now() < deadline) {
    OperationResult result = component.poll(id);
    if (result.state != OperationState::kRunning) {
      return result;
    }
    std::this_thread::sleep_for(milliseconds(1));
  }
  return OperationResult::failure("the test's hang guard: no end");
}

class RemoteComponentTest : public ::testing::Test {
 protected:
  RemoteComponentTest() { config_.partition = uniquePartition(); }

  std::shared_ptr<RemoteComponent> connect(const std::string& component) {
    if (!client_) {
      client_ = RemoteClient::create(config_);
    }
    return client_->connect(component, std::chrono::duration_cast<milliseconds>(kHangGuard));
  }

  RemoteConfig config_;
  std::shared_ptr<RemoteClient> client_;
};

TEST_F(RemoteComponentTest, AnOperationRunsInTheHostAndEndsWithItsResult) {
  HostProcess host(config_.partition, {"test_actions"});
  const auto actions = connect("test_actions");
  EXPECT_EQ(actions->description().name, "test_actions");
  EXPECT_NE(actions->description().operation("TestAction"), nullptr);

  const auto ok = actions->start("TestAction", {{"result", "success"}, {"polls", 5LL}, {"reason", ""}});
  EXPECT_EQ(pollToEnd(*actions, ok).state, OperationState::kSuccess);
  // Once ended, the id is forgotten, as in the executor's process.
  EXPECT_THROW(actions->poll(ok), std::invalid_argument);

  const auto bad = actions->start("TestAction", {{"result", "failure"}, {"polls", 2LL}, {"reason", "jammed"}});
  const OperationResult failed = pollToEnd(*actions, bad);
  EXPECT_EQ(failed.state, OperationState::kFailure);
  EXPECT_EQ(failed.reason, "jammed");
}

TEST_F(RemoteComponentTest, AComponentFaultInTheHostIsAFailureWithItsReason) {
  HostProcess host(config_.partition, {"test_actions"});
  const auto actions = connect("test_actions");
  const OperationResult result = pollToEnd(*actions, actions->start("TestThrow", {}));
  EXPECT_EQ(result.state, OperationState::kFailure);
  EXPECT_NE(result.reason.find("simulated component fault"), std::string::npos) << result.reason;
}

TEST_F(RemoteComponentTest, AnUnknownOperationIsRejectedWithTheReason) {
  HostProcess host(config_.partition, {"test_actions"});
  const auto actions = connect("test_actions");
  const OperationResult result = pollToEnd(*actions, actions->start("NoSuchOperation", {}));
  EXPECT_EQ(result.state, OperationState::kFailure);
  EXPECT_NE(
      result.reason.find("test_actions rejected NoSuchOperation: test_actions has no operation 'NoSuchOperation'"),
      std::string::npos)
      << result.reason;
  // Parameters the operation does not declare are rejected likewise.
  const OperationResult typo = pollToEnd(*actions, actions->start("TestAction", {{"pols", 3LL}}));
  EXPECT_EQ(typo.state, OperationState::kFailure);
  EXPECT_NE(typo.reason.find("pols"), std::string::npos) << typo.reason;
}

TEST_F(RemoteComponentTest, CancelStopsTheOperationInTheHost) {
  HostProcess host(config_.partition, {"test_actions"});
  const auto actions = connect("test_actions");
  const auto id = actions->start("TestAction", {{"result", "success"}, {"polls", 1000000000LL}, {"reason", ""}});
  EXPECT_EQ(actions->poll(id).state, OperationState::kRunning);
  actions->cancel(id);
  EXPECT_THROW(actions->poll(id), std::invalid_argument);  // forgotten here at once
  const auto deadline = std::chrono::steady_clock::now() + kHangGuard;
  while (!actions->cancelConfirmed(id) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(milliseconds(1));
  }
  EXPECT_TRUE(actions->cancelConfirmed(id));
}

TEST_F(RemoteComponentTest, AnOperationsEndIsSeenWithTheReportItLeft) {
  HostProcess host(config_.partition, {"test_counter"});
  component::ComponentRegistry registry;
  const auto counter = connect("test_counter");
  registry.add(counter);
  for (int count = 1; count <= 20; ++count) {
    EXPECT_EQ(pollToEnd(*counter, counter->start("TestCount", {{"counter", "parts"}})).state, OperationState::kSuccess);
    // The next tick's world has the count, as in one process: a CheckPredicate after the
    // operation sees its effect.
    registry.refreshWorld();
    const std::vector<std::string> args = {"parts", std::to_string(count)};
    EXPECT_TRUE(registry.world().holds("test_count", args)) << "after count " << count;
  }
  EXPECT_TRUE(registry.stopReason().empty());
}

TEST_F(RemoteComponentTest, AKilledHostFailsItsRunningOperationNamingTheComponentAndStopsTheCell) {
  auto host = std::make_unique<HostProcess>(config_.partition, std::vector<std::string>{"test_actions"});
  const auto actions = connect("test_actions");
  component::ComponentRegistry registry;
  registry.add(actions);
  const auto id = actions->start("TestAction", {{"result", "success"}, {"polls", 1000000000LL}, {"reason", ""}});
  EXPECT_EQ(actions->poll(id).state, OperationState::kRunning);
  host->kill(SIGKILL);

  const OperationResult result = pollToEnd(*actions, id);
  EXPECT_EQ(result.state, OperationState::kFailure);
  EXPECT_NE(result.reason.find("component 'test_actions' stopped answering"), std::string::npos) << result.reason;
  EXPECT_NE(result.reason.find("TestAction ended with it"), std::string::npos) << result.reason;
  // The world cannot be trusted without it: the registry stops the cell, naming it.
  registry.refreshWorld();
  EXPECT_NE(registry.stopReason().find("test_actions"), std::string::npos) << registry.stopReason();
  EXPECT_THROW(actions->start("TestAction", {}), std::runtime_error);

  // A restarted host is used by the same proxy, with no restart of the executor.
  host = std::make_unique<HostProcess>(config_.partition, std::vector<std::string>{"test_actions"});
  const auto deadline = std::chrono::steady_clock::now() + kHangGuard;
  OperationResult again = OperationResult::failure("the restarted host was never heard");
  while (std::chrono::steady_clock::now() < deadline) {
    try {
      again =
          pollToEnd(*actions, actions->start("TestAction", {{"result", "success"}, {"polls", 1LL}, {"reason", ""}}));
      break;
    } catch (const std::runtime_error&) {
      std::this_thread::sleep_for(milliseconds(10));
    }
  }
  EXPECT_EQ(again.state, OperationState::kSuccess) << again.reason;
}

// A host that serves two components takes both with it: the reason the first of them gives (the
// registry asks each in turn) names the other too, whose operation may have been the one running.
TEST_F(RemoteComponentTest, AKilledHostsReasonNamesEveryComponentItServed) {
  HostProcess host(config_.partition, {"test_counter", "test_actions"});
  const auto counter = connect("test_counter");
  const auto actions = connect("test_actions");
  host.kill(SIGKILL);
  const auto deadline = std::chrono::steady_clock::now() + kHangGuard;
  std::string reason;
  while (reason.empty() && std::chrono::steady_clock::now() < deadline) {
    try {
      counter->report();
      std::this_thread::sleep_for(milliseconds(10));
    } catch (const std::runtime_error& error) {
      reason = error.what();
    }
  }
  EXPECT_NE(reason.find("component 'test_counter' stopped answering"), std::string::npos) << reason;
  EXPECT_NE(reason.find("which also served 'test_actions'"), std::string::npos) << reason;
}

TEST_F(RemoteComponentTest, NoHostIsAnErrorNamingTheComponentAndWhereItWasLookedFor) {
  client_ = RemoteClient::create(config_);
  try {
    client_->connect("gripper", milliseconds(200));
    FAIL() << "connected to a component nobody serves";
  } catch (const std::runtime_error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("component 'gripper': no host serves it on DDS domain 0, partition '" + config_.partition),
              std::string::npos)
        << message;
  }
}

TEST_F(RemoteComponentTest, AHostInThisProcessServesAProxyInThisProcess) {
  std::atomic<bool> stop{false};
  ComponentHost host(config_, {std::make_shared<testing::TestLogger>()});
  std::thread serving([&] { host.serve(stop); });
  const auto logger = connect("test_logger");
  EXPECT_EQ(pollToEnd(*logger, logger->start("TestLog", {{"message", "hello"}})).state, OperationState::kSuccess);
  stop = true;
  serving.join();
}

}  // namespace
}  // namespace costar::dds
