#include "trials/trials.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <ostream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "bt/plan.h"
#include "core/files.h"
#include "core/paths.h"
#include "sim/scene.h"
#include "trials/judge.h"
#include "trials/tool_plot.h"
#include "workcell/sim_cell_description.h"

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

// Issue 10: a time limit of nan, 0 or below failed every trial (nan printed -9223372036.85 s).
TEST(Trials, NumbersOutOfRangeAreRefusedBeforeAnyTrial) {
  const auto message = [](const TrialOptions& options) {
    try {
      runTrials(options);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  for (const double bad : {-5.0, 0.0, std::nan(""), std::numeric_limits<double>::infinity(), 2e6}) {
    TrialOptions options = blind(1, "blind_place");
    options.time_limit_s = bad;
    EXPECT_EQ(message(options).rfind(
                  "the time limit must be a number of simulated seconds above 0 and at most 1e+06, not ", 0),
              0u)
        << bad;
  }
  TrialOptions options = blind(1, "blind_place");
  options.time_limit_s = std::nan("");
  EXPECT_EQ(message(options),
            "the time limit must be a number of simulated seconds above 0 and at most 1e+06, not nan");
  options = blind(0, "blind_place");
  EXPECT_EQ(message(options), "the number of trials must be at least 1, not 0");
  options = blind(1, "blind_place");
  options.jobs = 0;
  EXPECT_EQ(message(options), "the number of trials run at once must be at least 1, not 0");
  options = blind(1, "blind_place");
  options.settle_s = -1;
  EXPECT_EQ(message(options), "the settle time must be a number of simulated seconds from 0 to 1e+06, not -1");
}

// Issue 10: `--plot /nonexistent/p.png` aborted after every trial had run, and `--json` to a
// folder printed "wrote" and wrote nothing.
TEST(Trials, OutputFilesAreCheckedBeforehandAndWrittenAfterwards) {
  const auto message = [](const std::filesystem::path& file) {
    try {
      checkOutputFile(file, "--json");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const auto folder = std::filesystem::temp_directory_path() / "costar_trials_output_test";
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  EXPECT_EQ(message("/nonexistent/p.png"),
            "cannot write --json '/nonexistent/p.png': there is no folder '/nonexistent'");
  EXPECT_EQ(message(folder), "cannot write --json '" + folder.string() + "': it is a folder");
  EXPECT_EQ(message(""), "--json: the file name is empty");
  EXPECT_EQ(message(folder / "results.json"), "no error");
  EXPECT_FALSE(std::filesystem::exists(folder / "results.json"));  // checking creates nothing
  EXPECT_EQ(message("/dev/null"), "no error");

  Summary summary;
  summary.options = blind(2, "blind_place");
  summary.trials.resize(2);
  summary.trials[0].success = true;
  summary.trials[0].cycle_time_s = 7.5;
  summary.trials[1].index = 1;
  summary.trials[1].failure_path = "judge";
  summary.trials[1].reason = "no node is held";
  writeJson(summary, folder / "results.json");
  EXPECT_EQ(nlohmann::json::parse(contents(folder / "results.json")), summary.toJson());
  // A device is written to, not replaced by a file.
  writeJson(summary, "/dev/null");
  EXPECT_TRUE(std::filesystem::is_character_file("/dev/null"));
  EXPECT_THROW(writeJson(summary, folder / "missing" / "results.json"), std::runtime_error);
  EXPECT_THROW(writePlot(summary, folder / "missing" / "plot.png"), std::runtime_error);
  // Issue 27: a full disk was "error while writing to output stream"; every output names the system's words.
  try {
    writePlot(summary, "/dev/full");
    ADD_FAILURE() << "a plot on a full disk";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "cannot write '/dev/full': No space left on device");
  }
  std::filesystem::remove_all(folder);
}

// The polishing pictures went to cairo's own file writer: a full disk was "error while writing
// to output stream". They are written checked like every other output.
TEST(Trials, ThePolishingPicturesAreWrittenChecked) {
  ToolTrace trace;
  trace.seed = 5;
  for (int k = 0; k < 50; ++k) {
    sim::PowerToolSample sample;
    sample.time = 0.1 * k;
    sample.powered = sample.held = sample.working = true;
    sample.pad_force = 10.0 + std::sin(0.3 * k);
    trace.log.push_back(sample);
  }
  sim::Coverage coverage;
  coverage.columns = 20;
  coverage.rows = 10;
  coverage.worked_seconds.assign(200, 0.1F);
  coverage.max_force.assign(200, 10.0F);
  trace.coverage = coverage;
  const auto folder = std::filesystem::temp_directory_path() / "costar_tool_plot_test";
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  writeForcePlot(trace, 10.0, 4.0, folder / "force.png");
  writeCoveragePlot(trace, folder / "coverage.png");
  EXPECT_EQ(contents(folder / "force.png").substr(1, 3), "PNG");
  EXPECT_EQ(contents(folder / "coverage.png").substr(1, 3), "PNG");
  for (const auto& write : {std::function<void(const std::filesystem::path&)>(
                                [&](const std::filesystem::path& png) { writeForcePlot(trace, 10.0, 4.0, png); }),
                            std::function<void(const std::filesystem::path&)>(
                                [&](const std::filesystem::path& png) { writeCoveragePlot(trace, png); })}) {
    try {
      write("/dev/full");
      ADD_FAILURE() << "a picture on a full disk";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "cannot write '/dev/full': No space left on device");
    }
  }
  std::filesystem::remove_all(folder);
}

// The power tool's log of a polishing trial: a pass along y = 0 from x = -4 to +4 cm, the tool
// taken at 2 s (`powered`: running then, else switched off after the pass), given back, and
// polishing again from `resume`.
std::vector<sim::PowerToolSample> polishingLog(bool powered, const Eigen::Vector2d& resume, double arm_speed = 0.0) {
  std::vector<sim::PowerToolSample> log;
  const auto add = [&log](double time, bool held, bool on, bool working, const Eigen::Vector2d& pad) {
    sim::PowerToolSample sample;
    sample.time = time;
    sample.held = held;
    sample.away = !held;
    sample.powered = on;
    sample.working = working;
    sample.pad = pad;
    sample.pad_force = working ? 10.0 : 0.0;
    log.push_back(sample);
  };
  for (int k = 0; k <= 160; ++k) {
    add(0.01 * k, true, true, true, Eigen::Vector2d(-0.04 + 0.0005 * k, 0.0));
  }
  for (int k = 161; k < 200; ++k) {
    add(0.01 * k, true, powered, powered, Eigen::Vector2d(0.04, 0.0));
  }
  for (int k = 200; k < 400; ++k) {  // taken: switched off at once
    add(0.01 * k, false, false, false, Eigen::Vector2d(0.04, 0.0));
    log.back().arm_speed = arm_speed;
  }
  for (int k = 400; k < 500; ++k) {  // back in the gripper, polishing again
    add(0.01 * k, true, true, k >= 450, resume);
  }
  return log;
}

// The judge wanted polishing to resume after a tool taken once the passes were done and the
// tool switched off ("never resumed"), and within 20 mm of where it stopped when the pass it was
// on had ended and the next one starts 3 cm away.
TEST(PolishingJudge, PolishingResumesWhereItStoppedOrAtTheNextPassAndNeedNotWhenTheToolWasOff) {
  const ToolLosses off = toolLosses(polishingLog(false, Eigen::Vector2d(0.04, 0.0)));
  EXPECT_EQ(off.count, 1);
  EXPECT_EQ(off.problem, "");
  std::vector<sim::PowerToolSample> never = polishingLog(true, Eigen::Vector2d(0.04, 0.0));
  for (auto& sample : never) {
    sample.working = sample.working && sample.time < 2.0;
  }
  EXPECT_EQ(toolLosses(never).problem, "polishing stopped when the tool was taken at 2.0000 s and never resumed");
  const ToolLosses next_pass = toolLosses(polishingLog(true, Eigen::Vector2d(0.04, 0.03)));
  EXPECT_EQ(next_pass.problem, "");
  EXPECT_NEAR(next_pass.farthest_resume, 0.03, 1e-9);
  const ToolLosses there = toolLosses(polishingLog(true, Eigen::Vector2d(0.035, 0.0)));
  EXPECT_EQ(there.problem, "");
  EXPECT_NEAR(there.farthest_resume, 0.005, 1e-9);
  EXPECT_EQ(toolLosses(polishingLog(true, Eigen::Vector2d(-0.04, 0.0))).problem,
            "polishing resumed 80 mm from where it stopped (more than 20 mm), over ground it had polished");
  EXPECT_EQ(toolLosses(polishingLog(true, Eigen::Vector2d(0.04, 0.0), 0.05)).problem,
            "the tool was taken out of the gripper at 2.0000 s, and 1 s later it was still on or the arm still moving");
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

// Issue 27: shards run with different --inject, --camera-move, --calibrate, --time-limit or
// --waypoints merged silently into one "batch". Every option that affects outcomes goes into each
// shard's JSON, and shards that differ are refused naming the option and both values.
TEST(Trials, ShardsRunWithDifferentOptionsAreNotMerged) {
  Summary first;
  first.options = blind(2, "blind_place");
  first.options.shard_count = 2;
  first.fingerprints = {{"plan", "fnv1a64:1"}, {"scene", "fnv1a64:2"}, {"waypoints", "fnv1a64:3"}};
  first.trials.resize(1);
  Summary second = first;
  second.options.shard_index = 1;
  second.trials[0].index = 1;
  const auto refused = [&first](Summary other) {
    try {
      mergeShards({Summary::fromJson(nlohmann::json::parse(first.toJson().dump())),
                   Summary::fromJson(nlohmann::json::parse(other.toJson().dump()))});
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("merged");
  };
  EXPECT_EQ(refused(second), "merged");
  Summary other = second;
  other.options.inject = {"nan:arm-driver@t=2s"};
  EXPECT_EQ(refused(other),
            R"(results 2 are of another batch: --inject '["nan:arm-driver@t=2s"]', not '[]' as in results 1)");
  other = second;
  other.options.camera_move_m = 0.05;
  other.options.camera_turn_deg = 5;
  EXPECT_EQ(refused(other), "results 2 are of another batch: --camera-move '0.05,5', not '0,0' as in results 1");
  other = second;
  other.options.calibrate = true;
  EXPECT_EQ(refused(other), "results 2 are of another batch: --calibrate 'on', not 'off' as in results 1");
  other = second;
  other.options.time_limit_s = 30;
  EXPECT_EQ(refused(other), "results 2 are of another batch: --time-limit '30', not '600' as in results 1");
  other = second;
  other.options.waypoints = "mine.json";
  EXPECT_NE(refused(other).find("another batch: --waypoints 'mine.json', not '"), std::string::npos);
  other = second;
  other.fingerprints["waypoints"] = "fnv1a64:4";
  EXPECT_EQ(refused(other),
            "results 2 are of another batch: the waypoints file's contents (fingerprint) 'fnv1a64:4', not "
            "'fnv1a64:3' as in results 1");
  other = second;
  other.fingerprints["plan"] = "fnv1a64:5";
  EXPECT_NE(refused(other).find("the plan file's contents (fingerprint) 'fnv1a64:5'"), std::string::npos);
  other = second;
  other.options.scene = "elsewhere.json";
  EXPECT_NE(refused(other).find("another batch: scene 'elsewhere.json'"), std::string::npos);
  other = second;
  other.interrupted = true;
  other.planned = 3;
  EXPECT_EQ(refused(other), "results 2 are of an interrupted run (1 of 3 trials finished): run that shard again");
}

// Issue 27: `costar trials` on SIGINT or SIGTERM wrote no --json and left empty trace files. A
// stop request starts no further trial, stops the running one at its next tick, and the summary
// holds the trials that finished, marked interrupted; the stopped trial's trace is complete.
TEST(Trials, AStopRequestKeepsTheTrialsThatFinishedAndMarksTheBatchInterrupted) {
  const auto traces = std::filesystem::temp_directory_path() / "costar_trials_stop_test";
  std::filesystem::remove_all(traces);
  std::filesystem::create_directories(traces);
  TrialOptions options = blind(4, "blind_place");
  options.jobs = 1;
  options.trace_dir = traces;
  std::atomic<bool> stop{false};
  int reported = 0;
  // The stop comes as the first trial ends: trial 1 sees it before it starts.
  const Summary summary = runTrials(
      options,
      [&](const TrialResult&, int) {
        ++reported;
        stop = true;
      },
      &stop);
  EXPECT_TRUE(summary.interrupted);
  EXPECT_EQ(summary.planned, 4);
  ASSERT_EQ(summary.trials.size(), 1u);
  EXPECT_EQ(summary.trials[0].index, 0);
  EXPECT_EQ(reported, 1);
  EXPECT_TRUE(summary.cancelled.empty());
  const nlohmann::json json = nlohmann::json::parse(summary.toJson().dump());
  EXPECT_EQ(json.at("interrupted"), true);
  EXPECT_EQ(json.at("planned"), 4);
  EXPECT_EQ(json.at("results").size(), 1u);
  EXPECT_NE(summary.text().find("INTERRUPTED: 1 of 4 trials finished"), std::string::npos) << summary.text();
  // One trace, of the trial that ran, and not empty; none for the trials never started.
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(traces)) {
    files.push_back(entry.path());
  }
  ASSERT_EQ(files.size(), 1u);
  EXPECT_EQ(files[0].filename(), "trial_5.jsonl");
  EXPECT_GT(std::filesystem::file_size(files[0]), 0u);

  // A stop while a trial runs (a plan that never ends): it is stopped at its next tick (its
  // operations cancelled), left out of the results, and its trace ends with the halt.
  const auto forever = traces / "forever.xml";
  std::ofstream(forever) << R"(<root BTCPP_format="4"><BehaviorTree ID="m"><Repeat num_cycles="-1">)"
                         << R"(<Sleep msec="10"/></Repeat></BehaviorTree></root>)";
  options.plan = forever;
  options.count = 1;
  options.time_limit_s = 1e5;
  std::filesystem::remove(traces / "trial_5.jsonl");
  std::atomic<bool> stop_later{false};
  std::thread stopper([&stop_later, &traces] {
    // Once the trial has ticked: its trace is written as it goes.
    std::error_code error;
    for (int i = 0; i < 12000 && (std::filesystem::file_size(traces / "trial_5.jsonl", error) == 0 || error); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    stop_later = true;
  });
  const Summary stopped = runTrials(options, {}, &stop_later);
  stopper.join();
  EXPECT_TRUE(stopped.interrupted);
  EXPECT_TRUE(stopped.trials.empty());
  EXPECT_EQ(stopped.cancelled, std::vector<int>{0});
  const std::string trace = contents(traces / "trial_5.jsonl");
  ASSERT_FALSE(trace.empty());
  const std::string last = trace.substr(trace.rfind('\n', trace.size() - 2) + 1);
  EXPECT_NE(last.find(R"("to":"IDLE")"), std::string::npos) << last;
  std::filesystem::remove_all(traces);
}

TEST(Trials, APersonInTheSceneIsRecordedAndTheArmWaitsForThemSafely) {
  TrialOptions options = blind(1, "blind_place");
  options.scene = dataRoot() / "trials/test/scenes/one_node_person.json";
  const Summary summary = runTrials(options);
  ASSERT_EQ(summary.trials.size(), 1u);
  const TrialResult& trial = summary.trials[0];
  EXPECT_TRUE(trial.success) << trial.failure_path << ": " << trial.reason;
  ASSERT_TRUE(trial.separation);
  EXPECT_EQ(trial.separation->violation_steps, 0u);
  EXPECT_EQ(trial.separation->contact_steps, 0u);
  EXPECT_GE(trial.separation->stops, 1);  // the arm stopped for the person ...
  EXPECT_GT(trial.separation->stopped_s, 1.0);
  EXPECT_GT(trial.separation->min_margin_fast_m, 0.0);  // ... and moved fast only far enough away
  EXPECT_NE(summary.text().find("a person in 1 trials: 0 steps within the protective distance"), std::string::npos);
  // The record survives the JSON (merged shards keep it).
  const Summary again = Summary::fromJson(summary.toJson());
  ASSERT_TRUE(again.trials[0].separation);
  EXPECT_EQ(again.trials[0].separation->stops, trial.separation->stops);
  EXPECT_DOUBLE_EQ(again.trials[0].separation->min_margin_fast_m, trial.separation->min_margin_fast_m);
  // Without a person there is no record.
  EXPECT_FALSE(runTrials(blind(1, "blind_place")).trials[0].separation);
}

// The collaborative assembly's judge on the simulator's truth: each node from the input area
// must end the person's (here: carried off beyond the table's edge) or in the assembly area.
TEST(CollaborativeAssemblyJudge, EveryNodeMustBeThePersonsOrInTheAssemblyArea) {
  sim::SimulationOptions options;
  options.settle_seconds = 0.3;
  const auto simulation =
      sim::Simulation::create(sim::parseScene(R"({"parts": [{"class": "node", "color": "red", "at": [0.5, -0.2, 0]},
                                   {"class": "node", "color": "blue", "at": [0.4, -0.3, 0]}]})",
                                              "test"),
                              options);
  const std::vector<sim::PartState> initial = simulation->parts();
  const Judge collaborative = judge("collaborative_assembly");
  const auto put = [&](const std::string& part, const Eigen::Vector3d& at) {
    world::Pose pose = world::Pose::Identity();
    pose.translation() = at;
    simulation->movePart(part, pose);
    simulation->stepTo(simulation->time() + std::chrono::milliseconds(500));
  };
  put("node_0", {0.5, 0.25, 0.025});  // the assembly area
  Verdict verdict = collaborative(*simulation, initial);
  EXPECT_FALSE(verdict.success);
  EXPECT_NE(verdict.reason.find("node_1 was never moved from the input area"), std::string::npos) << verdict.reason;
  put("node_1", {0.5, 0.9, 0.025});  // off the table's edge on the person's side, not carried off
  verdict = collaborative(*simulation, initial);
  EXPECT_FALSE(verdict.success);
  EXPECT_NE(verdict.reason.find("node_1 is neither in the person's hand nor resting in the assembly area"),
            std::string::npos)
      << verdict.reason;
  put("node_1", {0.55, 2.2, 0.025});  // where the person walked away with it
  verdict = collaborative(*simulation, initial);
  EXPECT_TRUE(verdict.success) << verdict.reason;
  EXPECT_EQ(verdict.reason, "1 handed over, 1 put in the assembly area");
}

// Issue 27: the default scene of `costar trials` was relative to the working directory.
TEST(Trials, TheDefaultSceneIsTheWorkcellsWhereverTheCommandRuns) {
  TrialOptions options;
  options.workcell = "ur5-sim";
  const std::filesystem::path scene = effectiveScene(options);
  EXPECT_TRUE(scene.is_absolute()) << scene;
  EXPECT_TRUE(std::filesystem::is_regular_file(scene)) << scene;
  options.scene = "mine.json";
  EXPECT_EQ(effectiveScene(options), "mine.json");
}

// How far Calibrate moved a part (--calibrate) goes into the JSON in millimetres and comes back;
// a trial without Calibrate has none.
TEST(Trials, HowFarCalibrateMovedAPartSurvivesTheJson) {
  Summary summary;
  summary.options.plan = "p.xml";
  summary.options.judge = "assembly";
  summary.options.count = 2;
  summary.trials.resize(2);
  summary.trials[0].index = 0;
  summary.trials[0].calibrate_moved_part_m = 0.0123;
  summary.trials[1].index = 1;
  const nlohmann::json json = nlohmann::json::parse(summary.toJson().dump());
  EXPECT_DOUBLE_EQ(json.at("results")[0].at("calibrate_moved_part_mm").get<double>(), 12.3);
  EXPECT_FALSE(json.at("results")[1].contains("calibrate_moved_part_mm"));
  const Summary back = Summary::fromJson(json);
  ASSERT_EQ(back.trials.size(), 2u);
  ASSERT_TRUE(back.trials[0].calibrate_moved_part_m.has_value());
  EXPECT_NEAR(*back.trials[0].calibrate_moved_part_m, 0.0123, 1e-9);
  EXPECT_FALSE(back.trials[1].calibrate_moved_part_m.has_value());
}

/// The paper's three tasks on every simulated cell (workcells/*.json, listed from the folder: a
/// new cell is tested here without a line of test code), with perception (DetectObjects on the
/// simulated camera), one trial each, judged from the simulator's true final state. The
/// 100-trial figures are in docs/BENCHMARKS.md (`costar trials ... -n 100`).
struct PaperTaskCase {
  std::string workcell;
  std::string plan;
  std::string judge;
};

void PrintTo(const PaperTaskCase& task, std::ostream* out) { *out << task.plan << " on " << task.workcell; }

std::vector<PaperTaskCase> paperTaskCases() {
  std::vector<PaperTaskCase> cases;
  for (const auto& [cell, label] : workcell::simCells()) {
    for (const auto& [plan, judge] : {std::pair<const char*, const char*>{"pick_up_node", "lift"},
                                      {"move_nodes_right_to_left", "right_to_left"},
                                      {"assemble_structure", "assembly"}}) {
      cases.push_back({cell, plan, judge});
    }
  }
  return cases;
}

class PaperTask : public ::testing::TestWithParam<PaperTaskCase> {};

TEST_P(PaperTask, SucceedsWithPerception) {
  TrialOptions options;
  options.plan = dataRoot() / "examples/ur5" / (GetParam().plan + ".xml");
  options.workcell = GetParam().workcell;
  options.judge = GetParam().judge;
  options.count = 1;
  options.seed = 3;
  options.jobs = 1;
  const Summary summary = runTrials(options);
  ASSERT_EQ(summary.trials.size(), 1u);
  EXPECT_TRUE(summary.trials[0].success) << summary.trials[0].failure_path << ": " << summary.trials[0].reason;
}

INSTANTIATE_TEST_SUITE_P(EveryCell, PaperTask, ::testing::ValuesIn(paperTaskCases()), [](const auto& test_info) {
  std::string name = test_info.param.workcell + "_" + test_info.param.plan;
  std::replace_if(
      name.begin(), name.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) == 0; }, '_');
  return name;
});

