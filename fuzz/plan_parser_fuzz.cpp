// libFuzzer target: any bytes as a plan file. Reading, validating, building and ticking must
// never crash, hang or leak; a valid plan must survive save -> load unchanged.

#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "bt/builder.h"
#include "bt/plan_xml.h"

using namespace costar;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bt::NodeRegistry registry = bt::builtinRegistry();
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const bt::BuildLimits limits{.max_nodes = 20'000, .max_depth = 300};
  try {
    const bt::Plan plan = bt::loadPlanText(text, "fuzz.xml", {.follow_includes = false});
    // Saving and reading back must give the same plan, valid or not.
    const bt::PlanFile again = bt::parsePlanFile(bt::writePlanFile(plan.file), "again.xml");
    if (!bt::sameContent(plan.file, again)) {
      std::abort();
    }
    if (!bt::validatePlan(plan, registry, limits).empty()) {
      return 0;
    }
    SimClock clock;
    bt::Tree tree = bt::buildTree(plan, registry, clock, {}, limits);
    for (int tick = 0; tick < 64 && tree.tick() == bt::Status::kRunning; ++tick) {
      clock.advanceBy(std::chrono::milliseconds(7));
    }
    tree.halt();
  } catch (const bt::PlanError&) {
    // Invalid input, reported with a location: the expected outcome for most inputs.
  }
  return 0;
}
