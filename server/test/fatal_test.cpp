// A server that must die stops the arm first: a real server process (serve_child, the
// simulated UR5 cell) moves the arm slowly under a Move operation when it hits std::terminate
// (an exception escaping a thread) or a fatal signal. Before it dies it stops the active run
// (the Move is cancelled: the arm decelerates and stops) and says so on stderr; then it dies
// of the same cause.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "core/paths.h"
#include "server/auth.h"
#include "server/test/child_process.h"
#include "server/test/http_client.h"

namespace costar::server {
namespace {

using nlohmann::json;
using testing::Child;

class FatalTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("costar_fatal_test_" + randomToken().substr(0, 8));
    std::filesystem::create_directories(dir_);
    std::filesystem::copy_file(dataRoot() / "examples/ur5/blind_waypoints.json", dir_ / "waypoints.json");
    token_ = tokenFromFile(dir_ / "token");
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::vector<std::string> args(const std::string& workcell = "ur5-sim") const {
    return {COSTAR_SERVE_CHILD,
            "--test-overflow-on-sigusr2",
            "--workcell",
            workcell,
            "--scene",
            (dataRoot() / "sim/scenes/one_node.json").string(),
            "--waypoints",
            (dir_ / "waypoints.json").string(),
            "--memory-only",
            "--store",
            (dir_ / "editor.sqlite").string(),
            "--token-file",
            (dir_ / "token").string(),
            "--pace",
            "1",
            "--test-terminate-on-sigusr1"};
  }
  std::string stderrText() const {
    std::ifstream in(dir_ / "stderr.txt");
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  }
  /// Starts a slow Move and waits until the run is active.
  void startSlowMove(std::uint16_t port) {
    const testing::Response started = testing::request(
        port, "POST", "/api/operations",
        json{{"node", "Move"}, {"attributes", {{"waypoint", "above_place"}, {"speed", "0.05"}}}}.dump(), token_);
    ASSERT_EQ(started.status, 202) << started.body;
    const std::string id = std::to_string(json::parse(started.body)["run"].get<long long>());
    for (int i = 0; i < 500; ++i) {
      const testing::Response status = testing::request(port, "GET", "/api/runs/" + id);
      ASSERT_EQ(status.status, 200) << status.body;
      if (json::parse(status.body)["active"].get<bool>()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the arm is on its way
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    FAIL() << "the Move never became active";
  }

  std::filesystem::path dir_;
  std::string token_;
};

TEST_F(FatalTest, TerminateMidMotionStopsTheRunBeforeDying) {
  Child child(args(), dir_ / "stderr.txt");
  const std::uint16_t port = child.waitForPort();
  ASSERT_NE(port, 0) << stderrText();
  startSlowMove(port);
  child.signal(SIGUSR1);  // an exception escapes a thread: std::terminate
  const int status = child.wait(20'000);
  ASSERT_NE(status, -1) << "the server did not die";
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGABRT);
  const std::string err = stderrText();
  EXPECT_NE(err.find("fatal error (std::terminate): TEST: an exception escapes a thread"), std::string::npos) << err;
  EXPECT_NE(err.find("the active run was stopped"), std::string::npos) << err;
}

TEST_F(FatalTest, FatalSignalMidMotionStopsTheRunBeforeDying) {
  Child child(args(), dir_ / "stderr.txt");
  const std::uint16_t port = child.waitForPort();
  ASSERT_NE(port, 0) << stderrText();
  startSlowMove(port);
  child.signal(SIGSEGV);
  const int status = child.wait(20'000);
  ASSERT_NE(status, -1) << "the server did not die";
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGSEGV);
  const std::string err = stderrText();
  EXPECT_NE(err.find("fatal signal SIGSEGV"), std::string::npos) << err;
  EXPECT_NE(err.find("the active run was stopped"), std::string::npos) << err;
}

TEST_F(FatalTest, StackOverflowInAnIoThreadMidMotionStopsTheRunBeforeDying) {
  // Issue 27: a request that overflowed a thread's stack killed the server with nothing
  // printed and the arm moving: the handler had no stack to run on. Each server thread has an
  // alternate signal stack now.
  Child child(args(), dir_ / "stderr.txt");
  const std::uint16_t port = child.waitForPort();
  ASSERT_NE(port, 0) << stderrText();
  startSlowMove(port);
  ASSERT_TRUE(child.signalThread("costar-io", SIGUSR2));  // that thread recurses until its stack runs out
  const int status = child.wait(20'000);
  ASSERT_NE(status, -1) << "the server did not die";
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGSEGV);
  const std::string err = stderrText();
  EXPECT_NE(err.find("fatal signal SIGSEGV (a stack overflow) in the io thread"), std::string::npos) << err;
  EXPECT_NE(err.find("the active run was stopped (its operations cancelled)"), std::string::npos) << err;
}

TEST_F(FatalTest, StackOverflowInTheEngineThreadSaysNothingCommandsTheArm) {
  Child child(args(), dir_ / "stderr.txt");
  const std::uint16_t port = child.waitForPort();
  ASSERT_NE(port, 0) << stderrText();
  startSlowMove(port);
  ASSERT_TRUE(child.signalThread("costar-engine", SIGUSR2));
  const int status = child.wait(20'000);
  ASSERT_NE(status, -1) << "the server did not die";
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGSEGV);
  const std::string err = stderrText();
  EXPECT_NE(err.find("fatal signal SIGSEGV (a stack overflow) in the engine thread"), std::string::npos) << err;
  EXPECT_NE(err.find("the engine thread, which commands the arm, is the one that failed"), std::string::npos) << err;
}

TEST_F(FatalTest, TerminateWhileIdleSaysNothingWasMoving) {
  Child child(args("test"), dir_ / "stderr.txt");
  const std::uint16_t port = child.waitForPort();
  ASSERT_NE(port, 0) << stderrText();
  child.signal(SIGUSR1);
  const int status = child.wait(20'000);
  ASSERT_TRUE(status != -1 && WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGABRT);
  EXPECT_NE(stderrText().find("no run was active"), std::string::npos) << stderrText();
}

}  // namespace
}  // namespace costar::server
