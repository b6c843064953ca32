#include "dds/remote_config.h"

#include <algorithm>
#include <set>
#include <stdexcept>

namespace costar::dds {

bool RemoteConfig::isRemote(const std::string& component) const {
  return std::find(components.begin(), components.end(), component) != components.end();
}

RemoteConfig remoteConfigFromJson(const nlohmann::json& json, const std::string& where) {
  if (!json.is_object()) {
    throw std::invalid_argument(where + ": must be an object {domain, partition, interface, components}");
  }
  static const std::set<std::string> kKnown = {"domain", "partition", "interface", "components"};
  for (const auto& [key, value] : json.items()) {
    if (!kKnown.contains(key)) {
      throw std::invalid_argument(where + ": unknown field '" + key +
                                  "' (known: components, domain, interface, partition)");
    }
  }
  RemoteConfig config;
  if (const auto it = json.find("domain"); it != json.end()) {
    // DDS over UDP maps a domain to ports: 232 is the highest that fits (as ROS_DOMAIN_ID).
    if (!it->is_number_integer() || it->get<std::int64_t>() < 0 || it->get<std::int64_t>() > 232) {
      throw std::invalid_argument(where + ".domain: must be an integer from 0 to 232, got " + it->dump());
    }
    config.domain = it->get<std::uint32_t>();
  }
  for (const auto& [field, target] :
       {std::pair{"partition", &config.partition}, std::pair{"interface", &config.network_interface}}) {
    if (const auto it = json.find(field); it != json.end()) {
      if (!it->is_string() || it->get<std::string>().empty()) {
        throw std::invalid_argument(where + "." + field + ": must be a non-empty string, got " + it->dump());
      }
      *target = it->get<std::string>();
    }
  }
  const auto components = json.find("components");
  if (components == json.end() || !components->is_array() || components->empty()) {
    throw std::invalid_argument(where + ".components: must list the names of the components served by hosts");
  }
  for (std::size_t i = 0; i < components->size(); ++i) {
    const auto& name = (*components)[i];
    if (!name.is_string() || name.get<std::string>().empty()) {
      throw std::invalid_argument(where + ".components[" + std::to_string(i) + "]: must be a component name");
    }
    if (config.isRemote(name.get<std::string>())) {
      throw std::invalid_argument(where + ".components[" + std::to_string(i) + "]: '" + name.get<std::string>() +
                                  "' is listed twice");
    }
    config.components.push_back(name.get<std::string>());
  }
  return config;
}

nlohmann::json toJson(const RemoteConfig& config) {
  return {{"domain", config.domain},
          {"partition", config.partition},
          {"interface", config.network_interface},
          {"components", config.components}};
}

}  // namespace costar::dds
