// Random motion commands on the simulated UR5, through the whole stack (plan -> Arm component
// -> IK, collision checks, planner, trajectory -> controller -> physics). Reports how many were
// carried out or refused (and why), the fastest joint speed and the largest joint position
// observed at any physics tick, the lowest point the tool reached, and every physics step in
// which the arm touched the table. Target: 0 limit violations and 0 table contacts in 10,000.
//   build/bench/motion_safety [count] [seed]

#include <chrono>
#include <cstdio>
#include <map>
#include <random>
#include <regex>
#include <string>

#include "bt/builder.h"
#include "bt/executor.h"
#include "bt/plan_xml.h"
#include "core/paths.h"
#include "sim/simulation.h"
#include "workcell/workcell.h"

using namespace costar;

int main(int argc, char** argv) {
  if (argc > 3 || (argc > 1 && std::string(argv[1]).find_first_not_of("0123456789") != std::string::npos) ||
      (argc > 2 && std::string(argv[2]).find_first_not_of("0123456789") != std::string::npos)) {
    std::fprintf(stderr,
                 "usage: motion_safety [COUNT] [SEED]\n"
                 "  sends COUNT (default 1000) random MoveToPose commands to the simulated UR5 and reports\n"
                 "  joint limits, speeds, the lowest tool point and arm-table contacts seen in physics\n");
    return 2;
  }
  const int count = argc > 1 ? std::atoi(argv[1]) : 1000;
  const std::uint64_t seed = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 1;
  const auto cell = workcell::makeWorkcell(
      {.name = "ur5-sim", .scene = dataRoot() / "sim/scenes/assembly.json", .seed = seed, .memory_only = true});
  sim::Simulation& simulation = *cell->simulation();
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> x(-0.2, 0.9), y(-0.7, 0.7), z(-0.15, 0.7), angle(-M_PI, M_PI);
  std::uniform_real_distribution<double> speed(0.1, 1.0);
  int moved = 0;
  double fastest = 0, widest = 0, lowest_tool = 1e9;
  std::map<std::string, int> refusals;
  const std::regex number(R"(-?\d+(\.\d+)?)");
  const auto wall_start = std::chrono::steady_clock::now();
  for (int i = 0; i < count; ++i) {
    const world::Pose goal =
        world::poseFromXyzRpy(x(random), y(random), z(random), angle(random), angle(random) / 2, angle(random));
    const std::string xml = R"(<root BTCPP_format="4"><BehaviorTree ID="m"><MoveToPose pose=")" +
                            world::formatPose(goal) + R"(" speed=")" + std::to_string(speed(random)) +
                            R"("/></BehaviorTree></root>)";
    bt::Tree tree = bt::buildTree(bt::loadPlanText(xml, "random"), cell->nodes(), cell->clock());
    bt::Executor executor(tree, cell->clock());
    executor.setBeforeTick([&] {
      cell->beforeTick();
      for (const double v : simulation.armVelocities()) fastest = std::max(fastest, std::abs(v));
      for (const double q : simulation.armPositions()) widest = std::max(widest, std::abs(q));
      lowest_tool = std::min(lowest_tool, simulation.tcpPose().translation().z());
    });
    const bt::RunResult result = executor.run();
    if (result.status == bt::Status::kSuccess) {
      ++moved;
    } else {
      ++refusals[std::regex_replace(result.failure_reason.substr(0, 90), number, "#")];
    }
    if ((i + 1) % 500 == 0) {
      std::fprintf(stderr, "%d/%d commands, %llu table-contact steps so far\n", i + 1, count,
                   static_cast<unsigned long long>(simulation.armTableContactSteps()));
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  std::printf("%d random motion commands (seed %llu): %d carried out, %d refused\n", count,
              static_cast<unsigned long long>(seed), moved, count - moved);
  std::printf("fastest joint speed %.3f rad/s (limit %.3f), largest |joint| %.3f rad (limit %.3f)\n", fastest, M_PI,
              widest, 2 * M_PI);
  std::printf("lowest tool centre point %.4f m above the table; arm-table contact steps: %llu\n", lowest_tool,
              static_cast<unsigned long long>(simulation.armTableContactSteps()));
  std::printf("%.0f s simulated in %.0f s wall\n", toSeconds(simulation.time()), wall);
  std::printf("refusals:\n");
  for (const auto& [reason, n] : refusals) std::printf("  %5d  %s\n", n, reason.c_str());
  return simulation.armTableContactSteps() == 0 && fastest <= M_PI * 1.02 && widest <= 2 * M_PI + 1e-3 ? 0 : 1;
}
