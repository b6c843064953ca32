// Stage 4: ObjRecRANSAC + ICP + the depth check, on ray-cast scenes with depth noise.

#include "perception/pose_estimation.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <numeric>
#include <sstream>
#include <string>
#include <thread>

#include "core/paths.h"
#include "perception/canonical_orientation.h"
#include "perception/test/synthetic_scene.h"
#include "perception/workspace.h"

namespace costar::perception {
namespace {

class PoseEstimation : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    models_ = new std::vector<ObjectModel>(
        loadObjectModels(dataRoot() / "data/objects", dataRoot() / "data/perception/classes.json"));
  }
  static void TearDownTestSuite() {
    delete models_;
    models_ = nullptr;
  }
  static const ObjectModel& model(const std::string& name) {
    for (const auto& m : *models_) {
      if (m.name() == name) {
        return m;
      }
    }
    throw std::runtime_error(name);
  }
  /// The points of the rendered frame above the table with the given colour.
  static Cloud pointsOfColor(const camera::RgbdFrame& frame, const Rgb& color) {
    WorkspaceCloud workspace = cropWorkspace(frame, {});
    estimateNormals(frame, workspace.cloud);
    Cloud out;
    for (std::size_t i = 0; i < workspace.cloud.size(); ++i) {
      if (workspace.cloud.colors[i] == color) {
        out.append(workspace.cloud, i);
      }
    }
    return out;
  }
  /// A red node turned 0.2 rad on the table, depth noise drawn from seed 3.
  static constexpr Rgb kRed{200, 30, 30};
  static camera::RgbdFrame oneRedNode() {
    return test::renderSynthetic(
        {{&model("node").object_class, world::poseFromXyzRpy(0.55, 0.0, 0.025, 0, 0, 0.2), kRed}}, 0.001, 3);
  }
  static std::vector<ObjectModel>* models_;
};

std::vector<ObjectModel>* PoseEstimation::models_ = nullptr;

// Parts rest on the table or on each other; a box matched on the robot's arm or gripper floats
// (the UR5 cell with its arm over the parts, `perception eval --arm-over`, seed 101: 18 false
// detections 6-24 cm above the table).
TEST_F(PoseEstimation, OnlyDetectionsRestingOnTheTableOrAnotherPartAreKept) {
  TablePlane table;  // z = 0 of the frame the poses are in
  const auto detection = [](const std::string& object_class, double x, double z, double yaw = 0.0) {
    Detection d;
    d.object_class = object_class;
    d.pose_in_camera = world::poseFromXyzRpy(x, 0.0, z, 0, 0, yaw);
    return d;
  };
  const std::vector<Detection> found = {
      detection("node", 0.5, 0.025),         // on the table
      detection("link", 0.51, 0.0625, 0.7),  // across it: its bottom on the node's top
      detection("link", 0.8, 0.0625),        // as high, over nothing
      detection("node", 0.5, 0.20),          // high over the first node
      detection("link", 0.3, 0.0085, 0.1),   // on the table, 4 mm of noise under it
  };
  const std::vector<Detection> kept = keepSupported(found, *models_, table, 0.01);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_NEAR(kept[0].pose_in_camera.translation().x(), 0.5, 1e-12);
  EXPECT_NEAR(kept[1].pose_in_camera.translation().x(), 0.51, 1e-12);
  EXPECT_NEAR(kept[2].pose_in_camera.translation().x(), 0.3, 1e-12);
  // The chain needs its base: without the node the link across it floats.
  EXPECT_EQ(keepSupported({found[1]}, *models_, table, 0.01).size(), 0u);
  EXPECT_THROW(keepSupported({detection("cone", 0.5, 0.0)}, *models_, table, 0.01), std::invalid_argument);
}

