// Measures the editor's server on the simulated UR5 cell (figures for docs/BENCHMARKS.md):
//   1. the run's speed with no browser and with browsers connected to the live stream
//      (the blind pick-and-place, unpaced, i.e. as fast as the machine allows),
//   2. the stream's rate at real-time pace,
//   3. API latency over loopback (reads, a validated and committed save, a run start).
// Usage: build-server/server/server_bench [clients=3] [repeats=3]

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "bt/plan_xml.h"
#include "core/paths.h"
#include "server/auth.h"
#include "server/engine.h"
#include "server/http_server.h"
#include "server/plan_json.h"
#include "server/serve.h"
#include "server/test/http_client.h"

using namespace costar;
using nlohmann::json;
namespace testing = costar::server::testing;
using Wall = std::chrono::steady_clock;

namespace {

std::filesystem::path g_dir;

std::unique_ptr<server::Server> startServer(double pace) {
  server::ServeOptions options;
  options.workcell.name = "ur5-sim";
  options.workcell.scene = dataRoot() / "sim/scenes/one_node.json";
  options.workcell.waypoints = dataRoot() / "examples/ur5/blind_waypoints.json";
  options.workcell.memory_only = true;
  options.port = 0;
  options.store = g_dir / ("bench_" + server::randomToken().substr(0, 6) + ".sqlite");
  options.pace = pace;
  return std::make_unique<server::Server>(options);
}

/// Clients that read the stream until stopped, counting state messages.
struct Watchers {
  Watchers(std::uint16_t port, int count) {
    for (int i = 0; i < count; ++i) {
      threads.emplace_back([this, port] {
        testing::WebSocket ws(port);
        while (!stop) {
          const auto message = ws.read(std::chrono::milliseconds(500));
          if (!message) {
            continue;
          }
          ++messages;
          if (message->find("\"type\":\"state\"") != std::string::npos) {
            ++states;
          }
        }
      });
    }
  }
  ~Watchers() {
    stop = true;
    for (auto& t : threads) {
      t.join();
    }
  }
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> messages{0};
  std::atomic<std::uint64_t> states{0};
  std::vector<std::thread> threads;
};

double runBlindPlan(server::Server& server) {
  const std::string xml = bt::writePlanFile(bt::loadPlan(dataRoot() / "examples/ur5/blind_pick_place.xml").file);
  const auto start = Wall::now();
  const auto response = testing::request(server.port(), "POST", "/api/runs", json{{"xml", xml}}.dump(), server.token());
  if (response.status != 202) {
    std::fprintf(stderr, "run refused: %s\n", response.body.c_str());
    std::exit(1);
  }
  const std::int64_t id = json::parse(response.body)["run"];
  while (true) {
    const auto status = server.engine().runStatus(id);
    if (status && !(*status)["active"].get<bool>()) {
      if ((*status)["result"] != "SUCCESS") {
        std::fprintf(stderr, "run failed: %s\n", status->dump().c_str());
      }
      return std::chrono::duration<double>(Wall::now() - start).count();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

double percentile(std::vector<double> values, double p) {
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, static_cast<std::size_t>(p * values.size()))];
}

}  // namespace

int main(int argc, char** argv) {
  const int clients = argc > 1 ? std::atoi(argv[1]) : 3;
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 3;
  g_dir = std::filesystem::temp_directory_path() / ("costar_server_bench_" + server::randomToken().substr(0, 8));
  std::filesystem::create_directories(g_dir);

  // 1. Run speed, unpaced, without and with stream clients (interleaved, so that the machine's
  //    other load affects both alike).
  std::printf("1. blind pick-and-place (examples/ur5/blind_pick_place.xml), unpaced, %d repeats each, interleaved\n",
              repeats);
  struct Series {
    std::vector<double> walls, cpus;
    double sim_seconds = 0, snapshot_ms = 0;
    std::uint64_t states = 0;
  };
  Series series[2];
  for (int r = 0; r < repeats; ++r) {
    for (int k = 0; k < 2; ++k) {
      const int watching = k == 0 ? 0 : clients;
      Series& out = series[k];
      auto server = startServer(0.0);
      std::unique_ptr<Watchers> watchers;
      if (watching > 0) {
        watchers = std::make_unique<Watchers>(server->port(), watching);
        while (server->http().streamClients() < static_cast<std::size_t>(watching)) {
          std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
      }
      out.walls.push_back(runBlindPlan(*server));
      const auto last = server->engine().runStatus(std::nullopt);
      out.sim_seconds = (*last)["clock_seconds"];
      out.cpus.push_back((*last)["cpu_seconds"].get<double>());
      const auto stats = server->engine().stats();
      out.snapshot_ms = 1000.0 * stats.snapshot_seconds / std::max<std::uint64_t>(1, stats.snapshots);
      if (watchers) {
        out.states += watchers->states / static_cast<std::uint64_t>(watching);
      }
    }
  }
  for (int k = 0; k < 2; ++k) {
    const Series& out = series[k];
    std::printf(
        "   %d stream client(s): median %.3f s wall, %.3f s CPU of the engine thread, for %.2f s simulated "
        "(%.1fx real time); snapshot %.3f ms each%s\n",
        k == 0 ? 0 : clients, median(out.walls), median(out.cpus), out.sim_seconds, out.sim_seconds / median(out.walls),
        out.snapshot_ms,
        k == 0 ? ""
               : (", " + std::to_string(out.states / static_cast<std::uint64_t>(repeats)) +
                  " state messages per client per run")
                     .c_str());
  }

  // 2. Stream rate at real-time pace (idle cell, then during a run).
  {
    auto server = startServer(1.0);
    Watchers watchers(server->port(), clients);
    while (server->http().streamClients() < static_cast<std::size_t>(clients)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    const std::uint64_t before = watchers.states;
    const auto start = Wall::now();
    std::this_thread::sleep_for(std::chrono::seconds(3));
    const double seconds = std::chrono::duration<double>(Wall::now() - start).count();
    const double rate = static_cast<double>(watchers.states - before) / seconds / clients;
    std::printf("2. stream at real-time pace, %d clients, idle cell: %.1f state messages/s per client\n", clients,
                rate);
    const std::uint64_t before_run = watchers.states;
    const double wall = runBlindPlan(*server);
    const auto last = server->engine().runStatus(std::nullopt);
    std::printf(
        "   during the blind run (%.2f s wall for %.2f s simulated): %.1f state messages/s per client, "
        "%llu messages in all\n",
        wall, (*last)["clock_seconds"].get<double>(),
        static_cast<double>(watchers.states - before_run) / wall / clients,
        static_cast<unsigned long long>(watchers.messages.load()));
  }

  // 3. API latency over loopback.
  {
    auto server = startServer(1.0);
    const std::uint16_t port = server->port();
    const auto time = [&](const char* what, auto&& request, int n) {
      std::vector<double> ms;
      for (int i = 0; i < n; ++i) {
        const auto start = Wall::now();
        const int status = request(i);
        ms.push_back(std::chrono::duration<double, std::milli>(Wall::now() - start).count());
        if (status >= 400) {
          std::fprintf(stderr, "%s: status %d\n", what, status);
          std::exit(1);
        }
      }
      std::printf("   %-48s median %.2f ms, p99 %.2f ms (%d requests)\n", what, median(ms), percentile(ms, 0.99), n);
    };
    std::printf("3. API latency over loopback (new connection per request)\n");
    time(
        "GET /api/state", [&](int) { return testing::request(port, "GET", "/api/state").status; }, 300);
    time(
        "GET /api/nodes", [&](int) { return testing::request(port, "GET", "/api/nodes").status; }, 300);
    time(
        "GET /api/choices (engine thread)", [&](int) { return testing::request(port, "GET", "/api/choices").status; },
        300);
    const std::string plan =
        json{{"xml", bt::writePlanFile(bt::loadPlan(dataRoot() / "examples/ur5/blind_pick_place.xml").file)}}.dump();
    time(
        "PUT /api/plans/NAME (validate + commit)",
        [&](int i) {
          return testing::request(port, "PUT", "/api/plans/p" + std::to_string(i % 10), plan, server->token()).status;
        },
        300);
  }
  // 4. Motions without the token: none may be accepted.
  {
    auto server = startServer(1.0);
    const std::uint16_t port = server->port();
    const std::string run =
        json{{"xml", bt::writePlanFile(bt::loadPlan(dataRoot() / "examples/ur5/blind_pick_place.xml").file)}}.dump();
    const std::string move = json{{"node", "Move"}, {"attributes", {{"waypoint", "above_pick"}}}}.dump();
    const std::string jog = json{{"node", "JogJoint"}, {"attributes", {{"joint", "1"}, {"degrees", "10"}}}}.dump();
    const std::string tokens[] = {"", "wrong-token-0123456789", server->token().substr(0, 63), server->token() + "x"};
    int accepted = 0;
    int requests = 0;
    for (int i = 0; i < 2500; ++i) {
      const std::string& token = tokens[i % 4];
      for (const auto& [target, body] : {std::pair<std::string, std::string>{"/api/runs", run},
                                         {"/api/operations", move},
                                         {"/api/operations", jog},
                                         {"/api/control", R"({"action": "step"})"}}) {
        ++requests;
        if (testing::request(port, "POST", target, body, token).status < 300) {
          ++accepted;
        }
      }
    }
    std::printf(
        "4. motions without the token (none, wrong, truncated, extended): %d of %d accepted; runs started: %llu\n",
        accepted, requests, static_cast<unsigned long long>(server->engine().stats().runs));
  }
  std::filesystem::remove_all(g_dir);
  return 0;
}
