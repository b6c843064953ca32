#pragma once
// A parallel 2-finger gripper's description as the cell needs it, read from the same file the
// simulator's and the planner's models are generated from (robots/grippers/NAME.json, "kind":
// "parallel", robots/README.md; robots/parallel_gripper.py writes the models).

#include <Eigen/Core>
#include <filesystem>
#include <string>

#include "gripper/finger_geometry.h"
#include "gripper/gripper_description.h"

namespace costar::gripper {

struct ParallelGripperDescription {
  std::string name;
  /// The +y finger's boxes closed (its link, then its pad) and the stroke.
  FingerGeometry fingers;
  Eigen::Vector3d tcp = Eigen::Vector3d::Zero();          // the tool centre point in the flange frame
  Eigen::Vector3d body_centre = Eigen::Vector3d::Zero();  // the body's box in the flange frame
  Eigen::Vector3d body_size = Eigen::Vector3d::Zero();    // full side lengths
  double default_force = 0.0;                             // N: Close's grip force when none is given
  double max_force = 0.0;                                 // N: the most Close accepts
  std::string grasps;                                     // its grasps' key in data/grasps.json
};

/// @throws std::runtime_error naming the file, the field and the problem.
ParallelGripperDescription loadParallelGripperDescription(const std::filesystem::path& file);

}  // namespace costar::gripper
