#include "arm/cartesian_path.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace costar::arm {
namespace {

using std::chrono::milliseconds;
using testing::HasSubstr;

world::Pose at(double x, double y, double z, double yaw = 0.0) {
  return world::poseFromXyzRpy(x, y, z, M_PI, 0.0, yaw);
}

TEST(CartesianPath, OnePoseIsHeldWithoutMoving) {
  const CartesianPath path = CartesianPath::through({at(0.4, 0.1, 0.2)}, {});
  EXPECT_EQ(path.duration(), Duration{0});
  EXPECT_EQ(path.length(), 0.0);
  const CartesianPath::Sample sample = path.sample(milliseconds(500));
  EXPECT_TRUE(sample.pose.isApprox(at(0.4, 0.1, 0.2)));
  EXPECT_EQ(sample.velocity.norm(), 0.0);
}

TEST(CartesianPath, AStraightLineIsTravelledWithATrapezoidalProfileAndEndsAtRest) {
  const CartesianPath path =
      CartesianPath::through({at(0.4, 0.0, 0.1), at(0.6, 0.0, 0.1)}, {.speed = 0.05, .acceleration = 0.5});
  EXPECT_NEAR(path.length(), 0.2, 1e-12);
  // 0.2 m at 0.05 m/s plus the ramps' 0.1 s.
  EXPECT_NEAR(toSeconds(path.duration()), 4.1, 1e-6);
  const CartesianPath::Sample middle = path.sample(milliseconds(2050));
  EXPECT_NEAR(middle.velocity.x(), 0.05, 1e-9);
  EXPECT_NEAR(middle.pose.translation().x(), 0.5, 1e-6);
  const CartesianPath::Sample end = path.sample(path.duration() + milliseconds(100));
  EXPECT_TRUE(end.pose.isApprox(at(0.6, 0.0, 0.1), 1e-9));
  EXPECT_NEAR(end.velocity.norm(), 0.0, 1e-6);
}

TEST(CartesianPath, ACornerIsRoundedWithinItsBlendAndTheMotionStaysContinuous) {
  const double blend = 0.01;
  const CartesianPath path = CartesianPath::through({at(0.4, 0.0, 0.1), at(0.5, 0.0, 0.1), at(0.5, 0.1, 0.1)},
                                                    {.speed = 0.05, .acceleration = 0.5, .blend = blend});
  // A quarter circle of radius 1 cm replaces 2 cm of the corner.
  EXPECT_NEAR(path.length(), 0.2 - 0.02 + 0.01 * M_PI / 2, 1e-9);
  EXPECT_NEAR(path.arcAt(1), 0.09 + 0.01 * M_PI / 4, 1e-9);
  const world::Pose corner = path.poseAt(path.arcAt(1));
  // The blend's middle: 1 cm from both lines' continuations, (1 - 1/sqrt 2) cm from the corner's lines.
  EXPECT_NEAR((corner.translation() - Eigen::Vector3d(0.5, 0.0, 0.1)).norm(), 0.01 * (std::sqrt(2.0) - 1.0), 1e-6);
  Eigen::Vector3d last = path.sample(Duration{0}).pose.translation();
  Eigen::Vector3d last_velocity = Eigen::Vector3d::Zero();
  for (Duration t = milliseconds(2); t <= path.duration(); t += milliseconds(2)) {
    const CartesianPath::Sample sample = path.sample(t);
    EXPECT_LE((sample.pose.translation() - last).norm(), 0.05 * 0.002 + 1e-9);
    EXPECT_LE(sample.velocity.norm(), 0.05 + 1e-9);
    // The speed along the blend is 5 cm/s on a 1 cm radius: 0.25 m/s^2, 0.5 mm/s per 2 ms.
    EXPECT_LE((sample.velocity - last_velocity).norm(), 0.0011) << toSeconds(t);
    last = sample.pose.translation();
    last_velocity = sample.velocity;
  }
}

TEST(CartesianPath, ATurnInPlaceCountsATenthOfAMetrePerRadian) {
  const CartesianPath path = CartesianPath::through({at(0.4, 0.0, 0.1, 0.0), at(0.4, 0.0, 0.1, M_PI / 2)},
                                                    {.speed = 0.05, .acceleration = 0.5});
  EXPECT_NEAR(path.length(), 0.1 * M_PI / 2, 1e-9);
  const CartesianPath::Sample middle = path.sample(path.duration() / 2);
  EXPECT_NEAR(middle.pose.translation().x(), 0.4, 1e-12);
  EXPECT_NEAR(middle.angular_velocity.norm(), 0.05 / 0.1, 1e-6);
  EXPECT_NEAR(world::rotationAngle(middle.pose, at(0.4, 0.0, 0.1, 0.0)), M_PI / 4, 1e-6);
}

TEST(CartesianPath, BadInputIsRefused) {
  EXPECT_THROW(CartesianPath::through({}, {}), std::invalid_argument);
  world::Pose broken = at(0.4, 0.0, 0.1);
  broken.translation().x() = std::nan("");
  try {
    CartesianPath::through({at(0.4, 0.0, 0.1), broken}, {});
    ADD_FAILURE() << "a pose that is not a number was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("pose 2"));
  }
  EXPECT_THROW(CartesianPath::through({at(0.4, 0.0, 0.1)}, {.speed = 0.0}), std::invalid_argument);
  EXPECT_THROW(CartesianPath::through({at(0.4, 0.0, 0.1)}, {.speed = 0.1, .acceleration = -1.0}),
               std::invalid_argument);
}

}  // namespace
}  // namespace costar::arm
