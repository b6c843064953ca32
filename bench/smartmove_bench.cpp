// SmartMove's choice of a goal among 20 nodes x 24 symmetries (480 candidates) with the real
// IK, joint limits, collision checks (table, the other parts, self) and path planning of the
// chosen one, in each simulated cell's geometry (workcells/ur5-sim.json: the UR5 closed form;
// workcells/iiwa-sim.json: the LBR iiwa 14's analytic S-R-S solver). Target: <= 20 ms.
// Figures: docs/BENCHMARKS.md.

#include <benchmark/benchmark.h>

#include <random>

#include "arm/arm_component.h"
#include "arm/robot_description.h"
#include "core/paths.h"
#include "smartmove/smartmove.h"
#include "workcell/grippers.h"
#include "workcell/sim_cell_description.h"

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
  explicit Cell(const std::string& name)
      : description(workcell::loadSimCellDescription(workcell::simCellFile(name))),
        robot_description(arm::loadRobotDescription(arm::robotDescriptionFile(description.robot))),
        gripper_model(workcell::gripperModel(description.gripper)),
        robot(planning::RobotModel::fromUrdf(robot_description.urdf, dataRoot() / gripper_model.urdf,
                                             robot_description.urdf_tool_link, robot_description.urdf_base_link,
                                             gripper_model.tcp_link)),
        collisions(robot, description.robot_base, {.padding = 0.005}, {robot_description.home.eigen()}),
        driver(robot_description.home),
        grasps(dataRoot() / "data/grasps.json", {}),
        kinematics(arm::makeKinematics(robot_description)),
        arm(driver, clock, collisions, waypoints, nullptr, kinematics, config()),
        motion(driver, clock, collisions, kinematics, config()),
        smartmove(motion, arm, gripper, world, collisions, world::loadObjectClasses(dataRoot() / "data/objects"),
                  grasps, smartmoveConfig()) {
    collisions.setBox("table", world::Pose(Eigen::Translation3d(description.table_centre)), description.table_size);
    collisions.allow(robot_description.base_link, "table");
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
  arm::ArmConfig config() const {
    arm::ArmConfig c;
    c.base_in_world = description.robot_base;
    c.home = robot_description.home;
    c.tcp_in_flange = gripper_model.tcp_in_flange;
    c.joint_names = robot_description.joint_names;
    c.joint_labels = robot_description.joint_labels;
    return c;
  }
  smartmove::SmartMoveConfig smartmoveConfig() const {
    smartmove::SmartMoveConfig c;
    c.gripper_links = robot_description.gripper_links;
    return c;
  }

  workcell::SimCellDescription description;
  arm::RobotDescription robot_description;
  const workcell::GripperModel& gripper_model;
  SimClock clock;
  world::WorldState world;
  planning::RobotModel robot;
  planning::CollisionWorld collisions;
  StillArm driver;
  arm::WaypointStore waypoints;
  smartmove::GraspLibrary grasps;
  NoGripper gripper;
  std::shared_ptr<const arm::Kinematics> kinematics;
  arm::ArmComponent arm;
  arm::MotionPlanner motion;
  smartmove::SmartMoveComponent smartmove;
};

void selection(benchmark::State& state, const std::string& workcell, double approach) {
  Cell cell(workcell);
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

void BM_SmartMoveSelection20x24(benchmark::State& state) { selection(state, "ur5-sim", 0.0); }
BENCHMARK(BM_SmartMoveSelection20x24)->Unit(benchmark::kMillisecond);

void BM_SmartGraspSelection20x24(benchmark::State& state) { selection(state, "ur5-sim", 0.1); }
BENCHMARK(BM_SmartGraspSelection20x24)->Unit(benchmark::kMillisecond);

void BM_SmartMoveSelection20x24_Iiwa(benchmark::State& state) { selection(state, "iiwa-sim", 0.0); }
BENCHMARK(BM_SmartMoveSelection20x24_Iiwa)->Unit(benchmark::kMillisecond);

void BM_SmartGraspSelection20x24_Iiwa(benchmark::State& state) { selection(state, "iiwa-sim", 0.1); }
BENCHMARK(BM_SmartGraspSelection20x24_Iiwa)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace costar::bench

BENCHMARK_MAIN();
