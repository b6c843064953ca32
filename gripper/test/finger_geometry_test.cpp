#include "gripper/finger_geometry.h"

#include <gtest/gtest.h>

#include "gripper/parallel_gripper_description.h"

namespace costar::gripper {
namespace {

/// The 2-finger gripper of the UR5 cell, as its description gives it.
FingerGeometry twoFingers() { return loadParallelGripperDescription(gripperDescriptionFile("parallel-2f")).fingers; }

TEST(FingerGeometry, PadsAreTheOpeningApartAndTheFingersMirrorEachOther) {
  const FingerGeometry fingers = twoFingers();
  for (const double opening : {0.0, 0.03, 0.07, fingers.max_opening}) {
    const std::vector<FingerBox> boxes = fingers.at(opening);
    ASSERT_EQ(boxes.size(), 2 * fingers.closed.size());
    // The inner faces of the two pads (the second box of each finger).
    const FingerBox& left_pad = boxes[1];
    const FingerBox& right_pad = boxes[fingers.closed.size() + 1];
    EXPECT_NEAR(left_pad.centre.y() - 0.5 * left_pad.size.y(), 0.5 * opening, 1e-12) << opening;
    EXPECT_NEAR(right_pad.centre.y() + 0.5 * right_pad.size.y(), -0.5 * opening, 1e-12) << opening;
    for (std::size_t i = 0; i < fingers.closed.size(); ++i) {
      const FingerBox& a = boxes[i];
      const FingerBox& b = boxes[fingers.closed.size() + i];
      EXPECT_DOUBLE_EQ(a.centre.y(), -b.centre.y());
      EXPECT_EQ(a.centre.x(), b.centre.x());
      EXPECT_EQ(a.centre.z(), b.centre.z());
      EXPECT_EQ(a.size, b.size);
    }
  }
}

TEST(FingerGeometry, OpeningsBeyondTheStrokeAreClamped) {
  const FingerGeometry fingers = twoFingers();
  const auto widest = fingers.at(fingers.max_opening);
  const auto beyond = fingers.at(1.0);
  for (std::size_t i = 0; i < widest.size(); ++i) {
    EXPECT_EQ(beyond[i].centre, widest[i].centre);
  }
  EXPECT_EQ(fingers.at(-1.0)[0].centre, fingers.at(0.0)[0].centre);
  // Fully open, the finger links reach 42.5 + 20 mm from the centre line.
  double reach = 0.0;
  for (const FingerBox& box : widest) {
    reach = std::max(reach, box.centre.y() + 0.5 * box.size.y());
  }
  EXPECT_NEAR(reach, 0.0625, 1e-12);
}

}  // namespace
}  // namespace costar::gripper
