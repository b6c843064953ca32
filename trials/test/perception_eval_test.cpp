#include "trials/perception_eval.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

#include "core/files.h"
#include "perception/training_data.h"
#include "perception/workspace.h"
#include "trials/perception_collect.h"
#include "trials/perception_scenes.h"
#include "workcell/cell_simulation.h"

#include "core/paths.h"

namespace costar::trials {
namespace {

const std::vector<world::ObjectClass>& classes() {
  static const std::vector<world::ObjectClass> loaded = world::loadObjectClasses(dataRoot() / "data/objects");
  return loaded;
}

world::Pose at(double x, double y, double yaw_deg = 0.0) {
  return world::poseFromXyzRpy(x, y, 0.025, 0, 0, yaw_deg * M_PI / 180.0);
}

TruePart part(const std::string& name, const std::string& object_class, const world::Pose& pose, double visible = 1.0) {
  return {name, object_class, pose, visible};
}

DetectedPart detection(const std::string& name, const std::string& object_class, const world::Pose& pose) {
  return {name, object_class, pose, 0.9};
}

TEST(PerceptionEval, MatchingTakesTheClosestPairsFirstWithinTheirClass) {
  const std::vector<TruePart> truth = {part("node_0", "node", at(0.50, 0.00)), part("node_1", "node", at(0.53, 0.00)),
                                       part("link_0", "link", at(0.40, 0.20))};
  const std::vector<DetectedPart> detected = {
      detection("a", "node", at(0.515, 0.0)),        // 15 mm from both nodes; node_1 is taken by
      detection("b", "node", at(0.529, 0.0)),        // b, 1 mm from it, first
      detection("c", "link", at(0.50, 0.0)),         // a link where a node is: no match
      detection("d", "link", at(0.402, 0.20, 93))};  // 2 mm, 3 degrees off
  const Match match = matchToTruth(detected, truth, classes());
  EXPECT_EQ(match.detection_of_part, (std::vector<int>{0, 1, 3}));
  EXPECT_EQ(match.part_of_detection, (std::vector<int>{0, 1, -1, 2}));
  EXPECT_NEAR(match.translation_error[0], 0.015, 1e-9);
  EXPECT_NEAR(match.translation_error[1], 0.001, 1e-9);
  EXPECT_FALSE(match.accurate(0));  // 15 mm off
  EXPECT_TRUE(match.accurate(1));
  // A link (symmetric under 180 degrees about z and 90 about its long axis x) turned 93
  // degrees about z is 87 degrees from the nearest of its symmetric poses.
  EXPECT_NEAR(match.rotation_error[2] * 180.0 / M_PI, 87.0, 1e-6);
  EXPECT_FALSE(match.accurate(2));

  // A node is symmetric under 90 degrees about z: 92 degrees is 2 off.
  const Match turned = matchToTruth({detection("e", "node", at(0.5, 0.0, 92))}, {truth[0]}, classes());
  EXPECT_NEAR(turned.rotation_error[0] * 180.0 / M_PI, 2.0, 1e-6);
  EXPECT_TRUE(turned.accurate(0));

  // 2.5 cm or more apart: no match.
  const Match far = matchToTruth({detection("f", "node", at(0.5, 0.026))}, {truth[0]}, classes());
  EXPECT_EQ(far.detection_of_part[0], -1);
  EXPECT_THROW(matchToTruth({detection("g", "widget", at(0.5, 0))}, {part("w", "widget", at(0.5, 0))}, classes()),
               std::runtime_error);
}

TEST(PerceptionEval, ScoresCountVisiblePartsFalseDetectionsAndNameTheProblems) {
  const std::vector<TruePart> truth = {part("node_0", "node", at(0.50, 0.00)), part("node_1", "node", at(0.60, 0.00)),
                                       part("node_2", "node", at(0.60, 0.10), 0.1),  // mostly hidden
                                       part("link_0", "link", at(0.40, 0.20))};
  const std::vector<DetectedPart> detected = {detection("node_7", "node", at(0.501, 0.0)),
                                              detection("node_8", "node", at(0.608, 0.0)),  // 8 mm off
                                              detection("node_9", "node", at(0.30, -0.3))};
  Scores scores;
  scores.add(detected, truth, matchToTruth(detected, truth, classes()), "scene 1");
  const ClassScore& nodes = scores.classes.at("node");
  EXPECT_EQ(nodes.visible, 2);
  EXPECT_EQ(nodes.visible_found, 2);
  EXPECT_EQ(nodes.visible_accurate, 1);
  EXPECT_EQ(nodes.detections, 3);
  EXPECT_EQ(nodes.false_positives, 1);
  EXPECT_NEAR(nodes.precision(), 2.0 / 3.0, 1e-12);
  EXPECT_EQ(scores.classes.at("link").visible, 1);
  EXPECT_EQ(scores.classes.at("link").recall(), 0.0);
  EXPECT_EQ(scores.hidden_part_views, 1);
  EXPECT_EQ(scores.visiblePartViews(), 3);
  EXPECT_NEAR(scores.foundWithinTolerance(), 1.0 / 3.0, 1e-12);
  ASSERT_EQ(scores.problems.size(), 3u);
  EXPECT_NE(scores.problems[0].find("scene 1: node_1 (node) found with 8.0 mm"), std::string::npos)
      << scores.problems[0];
  EXPECT_NE(scores.problems[1].find("scene 1: missed link_0"), std::string::npos) << scores.problems[1];
  EXPECT_NE(scores.problems[2].find("false detection node_9"), std::string::npos) << scores.problems[2];
}

TEST(PerceptionEval, PercentilesInterpolate) {
  EXPECT_EQ(percentile({}, 50), 0.0);
  EXPECT_EQ(percentile({3, 1, 2}, 50), 2.0);
  EXPECT_DOUBLE_EQ(percentile({0, 10}, 95), 9.5);
  EXPECT_EQ(percentile({4, 1, 9}, 100), 9.0);
}

// The whole loop on the simulated cell, small: one scene, one repeat, one push, 5 frames.
TEST(PerceptionEval, ASmallEvaluationScoresEveryRoundAndKeepsItsCountsConsistent) {
  PerceptionEvalOptions options;
  options.scenes = 1;
  options.seed = 3;
  options.repeats = 1;
  options.pushes = 1;
  options.frames = 5;
  int reports = 0;
  SceneReport last;
  const PerceptionEvalSummary summary = evaluatePerception(options, [&](const SceneReport& report) {
    ++reports;
    last = report;
  });
  EXPECT_EQ(reports, 1);
  EXPECT_EQ(last.scene, 1);
  EXPECT_GE(last.parts, 4);  // 3-6 nodes and 1-3 links
  EXPECT_LE(last.parts, 9);
  EXPECT_EQ(summary.parts, last.parts);
  // Three rounds scored (first look, repeat, push): every part view counted once per round.
  EXPECT_EQ(summary.latency_ms.at("total").size(), 3u);
  EXPECT_EQ(summary.scores.visiblePartViews() + summary.scores.hidden_part_views, 3 * last.parts);
  EXPECT_EQ(summary.repeat_checks, last.name_checks);
  EXPECT_GE(summary.scores.foundWithinTolerance(), 0.9);
  EXPECT_GE(last.accurate_first_look, last.parts - 1);
  EXPECT_EQ(summary.pushed_part_checks, 1);
  const nlohmann::json json = summary.toJson();
  EXPECT_EQ(json.at("parts"), last.parts);
  EXPECT_EQ(json.at("persistence").at("still_name_checks"), summary.repeat_checks);
  EXPECT_NE(summary.text().find("latency per DetectObjects (3 runs"), std::string::npos);

  // The same seed, the same scores (scenes, noise and pushes are drawn from it).
  const PerceptionEvalSummary again = evaluatePerception(options);
  EXPECT_EQ(again.toJson().at("classes"), json.at("classes"));
  EXPECT_EQ(again.scores.problems, summary.scores.problems);
}

// The 3-finger iiwa cell with its arm and hand over the parts and links across nodes: nothing
// detected on the robot; pushes re-create the scene with the stacked links on their nodes (a
// link leaning from a node onto the table was placed inside the node and refused, iiwa-sim,
// seed 101, scene 5).
TEST(PerceptionEval, TheArmOverStackedPartsGivesNoDetectionAndPushesKeepTheStack) {
  PerceptionEvalOptions options;
  options.workcell = "iiwa-3f-sim";
  options.scenes = 1;
  options.seed = 101;
  options.repeats = 0;
  options.pushes = 2;
  options.frames = 5;
  options.stacked = 2;
  options.arm_over = 1.0;
  const PerceptionEvalSummary summary = evaluatePerception(options);
  EXPECT_EQ(summary.scenes_arm_over, 1);
  EXPECT_GE(summary.parts_stacked, 1);
  EXPECT_EQ(summary.latency_ms.at("total").size(), 3u);  // first look and two pushes
  for (const auto& [name, score] : summary.scores.classes) {
    EXPECT_EQ(score.false_positives, 0) << name;
  }
  EXPECT_EQ(summary.toJson().at("false_detections"), 0);
}

TEST(PerceptionEval, DetectInASceneFileFindsItsPartsAndDrawsThem) {
  const SceneDetection found = detectInScene(dataRoot() / "sim/scenes/assembly.json", 7, 5);
  ASSERT_EQ(found.truth.size(), 5u);
  int accurate = 0;
  for (std::size_t p = 0; p < found.truth.size(); ++p) {
    accurate += found.match.accurate(p) ? 1 : 0;
  }
  EXPECT_EQ(accurate, 5);
  EXPECT_EQ(found.detected.size(), 5u);
  EXPECT_GT(found.milliseconds, 0.0);
  EXPECT_GT(found.picture.width, 0);
  EXPECT_THROW(detectInScene(dataRoot() / "sim/scenes/no_such_scene.json", 1, 5), std::runtime_error);
}

// `perception detect --look` looks at an evaluation's scene again as its first look did: the
// camera's noise and the arm standing over the parts (without the arm a false detection on it,
// or a part it hid, could not be looked at again).
TEST(PerceptionEval, ALookFileShowsTheSceneAgainWithTheArmWhereTheEvaluationHadIt) {
  const auto folder = std::filesystem::temp_directory_path() / "costar_perception_look_test";
  std::filesystem::remove_all(folder);
  PerceptionEvalOptions options;
  options.workcell = "iiwa-3f-sim";
  options.scenes = 1;
  options.seed = 101;
  options.repeats = 0;
  options.pushes = 0;
  options.frames = 5;
  options.stacked = 1;
  options.arm_over = 1.0;
  options.pictures = folder;
  SceneReport report;
  const PerceptionEvalSummary summary = evaluatePerception(options, [&](const SceneReport& r) { report = r; });
  ASSERT_EQ(summary.scenes_arm_over, 1);
  const SceneLook look = loadSceneLook(folder / "scene_001_look.json");
  EXPECT_EQ(look.workcell, "iiwa-3f-sim");
  ASSERT_TRUE(look.arm_over.has_value());
  EXPECT_EQ(look.arm_over->arm.size(), 7);       // the LBR iiwa's joints
  EXPECT_EQ(look.arm_over->fingers.size(), 3u);  // the 3-finger hand's
  const SceneDetection again = detectInScene(folder / "scene_001.json", std::nullopt, 5, "iiwa-3f-sim", look);
  int accurate = 0, hidden = 0;
  for (std::size_t p = 0; p < again.truth.size(); ++p) {
    accurate += again.match.accurate(p) ? 1 : 0;
    hidden += again.truth[p].visible_fraction < kVisibleFraction ? 1 : 0;
  }
  EXPECT_EQ(static_cast<int>(again.truth.size()), report.parts);
  EXPECT_EQ(accurate, report.accurate_first_look);
  EXPECT_EQ(hidden, summary.scores.hidden_part_views);
  int detections = 0;
  for (const auto& [name, score] : summary.scores.classes) {
    detections += score.detections;
  }
  EXPECT_EQ(static_cast<int>(again.detected.size()), detections);
  // Without the arm, the parts it hid are seen.
  SceneLook no_arm = look;
  no_arm.arm_over.reset();
  const SceneDetection bare = detectInScene(folder / "scene_001.json", std::nullopt, 5, "iiwa-3f-sim", no_arm);
  double seen_with_arm = 0.0, seen_without = 0.0;
  for (std::size_t p = 0; p < again.truth.size(); ++p) {
    seen_with_arm += again.truth[p].visible_fraction;
    seen_without += bare.truth[p].visible_fraction;
  }
  EXPECT_GT(seen_without, seen_with_arm + 0.05);
  // A look made in another cell is refused, naming it.
  try {
    detectInScene(folder / "scene_001.json", std::nullopt, 5, "iiwa-sim", look);
    ADD_FAILURE() << "a look of iiwa-3f-sim accepted in iiwa-sim";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'iiwa-3f-sim'"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(folder);
}

TEST(PerceptionEval, ABadLookFileIsRefusedNamingTheFieldAndTheProblem) {
  const auto file = std::filesystem::temp_directory_path() / "costar_bad_look.json";
  const auto refusal = [&file](const std::string& text) {
    writeOutputFile(file, text);
    try {
      loadSceneLook(file);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refusal(R"({"camera_noise_seed": 3})").find("workcell: must be the cell's name"), std::string::npos);
  EXPECT_NE(refusal(R"({"workcell": "ur5-sim", "camera_noise_seed": -3})").find("camera_noise_seed: must be a whole"),
            std::string::npos);
  EXPECT_NE(refusal(R"({"workcell": "ur5-sim", "camera_noise_seed": 3, "arm": [0, 1]})").find("fingers: missing"),
            std::string::npos);
  EXPECT_NE(refusal(R"({"workcell": "ur5-sim", "camera_noise_seed": 3, "arm": [0, "x"], "fingers": [0.01]})")
                .find("arm[1]: must be a finite number"),
            std::string::npos);
  EXPECT_NE(refusal(R"({"workcell": "ur5-sim", "camera_noise_seed": 3, "arms": []})").find("arms: unknown field"),
            std::string::npos);
  EXPECT_NE(refusal("{").find(file.string()), std::string::npos);
  // What the evaluation writes reads back.
  SceneLook look;
  look.workcell = "ur5-sim";
  look.noise_seed = 18446744073709551615u;
  look.arm_over = ArmOverPose{sim::ArmJoints{-1.0, -0.6, -0.2, 0.2, 0.6, 1.0}, {0.042}};
  writeOutputFile(file, sceneLookJson(look).dump());
  const SceneLook read = loadSceneLook(file);
  EXPECT_EQ(read.noise_seed, look.noise_seed);
  ASSERT_TRUE(read.arm_over.has_value());
  EXPECT_EQ(read.arm_over->arm, look.arm_over->arm);
  EXPECT_EQ(read.arm_over->fingers, look.arm_over->fingers);
  std::filesystem::remove(file);
}

/// Every part of the scene file found within 5 mm / 5 degrees, for each sensor noise seed.
void expectEveryPartFound(const std::string& scene, std::initializer_list<std::uint64_t> seeds) {
  for (const std::uint64_t seed : seeds) {
    const SceneDetection found = detectInScene(dataRoot() / "trials/test/scenes" / scene, seed, 15);
    ASSERT_EQ(found.truth.size(), 6u);
    for (std::size_t p = 0; p < found.truth.size(); ++p) {
      EXPECT_TRUE(found.match.accurate(p)) << scene << ", noise seed " << seed << ": " << found.truth[p].name
                                           << " error " << found.match.translation_error[p] * 1000 << " mm";
    }
    EXPECT_EQ(found.detected.size(), found.truth.size()) << scene << ", noise seed " << seed;
  }
}

TEST(PerceptionEval, TwoLinksLyingEndToEndAreBothFound) {
  // One detection straddling both (half of each) fitted well enough to be accepted, and then
  // every start on either link overlapped it: with these noise seeds both links were missed
  // (17) or one was found 4 cm off along its length (15). The straddling detection is now
  // replaced by detections started at both ends of its points.
  expectEveryPartFound("links_end_to_end.json", {15, 17});
}

TEST(PerceptionEval, ALinkWhoseEndTouchesAnotherLinksSideIsNotSlidIntoIt) {
  // The neighbour's top, at the same height, confirmed a link slid 2.5 cm into it as well as
  // its own far end did: found 15-26 mm off (or missed) with each of these noise seeds. Now it
  // slides again crediting only surface the neighbour does not explain.
  expectEveryPartFound("links_in_a_t.json", {1, 3});
}

TEST(PerceptionEval, ALinkAcrossANodeItHidesIsFoundOnTheUr5AndPandaCells) {
  // The UR5 assembly's third look, seed 16039: of the base node under the grey link only two
  // slivers of its sides are seen (about 100 points each) and it is not found; the link across
  // it was then dropped as resting on nothing (keepSupported), so the top node had nowhere to go.
  // The Panda's own model missed it the same way with these noise seeds.
  for (const std::string cell : {"ur5-sim", "panda-sim"}) {
    for (const std::uint64_t seed : {1, 2}) {
      const SceneDetection found =
          detectInScene(dataRoot() / "trials/test/scenes/link_across_a_hidden_node.json", seed, 15, cell);
      const auto link = std::find_if(found.truth.begin(), found.truth.end(),
                                     [](const TruePart& part) { return part.name == "link_0"; });
      ASSERT_NE(link, found.truth.end());
      EXPECT_TRUE(found.match.accurate(static_cast<std::size_t>(link - found.truth.begin())))
          << cell << ", noise seed " << seed << ": the link across the node missed or off";
    }
  }
}

TEST(PerceptionEval, ALinkSeenAtOneEndOnlyIsFoundAsTheEvaluationSawIt) {
  // perception eval seed 501 scene 9, the first look on each cell (its look file): the grey link
  // is seen over 40 % of its length, the rest under the wood link across it and behind a node,
  // and was missed on ur5-sim, iiwa-sim and iiwa-3f-sim; the starts that put its end at either
  // end of its points find it.
  const auto scenes = dataRoot() / "trials/test/scenes";
  for (const std::string cell : {"ur5-sim", "iiwa-3f-sim"}) {
    const SceneLook look = loadSceneLook(scenes / ("link_with_one_end_hidden_" + cell + "_look.json"));
    const SceneDetection found = detectInScene(scenes / "link_with_one_end_hidden.json", std::nullopt, 15, cell, look);
    const auto link = std::find_if(found.truth.begin(), found.truth.end(),
                                   [](const TruePart& part) { return part.name == "link_0"; });
    ASSERT_NE(link, found.truth.end());
    EXPECT_GE(link->visible_fraction, kVisibleFraction) << cell;
    EXPECT_TRUE(found.match.accurate(static_cast<std::size_t>(link - found.truth.begin())))
        << cell << ": the link seen at one end missed or off";
  }
}

TEST(PerceptionEval, NoNodeIsFoundInTheGapBetweenFourTouchingNodes) {
  // perception eval seed 502 scene 8 on iiwa-3f-sim, its first look: a node fitted between the
  // tops of four touching nodes (confidence 0.942) was a false detection; each of the four held a
  // fifth or less of its volume, together most of it.
  const auto scenes = dataRoot() / "trials/test/scenes";
  const SceneLook look = loadSceneLook(scenes / "node_gap_between_four_nodes_iiwa-3f-sim_look.json");
  const SceneDetection found =
      detectInScene(scenes / "node_gap_between_four_nodes.json", std::nullopt, 15, "iiwa-3f-sim", look);
  for (std::size_t d = 0; d < found.detected.size(); ++d) {
    EXPECT_GE(found.match.part_of_detection[d], 0) << "false detection " << found.detected[d].name;
  }
  int accurate = 0, counted = 0;
  for (std::size_t p = 0; p < found.truth.size(); ++p) {
    if (found.truth[p].visible_fraction >= kVisibleFraction) {
      ++counted;
      accurate += found.match.accurate(p) ? 1 : 0;
    }
  }
  EXPECT_EQ(accurate, counted);
}

// Collection, small: one placement per class, one of clutter, 2 frames each.
TEST(PerceptionCollect, ASmallCollectionLabelsEveryClassAndFindsTheWorkspaceCentre) {
  const auto folder = std::filesystem::temp_directory_path() / "costar_perception_collect_test";
  std::filesystem::remove_all(folder);
  CollectOptions options;
  options.out = folder;
  options.scenes_per_class = 1;
  options.parts_per_scene = 2;
  options.arm_scenes = 0;
  options.clutter_scenes = 1;
  options.mixed_scenes = 1;
  options.frames = 2;
  // The 3-finger iiwa cell: its hand's description is found from the clutter's data root too.
  options.workcell = "iiwa-3f-sim";
  std::vector<CollectProgress> events;
  const CollectResult result =
      collectTrainingData(options, [&events](const CollectProgress& event) { events.push_back(event); });
  // Steps 1-4 announced, then 4 placements (node, link, clutter, mixed), counted to their total.
  ASSERT_EQ(events.size(), 8u);
  EXPECT_EQ(events[0].step, 1);
  EXPECT_TRUE(events[0].scene.empty());
  EXPECT_EQ(events.back().done, 4);
  EXPECT_EQ(events.back().total, 4);
  EXPECT_EQ(events.back().scene, "mixed scene 1");
  EXPECT_GE(events.back().examples, 2);  // a mixed scene holds nodes and links
  // The marker lies at the table's centre (x 0.5 m, y 0) on the table top.
  EXPECT_NEAR(result.table_center.translation().x(), 0.5, 0.003);
  EXPECT_NEAR(result.table_center.translation().y(), 0.0, 0.003);
  EXPECT_NEAR(result.table_center.translation().z(), 0.0, 0.003);
  // The file keeps 0.01 mm and 0.001 degrees.
  const world::Pose saved = perception::loadTableCenter(result.workspace_file);
  EXPECT_LT((saved.translation() - result.table_center.translation()).norm(), 1e-4);
  EXPECT_LT(Eigen::AngleAxisd(saved.linear().transpose() * result.table_center.linear()).angle(), 1e-4);
  // Every class labelled, the clutter as background; the files read back as written.
  const perception::TrainingSet set = perception::loadTrainingSet(folder);
  EXPECT_EQ(static_cast<long>(set.labels.size()), result.rows);
  for (const auto& [label, name] : result.names) {
    EXPECT_GT(result.voxels.at(label), 50) << name;
  }
  EXPECT_EQ(result.names.at(0), "background");
  std::filesystem::remove_all(folder);
}

// The negatives pose the cell's own arm: its joint count and limits, the flange over the table.
TEST(PerceptionScenes, EachCellsArmIsPosedWithItsOwnJointsOverTheTable) {
  for (const auto& [name, joints] : {std::pair<std::string, int>{"ur5-sim", 6}, {"iiwa-3f-sim", 7}}) {
    const workcell::CellSimulation cell = workcell::cellSimulation(name);
    const auto kinematics = arm::makeKinematics(cell.robot);
    std::mt19937_64 random(5);
    for (int i = 0; i < 20; ++i) {
      const std::optional<sim::ArmJoints> q = armOverTable(cell, *kinematics, 0.06, random);
      ASSERT_TRUE(q) << name;
      ASSERT_EQ(q->size(), joints) << name;
      for (int j = 0; j < joints; ++j) {
        EXPECT_GE((*q)[j], cell.robot.limits.min_position[j]) << name << " joint " << j;
        EXPECT_LE((*q)[j], cell.robot.limits.max_position[j]) << name << " joint " << j;
      }
      const Eigen::Vector3d flange = (cell.cell.robot_base * kinematics->forward(*q)).translation();
      EXPECT_GT(flange.x(), 0.2) << name;
      EXPECT_LT(flange.x(), 0.8) << name;
      EXPECT_LT(std::abs(flange.y()), 0.45) << name;
      EXPECT_GT(flange.z(), 0.14) << name;
    }
  }
}

// Links across nodes: over a node, dropped from above it, never two starting inside each other;
// asking for none draws nothing (the evaluation's seeds keep their scenes).
TEST(PerceptionScenes, LinksAreStackedOnNodesNeverInsideEachOther) {
  std::mt19937_64 random(11);
  sim::Scene scene = sim::clutteredScene(classes(), {{"node", 6}, {"link", 1}}, 0.0, random, "stack test").scene;
  const std::size_t before = scene.parts.size();
  std::mt19937_64 copy = random;
  EXPECT_EQ(stackLinksOnNodes(scene, classes(), 0, random), 0);
  EXPECT_EQ(random(), copy());
  const int stacked = stackLinksOnNodes(scene, classes(), 3, random);
  EXPECT_GE(stacked, 1);
  EXPECT_LE(stacked, 3);
  ASSERT_EQ(scene.parts.size(), before + static_cast<std::size_t>(stacked));
  for (std::size_t p = before; p < scene.parts.size(); ++p) {
    const sim::PartRequest& link = scene.parts[p];
    EXPECT_EQ(link.object_class, "link");
    EXPECT_NEAR(link.height, 0.053, 1e-9);  // the node's 5 cm and 3 mm
    bool over_a_node = false;
    for (std::size_t n = 0; n < before; ++n) {
      over_a_node |= scene.parts[n].object_class == "node" &&
                     (scene.parts[n].at->head<2>() - link.at->head<2>()).norm() <= 0.03 + 1e-9;
    }
    EXPECT_TRUE(over_a_node) << p;
  }
  // The simulator accepts the scene (no two parts starting inside each other).
  EXPECT_NO_THROW(sim::placeParts(scene, classes()));
}

}  // namespace
}  // namespace costar::trials
