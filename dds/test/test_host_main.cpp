// TEST ONLY: serves the test components (testing/test_components.h) named on the command
// line over DDS, for dds/test/remote_component_test.cpp, until SIGTERM or SIGINT.
//   dds_test_host PARTITION COMPONENT...   (test_actions, test_counter, test_logger, test_arm)

#include <atomic>
#include <csignal>
#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include "dds/host.h"
#include "testing/test_components.h"

namespace {

std::atomic<bool> g_stop{false};

extern "C" void onSignal(int /*signal*/) { g_stop = true; }

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s PARTITION COMPONENT...\n", argv[0]);
    return 2;
  }
  std::signal(SIGTERM, onSignal);
  std::signal(SIGINT, onSignal);
  const std::map<std::string, std::shared_ptr<costar::component::Component>> known = {
      {"test_actions", std::make_shared<costar::testing::TestActions>()},
      {"test_counter", std::make_shared<costar::testing::TestCounter>()},
      {"test_logger", std::make_shared<costar::testing::TestLogger>()},
      {"test_arm", std::make_shared<costar::testing::TestArm>()},
  };
  costar::dds::RemoteConfig config;
  config.partition = argv[1];
  std::vector<std::shared_ptr<costar::component::Component>> served;
  for (int i = 2; i < argc; ++i) {
    const auto it = known.find(argv[i]);
    if (it == known.end()) {
      std::fprintf(stderr, "%s: unknown test component '%s'\n", argv[0], argv[i]);
      return 2;
    }
    served.push_back(it->second);
  }
  try {
    costar::dds::ComponentHost host(config, served);
    host.serve(g_stop);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "%s: %s\n", argv[0], error.what());
    return 1;
  }
  return 0;
}
