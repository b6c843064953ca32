// A few faults of each kind in the simulated UR5 cell, on the paper's task 1 (its first
// seconds): every one must end as FAILURE with a path and a reason within 1 s of taking
// effect, with the arm at rest and the waypoint file unchanged.

#include "faults/campaign.h"

#include <gtest/gtest.h>

#include "core/paths.h"

namespace costar::faults {
namespace {

TEST(FaultCampaign, EveryFaultStopsTheTaskInTimeWithTheArmAtRest) {
  CampaignOptions options;
  options.tasks = {paperTasks().front()};
  options.faults = {"nan:arm-driver", "hang:arm-driver", "throw:gripper-driver", "nan-frame:camera",
                    "hang:camera",    "die:smartmove",   "hang:perception",      "throw:arm"};
  options.count = static_cast<int>(options.faults.size());
  options.seed = 11;
  options.window_s = 4.0;  // task 1 takes about 6 s: every fault is due while it runs
  options.waypoints = dataRoot() / "examples/ur5/blind_waypoints.json";
  const CampaignSummary summary = runCampaign(options);
  ASSERT_EQ(summary.trials.size(), options.faults.size());
  for (const FaultTrial& trial : summary.trials) {
    SCOPED_TRACE(trial.fault + ": " + trial.outcome + " at " + trial.failure_path + ": " + trial.reason);
    if (trial.outcome == "no-effect") {
      continue;  // throw:arm when no Move/Home followed the moment: honest, and judged apart
    }
    EXPECT_EQ(trial.outcome, "stopped");
    EXPECT_FALSE(trial.failure_path.empty());
    EXPECT_FALSE(trial.reason.empty());
    EXPECT_LE(trial.latency_s, 1.0);
    EXPECT_LT(trial.final_speed, 0.01);
    EXPECT_TRUE(trial.waypoints_intact);
  }
  EXPECT_NE(summary.text().find("all"), std::string::npos);
}

}  // namespace
}  // namespace costar::faults