// A node under the link put across it shows only slivers of its sides, too few to be found
// (the UR5 assembly's third look, seeds 16039, 16062 and 16069: 98-124 points a side): those
// points standing on the table hold the link up, or it was dropped as floating and the top node
// had nowhere to go ("put it on the link: 1 candidate, none feasible").
TEST_F(PoseEstimation, ALinkAcrossANodeSeenOnlyAtItsSidesIsKept) {
  TablePlane table;  // z = 0 of the frame the poses are in
  Detection link;
  link.object_class = "link";
  link.pose_in_camera = world::poseFromXyzRpy(0.5, 0.0, 0.0625, 0, 0, 0);  // its bottom 5 cm up
  // A side of a node 5 cm wide, its points from `bottom` to `top` above the table.
  const auto side = [](double x, double y, double bottom, double top) {
    std::vector<Eigen::Vector3f> points;
    for (double along = -0.025; along <= 0.025; along += 0.005) {
      for (double z = bottom; z <= top + 1e-9; z += 0.004) {
        points.emplace_back(static_cast<float>(x + along), static_cast<float>(y), static_cast<float>(z));
      }
    }
    return points;
  };
  EXPECT_EQ(
      keepSupported({link}, *models_, table, 0.01, {side(0.5, -0.025, 0.002, 0.05), side(0.5, 0.025, 0.002, 0.05)})
          .size(),
      1u);
  // Points that float (matched on the arm) hold nothing up; nor does a part lower than the
  // link's bottom, or one beside it.
  EXPECT_EQ(keepSupported({link}, *models_, table, 0.01, {side(0.5, 0.025, 0.022, 0.05)}).size(), 0u);
  EXPECT_EQ(keepSupported({link}, *models_, table, 0.01, {side(0.5, 0.025, 0.002, 0.026)}).size(), 0u);
  EXPECT_EQ(keepSupported({link}, *models_, table, 0.01, {side(0.7, 0.025, 0.002, 0.05)}).size(), 0u);
}

// Resting is within the tolerance on both sides: a link sunk 2.6 cm into the table rests on
// nothing (iiwa-3f-sim, perception eval seed 202 scene 9: one refined among its neighbours'
// points was reported with its centre 1.4 cm below the table top).
TEST_F(PoseEstimation, ADetectionSunkIntoTheTableIsNotKept) {
  TablePlane table;
  Detection sunk;
  sunk.object_class = "link";
  sunk.pose_in_camera = world::poseFromXyzRpy(0.5, 0.0, -0.014, 0, 0, 0);
  EXPECT_TRUE(keepSupported({sunk}, *models_, table, 0.01).empty());
  sunk.pose_in_camera = world::poseFromXyzRpy(0.5, 0.0, 0.004, 0, 0, 0);  // 8.5 mm in: noise
  EXPECT_EQ(keepSupported({sunk}, *models_, table, 0.01).size(), 1u);
}

// A leaning part rests on the table at one end and on another part at the other: a box matched
// on the arm stood tilted on the table with nothing under its raised end (iiwa-sim, perception
// eval seed 203 scene 3: a link tilted 45 degrees on the iiwa's orange elbow, confidence 0.98,
// 22 % of it seen, its lowest corner on the table). What holds a part up may be hidden (a link
// leaning on a node the arm hides, ur5-sim seed 201 scene 1, 39 % of it seen): one seen a third
// or more is kept.
TEST_F(PoseEstimation, ALeaningDetectionIsKeptOnlyWithAPartUnderItsRaisedEndOrMoreOfItSeen) {
  TablePlane table;
  const double pitch = 25.0 * M_PI / 180.0;
  Detection leaning;
  leaning.object_class = "link";
  leaning.visible_fraction = 0.22;
  // Its lowest corner on the table, its +x end raised 8.6 cm.
  leaning.pose_in_camera =
      world::poseFromXyzRpy(0.5, 0.0, 0.075 * std::sin(pitch) + 0.0125 * std::cos(pitch), 0, -pitch, 0);
  EXPECT_TRUE(keepSupported({leaning}, *models_, table, 0.01).empty());
  Detection node;
  node.object_class = "node";
  node.pose_in_camera = world::poseFromXyzRpy(0.55, 0.0, 0.025, 0, 0, 0);  // under the raised end
  EXPECT_EQ(keepSupported({leaning, node}, *models_, table, 0.01).size(), 2u);
  node.pose_in_camera = world::poseFromXyzRpy(0.45, 0.12, 0.025, 0, 0, 0);  // beside it
  EXPECT_EQ(keepSupported({leaning, node}, *models_, table, 0.01).size(), 1u);
  Detection seen = leaning;
  seen.visible_fraction = 0.39;
  EXPECT_EQ(keepSupported({seen}, *models_, table, 0.01).size(), 1u);
  // Tilted 15 degrees, it lies flat enough (levelResting lays it flat): the table keeps it.
  leaning.pose_in_camera =
      world::poseFromXyzRpy(0.5, 0.0, 0.075 * std::sin(0.26) + 0.0125 * std::cos(0.26), 0, -0.26, 0);
  EXPECT_EQ(keepSupported({leaning}, *models_, table, 0.01).size(), 1u);
}

