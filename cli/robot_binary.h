#pragma once
// The `costar` executable is light: it links the behavior-tree engine, the component model
// and the workcells without a robot, so `costar --help`, `costar validate` and
// `costar run -w none` start in milliseconds. Commands that need the robot libraries (the
// MuJoCo simulator, PCL and OpenCV perception, KDL/FCL/OMPL planning) run in `costar-robot`,
// installed beside it: `costar` replaces itself with it (exec), same arguments.

#include <filesystem>

namespace costar::cli {

/// Keeps the command line, for handing it on to costar-robot. Call first in main().
void rememberCommandLine(int argc, char** argv);

/// The folder of the running executable (from /proc/self/exe, so not the working directory).
std::filesystem::path executableDir();

/// Replaces this process with costar-robot (beside this executable), same arguments. Never
/// returns: when it cannot be started, prints why and exits with status 2.
[[noreturn]] void runInRobotBinary();

}  // namespace costar::cli
