// The LBR iiwa 14 model generated from robots/iiwa14/iiwa14.json: MuJoCo loads it, its forward
// kinematics agrees with KDL's on the URDF generated from the same file (and with the analytic
// solver's), and it holds its pose under gravity with the simulation's position control.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <array>
#include <fstream>
#include <memory>
#include <numbers>
#include <random>
#include <string>

#include "arm/srs_kinematics.h"
#include "arm/test/published_arms.h"
#include "planning/robot_model.h"
#include "sim/test/arm_model_fixture.h"

namespace costar::sim {
namespace {

using arm::Joints7;

constexpr double kDegree = std::numbers::pi / 180.0;

class Iiwa14Model : public testing::ArmModelTest {
 protected:
  void SetUp() override { load(COSTAR_IIWA14_MJCF, "tool0"); }
  Joints7 positions() const { return ArmModelTest::positions(); }
  void hold(const Joints7& target, double seconds) { ArmModelTest::hold(Eigen::VectorXd(target), seconds); }
};

TEST_F(Iiwa14Model, HasTheDescribedJointsActuatorsAndHome) {
  ASSERT_EQ(model_->nq, 7);
  ASSERT_EQ(model_->nv, 7);
  ASSERT_EQ(model_->nu, 7);
  const arm::SrsLimits limits = arm::published::iiwa14Limits();
  const std::array<double, 7> torque = {320, 320, 176, 176, 110, 40, 40};
  for (int i = 0; i < 7; ++i) {
    const std::string name = "iiwa_joint_" + std::to_string(i + 1);
    const int joint = mj_name2id(model_.get(), mjOBJ_JOINT, name.c_str());
    ASSERT_EQ(joint, i) << name;
    EXPECT_TRUE(model_->jnt_limited[joint]);
    EXPECT_NEAR(model_->jnt_range[2 * joint], limits.lower[i], 1e-9);
    EXPECT_NEAR(model_->jnt_range[2 * joint + 1], limits.upper[i], 1e-9);
    const int actuator = mj_name2id(model_.get(), mjOBJ_ACTUATOR, name.c_str());
    ASSERT_EQ(actuator, i) << name;
    EXPECT_EQ(model_->actuator_trnid[2 * actuator], joint);
    EXPECT_NEAR(model_->actuator_ctrlrange[2 * actuator + 1], torque[i], 1e-9);
  }
  const int home = mj_name2id(model_.get(), mjOBJ_KEY, "home");
  ASSERT_GE(home, 0);
  const Joints7 expected = Joints7(Eigen::Map<const Joints7>(model_->key_qpos + home * model_->nq));
  // The keyframe is the description's home_deg (read from the file the model was generated from).
  std::ifstream description_file(COSTAR_IIWA14_DESCRIPTION);
  ASSERT_TRUE(description_file.good()) << COSTAR_IIWA14_DESCRIPTION;
  const nlohmann::json home_deg = nlohmann::json::parse(description_file).at("home_deg");
  ASSERT_EQ(home_deg.size(), 7U);
  Joints7 described;
  for (int i = 0; i < 7; ++i) {
    described[i] = home_deg[static_cast<std::size_t>(i)].get<double>();
  }
  EXPECT_TRUE(expected.isApprox(described * kDegree, 1e-9)) << expected.transpose() / kDegree;
  // The published mass of the LBR iiwa 14 R820 (29.9 kg) with the estimated link masses.
  double mass = 0.0;
  for (int b = 1; b < model_->nbody; ++b) {
    mass += model_->body_mass[b];
  }
  EXPECT_NEAR(mass, 29.9, 1e-6);
}

TEST_F(Iiwa14Model, ForwardKinematicsAgreesWithKdlAndTheAnalyticSolver) {
  const planning::RobotModel kdl = planning::RobotModel::fromUrdf(COSTAR_IIWA14_URDF, "iiwa_link_0", "tool0");
  const arm::SrsKinematics analytic(arm::published::iiwa14Geometry());
  const arm::SrsLimits limits = arm::published::iiwa14Limits();
  std::mt19937_64 random(1111);
  double worst_position = 0.0;
  double worst_angle = 0.0;
  double worst_analytic = 0.0;
  for (int n = 0; n < 2000; ++n) {
    Joints7 q;
    for (int i = 0; i < 7; ++i) {
      q[i] = std::uniform_real_distribution<double>(limits.lower[i], limits.upper[i])(random);
      data_->qpos[i] = q[i];
    }
    mj_kinematics(model_.get(), data_.get());
    const world::Pose mujoco = flange();
    const world::Pose reference = kdl.forward(q);
    worst_position = std::max(worst_position, (mujoco.translation() - reference.translation()).norm());
    worst_angle = std::max(worst_angle, world::rotationAngle(mujoco, reference));
    worst_analytic = std::max(worst_analytic, (analytic.forward(q).translation() - mujoco.translation()).norm());
  }
  RecordProperty("worst_position_m", std::to_string(worst_position));
  RecordProperty("worst_angle_rad", std::to_string(worst_angle));
  EXPECT_LT(worst_position, 1e-4);         // 0.1 mm, the requirement; in fact ~1e-15 m
  EXPECT_LT(worst_angle, 0.01 * kDegree);  // 0.01 degree
  EXPECT_LT(worst_position, 1e-12);        // the same numbers, so rounding only
  EXPECT_LT(worst_angle, 1e-9);
  EXPECT_LT(worst_analytic, 1e-12);
}

TEST_F(Iiwa14Model, HoldsPosesUnderGravityWithPositionControl) {
  Joints7 horizontal;  // the largest gravity load on joint 2: the arm stretched out sideways
  horizontal << 0, 90 * kDegree, 0, 0, 0, 0, 0;
  const int home = mj_name2id(model_.get(), mjOBJ_KEY, "home");
  const Joints7 home_q = Joints7(Eigen::Map<const Joints7>(model_->key_qpos + home * model_->nq));
  for (const Joints7& target : {home_q, horizontal}) {
    mj_resetData(model_.get(), data_.get());
    Eigen::Map<Joints7>(data_->qpos) = target;
    hold(target, 5.0);
    ASSERT_TRUE(positions().allFinite());
    EXPECT_LT((positions() - target).cwiseAbs().maxCoeff(), 1e-4) << target.transpose();
    EXPECT_LT(Eigen::Map<const Joints7>(data_->qvel).cwiseAbs().maxCoeff(), 1e-4);
    for (int i = 0; i < 7; ++i) {
      // Within the motors' torque limits, not saturated.
      EXPECT_LT(std::abs(data_->ctrl[i]), model_->actuator_ctrlrange[2 * i + 1]) << i;
    }
  }
}

TEST_F(Iiwa14Model, WithoutControlGravityPullsTheArmDownAndItStaysFinite) {
  // The check above can fail: unpowered, the arm does not hold home.
  const int home = mj_name2id(model_.get(), mjOBJ_KEY, "home");
  mj_resetDataKeyframe(model_.get(), data_.get(), home);
  const Joints7 start = positions();
  for (int n = 0; n < 2500; ++n) {
    mj_step(model_.get(), data_.get());
  }
  ASSERT_TRUE(positions().allFinite());
  EXPECT_GT((positions() - start).cwiseAbs().maxCoeff(), 0.1);
  const arm::SrsLimits limits = arm::published::iiwa14Limits();
  // Joint limits hold it (within the soft constraint's give).
  EXPECT_TRUE((positions().array() >= limits.lower.array() - 0.05).all());
  EXPECT_TRUE((positions().array() <= limits.upper.array() + 0.05).all());
}

}  // namespace
}  // namespace costar::sim