TEST_F(PoseEstimation, IcpConvergesFromAnOffsetPose) {
  const ObjectModel& node = model("node");
  const world::Pose truth = world::poseFromXyzRpy(0.02, -0.01, 1.1, 0.4, -0.3, 0.7);
  // The camera-facing samples of the model, as a scene.
  std::vector<Eigen::Vector3f> scene;
  for (std::size_t i = 0; i < node.surface.size(); ++i) {
    const Eigen::Vector3d p = truth * node.surface.points[i].cast<double>();
    const Eigen::Vector3d n = truth.linear() * node.surface.normals[i].cast<double>();
    if (n.dot(p) < 0) {
      scene.push_back(p.cast<float>());
    }
  }
  const world::Pose start = truth * world::poseFromXyzRpy(0.006, -0.004, 0.003, 0.08, 0.05, -0.1);
  const IcpResult result = refinePose(node, scene, start, 30, 0.02, 0.003);
  EXPECT_LT((result.pose.translation() - truth.translation()).norm(), 0.0005);
  EXPECT_LT(symmetricRotationDistance(result.pose.linear(), truth.linear(), node.object_class), 0.5 * M_PI / 180);
  EXPECT_GT(result.inliers, static_cast<int>(scene.size() * 0.9));
}

TEST_F(PoseEstimation, TheDepthCheckConfirmsTheTruePoseAndRejectsAShiftedOne) {
  const ObjectModel& link = model("link");
  const world::Pose pose = world::poseFromXyzRpy(0.5, 0.1, 0.0125, 0, 0, 0.4);
  const camera::RgbdFrame frame = test::renderSynthetic({{&link.object_class, pose}});
  const world::Pose in_camera = frame.camera_pose.inverse() * pose;
  const DepthAgreement good = compareWithDepth(link, in_camera, frame, 0.004);
  EXPECT_GT(good.agreement(), 0.98);
  EXPECT_GT(good.visibleFraction(), 0.8);
  // Slid 3 cm along its axis: the overhang sees the table behind it.
  const DepthAgreement slid =
      compareWithDepth(link, in_camera * world::Pose(Eigen::Translation3d(0.03, 0, 0)), frame, 0.004);
  EXPECT_LT(slid.agreement(), 0.85);
}

TEST_F(PoseEstimation, OverlapMeasuresSharedVolume) {
  const ObjectModel& node = model("node");
  const world::Pose a(Eigen::Translation3d(0, 0, 1));
  EXPECT_GT(overlapFraction(node, a, node, a), 0.95);
  // Half a cube over (less than half its samples: the sockets are hollow).
  EXPECT_NEAR(overlapFraction(node, a, node, a * world::Pose(Eigen::Translation3d(0.025, 0, 0))), 0.4, 0.1);
  EXPECT_EQ(overlapFraction(node, a, node, a * world::Pose(Eigen::Translation3d(0.051, 0, 0))), 0.0);
}

// Four nodes touching in a square (5.3 cm apart, as iiwa-3f-sim perception eval seed 502 scene 8
// put them, a link across two of them): a node fitted into the gap between their tops is
// confirmed by the four tops at its height, its sides hidden by theirs. Each of them holds a
// fifth or less of it, so it was kept (a false detection, confidence 0.942); together they hold
// most of it.
TEST_F(PoseEstimation, ADetectionInTheGapBetweenFourTouchingNodesIsNotKept) {
  const ObjectModel& node = model("node");
  std::vector<Detection> detections;
  std::vector<PlacedModel> four;
  for (const double x : {0.0, 0.053}) {
    for (const double y : {0.0, 0.053}) {
      Detection d;
      d.object_class = "node";
      d.pose_in_camera = world::Pose(Eigen::Translation3d(x, y, 0.6));
      d.confidence = 0.98;
      d.visible_fraction = 0.6;
      detections.push_back(d);
      four.push_back({&node, d.pose_in_camera});
    }
  }
  Detection gap;
  gap.object_class = "node";
  gap.pose_in_camera = world::Pose(Eigen::Translation3d(0.0265, 0.0265, 0.6)) *
                       world::Pose(Eigen::AngleAxisd(0.33, Eigen::Vector3d::UnitZ()));
  gap.confidence = 0.942;
  gap.visible_fraction = 0.3;
  for (const PlacedModel& one : four) {
    EXPECT_LE(overlapFraction(node, gap.pose_in_camera, *one.model, one.pose), kOverlapTaken);
  }
  EXPECT_GT(overlapFraction(node, gap.pose_in_camera, four), 0.6);
  detections.push_back(gap);
  const std::vector<Detection> kept = mergeDetections(detections, node);
  ASSERT_EQ(kept.size(), 4u);
  for (const Detection& d : kept) {
    EXPECT_GT(d.confidence, 0.95);  // the four, not the one between them
  }
  // A fifth node touching the square's side is its own.
  Detection beside = detections[0];
  beside.pose_in_camera = world::Pose(Eigen::Translation3d(0.106, 0.0, 0.6));
  beside.confidence = 0.9;
  detections.back() = beside;
  EXPECT_EQ(mergeDetections(detections, node).size(), 5u);
  EXPECT_EQ(overlapFraction(node, beside.pose_in_camera, std::vector<PlacedModel>{}), 0.0);
}

