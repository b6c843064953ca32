// Stage 2: the workspace crop, the table plane, the height band; normals; the table_center file.

#include "perception/workspace.h"

#include <gtest/gtest.h>

#include "core/paths.h"
#include "perception/test/synthetic_scene.h"

namespace costar::perception {
namespace {

world::ObjectClass blockClass() {
  world::ObjectClass block;
  block.name = "block";
  block.boxes = {{Eigen::Vector3d::Zero(), Eigen::Vector3d(0.02, 0.02, 0.02)}};
  return block;
}

TEST(Workspace, KeepsThePointsAboveTheTableInTheBox) {
  const world::ObjectClass block = blockClass();
  // One block inside the box, one outside it (x = 0.95).
  const camera::RgbdFrame frame = test::renderSynthetic({{&block, world::Pose(Eigen::Translation3d(0.5, 0.1, 0.02))},
                                                         {&block, world::Pose(Eigen::Translation3d(0.95, 0.0, 0.02))}},
                                                        0.0005);
  WorkspaceOptions options;
  const WorkspaceCloud workspace = cropWorkspace(frame, options);
  ASSERT_GT(workspace.cloud.size(), 200u);
  // The fitted plane is the table: through the world origin plane, normal up.
  const Eigen::Vector3d up_in_camera = frame.camera_pose.linear().transpose() * Eigen::Vector3d::UnitZ();
  EXPECT_GT(workspace.plane.normal.dot(up_in_camera), 0.9999);
  EXPECT_NEAR(workspace.plane.height((frame.camera_pose.inverse() * Eigen::Vector3d(0.3, -0.2, 0.0)).cast<float>()),
              0.0, 0.001);
  for (std::size_t i = 0; i < workspace.cloud.size(); ++i) {
    const Eigen::Vector3d world = frame.camera_pose * workspace.cloud.points[i].cast<double>();
    EXPECT_NEAR(world.x(), 0.5, 0.021);
    EXPECT_NEAR(world.y(), 0.1, 0.021);
    EXPECT_GE(workspace.heights[i], options.min_height);
    EXPECT_NEAR(workspace.heights[i], world.z(), 0.002);
  }
  EXPECT_EQ(workspace.cloud.colors.size(), workspace.cloud.size());
  EXPECT_EQ(workspace.cloud.pixels.size(), workspace.cloud.size());
  EXPECT_GT(workspace.table.size(), 100u);
}

TEST(Workspace, TheRegionCoversTheBoxAndLeavesTheRestOut) {
  const camera::Intrinsics in = test::workcellIntrinsics();
  WorkspaceOptions options;
  const PixelRect region = workspaceRegion(in, test::workcellCameraPose(), options);
  EXPECT_FALSE(region.empty());
  EXPECT_LT(region.height(), in.height);  // the floor far behind the table is left out
  // The box's corners on the table project inside the region.
  const world::Pose to_camera = test::workcellCameraPose().inverse();
  for (const double x : {0.2, 0.8}) {
    for (const double y : {-0.5, 0.5}) {
      const Eigen::Vector3d p = to_camera * Eigen::Vector3d(x, y, 0.0);
      const double u = in.fx * p.x() / p.z() + in.cx;
      const double v = in.fy * p.y() / p.z() + in.cy;
      EXPECT_GE(u, region.u_min - 1);
      EXPECT_LE(u, region.u_max + 1);
      EXPECT_GE(v, region.v_min - 1);
      EXPECT_LE(v, region.v_max + 1);
    }
  }
}

TEST(Workspace, FailsWithAReasonWhenNoTableIsInView) {
  const world::ObjectClass block = blockClass();
  const camera::RgbdFrame frame =
      test::renderSynthetic({{&block, world::Pose(Eigen::Translation3d(0.5, 0.0, 0.02))}}, 0.0, 1, /*table=*/false);
  EXPECT_THROW(cropWorkspace(frame, {}), std::runtime_error);
}

TEST(Workspace, NormalsPointOutOfTheFacesTowardsTheCamera) {
  const world::ObjectClass block = blockClass();
  const world::Pose pose(Eigen::Translation3d(0.5, 0.0, 0.02));
  const camera::RgbdFrame frame = test::renderSynthetic({{&block, pose}});
  WorkspaceCloud workspace = cropWorkspace(frame, {});
  estimateNormals(frame, workspace.cloud);
  ASSERT_EQ(workspace.cloud.normals.size(), workspace.cloud.size());
  int top = 0;
  int checked = 0;
  for (std::size_t i = 0; i < workspace.cloud.size(); ++i) {
    const Eigen::Vector3d p = frame.camera_pose * workspace.cloud.points[i].cast<double>();
    const Eigen::Vector3d n = frame.camera_pose.linear() * workspace.cloud.normals[i].cast<double>();
    EXPECT_LT(workspace.cloud.normals[i].dot(workspace.cloud.points[i]), 0.0f);
    if (p.z() > 0.039 && std::abs(p.x() - 0.5) < 0.012 && std::abs(p.y()) < 0.012) {
      ++checked;
      top += n.z() > 0.99;
    }
  }
  EXPECT_GT(checked, 20);
  EXPECT_EQ(top, checked);  // the middle of the top face: straight up
}

TEST(Workspace, TheTableCentreFileRoundTrips) {
  const auto file = std::filesystem::temp_directory_path() / "costar_workspace_test.json";
  const world::Pose pose = world::poseFromXyzRpy(0.5, -0.01, 0.001, 0.001, -0.002, 0.3);
  saveTableCenter(file, pose, "test");
  const world::Pose back = loadTableCenter(file);
  EXPECT_LT((back.translation() - pose.translation()).norm(), 1e-5);
  EXPECT_LT(world::rotationAngle(back, pose), 1e-4);
  std::filesystem::remove(file);
  EXPECT_THROW(loadTableCenter(file), std::runtime_error);
  // The committed file: the marker's centre on the simulated table.
  const world::Pose committed = loadTableCenter(dataRoot() / "data/perception/workspace.json");
  EXPECT_LT((committed.translation() - Eigen::Vector3d(0.5, 0, 0)).norm(), 0.003);
}

}  // namespace
}  // namespace costar::perception
