#include "trials/trials.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "bt/plan.h"
#include "core/paths.h"
#include "trials/judge.h"

namespace costar::trials {
namespace {

TrialOptions blind(int count, const std::string& judge) {
  TrialOptions options;
  options.plan = dataRoot() / "examples/ur5/blind_pick_place.xml";
  options.scene = dataRoot() / "sim/scenes/one_node.json";
  options.waypoints = dataRoot() / "examples/ur5/blind_waypoints.json";
  options.judge = judge;
  options.count = count;
  options.seed = 5;
  options.jobs = 2;
  return options;
}

std::string contents(const std::filesystem::path& file) {
  std::ifstream stream(file);
  return {std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>()};
}

TEST(Trials, RunJudgeAndSummarize) {
  const std::string waypoints_before = contents(dataRoot() / "examples/ur5/blind_waypoints.json");
  int calls = 0;
  const Summary summary = runTrials(blind(2, "blind_place"), [&calls](const TrialResult&, int done) {
    ++calls;
    EXPECT_EQ(done, calls);
  });
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(summary.successes(), 2);
  EXPECT_EQ(summary.trials[1].seed, 6u);
  EXPECT_GT(summary.cycleTimes().at("median"), 5.0);  // simulated seconds of a real pick and place
  const nlohmann::json json = summary.toJson();
  EXPECT_EQ(json.at("success_rate"), 1.0);
  EXPECT_EQ(json.at("results").size(), 2u);
  const auto png = std::filesystem::temp_directory_path() / "costar_trials_test.png";
  writePlot(summary, png);
  EXPECT_GT(std::filesystem::file_size(png), 5000u);
  std::filesystem::remove(png);
  // Waypoints are read, never written (the plan moves through them; the file is unchanged).
  EXPECT_EQ(contents(dataRoot() / "examples/ur5/blind_waypoints.json"), waypoints_before);
}

TEST(Trials, AJudgeThatDisagreesMakesAFailureWithItsReason) {
  const Summary summary = runTrials(blind(1, "lift"));
  EXPECT_EQ(summary.successes(), 0);
  ASSERT_EQ(summary.failureHistogram().size(), 1u);
  EXPECT_EQ(summary.failureHistogram()[0].first, "judge: no node is held # cm above the table");
  EXPECT_NE(summary.text().find("0 of 1 trials succeeded"), std::string::npos);
}

TEST(Trials, BadInputIsRefusedBeforeAnyTrial) {
  TrialOptions options = blind(1, "blind_place");
  options.judge = "tidy";
  EXPECT_THROW(runTrials(options), std::invalid_argument);
  options = blind(1, "blind_place");
  options.plan = dataRoot() / "cli/test/fixtures/invalid.xml";
  EXPECT_THROW(runTrials(options), bt::PlanError);
}

TEST(Trials, ShardsRunTheirSliceAndMergeIntoTheWholeBatch) {
  TrialOptions options = blind(3, "blind_place");
  options.jobs = 1;
  options.shard_count = 2;
  options.shard_index = 1;
  const Summary odd = runTrials(options);
  ASSERT_EQ(odd.trials.size(), 1u);
  EXPECT_EQ(odd.trials[0].index, 1);
  EXPECT_EQ(odd.trials[0].seed, 6u);  // trial i keeps seed + i whichever shard runs it
  EXPECT_NE(odd.text().find("shard 1/2"), std::string::npos);
  options.shard_index = 0;
  const Summary even = runTrials(options);
  ASSERT_EQ(even.trials.size(), 2u);
  EXPECT_EQ(even.trials[1].index, 2);

  // Through JSON files, as a batch scheduler's jobs would hand them over.
  const Summary merged =
      mergeShards({Summary::fromJson(nlohmann::json::parse(odd.toJson().dump())), Summary::fromJson(even.toJson())});
  ASSERT_EQ(merged.trials.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(merged.trials[i].index, i);
    EXPECT_EQ(merged.trials[i].seed, 5u + i);
  }
  EXPECT_EQ(merged.successes(), odd.successes() + even.successes());
  EXPECT_EQ(merged.toJson().at("shard").at("count"), 1);
  EXPECT_NE(merged.text().find("of 3 trials succeeded"), std::string::npos);

  // Results that do not add up are refused with the reason.
  const auto refused = [](const std::vector<Summary>& shards) {
    try {
      mergeShards(shards);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("merged");
  };
  EXPECT_NE(refused({even}).find("1 of 3 trials are missing (a shard not merged?): 1"), std::string::npos);
  EXPECT_NE(refused({even, odd, odd}).find("trial 1 appears twice"), std::string::npos);
  Summary other = odd;
  other.options.judge = "lift";
  EXPECT_NE(refused({even, other}).find("another batch: judge 'lift'"), std::string::npos);
  EXPECT_THROW(Summary::fromJson(nlohmann::json::parse(R"({"plan": "p.xml"})")), std::runtime_error);
  options.shard_index = 2;
  EXPECT_THROW(runTrials(options), std::invalid_argument);
}

/// The paper's three UR5 tasks, with perception (DetectObjects on the simulated camera), one
/// trial each, judged from the simulator's true final state. The 100-trial figures are in
/// docs/BENCHMARKS.md (`costar trials ... -n 100`).
class PaperTask : public ::testing::TestWithParam<std::pair<const char*, const char*>> {};

TEST_P(PaperTask, SucceedsWithPerception) {
  TrialOptions options;
  options.plan = dataRoot() / "examples/ur5" / (std::string(GetParam().first) + ".xml");
  options.judge = GetParam().second;
  options.count = 1;
  options.seed = 3;
  options.jobs = 1;
  const Summary summary = runTrials(options);
  ASSERT_EQ(summary.trials.size(), 1u);
  EXPECT_TRUE(summary.trials[0].success) << summary.trials[0].failure_path << ": " << summary.trials[0].reason;
}

INSTANTIATE_TEST_SUITE_P(Ur5, PaperTask,
                         ::testing::Values(std::make_pair("pick_up_node", "lift"),
                                           std::make_pair("move_nodes_right_to_left", "right_to_left"),
                                           std::make_pair("assemble_structure", "assembly")),
                         [](const auto& info) { return std::string(info.param.first); });
}  // namespace
}  // namespace costar::trials