TEST_F(PoseEstimation, FindsEveryInstanceOfAClassWithDepthNoise) {
  const ObjectModel& node = model("node");
  const ObjectModel& link = model("link");
  const Rgb red{200, 30, 30};
  const Rgb wood{184, 133, 77};
  std::vector<world::Pose> nodes = {world::poseFromXyzRpy(0.45, -0.2, 0.025, 0, 0, 0.3),
                                    world::poseFromXyzRpy(0.6, 0.15, 0.025, 0, 0, -1.1)};
  nodes.push_back(nodes[0] * world::Pose(Eigen::Translation3d(0, 0.0505, 0)));  // touching the first
  const world::Pose link_pose = world::poseFromXyzRpy(0.4, 0.2, 0.0125, 0, 0, 2.0);
  std::vector<test::SyntheticObject> objects;
  for (const auto& pose : nodes) {
    objects.push_back({&node.object_class, pose, red});
  }
  objects.push_back({&link.object_class, link_pose, wood});
  const camera::RgbdFrame frame = test::renderSynthetic(objects, 0.001, 7);

  ClassPoseEstimator node_estimator(node);
  std::vector<Detection> found;
  { found = node_estimator.estimate(pointsOfColor(frame, red), frame); }
  ASSERT_EQ(found.size(), nodes.size());
  for (const auto& truth : nodes) {
    const auto best = std::min_element(found.begin(), found.end(), [&](const Detection& a, const Detection& b) {
      return ((frame.camera_pose * a.pose_in_camera).translation() - truth.translation()).norm() <
             ((frame.camera_pose * b.pose_in_camera).translation() - truth.translation()).norm();
    });
    const world::Pose world_pose = frame.camera_pose * best->pose_in_camera;
    EXPECT_LT((world_pose.translation() - truth.translation()).norm(), 0.003);
    EXPECT_LT(symmetricRotationDistance(world_pose.linear(), truth.linear(), node.object_class), 3 * M_PI / 180);
    EXPECT_GE(best->confidence, 0.93);
  }
  ClassPoseEstimator link_estimator(link);
  { found = link_estimator.estimate(pointsOfColor(frame, wood), frame); }
  ASSERT_EQ(found.size(), 1u);
  const world::Pose world_pose = frame.camera_pose * found[0].pose_in_camera;
  EXPECT_LT((world_pose.translation() - link_pose.translation()).norm(), 0.003);
  EXPECT_LT(symmetricRotationDistance(world_pose.linear(), link_pose.linear(), link.object_class), 3 * M_PI / 180);
}

TEST_F(PoseEstimation, IsDeterministic) {
  const ObjectModel& node = model("node");
  const camera::RgbdFrame frame = oneRedNode();
  const Cloud points = pointsOfColor(frame, kRed);
  std::vector<Detection> first;
  std::vector<Detection> second;
  {
    ClassPoseEstimator a(node);
    ClassPoseEstimator b(node);
    first = a.estimate(points, frame);
    second = b.estimate(points, frame);
  }
  ASSERT_EQ(first.size(), 1u);
  ASSERT_EQ(second.size(), 1u);
  EXPECT_TRUE(first[0].pose_in_camera.isApprox(second[0].pose_in_camera, 1e-12));
}

