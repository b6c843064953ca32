#pragma once
// A person's hand from one RGB-D frame (issue 31, docs/PERSON.md "Perceiving the hand"): the
// skin-coloured points above the table are grouped (Euclidean clusters); the largest group over
// the table is the forearm and hand; its root is where it enters the view (the point farthest from
// the table's centre), its tip the point farthest from the root; the hand is the group's end
// around the tip. An open palm turned up shows its pinker skin (a palm is less yellow than the
// back of a hand), its fingers reaching past it to the tip; a fist's fingers curl back over the
// palm, hiding part of it and bringing the tip near it. An open hand palm down and a fist palm
// down are not told apart. Only the frame's points and colours and the table's frame
// are used, never the simulator's truth.

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "camera/rgbd.h"
#include "world/pose.h"

namespace costar::perception {

struct HandOptions {
  /// The table's frame (on the table top, z up); heights are measured from its xy plane.
  world::Pose table_center = world::Pose(Eigen::Translation3d(0.5, 0.0, 0.0));
  /// Half extents of the region searched, along table_center's x and y (m): the table and
  /// where a person standing beside it holds a forearm.
  double half_size_x = 0.45;
  double half_size_y = 0.75;
  /// Heights above the table searched (m): above the parts lying on it, below a head.
  double min_height = 0.02;
  double max_height = 0.55;
  /// Skin colour as chromaticity (r, g, b over their sum) and brightness (the largest channel,
  /// 0-1): skin is red over green over blue, less saturated than wood or a red part.
  double min_red_minus_blue = 0.07;
  double max_red_minus_blue = 0.24;
  double min_blue = 0.2;
  double min_brightness = 0.25;
  /// Two skin points closer than this are in one group (m).
  double cluster_tolerance = 0.02;
  /// A group smaller than this is not a hand (noise, a head's edge) (points).
  int min_points = 120;
  /// The hand: the group's points within this distance of the tip (m).
  double hand_radius = 0.2;
  /// The palm's pinker skin: green minus blue chromaticity below this (the back of the hand's,
  /// lit from above, is about 0.07); an open palm is up when at least palm_up_min_fraction of
  /// the hand's points are palm-coloured (measured: 0.37-0.39 open and up, 0.12-0.13 a fist
  /// with its palm up, 0 palm down).
  double palm_max_green_minus_blue = 0.03;
  double palm_up_min_fraction = 0.25;
  /// An open hand: the palm's centre at least this far from the tip (measured: 0.124-0.129 m
  /// open, 0.07-0.09 m a fist, 0.11 half closed).
  double open_min_palm_to_tip = 0.11;
};

/// What the camera shows of the hand, in the world frame.
struct HandObservation {
  /// The hand's centre (the mean of its points) and its fingertips' end.
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d tip = Eigen::Vector3d::Zero();
  /// From the root of the forearm towards the tip (unit).
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  /// The fraction of the hand's points of palm colour; from their centre to the tip (m): an open
  /// hand's fingers reach past the palm, a fist's curl back over it; whether both show an open
  /// palm up.
  double palm_fraction = 0.0;
  double palm_to_tip = 0.0;
  bool open_palm_up = false;
  /// Points of the hand and of the whole group (forearm included).
  int hand_points = 0;
  int group_points = 0;
};

/// The hand in `frame` seen from `camera_pose` (the optical frame in the world), or nothing
/// when no group of skin-coloured points large enough lies over the table.
/// @throws std::invalid_argument when the frame has no colour image matching its points.
std::optional<HandObservation> detectHand(const camera::RgbdFrame& frame, const world::Pose& camera_pose,
                                          const HandOptions& options = {});

/// Whether a colour (0-255 per channel) is skin by `options`' thresholds.
bool isSkinColour(const unsigned char* rgb, const HandOptions& options);

}  // namespace costar::perception
