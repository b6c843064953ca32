// Success counts of the 3-finger adaptive gripper: every mode x part (node, link) over seeded
// part placements and yaws on the test bench, the gripper missing the grasp by up to 4 mm and
// 4 degrees (as a perception error would), each pick judged from the simulated world's true
// state (sim/gripper_bench.h). Usage: gripper_trials [N per cell, default 20] [seed, default 1]
// Figures: docs/BENCHMARKS.md, section "3-finger adaptive gripper".

#include <cstdio>
#include <cstdlib>
#include <map>
#include <random>
#include <string>

#include "core/paths.h"
#include "sim/gripper_bench.h"
#include "smartmove/grasps.h"

int main(int argc, char** argv) {
  using namespace costar;
  const int n = argc > 1 ? std::atoi(argv[1]) : 20;
  const unsigned seed = argc > 2 ? static_cast<unsigned>(std::strtoul(argv[2], nullptr, 10)) : 1u;
  if (n <= 0 || n > 10000) {
    std::fprintf(stderr, "usage: gripper_trials [N per mode and part, 1..10000] [seed]\n");
    return 2;
  }
  const smartmove::GraspLibrary grasps(dataRoot() / "data/grasps.json", {}, smartmove::kAdaptiveGripper);
  std::printf("%-6s %-8s %9s %12s %12s  first failure\n", "part", "mode", "success", "close s", "lifted mm");
  int total = 0;
  int total_ok = 0;
  for (const std::string part : {"node", "link"}) {
    for (const gripper::GripperMode mode : gripper::kGripperModes) {
      // The same placements for every mode of a part: seed, part.
      std::mt19937_64 random(seed * 1000 + (part == "node" ? 1 : 2));
      std::uniform_real_distribution<double> offset(-0.08, 0.08);
      std::uniform_real_distribution<double> yaw(-M_PI, M_PI);
      // The gripper misses the part as a perception error would: up to 4 mm and 4 degrees.
      std::uniform_real_distribution<double> miss(-0.004, 0.004);
      std::uniform_real_distribution<double> turn(-4.0 * M_PI / 180.0, 4.0 * M_PI / 180.0);
      int ok = 0;
      double close = 0.0;
      double lifted = 0.0;
      std::string first_failure;
      for (int i = 0; i < n; ++i) {
        sim::GripperTrialOptions options;
        options.bench.part_class = part;
        options.bench.part_x = offset(random);
        options.bench.part_y = offset(random);
        options.bench.part_yaw = yaw(random);
        options.approach_error.x() = miss(random);
        options.approach_error.y() = miss(random);
        options.approach_error.z() = turn(random);
        options.mode = mode;
        options.tcp_in_part = grasps.find(part, std::string(gripper::toString(mode)))->tcp_in_object;
        const sim::GripperTrialResult result = sim::runGripperTrial(options);
        ok += result.success ? 1 : 0;
        close += result.close_seconds;
        lifted += result.lifted;
        if (!result.success && first_failure.empty()) {
          first_failure = "#" + std::to_string(i) + ": " + result.reason;
        }
      }
      std::printf("%-6s %-8s %5d/%-3d %12.3f %12.1f  %s\n", part.c_str(), std::string(gripper::toString(mode)).c_str(),
                  ok, n, close / n, 1000 * lifted / n, first_failure.c_str());
      std::fflush(stdout);
      total += n;
      total_ok += ok;
    }
  }
  std::printf("total %d/%d\n", total_ok, total);
  return total_ok == total ? 0 : 1;
}