TEST_F(PoseEstimation, RestingSeedsStartNearANodeSeenSquareOn) {
  // A node turned square to the camera (its top and its front face in view, the sides at
  // grazing angles): the points' principal axes lie between the two faces; standing on the
  // table, turned in steps, one start is near the truth.
  const ObjectModel& node = model("node");
  const Rgb green{30, 180, 60};
  const world::Pose truth = world::poseFromXyzRpy(0.42, 0.05, 0.025, 0, 0, M_PI / 2);
  const camera::RgbdFrame frame = test::renderSynthetic({{&node.object_class, truth, green}}, 0.001, 5);
  const Cloud points = pointsOfColor(frame, green);
  ASSERT_GT(points.size(), 100u);
  std::vector<int> indices(points.size());
  std::iota(indices.begin(), indices.end(), 0);
  const TablePlane plane = cropWorkspace(frame, {}).plane;
  const std::vector<world::Pose> seeds = restingSeeds(points, indices, plane, node.object_class);
  ASSERT_EQ(seeds.size(), 60u);  // 12 turns under the points' mean and a quarter width off it four ways
  const world::Pose truth_in_camera = frame.camera_pose.inverse() * truth;
  double nearest_angle = M_PI;
  double nearest_distance = 1.0;
  for (const world::Pose& seed : seeds) {
    // Upright on the plane: z along its normal, the bottom face's middle on it.
    EXPECT_GT(seed.linear().col(2).dot(plane.normal), 0.999);
    EXPECT_NEAR(plane.height((seed * Eigen::Vector3d(0, 0, node.object_class.bounds().min().z())).cast<float>()), 0.0,
                1e-6);
    nearest_angle =
        std::min(nearest_angle, symmetricRotationDistance(seed.linear(), truth_in_camera.linear(), node.object_class));
    nearest_distance = std::min(nearest_distance, (seed.translation() - truth_in_camera.translation()).norm());
  }
  EXPECT_LT(nearest_angle, 8 * M_PI / 180);
  EXPECT_LT(nearest_distance, 0.015);
  EXPECT_TRUE(restingSeeds(points, {0, 1, 2}, plane, node.object_class).empty());  // too few points
}

TEST_F(PoseEstimation, RestingSeedsStartNearALinkLyingOnANode) {
  // A link put on a node, seen end-on (its top and its near end in view): its lowest points
  // are a node's height above the table, so it rests on something else; seeds on that level
  // start near it too (a link on the base node of the assembly was missed, trial seed 9183's
  // kin).
  const ObjectModel& node = model("node");
  const ObjectModel& link = model("link");
  const Rgb red{200, 30, 30};
  const Rgb grey{128, 128, 128};
  const world::Pose node_pose = world::poseFromXyzRpy(0.54, 0.05, 0.025, 0, 0, M_PI / 2);
  const world::Pose truth = world::poseFromXyzRpy(0.54, 0.05, 0.0625, 0, 0, 0.0);
  const camera::RgbdFrame frame =
      test::renderSynthetic({{&node.object_class, node_pose, red}, {&link.object_class, truth, grey}}, 0.001, 5);
  const Cloud points = pointsOfColor(frame, grey);
  ASSERT_GT(points.size(), 50u);
  std::vector<int> indices(points.size());
  std::iota(indices.begin(), indices.end(), 0);
  const TablePlane plane = cropWorkspace(frame, {}).plane;
  const std::vector<world::Pose> seeds = restingSeeds(points, indices, plane, link.object_class);
  ASSERT_EQ(seeds.size(), 120u);  // on the table, and on the node's top, at each of 5 places
  const world::Pose truth_in_camera = frame.camera_pose.inverse() * truth;
  const double bottom = link.object_class.bounds().min().z();
  double nearest_angle = M_PI;
  double nearest_distance = 1.0;
  int on_table = 0;
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    const double level = plane.height((seeds[i] * Eigen::Vector3d(0, 0, bottom)).cast<float>());
    if (std::abs(level) < 1e-6) {
      ++on_table;
      continue;
    }
    EXPECT_NEAR(level, 0.05, 0.01);  // the node's top, from the lowest points seen (on the near end's face)
    nearest_angle = std::min(nearest_angle,
                             symmetricRotationDistance(seeds[i].linear(), truth_in_camera.linear(), link.object_class));
    nearest_distance = std::min(nearest_distance, (seeds[i].translation() - truth_in_camera.translation()).norm());
  }
  EXPECT_LT(nearest_angle, 8 * M_PI / 180);
  EXPECT_LT(nearest_distance, 0.03);
  std::printf("nearest raised seed: %.1f mm, %.1f deg\n", 1000 * nearest_distance, nearest_angle * 180 / M_PI);
  EXPECT_EQ(on_table, 60);
  // A node on the table gets the table's 60 only (RestingSeedsStartNearANodeSeenSquareOn).
}

