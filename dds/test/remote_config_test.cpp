#include "dds/remote_config.h"

#include <gtest/gtest.h>

namespace costar::dds {
namespace {

using nlohmann::json;

std::string errorOf(const json& input) {
  try {
    remoteConfigFromJson(input, "cell.json: remote");
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "";
}

TEST(RemoteConfig, DefaultsToLoopbackInTheCostarPartition) {
  const RemoteConfig config = remoteConfigFromJson(json{{"components", {"gripper", "perception"}}}, "remote");
  EXPECT_EQ(config.domain, 0u);
  EXPECT_EQ(config.partition, "costar");
  EXPECT_EQ(config.network_interface, "lo");
  EXPECT_TRUE(config.isRemote("perception"));
  EXPECT_FALSE(config.isRemote("arm"));
  EXPECT_EQ(remoteConfigFromJson(toJson(config), "remote").components, config.components);
}

TEST(RemoteConfig, ReadsEveryField) {
  const RemoteConfig config = remoteConfigFromJson(
      json{{"domain", 7}, {"partition", "cell-2"}, {"interface", "eth1"}, {"components", {"gripper"}}}, "remote");
  EXPECT_EQ(config.domain, 7u);
  EXPECT_EQ(config.partition, "cell-2");
  EXPECT_EQ(config.network_interface, "eth1");
}

TEST(RemoteConfig, BadFieldsAreNamed) {
  EXPECT_NE(errorOf(json::array()).find("cell.json: remote: must be an object"), std::string::npos);
  EXPECT_NE(errorOf(json{{"components", {"a"}}, {"domian", 1}}).find("unknown field 'domian'"), std::string::npos);
  EXPECT_NE(
      errorOf(json{{"components", {"a"}}, {"domain", 233}}).find("remote.domain: must be an integer from 0 to 232"),
      std::string::npos);
  EXPECT_NE(errorOf(json{{"components", {"a"}}, {"domain", "0"}}).find("remote.domain"), std::string::npos);
  EXPECT_NE(errorOf(json{{"components", {"a"}}, {"partition", ""}}).find("remote.partition: must be a non-empty"),
            std::string::npos);
  EXPECT_NE(errorOf(json{{"domain", 0}}).find("remote.components: must list"), std::string::npos);
  EXPECT_NE(errorOf(json{{"components", json::array()}}).find("remote.components: must list"), std::string::npos);
  EXPECT_NE(errorOf(json{{"components", {"a", 3}}}).find("remote.components[1]: must be a component name"),
            std::string::npos);
  EXPECT_NE(errorOf(json{{"components", {"a", "a"}}}).find("remote.components[1]: 'a' is listed twice"),
            std::string::npos);
}

}  // namespace
}  // namespace costar::dds
