// Disturbances during a trial (issue 12): the simulated world changed under a running plan,
// seeded, and a plan that looks again and retries recovering from them. Judged from the
// simulator's true state.

#include "trials/disturbance.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>

#include <unistd.h>

#include "core/paths.h"
#include "sim/scene.h"
#include "trials/trials.h"

namespace costar::trials {
namespace {

std::string errorOf(const std::string& text) {
  try {
    parseDisturbance(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(Disturbance, SpecsAreParsedAndBadOnesNamed) {
  EXPECT_EQ(parseDisturbance("nudge").kind, DisturbanceKind::kNudge);
  EXPECT_EQ(parseDisturbance("nudge").grasp, 0);
  EXPECT_EQ(parseDisturbance("take-away@grasp=2").kind, DisturbanceKind::kTakeAway);
  EXPECT_EQ(parseDisturbance("take-away@grasp=2").grasp, 2);
  EXPECT_EQ(parseDisturbance("drop-frame").kind, DisturbanceKind::kDropFrame);
  EXPECT_NE(errorOf("shove").find("unknown kind 'shove'"), std::string::npos) << errorOf("shove");
  EXPECT_NE(errorOf("nudge@grasp=0").find("from 1 to 100, not '0'"), std::string::npos);
  EXPECT_NE(errorOf("nudge@grasp=2x").find("not '2x'"), std::string::npos);
  EXPECT_NE(errorOf("nudge@t=3").find("expected @grasp=N"), std::string::npos);
  EXPECT_NE(errorOf("drop-frame@grasp=1").find("takes no @"), std::string::npos);
}

// take-tool's moment is drawn within the polishing plan's span (1-19 s; the plan ends at 22 s
// undisturbed), so every disturbed trial is disturbed while the plan works: the draw was 4-40 s,
// and 47 of 100 trials on seeds 7101-7200 ended before it.
TEST(Disturbance, TheToolIsTakenAtAMomentDrawnWithinThePlansSpan) {
  EXPECT_EQ(parseDisturbance("take-tool").kind, DisturbanceKind::kTakeTool);
  EXPECT_EQ(parseDisturbance("take-tool@at=20").at_seconds, 20.0);
  EXPECT_EQ(parseDisturbance("take-tool@within=2-10").within, std::make_pair(2.0, 10.0));
  EXPECT_NE(errorOf("take-tool@within=10-2").find("within=A-B needs A before B, not '10-2'"), std::string::npos)
      << errorOf("take-tool@within=10-2");
  EXPECT_NE(errorOf("take-tool@within=5").find("two numbers of seconds joined by '-'"), std::string::npos);
  EXPECT_NE(errorOf("take-tool@within=x-5").find("within=A-B needs a number of seconds from 0 to 10000, not 'x'"),
            std::string::npos)
      << errorOf("take-tool@within=x-5");
  EXPECT_NE(errorOf("take-tool@grasp=2").find("expected @at=SECONDS or @within=A-B"), std::string::npos);
  // The moment drawn, as a trial that ended at once reports it ("not applied: the trial ended before X s").
  const auto moment = [](const std::string& spec, std::uint64_t seed) {
    const std::vector<std::string> events = Disturber({parseDisturbance(spec)}, seed).events();
    const std::regex before(R"(take-tool: not applied: the trial ended before ([0-9.]+) s)");
    std::smatch match;
    EXPECT_EQ(events.size(), 1u);
    EXPECT_TRUE(std::regex_match(events.at(0), match, before)) << events.at(0);
    return std::stod(match[1]);
  };
  double earliest = 1e9;
  double latest = 0.0;
  for (std::uint64_t seed = 7101; seed <= 7200; ++seed) {
    const double at = moment("take-tool", seed);
    earliest = std::min(earliest, at);
    latest = std::max(latest, at);
    const double within = moment("take-tool@within=2-3", seed);
    EXPECT_GE(within, 1.95);
    EXPECT_LE(within, 3.05);
  }
  EXPECT_GE(earliest, kTakeToolWindow.first - 0.05);  // events round to 0.1 s
  EXPECT_LE(latest, kTakeToolWindow.second + 0.05);
  EXPECT_GT(latest - earliest, 12.0);  // spread over the window, not one moment
  EXPECT_EQ(moment("take-tool@at=12.5", 7101), 12.5);
}

TEST(Disturbance, ADroppedFrameIsDrawnFromTheSeedAmongThePlansFrames) {
  const auto frames = [](std::uint64_t seed) { return Disturber({parseDisturbance("drop-frame")}, seed).faultSpecs(); };
  ASSERT_EQ(frames(7).size(), 1u);
  EXPECT_EQ(frames(7), frames(7));
  const std::regex spec(R"(drop-frame:camera@op=(\d+))");
  std::set<int> drawn;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    std::smatch match;
    const std::string text = frames(seed)[0];
    ASSERT_TRUE(std::regex_match(text, match, spec)) << text;
    const int frame = std::stoi(match[1]);
    EXPECT_GE(frame, 1);
    EXPECT_LE(frame, Disturber::kFramesDrawn);
    drawn.insert(frame);
  }
  EXPECT_GT(drawn.size(), 10u);  // not one frame for every seed
}

class DisturbedTrials : public ::testing::Test {
 protected:
  void SetUp() override {
    folder = std::filesystem::temp_directory_path() / ("costar_disturbed_" + std::to_string(::getpid()));
    std::filesystem::create_directories(folder);
    // Two nodes apart on the right: the first grasp goes for one; the other is left.
    std::ofstream(folder / "scene.json") << R"({"seed": 5, "parts": [
        {"class": "node", "color": "red", "at": [0.45, -0.22, 30]},
        {"class": "node", "color": "blue", "at": [0.58, -0.32, 0]}]})";
  }
  void TearDown() override { std::filesystem::remove_all(folder); }