TEST_F(PoseEstimation, RestingSeedsStartNearANodeOnlyItsFrontFaceShows) {
  // A node whose top is hidden (a link lying on it, iiwa-sim perception eval seed 201 scene 4):
  // only its front face is in view, so the points' mean lies half a node in front of its middle.
  // One of the starts a quarter width off the mean is within 6 mm of it (4.9 mm; under the mean
  // alone the nearest was 8.1 mm, and in the simulated scene ICP on one face did not carry the
  // start there).
  const ObjectModel& node = model("node");
  const Rgb green{30, 180, 60};
  const world::Pose truth = world::poseFromXyzRpy(0.42, 0.05, 0.025, 0, 0, M_PI / 2 + 0.05);
  const camera::RgbdFrame frame = test::renderSynthetic({{&node.object_class, truth, green}}, 0.001, 5);
  const TablePlane plane = cropWorkspace(frame, {}).plane;
  Cloud all = pointsOfColor(frame, green);
  Cloud points;
  for (std::size_t i = 0; i < all.size(); ++i) {
    if (plane.height(all.points[i]) < 0.04) {  // below the top: the faces towards the camera
      points.append(all, i);
    }
  }
  ASSERT_GT(points.size(), 100u);
  std::vector<int> indices(points.size());
  std::iota(indices.begin(), indices.end(), 0);
  const world::Pose truth_in_camera = frame.camera_pose.inverse() * truth;
  double nearest = 1.0;
  for (const world::Pose& seed : restingSeeds(points, indices, plane, node.object_class)) {
    if (symmetricRotationDistance(seed.linear(), truth_in_camera.linear(), node.object_class) < 8 * M_PI / 180) {
      nearest = std::min(nearest, (seed.translation() - truth_in_camera.translation()).norm());
    }
  }
  std::printf("nearest seed within 8 deg: %.1f mm\n", 1000 * nearest);
  EXPECT_LT(nearest, 0.006);
}

TEST_F(PoseEstimation, RestingSeedsStartNearALinkWithOneEndHidden) {
  // A link seen over 40 % of its length, the rest hidden (under a link lying across it and
  // behind a node: ur5-sim, iiwa-sim and iiwa-3f-sim perception eval seed 501 scene 9, missed on
  // all three): its middle lies 4.5 cm from its points' mean, along it. Starts with the link's
  // end at either extreme of the points bring one within 1.5 cm of it; a link seen whole gets
  // none.
  const ObjectModel& link = model("link");
  const Rgb grey{128, 128, 128};
  const world::Pose truth = world::poseFromXyzRpy(0.47, 0.05, 0.0125, 0, 0, 1.2);
  const camera::RgbdFrame frame = test::renderSynthetic({{&link.object_class, truth, grey}}, 0.001, 5);
  const TablePlane plane = cropWorkspace(frame, {}).plane;
  const Cloud all = pointsOfColor(frame, grey);
  std::vector<int> whole(all.size());
  std::iota(whole.begin(), whole.end(), 0);
  EXPECT_TRUE(restingSeedsAtEnds(all, whole, plane, link.object_class).empty());
  const world::Pose truth_in_camera = frame.camera_pose.inverse() * truth;
  Cloud points;
  for (std::size_t i = 0; i < all.size(); ++i) {
    if ((truth_in_camera.inverse() * all.points[i].cast<double>()).x() > 0.015) {  // its last 6 of 15 cm
      points.append(all, i);
    }
  }
  ASSERT_GT(points.size(), 50u);
  std::vector<int> indices(points.size());
  std::iota(indices.begin(), indices.end(), 0);
  const auto nearest = [&](const std::vector<world::Pose>& seeds) {
    double distance = 1.0;
    for (const world::Pose& seed : seeds) {
      if (symmetricRotationDistance(seed.linear(), truth_in_camera.linear(), link.object_class) < 8 * M_PI / 180) {
        distance = std::min(distance, (seed.translation() - truth_in_camera.translation()).norm());
      }
    }
    return distance;
  };
  const std::vector<world::Pose> ends = restingSeedsAtEnds(points, indices, plane, link.object_class);
  ASSERT_EQ(ends.size(), 24u);
  const double at_ends = nearest(ends);
  const double under_middle = nearest(restingSeeds(points, indices, plane, link.object_class));
  std::printf("nearest start within 8 deg: %.1f mm at the ends, %.1f mm under the middle\n", 1000 * at_ends,
              1000 * under_middle);
  EXPECT_LT(at_ends, 0.015);
  EXPECT_GT(under_middle, 0.03);
}

