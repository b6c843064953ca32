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

}  // namespace costar::gripper
