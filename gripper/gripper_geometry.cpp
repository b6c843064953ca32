#include "gripper/gripper_geometry.h"

#include <algorithm>
#include <cmath>

namespace costar::gripper {

namespace {

/// The robot model's fingers, unchanged; a 3 cm square closed.
class RigidGeometry final : public GripperGeometry {
 public:
  std::optional<std::vector<OrientedBox>> fingerBoxes(const FingerStance&) const override { return std::nullopt; }
  std::optional<double> stroke() const override { return std::nullopt; }
  std::optional<double> graspOpening(double, double) const override { return 0.0; }
  bool plansMode(const std::string&) const override { return false; }
  double fingertipPosition(const std::string&, double) const override { return 0.0; }
  std::optional<double> reachAcross(const std::string&) const override { return std::nullopt; }
  Eigen::Vector2d closedHalfExtent() const override { return {0.015, 0.015}; }
  void openTo(const FingerStance&, component::ParamMap&) const override {}
  std::vector<std::string> modes() const override { return {}; }
};

/// Two fingers that open to a width (gripper/finger_geometry.h).
class ParallelGeometry final : public GripperGeometry {
 public:
  explicit ParallelGeometry(FingerGeometry fingers) : fingers_(std::move(fingers)) {}

  std::optional<std::vector<OrientedBox>> fingerBoxes(const FingerStance& stance) const override {
    if (!stance.opening) {
      return std::nullopt;
    }
    std::vector<OrientedBox> boxes;
    for (const FingerBox& box : fingers_.at(*stance.opening)) {
      OrientedBox oriented;
      oriented.pose = Eigen::Translation3d(box.centre);
      oriented.size = box.size;
      boxes.push_back(oriented);
    }
    return boxes;
  }
  std::optional<double> stroke() const override { return fingers_.max_opening; }
  std::optional<double> graspOpening(double half_width, double margin) const override {
    if (2.0 * half_width > fingers_.max_opening) {
      return std::nullopt;
    }
    return std::min(2.0 * half_width + margin, fingers_.max_opening);
  }
  bool plansMode(const std::string&) const override { return false; }
  double fingertipPosition(const std::string&, double) const override { return 0.0; }
  std::optional<double> reachAcross(const std::string&) const override {
    double pad = 0.0;
    for (const FingerBox& box : fingers_.closed) {
      pad = std::max(pad, std::abs(box.centre.x()) + 0.5 * box.size.x());
    }
    return pad;
  }
  Eigen::Vector2d closedHalfExtent() const override {
    Eigen::Vector2d half = Eigen::Vector2d::Zero();
    for (const FingerBox& box : fingers_.at(0.0)) {
      half.x() = std::max(half.x(), std::abs(box.centre.x()) + 0.5 * box.size.x());
      half.y() = std::max(half.y(), std::abs(box.centre.y()) + 0.5 * box.size.y());
    }
    return half;
  }
  void openTo(const FingerStance& stance, component::ParamMap& params) const override {
    if (stance.opening && *stance.opening > 0.0) {
      params["opening"] = *stance.opening;
    }
  }
  std::vector<std::string> modes() const override { return {}; }

 private:
  FingerGeometry fingers_;
};

/// Three fingers in modes (gripper/adaptive_gripper_description.h).
class AdaptiveGeometry final : public GripperGeometry {
 public:
  explicit AdaptiveGeometry(AdaptiveGripperDescription description) : description_(std::move(description)) {}

  std::optional<std::vector<OrientedBox>> fingerBoxes(const FingerStance& stance) const override {
    const auto mode = stance.mode.empty() ? std::nullopt : modeFromString(stance.mode);
    if (!mode) {
      return std::nullopt;
    }
    std::vector<OrientedBox> boxes = fingerBoxesAt(description_, *mode, stance.position);
    return boxes.empty() ? std::nullopt : std::optional(std::move(boxes));
  }
  std::optional<double> stroke() const override { return std::nullopt; }
  std::optional<double> graspOpening(double, double) const override { return 0.0; }
  bool plansMode(const std::string& mode) const override { return !mode.empty(); }
  double fingertipPosition(const std::string& mode, double half_width) const override {
    const auto known = modeFromString(mode);
    return known ? fingertipPositionFor(description_, *known, half_width) : 0.0;
  }
  std::optional<double> reachAcross(const std::string& mode) const override {
    const auto known = mode.empty() ? std::nullopt : modeFromString(mode);
    const double reach = known ? fingerReachAcross(description_, *known) : 0.0;
    return reach > 0.0 ? std::optional(reach) : std::nullopt;
  }
  Eigen::Vector2d closedHalfExtent() const override { return {0.015, 0.015}; }
  void openTo(const FingerStance& stance, component::ParamMap& params) const override {
    if (stance.position > 0.0) {
      params["position"] = stance.position;
    }
  }
  std::vector<std::string> modes() const override {
    std::vector<std::string> names;
    for (const GripperMode mode : kGripperModes) {
      names.emplace_back(toString(mode));
    }
    return names;
  }

 private:
  AdaptiveGripperDescription description_;
};

}  // namespace

std::unique_ptr<GripperGeometry> parallelGripperGeometry(FingerGeometry fingers) {
  return std::make_unique<ParallelGeometry>(std::move(fingers));
}

std::unique_ptr<GripperGeometry> adaptiveGripperGeometry(AdaptiveGripperDescription description) {
  return std::make_unique<AdaptiveGeometry>(std::move(description));
}

std::unique_ptr<GripperGeometry> rigidGripperGeometry() { return std::make_unique<RigidGeometry>(); }

}  // namespace costar::gripper
