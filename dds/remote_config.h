#pragma once
// Which components of a workcell run in other processes, and where to find them on DDS: the
// `remote` object of a workcell description. Absent: every component runs in the executor's
// process. Loopback only unless an interface is named.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace costar::dds {

struct RemoteConfig {
  /// The DDS domain (0 to 232, as ROS_DOMAIN_ID).
  std::uint32_t domain = 0;
  /// The DDS partition: hosts and executors in another partition do not see each other.
  std::string partition = "costar";
  /// The network interface DDS uses; "lo" keeps every message on this machine.
  std::string network_interface = "lo";
  /// The components served by hosts (`costar host`), not built in the executor's process.
  std::vector<std::string> components;
  /// Set by a simulated cell, never read from the file: the executor's clock is simulated and
  /// published on rt/clock, each call of a remote component is answered at once at that time,
  /// and the executor answers the hosts' driver calls while it waits (dds/lockstep.h).
  bool lockstep = false;

  bool isRemote(const std::string& component) const;
};

/// Reads `{"domain": 0, "partition": "costar", "interface": "lo", "components": [...]}`;
/// every field but `components` is optional. `where` names the place in error messages.
/// @throws std::invalid_argument naming `where`, the field and the problem.
RemoteConfig remoteConfigFromJson(const nlohmann::json& json, const std::string& where);
nlohmann::json toJson(const RemoteConfig& config);

}  // namespace costar::dds