/// Assembly trials that failed on 6a7916a for a reason fixed since, each its own seed.
struct FixedTrial {
  const char* name;
  const char* workcell;
  std::uint64_t seed;
};
class FixedAssemblyTrial : public ::testing::TestWithParam<FixedTrial> {};

TEST_P(FixedAssemblyTrial, NowSucceeds) {
  TrialOptions options;
  options.plan = dataRoot() / "examples/ur5/assemble_structure.xml";
  options.workcell = GetParam().workcell;
  options.judge = "assembly";
  options.count = 1;
  options.seed = GetParam().seed;
  options.jobs = 1;
  const Summary summary = runTrials(options);
  ASSERT_EQ(summary.trials.size(), 1u);
  EXPECT_TRUE(summary.trials[0].success) << summary.trials[0].failure_path << ": " << summary.trials[0].reason;
}

INSTANTIATE_TEST_SUITE_P(Assembly, FixedAssemblyTrial,
                         ::testing::Values(
                             // The third look missed the grey link put across the base node (its points partly
                             // labelled node pulled every start 1.5 cm along its length, and the depth check refused
                             // them): "put it on the link: no feasible place for node_1: 1 candidate, none feasible
                             // (1 predicate false)". Now a start of a link lying on another part that the depth check
                             // nearly accepts is slid along its length first (ClassPoseEstimator::verify). The soak's
                             // 14705 and 14915 were the same.
                             FixedTrial{"LinkAcrossTheBaseNodeSeenAtTheNextLook", "ur5-sim", 14121},
                             // The iiwa's joint 5 ended the link grasp 2e-7 rad beyond its limit, and every place on
                             // the base node was refused: "joint 5 of the start is 2.96706 rad, above its maximum".
                             FixedTrial{"ThreeFingerIiwaMovesOnFromAJointLimit", "iiwa-3f-sim", 1835},
                             // The link put across the base node side-on to the camera was found rolled 17 deg about
                             // its length (the depth check passed it), so its top was "tilted" and nothing could be
                             // put on it; now a detection nearly resting flat is levelled (levelResting).
                             FixedTrial{"LinkAcrossTheBaseNodeFoundRolledIsLevelled", "iiwa-3f-sim", 2109},
                             // Most of that link labelled node: its own 366 points fit no link, and the node's
                             // detection left ~600 unexplained; now those are handed to the link cluster beside them.
                             FixedTrial{"LinkAcrossTheBaseNodeMostlyLabelledNodeIsFound", "iiwa-3f-sim", 2138},
                             // All of it labelled node (no link cluster at all): the ~1,000 points the base node's
                             // detection leaves, all 5 cm above the table, are searched as a link cluster.
                             FixedTrial{"LinkAcrossTheBaseNodeAllLabelledNodeIsFound", "iiwa-3f-sim", 2446},
                             // The link found at the third look but the base node under it not (two slivers of
                             // its sides): the link was dropped as resting on nothing (keepSupported), so the
                             // top node's one candidate was the spare link on the right. Now the slivers,
                             // standing on the table, hold it up. 16062 and 16069 were the same.
                             FixedTrial{"LinkAcrossABaseNodeItHidesIsKept", "ur5-sim", 16039}),
                         [](const auto& test_info) { return std::string(test_info.param.name); });