  TrialOptions options(const std::string& body, const std::string& disturb) {
    std::ofstream(folder / "plan.xml") << R"(<root BTCPP_format="4"><BehaviorTree ID="main">)" << body
                                       << "</BehaviorTree></root>";
    TrialOptions trial;
    trial.plan = folder / "plan.xml";
    trial.scene = folder / "scene.json";
    trial.judge = "lift";
    trial.count = 1;
    trial.seed = 21;
    trial.time_limit_s = 120;
    trial.disturb = {disturb};
    return trial;
  }

  static constexpr const char* kPickUp = R"(<Sequence><Home/><Open/><DetectObjects/>
      <SmartGrasp name="grasp a node" object_class="node" grasp="top"/>
      <MoveRelative name="lift" offset="0;0;0.15"/></Sequence>)";
  static constexpr const char* kPickUpRetrying = R"(<Sequence>
      <RetryUntilSuccessful num_attempts="3"><Sequence><Home/><Open/><DetectObjects/>
        <SmartGrasp name="grasp a node" object_class="node" grasp="top"/></Sequence></RetryUntilSuccessful>
      <MoveRelative name="lift" offset="0;0;0.15"/></Sequence>)";

  std::filesystem::path folder;
};

TEST_F(DisturbedTrials, APartNudgedAsTheGripperGoesDownMovesOneToThreeCentimetres) {
  const Summary summary = runTrials(options(kPickUpRetrying, "nudge@grasp=1"));
  ASSERT_EQ(summary.trials.size(), 1u);
  const TrialResult& trial = summary.trials[0];
  ASSERT_EQ(trial.disturbances.size(), 1u);
  std::smatch match;
  ASSERT_TRUE(std::regex_search(trial.disturbances[0], match,
                                std::regex(R"(nudge node_\d: (\d+) mm, ([-+]\d+) deg at [\d.]+ s \(approach 1\))")))
      << trial.disturbances[0];
  EXPECT_GE(std::stoi(match[1]), 10);
  EXPECT_LE(std::stoi(match[1]), 30);
  EXPECT_LE(std::abs(std::stoi(match[2])), 15);
  // Looking again and grasping where the part is now: a node is lifted.
  EXPECT_TRUE(trial.success) << trial.failure_path << ": " << trial.reason;
  EXPECT_GT(trial.rss_kb, 0);
  // The same seed, the same nudge.
  EXPECT_EQ(runTrials(options(kPickUpRetrying, "nudge@grasp=1")).trials[0].disturbances, trial.disturbances);
}