// A square link lying across a node, side-on to the camera (as the 3-finger iiwa puts it in the
// assembly, trial seed 2109), found rolled 12 deg about its length: the depth check (6 mm) passes
// it, but SmartRelease puts nothing on a top tilted that much. Levelled, it rests flat; a link
// leaning 25 deg is left as found.
TEST_F(PoseEstimation, ADetectionNearlyRestingFlatIsLevelled) {
  const ObjectModel& node = model("node");
  const ObjectModel& link = model("link");
  const world::Pose node_pose = world::poseFromXyzRpy(0.6, 0.05, 0.025, 0, 0, 0);
  const world::Pose truth = world::poseFromXyzRpy(0.591, 0.05, 0.0625, 0, 0, M_PI / 2);
  const camera::RgbdFrame frame = test::renderSynthetic(
      {{&node.object_class, node_pose, {20, 60, 200}}, {&link.object_class, truth, {128, 128, 128}}}, 0.001, 7);
  ClassPoseEstimator estimator(link);
  estimator.setSupportPlane(cropWorkspace(frame, {}).plane);
  const world::Pose truth_in_camera = frame.camera_pose.inverse() * truth;
  const auto found = [&](double roll) {
    Detection detection;
    detection.object_class = "link";
    detection.pose_in_camera = truth_in_camera * world::Pose(Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()));
    const DepthAgreement agreement = compareWithDepth(link, detection.pose_in_camera, frame, 0.006);
    detection.confidence = agreement.agreement();
    detection.visible_fraction = agreement.visibleFraction();
    return detection;
  };
  std::vector<Detection> detections{found(12 * M_PI / 180), found(25 * M_PI / 180)};
  EXPECT_GT(detections[0].confidence, 0.93) << "the rolled pose passes the depth check";
  estimator.levelResting(detections, frame);
  EXPECT_LT(world::rotationAngle(detections[0].pose_in_camera, truth_in_camera), 0.5 * M_PI / 180);
  EXPECT_GT(detections[0].confidence, 0.93);
  EXPECT_NEAR(world::rotationAngle(detections[1].pose_in_camera, truth_in_camera), 25 * M_PI / 180, 1e-9);
}

// Refining touching parts on their own points keeps what verify() asked of a detection: a pose
// the refinement would take below the support plane (or below the confidence) is not taken, the
// detection stays as it was (iiwa-3f-sim, perception eval seed 202 scene 9: a link refined among
// its neighbours' points was reported 2.6 cm, then 6.2 cm below the table with confidence 0.50).
TEST_F(PoseEstimation, RefiningTouchingPartsNeverTakesAPoseThatFailsTheChecks) {
  const ObjectModel& node = model("node");
  const Rgb green{30, 180, 60};
  const std::vector<world::Pose> truths = {world::poseFromXyzRpy(0.47, -0.03, 0.025, 0, 0, 0.1),
                                           world::poseFromXyzRpy(0.47, 0.0205, 0.025, 0, 0, 0.1)};
  const camera::RgbdFrame frame =
      test::renderSynthetic({{&node.object_class, truths[0], green}, {&node.object_class, truths[1], green}}, 0.001, 5);
  const Cloud points = pointsOfColor(frame, green);
  std::vector<Detection> given;
  for (const world::Pose& truth : truths) {
    Detection detection;
    detection.object_class = "node";
    // 3 mm off along the table, 2 mm up: the refinement moves it back onto its points.
    detection.pose_in_camera = frame.camera_pose.inverse() * world::poseFromXyzRpy(0.003, 0.0, 0.002, 0, 0, 0) * truth;
    detection.confidence = 0.95;
    given.push_back(detection);
  }
  TablePlane table = cropWorkspace(frame, {}).plane;
  ClassPoseEstimator estimator(node);
  estimator.setSupportPlane(table);
  std::vector<Detection> refined = given;
  estimator.refineTouching(points, refined, frame);
  for (std::size_t i = 0; i < given.size(); ++i) {
    const world::Pose truth_in_camera = frame.camera_pose.inverse() * truths[i];
    EXPECT_LT((refined[i].pose_in_camera.translation() - truth_in_camera.translation()).norm(), 0.002);
    EXPECT_GE(refined[i].confidence, estimator.options().min_confidence);
  }
  // The same with the support plane 1 cm higher than the table: every refined pose would reach
  // below it, so none is taken.
  table.offset -= 0.01;
  estimator.setSupportPlane(table);
  refined = given;
  estimator.refineTouching(points, refined, frame);
  for (std::size_t i = 0; i < given.size(); ++i) {
    EXPECT_TRUE(refined[i].pose_in_camera.isApprox(given[i].pose_in_camera, 1e-12));
    EXPECT_EQ(refined[i].confidence, given[i].confidence);
  }
}

