#pragma once
// The person's hand as the camera sees it (issue 31, docs/PERSON.md "Perceiving the hand"): a
// component that watches the RGB-D camera and reports the hand for plans and the editor. It
// takes a frame every `period` of the cell's clock when the world state is read (every tick of a
// run), finds the hand (perception/hand_detector.h) and follows it (perception/hand_tracker.h):
//   symbols     hand_1               a frame at the hand's centre (x along the hand, from the
//                                    forearm to the fingertips; z up), while a hand is seen
//               hand_still_seconds   how long it has been still (s)
//   predicates  hand_still(hand_1)        it has not moved more than 1.5 cm since it came to rest
//               palm_up(hand_1)           an open palm turned up is seen
//               gesture(hand_1, offer)    the open palm up held still for hold_seconds
//               in_zone(hand_1, Z)        its centre lies in zone Z (a box in the table's frame)
// Relations to other symbols (near(hand_1, node_1), left_of(hand_1, table_center)) are the
// Predicator's, evaluated on demand from hand_1's frame. hand_1 is no object (no is_a): SmartMove
// never selects it as a part. It reads camera frames only, never the simulator's truth.

#include <functional>
#include <map>
#include <mutex>
#include <string>

#include "camera/rgbd.h"
#include "component/operation_table.h"
#include "core/clock.h"
#include "perception/hand_detector.h"
#include "perception/hand_tracker.h"

namespace costar::perception {

/// A box in the table's frame (table_center; m).
struct HandZone {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
};

struct HandComponentConfig {
  std::string name = "hand";
  HandOptions detector;
  HandTrackerOptions tracker;
  /// Time between the frames taken (the camera streams faster; rendering a simulated frame costs).
  Duration period = std::chrono::milliseconds(100);
  /// Named zones for in_zone (default: "handover", the table's half towards the person's side,
  /// +y, from 5 to 45 cm above the table).
  std::map<std::string, HandZone> zones = {
      {"handover", {Eigen::Vector3d(-0.3, 0.1, 0.05), Eigen::Vector3d(0.3, 0.5, 0.45)}}};
  /// false: no person can be in the cell (a simulated scene without one): no frames are taken and
  /// no hand is reported, the names declared all the same, so that plans using them validate.
  bool watch = true;
  /// Where the camera is as calibrated (calibration/); absent: the pose each frame carries.
  std::function<world::Pose()> camera_pose;
};

class HandComponent final : public component::TableComponent {
 public:
  /// The camera and clock must outlive the component.
  /// @throws std::invalid_argument for a zone whose min is not below its max, or a period <= 0.
  HandComponent(camera::RgbdCamera& camera, const Clock& clock, HandComponentConfig config = {});

  /// Takes a frame first when `period` has passed since the last one.
  world::Report report() const override;

  /// The hand as last seen (for tests and the editor).
  std::optional<TrackedHand> hand() const;

 private:
  void look() const;

  camera::RgbdCamera& camera_;
  const Clock& clock_;
  HandComponentConfig config_;
  mutable std::mutex mutex_;
  mutable HandTracker tracker_;
  mutable std::optional<TimePoint> last_look_;
};

}  // namespace costar::perception
