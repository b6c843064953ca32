#include "perception/hand_component.h"

#include <stdexcept>

namespace costar::perception {

HandComponent::HandComponent(camera::RgbdCamera& camera, const Clock& clock, HandComponentConfig config)
    : camera_(camera), clock_(clock), config_(std::move(config)), tracker_(config_.tracker) {
  if (config_.period <= Duration::zero()) {
    throw std::invalid_argument("hand component '" + config_.name + "': period must be above 0");
  }
  for (const auto& [zone, box] : config_.zones) {
    if (!(box.min.array() < box.max.array()).all()) {
      throw std::invalid_argument("hand component '" + config_.name + "': zone '" + zone +
                                  "': min must lie below max on every axis");
    }
  }
  component::ComponentDescription description;
  description.name = config_.name;
  description.type = "HandPerception";
  description.symbols = {
      {"hand_1", world::SymbolKind::kFrame, "the person's hand as the camera sees it (x toward the fingertips)"},
      {"hand_still_seconds", world::SymbolKind::kNumber, "how long the hand has been still (s)"}};
  // The signatures quote the words an argument takes ('a'|'b'): the editor offers them to choose.
  std::string zones;
  for (const auto& [zone, box] : config_.zones) {
    zones += (zones.empty() ? "'" : "|'") + zone + "'";
  }
  description.predicates = {
      {"hand_still", 1, "hand_still('hand_1'): the hand has not moved more than 1.5 cm since it came to rest"},
      {"palm_up", 1, "palm_up('hand_1'): an open palm turned up is seen"},
      {"gesture", 2, "gesture('hand_1', 'offer'): the open palm up held still"},
      {"in_zone", 2,
       "in_zone('hand_1', " + (zones.empty() ? std::string("zone") : zones) +
           "): the hand's centre lies in the named zone"}};
  declare(std::move(description), {});  // no operations
}

void HandComponent::look() const {
  if (!config_.watch) {
    return;
  }
  const TimePoint now = clock_.now();
  if (last_look_ && now - *last_look_ < config_.period) {
    return;
  }
  last_look_ = now;
  const camera::RgbdFrame frame = camera_.capture();
  const world::Pose camera_pose = config_.camera_pose ? config_.camera_pose() : frame.camera_pose;
  tracker_.update(detectHand(frame, camera_pose, config_.detector), now);
}

std::optional<TrackedHand> HandComponent::hand() const {
  const std::lock_guard lock(mutex_);
  return tracker_.hand();
}

world::Report HandComponent::report() const {
  const std::lock_guard lock(mutex_);
  look();
  world::Report report;
  const std::optional<TrackedHand>& hand = tracker_.hand();
  if (!hand) {
    return report;
  }
  world::Pose pose = world::Pose::Identity();
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d x = hand->seen.direction - hand->seen.direction.dot(z) * z;
  x = x.norm() > 1e-6 ? x.normalized() : Eigen::Vector3d::UnitX();
  pose.linear().col(0) = x;
  pose.linear().col(1) = z.cross(x);
  pose.linear().col(2) = z;
  pose.translation() = hand->seen.position;
  report.symbols.push_back({"hand_1", "", hand->seen_at, world::FrameValue{"world", pose}});
  report.symbols.push_back({"hand_still_seconds", "", hand->seen_at, world::NumberValue{hand->still_seconds, "s"}});
  report.predicates.push_back({"hand_still", {"hand_1"}, hand->still});
  report.predicates.push_back({"palm_up", {"hand_1"}, hand->seen.open_palm_up});
  report.predicates.push_back({"gesture", {"hand_1", "offer"}, hand->gesture});
  const Eigen::Vector3d in_table = config_.detector.table_center.inverse() * hand->seen.position;
  for (const auto& [zone, box] : config_.zones) {
    const bool inside = (in_table.array() >= box.min.array()).all() && (in_table.array() <= box.max.array()).all();
    report.predicates.push_back({"in_zone", {"hand_1", zone}, inside});
  }
  return report;
}

}  // namespace costar::perception
