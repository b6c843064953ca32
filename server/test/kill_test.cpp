// kill -9 during saves: a real server process (serve_child) saves plans and teaches waypoints
// for as long as a writer keeps asking, and is killed with SIGKILL at a random moment,
// repeatedly. Every save the server acknowledged must be there afterwards, and the database
// must pass SQLite's integrity_check. COSTAR_KILL_TRIALS sets the number of kills (default 10).

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <thread>

#include "arm/waypoints.h"
#include "core/paths.h"
#include "server/auth.h"
#include "server/store.h"
#include "server/test/child_process.h"
#include "server/test/http_client.h"

namespace costar::server {
namespace {

using nlohmann::json;

using testing::Child;

struct Acknowledged {
  std::mutex mutex;
  std::vector<std::tuple<std::string, int, std::string>> plans;  // name, version, marker
  std::vector<std::string> waypoints;
};

TEST(KillDuringSaves, LosesNothingAcknowledgedAndTheDatabaseStaysSound) {
  int trials = 10;
  if (const char* env = std::getenv("COSTAR_KILL_TRIALS")) {
    trials = std::max(1, std::atoi(env));
  }
  const auto dir = std::filesystem::temp_directory_path() / ("costar_kill_test_" + randomToken().substr(0, 8));
  std::filesystem::create_directories(dir);
  const auto db = dir / "editor.sqlite";
  const auto waypoints = dir / "waypoints.json";
  const auto token_file = dir / "token";
  std::filesystem::copy_file(dataRoot() / "examples/ur5/blind_waypoints.json", waypoints);
  const std::string token = tokenFromFile(token_file);

  std::mt19937 random(20261121);
  Acknowledged acknowledged;
  std::size_t interrupted_saves = 0;
  for (int trial = 0; trial < trials; ++trial) {
    Child child({COSTAR_SERVE_CHILD, "--workcell", "ur5-sim", "--scene",
                 (dataRoot() / "sim/scenes/one_node.json").string(), "--waypoints", waypoints.string(), "--store",
                 db.string(), "--token-file", token_file.string(), "--pace", "0"});
    const std::uint16_t port = child.waitForPort();
    ASSERT_NE(port, 0) << "trial " << trial << ": the server did not start";

    std::atomic<bool> stop{false};
    std::atomic<int> attempts{0};
    // Plans: three names, many versions, each with a marker that says which save it was.
    std::thread plans([&] {
      for (int k = 0; !stop; ++k) {
        const std::string name = "plan_" + std::to_string(k % 3);
        const std::string marker = "trial " + std::to_string(trial) + " save " + std::to_string(k);
        const json root = {{"id", "Sequence"},
                           {"attributes", json::array({json::array({"name", marker})})},
                           {"children", json::array({json{{"id", "AlwaysSuccess"}}, json{{"id", "Home"}}})}};
        const json body = {
            {"plan", {{"main_tree", "main"}, {"trees", json::array({json{{"id", "main"}, {"root", root}}})}}}};
        ++attempts;
        testing::Response response;
        try {
          response = testing::request(port, "PUT", "/api/plans/" + name, body.dump(), token);
        } catch (const std::exception&) {
          return;  // the server is gone
        }
        if (response.status == 201) {
          const std::lock_guard lock(acknowledged.mutex);
          acknowledged.plans.emplace_back(name, json::parse(response.body)["version"].get<int>(), marker);
        } else if (response.status == 0) {
          return;
        }
      }
    });
    // Waypoints: taught through the arm's Teach operation; acknowledged when it succeeded.
    std::thread teach([&] {
      for (int k = 0; !stop; ++k) {
        std::string name = "w";  // (not "w" + ...: GCC 12 warns falsely about that)
        name += std::to_string(trial) + "_" + std::to_string(k);
        try {
          const testing::Response started = testing::request(
              port, "POST", "/api/operations",
              json{{"node", "Teach"}, {"attributes", {{"waypoint", name}, {"kind", "joints"}}}}.dump(), token);
          if (started.status != 202) {
            if (started.status == 0) {
              return;
            }
            continue;
          }
          const std::string id = std::to_string(json::parse(started.body)["run"].get<long long>());
          while (!stop) {
            const testing::Response status = testing::request(port, "GET", "/api/runs/" + id);
            if (status.status != 200) {
              return;
            }
            const json run = json::parse(status.body);
            if (!run["active"].get<bool>()) {
              if (run["result"] == "SUCCESS") {
                const std::lock_guard lock(acknowledged.mutex);
                acknowledged.waypoints.push_back(name);
              }
              break;
            }
          }
        } catch (const std::exception&) {
          return;
        }
      }
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(std::uniform_int_distribution<int>(100, 600)(random)));
    child.kill();
    stop = true;
    plans.join();
    teach.join();
    ++interrupted_saves;

    // Everything acknowledged so far is there, and the database is sound.
    Store store(db);
    ASSERT_EQ(store.integrityCheck(), "ok") << "trial " << trial;
    const std::lock_guard lock(acknowledged.mutex);
    for (const auto& [name, version, marker] : acknowledged.plans) {
      const auto document = store.load(DocumentKind::kPlan, name, version);
      ASSERT_TRUE(document) << "trial " << trial << ": lost " << name << " v" << version;
      EXPECT_NE(document->xml.find(marker), std::string::npos) << name << " v" << version;
    }
    const arm::WaypointStore taught(waypoints, /*persist=*/false);
    for (const std::string& name : acknowledged.waypoints) {
      EXPECT_TRUE(taught.find(name)) << "trial " << trial << ": lost waypoint " << name;
    }
    EXPECT_TRUE(taught.find("above_pick"));
  }
  std::printf("kill -9 trials: %d, acknowledged plan saves: %zu, acknowledged waypoints: %zu, lost: 0\n", trials,
              acknowledged.plans.size(), acknowledged.waypoints.size());
  EXPECT_GT(acknowledged.plans.size(), 0u);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace costar::server
