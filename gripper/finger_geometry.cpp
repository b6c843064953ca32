#include "gripper/finger_geometry.h"

#include <algorithm>

namespace costar::gripper {

std::vector<FingerBox> FingerGeometry::at(double opening) const {
  const double half = 0.5 * std::clamp(opening, 0.0, max_opening);
  std::vector<FingerBox> boxes;
  boxes.reserve(2 * closed.size());
  for (const double side : {1.0, -1.0}) {
    for (FingerBox box : closed) {
      box.centre.y() = side * (box.centre.y() + half);
      boxes.push_back(box);
    }
  }
  return boxes;
}

FingerGeometry twoFingerGripper() {
  FingerGeometry fingers;
  fingers.closed = {{Eigen::Vector3d(0, 0.012, 0.12), Eigen::Vector3d(0.022, 0.016, 0.02)},
                    {Eigen::Vector3d(0, 0.004, 0.14), Eigen::Vector3d(0.026, 0.008, 0.04)}};
  fingers.max_opening = 0.085;
  return fingers;
}

}  // namespace costar::gripper
