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

/// The parameter `key` of the robot's solver, exactly `size` numbers.
std::vector<double> parameter(const RobotDescription& robot, const std::string& key, std::size_t size) {
  const auto it = robot.solver_parameters.find(key);
  if (it == robot.solver_parameters.end()) {
    throw std::runtime_error("kinematics." + key + ": missing (solver '" + robot.solver + "')");
  }
  if (it->second.size() != size) {
    throw std::runtime_error("kinematics." + key + ": must be " + std::to_string(size) + " numbers, not " +
                             std::to_string(it->second.size()));
  }
  return it->second;
}

/// "ur": the closed form of the UR arms from their DH table (d, a, alpha).
std::shared_ptr<const Kinematics> makeUr(const RobotDescription& robot) {
  for (const auto& [key, values] : robot.solver_parameters) {
    if (key != "d" && key != "a" && key != "alpha") {
      throw std::runtime_error("kinematics." + key + ": unknown parameter of solver 'ur' (known: a, alpha, d)");
    }
  }
  DhParameters dh;
  const auto copy = [&robot](const std::string& key, std::array<double, 6>& out) {
    const std::vector<double> values = parameter(robot, key, out.size());
    std::copy(values.begin(), values.end(), out.begin());
  };
  copy("d", dh.d);
  copy("a", dh.a);
  copy("alpha", dh.alpha);
  return std::make_shared<Ur5Kinematics>(dh, robot.limits);
}

/// "srs": 7-joint S-R-S arms (the LBR iiwa); the geometry from the joints and tool of the
/// robot's description file (format costar-robot-description/1, checked for the S-R-S form by
/// readSrsArmDescription), the limits from the description.
std::shared_ptr<const Kinematics> makeSrs(const RobotDescription& robot) {
  if (!robot.solver_parameters.empty()) {
    throw std::runtime_error("kinematics." + robot.solver_parameters.begin()->first +
                             ": solver 'srs' takes no parameters (its geometry comes from the joints)");
  }
  const SrsArmDescription arm = readSrsArmDescription(robot.file);
  return std::make_shared<SrsArmKinematics>(arm.geometry, robot.limits);
}

/// "chain": any serial chain of revolute joints (the Franka Panda), by Levenberg-Marquardt;
/// the geometry from the joints and tool of the robot's description file (format
/// costar-robot-description/1), the limits from the description.
std::shared_ptr<const Kinematics> makeChain(const RobotDescription& robot) {
  if (!robot.solver_parameters.empty()) {
    throw std::runtime_error("kinematics." + robot.solver_parameters.begin()->first +
                             ": solver 'chain' takes no parameters (its geometry comes from the joints)");
  }
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
