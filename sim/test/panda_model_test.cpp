// The Franka Emika Panda model generated from robots/panda/panda.json: MuJoCo loads it with the
// maker's joint limits and torques, its forward kinematics agrees with Franka's published
// Craig-convention DH table (an independent model written here from the maker's documentation),
// with KDL's on the URDF generated from the same file and with the general chain solver that
// is the Panda's IK, and it holds its pose under gravity with the simulation's position control.

#include <gtest/gtest.h>

#include <array>
#include <numbers>
#include <random>

#include "arm/chain_kinematics.h"
#include "arm/robot_description.h"
#include "planning/robot_model.h"
#include "sim/test/arm_model_fixture.h"

namespace costar::sim {
namespace {

constexpr double kPi = std::numbers::pi;

// Franka's published limits (FCI documentation, "Limits for Panda").
constexpr std::array<double, 7> kLower = {-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973};
constexpr std::array<double, 7> kUpper = {2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973};
constexpr std::array<double, 7> kTorque = {87, 87, 87, 87, 12, 12, 12};

/// Franka's kinematics as the maker publishes it: Craig's (modified) DH, per joint a(i-1),
/// d(i), alpha(i-1); each joint's transform RotX(alpha) TransX(a) RotZ(theta) TransZ(d); the
/// flange 0.107 m along the last z.
world::Pose craigDh(const Eigen::VectorXd& q) {
  struct Row {
    double a, d, alpha;
  };
  constexpr std::array<Row, 8> kRows = {{{0, 0.333, 0},
                                         {0, 0, -kPi / 2},
                                         {0, 0.316, kPi / 2},
                                         {0.0825, 0, kPi / 2},
                                         {-0.0825, 0.384, -kPi / 2},
                                         {0, 0, kPi / 2},
                                         {0.088, 0, kPi / 2},
                                         {0, 0.107, 0}}};
  world::Pose pose = world::Pose::Identity();
  for (int i = 0; i < 8; ++i) {
    pose.rotate(Eigen::AngleAxisd(kRows[i].alpha, Eigen::Vector3d::UnitX()));
    pose.translate(Eigen::Vector3d(kRows[i].a, 0, 0));
    pose.rotate(Eigen::AngleAxisd(i < 7 ? q[i] : 0.0, Eigen::Vector3d::UnitZ()));
    pose.translate(Eigen::Vector3d(0, 0, kRows[i].d));
  }
  return pose;
}

class PandaModel : public testing::ArmModelTest {
 protected:
  void SetUp() override { load(COSTAR_PANDA_MJCF, "panda_link8"); }
};

TEST_F(PandaModel, HasTheMakersJointLimitsTorquesAndHome) {
  ASSERT_EQ(model_->nq, 7);
  ASSERT_EQ(model_->nu, 7);
  for (int i = 0; i < 7; ++i) {
    const std::string name = "panda_joint" + std::to_string(i + 1);
    const int joint = mj_name2id(model_.get(), mjOBJ_JOINT, name.c_str());
    ASSERT_EQ(joint, i) << name;
    EXPECT_NEAR(model_->jnt_range[2 * joint], kLower[i], 1e-7) << name;
    EXPECT_NEAR(model_->jnt_range[2 * joint + 1], kUpper[i], 1e-7) << name;
    const int actuator = mj_name2id(model_.get(), mjOBJ_ACTUATOR, name.c_str());
    ASSERT_EQ(actuator, i) << name;
    EXPECT_NEAR(model_->actuator_ctrlrange[2 * actuator + 1], kTorque[i], 1e-9) << name;
  }
  // The runtime's description agrees (limits in rad, speeds 2.175 and 2.61 rad/s).
  const arm::RobotDescription robot = arm::loadRobotDescription(COSTAR_PANDA_DESCRIPTION);
  for (int i = 0; i < 7; ++i) {
    EXPECT_NEAR(robot.limits.min_position[i], kLower[i], 1e-7);
    EXPECT_NEAR(robot.limits.max_position[i], kUpper[i], 1e-7);
    EXPECT_NEAR(robot.limits.max_velocity[i], i < 4 ? 2.175 : 2.61, 1e-7);
  }
  EXPECT_TRUE(keyframe("home").isApprox(Eigen::Map<const Eigen::VectorXd>(robot.home.data(), 7), 1e-9));
  // Gaz et al.'s identified link masses, link 0 included: 16.69 kg (the products of inertia are not in the model).
  double mass = 0.0;
  for (int b = 1; b < model_->nbody; ++b) {
    mass += model_->body_mass[b];
  }
  EXPECT_NEAR(mass, 16.691901, 1e-6);
}

TEST_F(PandaModel, ForwardKinematicsAgreesWithTheMakersDhTableKdlAndTheChainSolver) {
  const planning::RobotModel kdl = planning::RobotModel::fromUrdf(COSTAR_PANDA_URDF, "panda_link0", "panda_link8");
  const arm::RobotDescription robot = arm::loadRobotDescription(COSTAR_PANDA_DESCRIPTION);
  const std::shared_ptr<const arm::Kinematics> chain = arm::makeKinematics(robot);
  std::mt19937_64 random(1212);
  double worst_maker = 0.0;
  double worst_maker_angle = 0.0;
  double worst_kdl = 0.0;
  double worst_chain = 0.0;
  for (int n = 0; n < 2000; ++n) {
    Eigen::VectorXd q(7);
    for (int i = 0; i < 7; ++i) {
      q[i] = std::uniform_real_distribution<double>(kLower[i], kUpper[i])(random);
      data_->qpos[i] = q[i];
    }
    mj_kinematics(model_.get(), data_.get());
    const world::Pose mujoco = flange();
    const world::Pose maker = craigDh(q);
    worst_maker = std::max(worst_maker, (mujoco.translation() - maker.translation()).norm());
    worst_maker_angle = std::max(worst_maker_angle, world::rotationAngle(mujoco, maker));
    worst_kdl = std::max(worst_kdl, (kdl.forward(q).translation() - mujoco.translation()).norm());
    worst_chain = std::max(
        worst_chain, (chain->forward(arm::JointVector::fromEigen(q)).translation() - mujoco.translation()).norm());
  }
  // MuJoCo's quaternions are the generator's, printed to 12 digits: 1e-10 m of rounding.
  EXPECT_LT(worst_maker, 1e-9);
  EXPECT_LT(worst_maker_angle, 1e-9);
  EXPECT_LT(worst_kdl, 1e-9);
  EXPECT_LT(worst_chain, 1e-9);
  // A known configuration: all zeros (joint 4 at 0 is outside its range, but the geometry is
  // defined), the flange 0.088 m forward and 0.926 m up, pointing down.
  data_->qpos[0] = data_->qpos[1] = data_->qpos[2] = data_->qpos[3] = data_->qpos[4] = data_->qpos[5] = data_->qpos[6] =
      0.0;
  mj_kinematics(model_.get(), data_.get());
  EXPECT_LT((flange().translation() - Eigen::Vector3d(0.088, 0, 0.926)).norm(), 1e-9);
  EXPECT_LT((flange().linear().col(2) - Eigen::Vector3d(0, 0, -1)).norm(), 1e-9);
}

TEST_F(PandaModel, HoldsPosesUnderGravityWithPositionControl) {
  Eigen::VectorXd stretched(7);  // the arm reaching out horizontally: the largest load on joint 2
  stretched << 0, 1.5, 0, -0.1, 0, 1.7, 0.8;
  for (const Eigen::VectorXd& target : {keyframe("home"), stretched}) {
    mj_resetData(model_.get(), data_.get());
    Eigen::Map<Eigen::VectorXd>(data_->qpos, 7) = target;
    hold(target, 5.0);
    ASSERT_TRUE(positions().allFinite());
    EXPECT_LT((positions() - target).cwiseAbs().maxCoeff(), 1e-4) << target.transpose();
    EXPECT_LT(velocities().cwiseAbs().maxCoeff(), 1e-4);
    for (int i = 0; i < 7; ++i) {
      EXPECT_LT(std::abs(data_->ctrl[i]), model_->actuator_ctrlrange[2 * i + 1]) << i;
    }
  }
}

}  // namespace
}  // namespace costar::sim
