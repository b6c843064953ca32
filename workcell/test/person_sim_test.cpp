// The simulated cell with a person (docs/PERSON.md): the speed and separation monitor's
// reading in the world state, as the editor and plans see it.
#include <gtest/gtest.h>

#include "core/paths.h"
#include "sim/simulation.h"
#include "workcell/workcell.h"

namespace costar::workcell {
namespace {

double number(Workcell& cell, const std::string& name) {
  const world::Symbol* symbol = cell.components().world().symbol(name);
  if (symbol == nullptr || symbol->number() == nullptr) {
    ADD_FAILURE() << "no number " << name;
    return -1.0;
  }
  return symbol->number()->value;
}

TEST(PersonSimWorkcell, TheMonitorsReadingIsInTheWorldStateWhenTheSceneHasAPerson) {
  // Away: nothing slows the arm.
  const auto away =
      makeWorkcell({.name = "iiwa-3f-sim", .scene = dataRoot() / "sim/scenes/person_away.json", .memory_only = true});
  away->beforeTick();
  EXPECT_DOUBLE_EQ(number(*away, "arm_speed_scale"), 1.0);
  EXPECT_GT(number(*away, "person_separation"), 1.0);
  EXPECT_FALSE(away->components().world().holds("arm_stopped_for_person", {}));
  // At the table, reaching over it: the arm is held (the person is within the protective
  // distance almost all the time).
  const auto near =
      makeWorkcell({.name = "iiwa-3f-sim", .scene = dataRoot() / "sim/scenes/person_random.json", .memory_only = true});
  static_cast<SimClock&>(near->clock()).advanceBy(std::chrono::seconds(1));
  near->beforeTick();
  EXPECT_LT(number(*near, "person_separation"), 0.7);
  EXPECT_GT(number(*near, "protective_distance"), 0.5);
  EXPECT_DOUBLE_EQ(number(*near, "arm_speed_scale"), 0.0);
  EXPECT_TRUE(near->components().world().holds("arm_stopped_for_person", {}));
  // Without a person the cell has no such component.
  const auto none =
      makeWorkcell({.name = "iiwa-3f-sim", .scene = dataRoot() / "sim/scenes/one_node.json", .memory_only = true});
  none->beforeTick();
  EXPECT_EQ(none->components().world().symbol("person_separation"), nullptr);
}

}  // namespace
}  // namespace costar::workcell
