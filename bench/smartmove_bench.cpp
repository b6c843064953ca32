// SmartMove's choice of a goal among 20 nodes x 24 symmetries (480 candidates) with the real
// UR5 IK, joint limits, collision checks (table, the other parts, self) and path planning of the
// chosen one. Target: <= 20 ms. Figures: docs/BENCHMARKS.md.

#include <benchmark/benchmark.h>

#include <random>

#include "arm/arm_component.h"
#include "arm/robot_description.h"
#include "arm/ur5_kinematics.h"
#include "core/paths.h"
#include "smartmove/smartmove.h"

namespace costar::bench {
namespace {

/// Holds still at a configuration (selection does not move the arm).
class StillArm final : public arm::ArmDriver {
 public:
  explicit StillArm(arm::JointVector q) : q_(q) {}
  arm::ArmState read() const override { return {q_, {}}; }
  void execute(std::shared_ptr<const arm::JointTrajectory>, TimePoint) override {}

 private:
  arm::JointVector q_;
};

/// Answers every gripper operation at once (selection does not use it).
class NoGripper final : public component::LocalComponent {
 public:
  NoGripper() { description_.name = "gripper"; }
  const component::ComponentDescription& description() const override { return description_; }
  world::Report report() const override { return {}; }

 private:
  std::unique_ptr<component::RunningOperation> begin(const std::string&, const component::ParamMap&) override {
    return std::make_unique<component::FinishedOperation>(component::OperationResult::success());
  }
  component::ComponentDescription description_;
};

struct Cell {
  Cell()
      : robot(planning::RobotModel::fromUrdf(dataRoot() / "sim/models/ur5.urdf", "base_link", "tcp")),
        collisions(robot, kBase, {.padding = 0.005}, {kHome.eigen()}),
        driver(kHome),
        grasps(dataRoot() / "data/grasps.json", {}),
        arm(driver, clock, collisions, waypoints, nullptr, std::make_shared<arm::Ur5Kinematics>(), config()),
        smartmove(arm, gripper, world, collisions, world::loadObjectClasses(dataRoot() / "data/objects"), grasps,
                  smartmoveConfig()) {
    collisions.setBox("table", world::Pose(Eigen::Translation3d(0.4, 0, -0.02)), {1.4, 1.2, 0.04});
    collisions.allow("base_link", "table");
    // 20 nodes at random on the table, any yaw, 6 cm apart at least.
    std::mt19937 random(3);
    std::uniform_real_distribution<double> x(0.3, 0.7);
    std::uniform_real_distribution<double> y(-0.4, 0.4);
    std::uniform_real_distribution<double> yaw(-M_PI, M_PI);
    world::Report report;
    std::vector<Eigen::Vector2d> placed;
    while (placed.size() < 20) {
      const Eigen::Vector2d p(x(random), y(random));
      if (std::any_of(placed.begin(), placed.end(), [&p](const auto& q) { return (p - q).norm() < 0.06; })) {
        continue;
      }
      placed.push_back(p);
      const std::string name = "node_" + std::to_string(placed.size());
      report.symbols.push_back(
          {name, "", {}, world::FrameValue{"world", world::poseFromXyzRpy(p.x(), p.y(), 0.025, 0, 0, yaw(random))}});
      report.predicates.push_back({"is_a", {name, "node"}, true, ""});
    }
    world.update("perception", report);
  }
  static arm::ArmConfig config() {
    arm::ArmConfig c;
    c.base_in_world = kBase;
    c.home = kHome;
    c.tcp_in_flange = world::Pose(Eigen::Translation3d(0, 0, 0.14));
    return c;
  }
  static smartmove::SmartMoveConfig smartmoveConfig() {
    smartmove::SmartMoveConfig c;
    c.gripper_links = arm::loadRobotDescription(arm::robotDescriptionFile("ur5")).gripper_links;
    return c;
  }
  static inline const arm::JointVector kHome = {0.0, -2.3, 1.9, -M_PI / 2 + 0.4, -M_PI / 2, 0.0};
  static inline const world::Pose kBase{Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ())};

  SimClock clock;
  world::WorldState world;
  planning::RobotModel robot;
  planning::CollisionWorld collisions;
  StillArm driver;
  arm::WaypointStore waypoints;
  smartmove::GraspLibrary grasps;
  NoGripper gripper;
  arm::ArmComponent arm;
  smartmove::SmartMoveComponent smartmove;
};

void selection(benchmark::State& state, double approach) {
  Cell cell;
  const world::Pose grasp = cell.grasps.find("node", "top")->tcp_in_object;
  smartmove::Selection last;
  for (auto _ : state) {
    last = cell.smartmove.selectGrasp("node", {}, grasp, approach, 0.5);
  }
  state.counters["candidates"] = static_cast<double>(last.candidates.size());
  state.counters["feasible_found"] = last.ok() ? 1 : 0;
  int checked = 0;
  for (const auto& candidate : last.candidates) {
    checked += candidate.chosen || (!candidate.rejected.empty() && candidate.rejected.rfind("not checked", 0) != 0 &&
                                    candidate.rejected.rfind("no IK", 0) != 0)
                   ? 1
                   : 0;
  }
  state.counters["fully_checked"] = checked;
}

void BM_SmartMoveSelection20x24(benchmark::State& state) { selection(state, 0.0); }
BENCHMARK(BM_SmartMoveSelection20x24)->Unit(benchmark::kMillisecond);

void BM_SmartGraspSelection20x24(benchmark::State& state) { selection(state, 0.1); }
BENCHMARK(BM_SmartGraspSelection20x24)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace costar::bench

BENCHMARK_MAIN();
