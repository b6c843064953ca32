#pragma once
// What costar says about itself, and the commands that run in costar-robot (robot_binary.h),
// which the light `costar` lists in its help (cli_test.sh checks that both helps agree).

#include <array>

namespace costar::cli {

inline constexpr const char* kAppDescription =
    "costar: build task plans as behavior trees of robot operations (DetectObjects, SmartMove, Close "
    "gripper, ...) and run them on a workcell (CoSTAR, ICRA 2017).";
inline constexpr const char* kVersion = "costar 0.1.0";

struct RobotCommand {
  const char* name;
  const char* description;  // as the command itself declares it (cli_test.sh compares the helps)
};

/// In the order costar-robot (main.cpp) adds them, after the plan commands.
inline constexpr std::array kRobotCommands = {
    RobotCommand{"sim", "The simulated UR5 workcell on its own"},
    RobotCommand{"perception",
                 "Set up and measure perception: the ArUco marker, training data, the SVM, and an evaluation "
                 "against the simulator's ground truth"},
    RobotCommand{"teach",
                 "Jog the arm and teach waypoints, interactively (commands from standard input; 'help' lists "
                 "them)"},
    RobotCommand{"smartmove", "SmartMove set-up"},
    RobotCommand{"trials", "Rerun a plan as N randomized trials in the simulated cell, judged from its true state"},
    RobotCommand{"calibrate",
                 "Calibrate the camera: the arm shows the marker on its gripper to the camera from poses it chooses, "
                 "and the camera's pose is saved with the cell (the editor's Calibrate button)"},
    RobotCommand{"serve", "Serve the task editor (a web page) and its API: build, run and watch plans on a workcell"},
    RobotCommand{"host", "Serve components of a workcell to an executor in another process or machine (DDS)"},
    RobotCommand{"host-campaign",
                 "Liveness of remote components: runs a plan with the gripper and perception in a host (this "
                 "executable), kills the host (SIGKILL) during a DetectObjects, an arm motion or between operations "
                 "at moments drawn from the seed, and judges each run: FAILURE naming the component within the "
                 "deadline, the arm at rest, the files unchanged"},
};

}  // namespace costar::cli
