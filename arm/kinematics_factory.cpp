// makeKinematics(): one row per kinematics solver. A new arm family adds its Kinematics class
// and a row here; its robots name the row's key in "kinematics.solver".

#include <algorithm>
#include <functional>
#include <stdexcept>
#include <utility>

#include "arm/chain_kinematics.h"
#include "arm/robot_description.h"
#include "arm/srs_kinematics.h"
#include "arm/ur5_kinematics.h"

namespace costar::arm {

namespace {

/// Solvers whose geometry comes from the joints take no parameters.
void requireNoParameters(const RobotDescription& robot) {
  if (!robot.solver_parameters.empty()) {
    throw std::runtime_error("kinematics." + robot.solver_parameters.begin()->first + ": solver '" + robot.solver +
                             "' takes no parameters (its geometry comes from the joints)");
  }
}

/// "ur": the closed form of the UR arms; their DH table read back from the joints and tool of
/// the robot's description file, which must be written in DH form (dhParametersOf).
std::shared_ptr<const Kinematics> makeUr(const RobotDescription& robot) {
  requireNoParameters(robot);
  return std::make_shared<Ur5Kinematics>(dhParametersOf(readChainGeometry(robot.file)), robot.limits);
}

/// "srs": 7-joint S-R-S arms (the LBR iiwa); the geometry from the joints and tool of the
/// robot's description file (format costar-robot-description/1, checked for the S-R-S form by
/// readSrsArmDescription), the limits from the description.
std::shared_ptr<const Kinematics> makeSrs(const RobotDescription& robot) {
  requireNoParameters(robot);
  const SrsArmDescription arm = readSrsArmDescription(robot.file);
  return std::make_shared<SrsArmKinematics>(arm.geometry, robot.limits);
}

/// "chain": any serial chain of revolute joints (the Franka Panda), by Levenberg-Marquardt;
/// the geometry from the joints and tool of the robot's description file (format
/// costar-robot-description/1), the limits from the description.
std::shared_ptr<const Kinematics> makeChain(const RobotDescription& robot) {
  requireNoParameters(robot);
  return std::make_shared<ChainKinematics>(readChainGeometry(robot.file), robot.limits);
}

using Maker = std::shared_ptr<const Kinematics> (*)(const RobotDescription&);

/// Every solver: key, maker. Sorted by key.
constexpr std::pair<const char*, Maker> kSolvers[] = {
    {"chain", &makeChain},
    {"srs", &makeSrs},
    {"ur", &makeUr},
};

}  // namespace

std::vector<std::string> kinematicsSolvers() {
  std::vector<std::string> keys;
  for (const auto& [key, maker] : kSolvers) {
    keys.emplace_back(key);
  }
  std::sort(keys.begin(), keys.end());
  return keys;
}

std::shared_ptr<const Kinematics> makeKinematics(const RobotDescription& robot) {
  const std::string label = "robot description '" + robot.file.string() + "': ";
  const auto* row = std::find_if(std::begin(kSolvers), std::end(kSolvers),
                                 [&robot](const auto& entry) { return robot.solver == entry.first; });
  if (row == std::end(kSolvers)) {
    std::string known;
    for (const std::string& key : kinematicsSolvers()) {
      known += (known.empty() ? "" : ", ") + key;
    }
    throw std::runtime_error(label + "kinematics.solver: unknown solver '" + robot.solver + "' (known: " + known + ")");
  }
  try {
    return row->second(robot);
  } catch (const std::exception& e) {  // the solver's own checks (std::invalid_argument) too
    throw std::runtime_error(label + e.what());
  }
}

}  // namespace costar::arm
