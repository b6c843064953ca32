// The simulated cell with a person (docs/PERSON.md): the speed and separation monitor's
// reading and the hand the camera sees in the world state, as the editor and plans see them.
#include <gtest/gtest.h>

#include "arm/motion_service.h"
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

bool holds(const world::WorldState& world, const std::string& name, std::vector<std::string> args) {
  return world.holds(name, args);
}

TEST(PersonSimWorkcell, TheMonitorsReadingAndCollaborativeModeAreInTheWorldStateWhenTheSceneHasAPerson) {
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
  // Collaborative mode for a hand-over, asked for by a plan through the safety component.
  component::Component* safety = near->components().find("safety");
  ASSERT_NE(safety, nullptr);
  EXPECT_FALSE(holds(near->components().world(), "arm_collaborative", {}));
  const component::OperationId on = safety->start("Collaborate", {{"on", true}});
  EXPECT_EQ(safety->poll(on).state, component::OperationState::kSuccess);
  static_cast<SimClock&>(near->clock()).advanceBy(std::chrono::milliseconds(100));
  near->beforeTick();
  EXPECT_TRUE(holds(near->components().world(), "arm_collaborative", {}));
  EXPECT_EQ(near->simulation()->separation()->stop_reason, "");  // not stopped for the separation
  const component::OperationId off = safety->start("Collaborate", {{"on", false}});
  EXPECT_EQ(safety->poll(off).state, component::OperationState::kSuccess);
  static_cast<SimClock&>(near->clock()).advanceBy(std::chrono::milliseconds(100));
  near->beforeTick();
  EXPECT_FALSE(holds(near->components().world(), "arm_collaborative", {}));
  // Without a person the cell has the components, so that a plan for a person validates in it,
  // but they report nothing, and collaborative mode is refused, saying why.
  const auto none =
      makeWorkcell({.name = "iiwa-3f-sim", .scene = dataRoot() / "sim/scenes/one_node.json", .memory_only = true});
  none->beforeTick();
  EXPECT_EQ(none->components().world().symbol("person_separation"), nullptr);
  EXPECT_EQ(none->components().world().symbol("hand_1"), nullptr);
  ASSERT_NE(none->components().find("hand"), nullptr);
  component::Component* no_safety = none->components().find("safety");
  ASSERT_NE(no_safety, nullptr);
  const component::OperationResult refused = no_safety->poll(no_safety->start("Collaborate", {{"on", true}}));
  EXPECT_EQ(refused.state, component::OperationState::kFailure);
  EXPECT_NE(refused.reason.find("no person in this cell's scene"), std::string::npos) << refused.reason;
  EXPECT_NE(none->nodes().find("Collaborate"), nullptr);
}

TEST(PersonSimWorkcell, TheHandAndItsGestureAreInTheWorldStateAsTheCameraSeesThem) {
  // The person reaches into the hand-over zone (1.2 s) and offers an open palm for 3 s.
  const auto cell =
      makeWorkcell({.name = "iiwa-3f-sim", .scene = dataRoot() / "sim/scenes/person_offer.json", .memory_only = true});
  const world::WorldState& world = cell->components().world();
  bool gesture_before_the_offer = false;
  for (int i = 0; i < 56; ++i) {  // to 2.8 s
    static_cast<SimClock&>(cell->clock()).advanceBy(std::chrono::milliseconds(50));
    cell->beforeTick();
    gesture_before_the_offer = gesture_before_the_offer || (i < 20 && holds(world, "gesture", {"hand_1", "offer"}));
  }
  EXPECT_FALSE(gesture_before_the_offer);  // reaching: the hand moves
  const world::Symbol* hand = world.symbol("hand_1");
  ASSERT_NE(hand, nullptr);
  ASSERT_NE(hand->frame(), nullptr);
  EXPECT_LT((hand->frame()->pose.translation() - Eigen::Vector3d(0.5, 0.24, 0.2)).norm(),
            0.04);  // 6 cm from the wrist along the hand
  EXPECT_TRUE(holds(world, "gesture", {"hand_1", "offer"}));
  EXPECT_TRUE(holds(world, "in_zone", {"hand_1", "handover"}));
  EXPECT_TRUE(holds(world, "hand_still", {"hand_1"}));
  EXPECT_GT(number(*cell, "hand_still_seconds"), 0.5);
  EXPECT_FALSE(holds(world, "is_a", {"hand_1", "node"}));
  // SmartMove plans no motion through the hand or the forearm behind it: the tool pointing down
  // 2 cm above the hand's centre, or 22 cm behind it over the forearm, collides with them; 25 cm
  // above the hand it is free.
  const arm::MotionService* motion = cell->motion();
  ASSERT_NE(motion, nullptr);
  const auto contactAt = [&](const Eigen::Vector3d& offset) -> std::string {
    world::Pose tool = world::Pose::Identity();
    tool.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
    tool.translation() = hand->frame()->pose * offset;
    const auto solutions = motion->solutions(tool, motion->joints());
    if (solutions.empty()) {
      return "unreachable";
    }
    const auto contact = motion->collision(solutions.front(), {});
    return contact ? contact->other : std::string();
  };
  EXPECT_EQ(contactAt({0, 0, 0.02}).rfind("part:hand_1", 0), 0u) << contactAt({0, 0, 0.02});
  EXPECT_EQ(contactAt({-0.22, 0, 0.03}).rfind("part:hand_1", 0), 0u) << contactAt({-0.22, 0, 0.03});
  EXPECT_EQ(contactAt({0, 0, 0.25}), "");
}

}  // namespace
}  // namespace costar::workcell