TEST_F(DisturbedTrials, APartTakenAwayFailsTheGraspAndARetryTakesTheOther) {
  const Summary plain = runTrials(options(kPickUp, "take-away@grasp=1"));
  ASSERT_EQ(plain.trials[0].disturbances.size(), 1u);
  EXPECT_NE(plain.trials[0].disturbances[0].find("take-away node_"), std::string::npos)
      << plain.trials[0].disturbances[0];
  EXPECT_FALSE(plain.trials[0].success);
  EXPECT_NE(plain.trials[0].failure_path.find("grasp a node"), std::string::npos) << plain.trials[0].failure_path;
  EXPECT_NE(plain.text().find("disturbed (take-away@grasp=1): 1 of 1 trials"), std::string::npos) << plain.text();

  const Summary retrying = runTrials(options(kPickUpRetrying, "take-away@grasp=1"));
  EXPECT_TRUE(retrying.trials[0].success) << retrying.trials[0].failure_path << ": " << retrying.trials[0].reason;
}

// A part added mid-task: a spare parked off the table from the start (the simulator's bodies
// are fixed once loaded) is put at a free place on the table as the gripper goes down to a
// node; the plan goes on and lifts a node all the same.
TEST_F(DisturbedTrials, APartAddedAsTheGripperGoesDownLandsOnTheTableAndThePlanGoesOn) {
  const Summary summary = runTrials(options(kPickUpRetrying, "add@grasp=1"));
  const TrialResult& trial = summary.trials[0];
  ASSERT_EQ(trial.disturbances.size(), 1u);
  std::smatch match;
  ASSERT_TRUE(std::regex_search(
      trial.disturbances[0], match,
      std::regex(R"(add (node|link)_\d at \(([-\d.]+), ([-\d.]+)\) m, [-+]\d+ deg at [\d.]+ s \(approach 1\))")))
      << trial.disturbances[0];
  const sim::Region table = sim::defaultRegions().at("table");
  const double x = std::stod(match[2]);
  const double y = std::stod(match[3]);
  EXPECT_GE(x, table.min.x() - 0.005);
  EXPECT_LE(x, table.max.x() + 0.005);
  EXPECT_GE(y, table.min.y() - 0.005);
  EXPECT_LE(y, table.max.y() + 0.005);
  EXPECT_TRUE(trial.success) << trial.failure_path << ": " << trial.reason;
  EXPECT_EQ(runTrials(options(kPickUpRetrying, "add@grasp=1")).trials[0].disturbances, trial.disturbances);
  EXPECT_THROW(parseDisturbance("add@t=3"), std::invalid_argument);
}

TEST_F(DisturbedTrials, ADisturbanceNeverDueIsListedAsNotApplied) {
  const Summary summary = runTrials(options(kPickUp, "nudge@grasp=2"));
  ASSERT_EQ(summary.trials[0].disturbances.size(), 1u);
  EXPECT_NE(summary.trials[0].disturbances[0].find("not applied: no approach 2 (1 approach(es)"), std::string::npos)
      << summary.trials[0].disturbances[0];
  EXPECT_TRUE(summary.trials[0].success);
  EXPECT_NE(summary.text().find("disturbed (nudge@grasp=2): 0 of 1 trials"), std::string::npos) << summary.text();
  // The record survives the JSON a shard writes.
  const Summary read = Summary::fromJson(summary.toJson());
  EXPECT_EQ(read.trials[0].disturbances, summary.trials[0].disturbances);
  EXPECT_EQ(read.options.disturb, summary.options.disturb);
}

