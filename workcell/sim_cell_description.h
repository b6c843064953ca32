#pragma once
// A simulated workcell as data: one JSON file per cell (workcells/NAME.json) names the robot,
// the gripper on its flange, where the robot stands, the cell model around it and the scene;
// workcell/sim_workcell.h builds the one generic simulated cell from it. `ur5-sim` and
// `iiwa-sim` are two such files.
//
//   name, label      the cell's name (`--workcell NAME`) and a line for `costar workcells`
//   notes            free text
//   robot            the robot description robots/ROBOT/ROBOT.json (arm/robot_description.h)
//   gripper          the gripper on the flange, a key of the gripper table (workcell/grippers.h:
//                    "parallel-2f")
//   robot_base       {position [x, y, z] (m), rpy [roll, pitch, yaw] (rad)}: the robot's base
//                    in the world (the simulator checks that the model agrees)
//   cell_model       MJCF of the cell around the robot (sim/cell_model.h)
//   scene            the default scene (sim/scenes/*.json)
//   waypoints        optional: a waypoint file the cell reads (never writes) when it keeps no
//                    waypoints of its own (tests, trials) and none is given
//   table            {centre [x, y, z], size [x, y, z]} (m): the table as the planner's box
//   workspace        {min [x, y, z], max [x, y, z]} (m): where the tool may go
//   part_area        optional {min [x, y, z], max [x, y, z]} (m): where parts may lie or stand
//                    on the table; the arm keeps out of it while it calibrates the camera
//                    (calibration/calibration_component.h), when no part's place is known
//   calibration      the shipped hand-eye calibration of the gripper's marker (the marker's place
//                    on the flange: one file per gripper and marker, whichever arm carries it)
//   perception_model optional: the SVM trained for this cell (`costar perception retrain -w NAME`:
//                    its own arm and gripper seen as background); DetectObjects in the cell loads
//                    it (a missing file is DetectObjects' error, not the description's: the
//                    training writes it). Absent: the default model (perception::PipelineFiles).
//   power_tool       optional {tool: NAME (data/tools/NAME.json), stand: {position, rpy}}: a
//                    power tool (tool/power_tool.h) and where its stand stands on the table; the
//                    scene says whether the tool sits on it (sim/scene.h "power_tool")
//   remote           optional {components, domain, partition, interface} (dds/remote_config.h):
//                    the cell's components served by hosts (`costar host`: gripper, perception)
//                    in lockstep with this process's simulation (dds/lockstep.h); read when the
//                    cell is built. Absent: every component runs in the executor's process.
//
// Paths are relative to the data root (core/paths.h). Unknown fields are refused.

#include <Eigen/Geometry>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "world/pose.h"

namespace costar::workcell {

struct SimCellDescription {
  std::filesystem::path file;  // where it was read from (for messages)
  std::string name;
  std::string label;
  std::string robot;
  std::string gripper;
  world::Pose robot_base = world::Pose::Identity();
  std::filesystem::path cell_model;        // absolute
  std::filesystem::path scene;             // absolute
  std::filesystem::path waypoints;         // absolute, or empty
  std::filesystem::path calibration;       // absolute
  std::filesystem::path perception_model;  // absolute, or empty: the default model
  Eigen::Vector3d table_centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d table_size = Eigen::Vector3d::Zero();
  Eigen::AlignedBox3d workspace;
  std::optional<Eigen::AlignedBox3d> part_area;
  /// The power tool (data/tools/NAME.json) and its stand's pose (the centre of its base).
  struct PowerTool {
    std::string tool;
    world::Pose stand = world::Pose::Identity();
  };
  std::optional<PowerTool> power_tool;
  /// The `remote` object as written (null: none); checked when the cell is built.
  nlohmann::json remote;
};

/// Reads a workcell description. @throws std::runtime_error "workcell description 'FILE':
/// FIELD: PROBLEM" for a missing or unreadable file, bad JSON, a missing, unknown or ill-typed
/// field, or a file it names that does not exist.
SimCellDescription loadSimCellDescription(const std::filesystem::path& file,
                                          const std::filesystem::path& data_root = {});

/// The description file of a simulated cell: DATA_ROOT/workcells/NAME.json.
std::filesystem::path simCellFile(const std::string& name, const std::filesystem::path& data_root = {});

/// The simulated cells of this data root (workcells/*.json): name and label, sorted by name;
/// a file that cannot be read is listed with the problem as its label.
std::vector<std::pair<std::string, std::string>> simCells(const std::filesystem::path& data_root = {});

}  // namespace costar::workcell