/// Speed work on the camera and the physics must not change what happens in a trial. Seeds 1
/// and 2 of the assembly, recorded with the build before the camera was made faster (commit
/// c3bbb4c: every frame rendered in colour with shadows, the noise drawn in one scan, njmax
/// 4000), succeed in 33.63 and 33.78 simulated seconds. The faster camera gives every frame the
/// same points (depth-only frames have the same depth; the noise is the same function of the
/// seed) and the physics buffers' size changes no step, so the robot sees, decides and moves
/// the same, to the 10 ms tick. A change here means a frame or a physics step differs: find
/// out why before recording new figures.
// Pins the whole trial (scene from the seed, rendering, perception, planning, physics) to values
// recorded with this build's placement: a change that moves any of it shows here. Recorded first
// when the camera was made faster (33.63 s, 33.78 s, unchanged by it); re-recorded after oriented part
// footprints (which change where a seed puts the parts) and per-class grasp defaults were merged
// (33.83 s, 33.89 s; the same in every run and build since). Re-recorded when the gripper began
// to open only as far as the part needs (issue 12: 66 mm for a node, 41 mm for a link, instead
// of 85 mm before each grasp and at each release): shorter finger strokes, 32.78 s and 33.05 s;
// then with the calibration marker on the gripper and the calibration component in the cell
// (issue 14): 32.86 s and 33.00 s; then when detections nearly resting flat began to be levelled
// (levelResting: the parts' tilts of a fraction of a degree are gone, and the grasps follow):
// 32.84 s and 33.03 s (the SVM's AVX2 path and the leftover hand-over, alone, change nothing here);
// then with the UR5 cell's own SVM (issue 33: trained with its arm, stacked parts; the voxels
// labelled a little differently move the parts' poses by a fraction of a millimetre): 32.83 s and
// 33.03 s; then with the joint controller's integral action while its setpoint rests (issue 30:
// the arm now settles onto each goal under the held part's weight, which its model does not
// carry): 32.84 s and 33.21 s; then with a full close pressing what is between the fingers with
// the set force (issue 30: the 25 mm link got 37.5 N of a 40 N close, kp x 12.5 mm): 32.86 s and
// 33.19 s; then with the UR5's model generated from robots/ur5/ur5.json (issue 35: UR's published
// link masses, 17.0 kg moving where the hand-written model's geoms gave 12.6; capsules in the planner's
// URDF where it had covering cylinders): 32.85 s and 33.14 s; then with ICP on a subset of the
// points while its gate shrinks (issue 33: the refined poses move by a fraction of a millimetre,
// and the grasps follow): 32.83 s and 33.09 s.
TEST(Trials, TheSameSeedsGiveTheSameAssemblyTrials) {
  TrialOptions options;
  options.plan = dataRoot() / "examples/ur5/assemble_structure.xml";
  options.scene = dataRoot() / "sim/scenes/assembly.json";
  options.judge = "assembly";
  options.count = 2;
  options.seed = 1;
  options.jobs = 2;
  const Summary summary = runTrials(options);
  ASSERT_EQ(summary.trials.size(), 2u);
  const double recorded[] = {32.83, 33.09};
  for (std::size_t i = 0; i < 2; ++i) {
    const TrialResult& trial = summary.trials[i];
    EXPECT_TRUE(trial.success) << "seed " << trial.seed << ": " << trial.failure_path << ": " << trial.reason;
    EXPECT_NEAR(trial.cycle_time_s, recorded[i], 1e-9) << "seed " << trial.seed;
  }
}
}  // namespace
}  // namespace costar::trials