// A link nudged along its length as the fingers go down is held 2-3 cm off its middle, which the
// fingers cannot feel, and put down that far off the base node's centre (the judge allows 2 cm).
// The recovering plan looks after each release: the link is seen misplaced, grasped where it is
// now and put again. The same trial without the looks after the releases fails. Seed 9518 of the
// nudge runs in docs/BENCHMARKS.md: the link, nudged 23 mm.
TEST_F(DisturbedTrials, ALinkHeldOffItsMiddleIsSeenMisplacedAndPutAgain) {
  std::ifstream file(dataRoot() / "examples/ur5/assemble_structure_recovering.xml");
  const std::string recovering((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  ASSERT_NE(recovering.find("until the link sits where it was put"), std::string::npos);
  // The plan without its three "until ... sits where it was put" fallbacks.
  const std::string blind = std::regex_replace(
      recovering, std::regex(R"(<Fallback name="until the [a-z ]+ sits where it was put">[\s\S]*?</Fallback>)"), "");
  ASSERT_EQ(blind.find("CheckPredicate"), std::string::npos);
  const auto run = [&](const std::string& plan) {
    std::ofstream(folder / "plan.xml") << plan;
    TrialOptions trial;
    trial.plan = folder / "plan.xml";
    trial.scene = dataRoot() / "sim/scenes/assembly.json";
    trial.judge = "assembly";
    trial.count = 1;
    trial.seed = 9518;
    trial.disturb = {"nudge"};
    trial.trace_dir = folder;
    return runTrials(trial).trials.at(0);
  };
  const auto traced = [&] {
    std::ifstream trace(folder / "trial_9518.jsonl");
    return std::string((std::istreambuf_iterator<char>(trace)), std::istreambuf_iterator<char>());
  };

  const TrialResult without = run(blind);
  ASSERT_EQ(without.disturbances.size(), 1u);
  EXPECT_NE(without.disturbances[0].find("nudge link_"), std::string::npos) << without.disturbances[0];
  EXPECT_FALSE(without.success);
  EXPECT_NE(without.reason.find("no link rests on the base node"), std::string::npos) << without.reason;

  const TrialResult with = run(recovering);
  // The same nudge (later: the plan looked at the base node first).
  const auto nudged = [](const TrialResult& trial) {
    return trial.disturbances.empty() ? std::string()
                                      : trial.disturbances[0].substr(0, trial.disturbances[0].find(" at "));
  };
  EXPECT_EQ(nudged(with), nudged(without));
  EXPECT_TRUE(with.success) << with.failure_path << ": " << with.reason;
  const std::string trace = traced();
  EXPECT_NE(
      trace.find(R"x(CheckPredicate \"the link is where it was put\"","reason":"some symbol satisfies misplaced(?)")x"),
      std::string::npos);
  EXPECT_NE(trace.find(R"x(SmartRelease \"put it on the base node again\"","t":)x"), std::string::npos);
}

TEST(Trials, ResidentMemoryIsSampledEveryHundredTrials) {
  Summary summary;
  for (int i = 0; i < 250; ++i) {
    TrialResult trial;
    trial.index = i;
    trial.rss_kb = 100000 + i * 10;
    summary.trials.push_back(trial);
  }
  const auto memory = summary.residentMemory();
  ASSERT_EQ(memory.size(), 3u);
  EXPECT_EQ(memory[0], std::make_pair(100, 100990L));
  EXPECT_EQ(memory[2], std::make_pair(250, 102490L));
  EXPECT_NEAR(summary.residentGrowthPercent(), 100.0 * 1500 / 100990, 1e-9);
  EXPECT_EQ(summary.toJson().at("resident_memory").size(), 3u);
  EXPECT_EQ(Summary::fromJson(summary.toJson()).trials[249].rss_kb, 102490);
}

}  // namespace
}  // namespace costar::trials