TEST_F(PoseEstimation, TwoTouchingNodesSeenSquareOnAreBothFound) {
  // Two nodes side by side, touching, both square to the camera (as in eval seed 17, scene 11,
  // where both were missed in every look): one cluster whose middle lies between them, so the
  // upright starts under the middle fit neither; the starts at both ends of the points are near
  // each. (This synthetic view is easier than the simulated one: ObjRecRANSAC finds both here
  // without those starts too; `perception eval` seeds 21-30 show the difference.)
  const ObjectModel& node = model("node");
  const Rgb green{30, 180, 60};
  const std::vector<world::Pose> truths = {world::poseFromXyzRpy(0.47, -0.03, 0.025, 0, 0, M_PI / 2),
                                           world::poseFromXyzRpy(0.47, 0.0205, 0.025, 0, 0, M_PI / 2)};
  const camera::RgbdFrame frame =
      test::renderSynthetic({{&node.object_class, truths[0], green}, {&node.object_class, truths[1], green}}, 0.001, 5);
  const Cloud points = pointsOfColor(frame, green);
  std::vector<int> indices(points.size());
  std::iota(indices.begin(), indices.end(), 0);
  const TablePlane plane = cropWorkspace(frame, {}).plane;
  const std::vector<world::Pose> ends = restingSeedsAtEnds(points, indices, plane, node.object_class);
  ASSERT_EQ(ends.size(), 24u);
  for (const world::Pose& truth : truths) {
    const world::Pose truth_in_camera = frame.camera_pose.inverse() * truth;
    double nearest = 1.0;
    for (const world::Pose& seed : ends) {
      if (symmetricRotationDistance(seed.linear(), truth_in_camera.linear(), node.object_class) < 8 * M_PI / 180) {
        nearest = std::min(nearest, (seed.translation() - truth_in_camera.translation()).norm());
      }
    }
    EXPECT_LT(nearest, 0.015);
  }
  // One node's points span one node: no starts at their ends.
  const camera::RgbdFrame single = test::renderSynthetic({{&node.object_class, truths[0], green}}, 0.001, 5);
  const Cloud single_points = pointsOfColor(single, green);
  std::vector<int> single_indices(single_points.size());
  std::iota(single_indices.begin(), single_indices.end(), 0);
  EXPECT_TRUE(restingSeedsAtEnds(single_points, single_indices, plane, node.object_class).empty());

  ClassPoseEstimator estimator(node);
  std::vector<Detection> found;
  { found = estimator.estimate(points, frame); }
  ASSERT_EQ(found.size(), 2u);
  for (const world::Pose& truth : truths) {
    double nearest = 1.0;
    for (const Detection& detection : found) {
      const world::Pose pose = frame.camera_pose * detection.pose_in_camera;
      if (symmetricRotationDistance(pose.linear(), truth.linear(), node.object_class) < 3 * M_PI / 180) {
        nearest = std::min(nearest, (pose.translation() - truth.translation()).norm());
      }
    }
    EXPECT_LT(nearest, 0.003);
  }
}

TEST_F(PoseEstimation, NoPointsNoDetections) {
  ClassPoseEstimator estimator(model("node"));
  const camera::RgbdFrame frame = test::renderSynthetic({});
  EXPECT_TRUE(estimator.estimate(Cloud{}, frame).empty());
}

TEST_F(PoseEstimation, PrintsNothingAndLosesNoOtherThreadsOutput) {
  // ObjRecRANSAC's library prints its progress to stdout; the estimator goes round it and leaves
  // the process's stdout alone, so what another thread prints meanwhile (the trials' progress
  // lines) arrives whole. The test sends file descriptor 1 to a file while it runs.
  const ObjectModel& node = model("node");
  const camera::RgbdFrame frame = oneRedNode();
  const Cloud points = pointsOfColor(frame, kRed);
  std::fflush(stdout);
  char path[] = "/tmp/costar_stdout_XXXXXX";
  const int file = ::mkstemp(path);
  ASSERT_GE(file, 0);
  const int saved = ::dup(1);
  ASSERT_GE(::dup2(file, 1), 0);
  constexpr int kLines = 200;
  std::thread printer([] {
    for (int i = 0; i < kLines; ++i) {
      std::printf("progress %d\n", i);
      std::fflush(stdout);
    }
  });
  std::vector<Detection> found;
  for (int run = 0; run < 3; ++run) {
    ClassPoseEstimator estimator(node);
    found = estimator.estimate(points, frame);
  }
  printer.join();
  std::fflush(stdout);
  ::dup2(saved, 1);
  ::close(saved);
  ::close(file);
  std::ifstream in(path);
  std::stringstream printed;
  printed << in.rdbuf();
  std::remove(path);
  std::string expected;
  for (int i = 0; i < kLines; ++i) {
    expected += "progress " + std::to_string(i) + "\n";
  }
  EXPECT_EQ(printed.str(), expected);
  EXPECT_EQ(found.size(), 1u);
}

}  // namespace
}  // namespace costar::perception
