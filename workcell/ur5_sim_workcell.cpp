#include "workcell/ur5_sim_workcell.h"

#include "arm/arm_component.h"
#include "core/paths.h"
#include "faults/injector.h"
#include "gripper/parallel_gripper.h"
#include "perception/perception_component.h"
#include "perception/pipeline.h"
#include "planning/collision_world.h"
#include "predicator/pattern.h"
#include "predicator/predicator.h"
#include "sim/arm_driver.h"
#include "sim/drivers.h"
#include "sim/simulation.h"
#include "smartmove/smartmove.h"

namespace costar::workcell {

namespace {

/// The workcell's fixed frames, as symbols: table_center (the workspace centre, on the table
/// top; found from the ArUco marker when perception is set up) and the robot's base.
class FixedFrames final : public component::LocalComponent {
 public:
  explicit FixedFrames(std::vector<std::pair<std::string, world::Pose>> frames) : frames_(std::move(frames)) {
    description_.name = "workcell";
    description_.type = "FixedFrames";
    for (const auto& [name, pose] : frames_) {
      description_.symbols.push_back({name, world::SymbolKind::kFrame, "a fixed frame of the workcell"});
    }
  }
  const component::ComponentDescription& description() const override { return description_; }
  world::Report report() const override {
    world::Report report;
    for (const auto& [name, pose] : frames_) {
      report.symbols.push_back({name, "", {}, world::FrameValue{"world", pose}});
    }
    return report;
  }

 private:
  std::unique_ptr<component::RunningOperation> begin(const std::string&, const component::ParamMap&) override {
    return nullptr;  // no operations
  }
  component::ComponentDescription description_;
  std::vector<std::pair<std::string, world::Pose>> frames_;
};

/// TEST ONLY: the simulator's true part poses as object symbols, standing in for perception
/// when SmartMove is tested apart from it.
class TestOraclePerception final : public component::LocalComponent {
 public:
  explicit TestOraclePerception(sim::Simulation& simulation) : simulation_(simulation) {
    description_.name = "test_oracle_perception";
    description_.type = "TestOraclePerception";
    description_.predicates = {{"is_a", 2, "TEST ONLY: is_a(part, class) from ground truth"}};
  }
  const component::ComponentDescription& description() const override { return description_; }
  world::Report report() const override {
    world::Report report;
    for (const sim::PartState& part : simulation_.parts()) {
      report.symbols.push_back({part.name, "", {}, world::FrameValue{"world", part.pose}});
      report.predicates.push_back({"is_a", {part.name, part.object_class}, true, ""});
    }
    return report;
  }

 private:
  std::unique_ptr<component::RunningOperation> begin(const std::string&, const component::ParamMap&) override {
    return nullptr;
  }
  component::ComponentDescription description_;
  sim::Simulation& simulation_;
};

/// The perception pipeline (models and SVM loaded from the data files, about half a second),
/// loaded once per thread and shared by the workcells that thread creates: trials create one
/// workcell per trial, and a pipeline runs one detection at a time.
std::shared_ptr<perception::Pipeline> threadPipeline(const perception::PerceptionConfig& config) {
  thread_local std::shared_ptr<perception::Pipeline> pipeline;
  if (!pipeline) {
    pipeline = perception::loadPipeline(config);
  }
  return pipeline;
}

/// The workspace centre as set up with the ArUco marker (`costar perception collect`).
const world::Pose& tableCenter() {
  static const world::Pose pose = perception::loadTableCenter(perception::PipelineFiles::under().workspace_file);
  return pose;
}

const world::Pose kBaseInWorld(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()));

class Ur5SimWorkcell final : public Workcell {
 public:
  explicit Ur5SimWorkcell(const WorkcellOptions& options)
      : Workcell(std::make_unique<SimClock>()),
        scene_(sim::loadScene(options.scene.empty() ? dataRoot() / "sim/scenes/assembly.json" : options.scene)),
        simulation_(sim::Simulation::create(scene_, simOptions(options))),
        arm_driver_(*simulation_),
        gripper_driver_(*simulation_),
        camera_(*simulation_, options.seed.value_or(scene_.seed)),
        robot_(planning::RobotModel::fromUrdf(dataRoot() / "sim/models/ur5.urdf", "base_link", "tcp")),
        collisions_(robot_, kBaseInWorld, {.padding = 0.005, .resolution = 0.01},
                    {toEigen(sim::Simulation::homeConfiguration())}),
        waypoints_(!options.waypoints.empty()
                       ? options.waypoints
                       : (options.memory_only ? std::filesystem::path() : defaultWaypointFile("ur5-sim")),
                   /*persist=*/!options.memory_only),
        grasps_(dataRoot() / "data/grasps.json",
                options.memory_only ? std::filesystem::path() : defaultGraspFile("ur5-sim")),
        faults_(options.faults) {
    simulation_->attach(static_cast<SimClock&>(clock()));
    if (faults_) {
      faults_->attach(clock());
    }
    // The drivers and components as the cell uses them: wrapped by the fault injector, if any.
    arm::ArmDriver& arm_driver = faults_ ? faults_->wrap(arm_driver_) : arm_driver_;
    gripper::GripperDriver& gripper_driver = faults_ ? faults_->wrap(gripper_driver_) : gripper_driver_;
    camera::RgbdCamera& camera = faults_ ? faults_->wrap(camera_) : camera_;
    const auto add = [this](std::shared_ptr<component::Component> component) {
      components().add(faults_ ? faults_->wrap(std::move(component)) : std::move(component));
    };
    collisions_.setBox("table", world::Pose(Eigen::Translation3d(0.4, 0, -0.02)), {1.4, 1.2, 0.04});
    collisions_.allow("base_link", "table");  // the robot stands on it
    // The tool stays above the table top, within the cell.
    collisions_.setWorkspace(Eigen::AlignedBox3d(Eigen::Vector3d(-0.45, -0.65, 0.0), Eigen::Vector3d(1.05, 0.65, 1.2)));

    arm::ArmConfig arm_config;
    arm_config.base_in_world = kBaseInWorld;
    arm_config.home = sim::Simulation::homeConfiguration();
    auto arm = std::make_shared<arm::ArmComponent>(
        arm_driver, clock(), collisions_, waypoints_,
        [this](const std::string& frame) { return components().world().worldPose(frame); }, arm_config);
    // SmartMove reaches the gripper through its operations, as the tree does: the same (possibly
    // fault-injected) component the registry holds.
    std::shared_ptr<component::Component> gripper = std::make_shared<gripper::ParallelGripper>(gripper_driver, clock());
    if (faults_) {
      gripper = faults_->wrap(std::move(gripper));
    }
    add(arm);
    components().add(gripper);
    add(std::make_shared<FixedFrames>(std::vector<std::pair<std::string, world::Pose>>{{"table_center", tableCenter()},
                                                                                       {"robot_base", kBaseInWorld}}));
    if (options.test_oracle_perception) {
      add(std::make_shared<TestOraclePerception>(*simulation_));
    } else {
      // DetectObjects: the camera's frames only, never the simulator's true poses.
      perception::PerceptionConfig perception_config;
      perception_config.table_center = tableCenter();
      add(std::make_shared<perception::PerceptionComponent>(camera, clock(), threadPipeline(perception_config),
                                                            perception_config));
    }
    smartmove_ = std::make_shared<smartmove::SmartMoveComponent>(*arm, *gripper, components().world(), collisions_,
                                                                 simulation_->objectClasses(), grasps_);
    add(smartmove_);
    // Last: it derives its predicates from what the others report.
    add(std::make_shared<predicator::Predicator>(components().world(), simulation_->objectClasses()));
    if (faults_) {
      faults_->checkTargets();
    }
    // The safety stop (a component failed, a driver's readings cannot be trusted): the arm
    // decelerates along its path and stops; the fingers keep their last command.
    components().setOnStop([arm](const std::string&) { arm->stop(); });
    smartmove_->setPatternCheck([this](const predicator::Pattern& pattern) { return checkPattern(pattern); });
    registerNodes();
    smartmove_->syncObstacles();
  }

  void beforeTick() override {
    Workcell::beforeTick();
    smartmove_->syncObstacles();
  }

  /// A plan's predicate pattern names a declared predicate with the right number of arguments,
  /// and its other arguments are frames that exist now (fixed frames, waypoints) or object
  /// classes; names of detected parts are not known before the plan runs and are refused.
  std::string checkPattern(const predicator::Pattern& pattern) {
    components().refreshWorld();
    return predicator::checkPatternAgainst(pattern, components().predicates(), [this](const std::string& arg) {
      const auto& classes = simulation_->objectClasses();
      return std::any_of(classes.begin(), classes.end(),
                         [&arg](const world::ObjectClass& c) { return c.name == arg; }) ||
             components().world().symbol(arg) != nullptr;
    });
  }

  std::string name() const override { return "ur5-sim"; }
  std::string description() const override {
    return "simulated UR5 with a 2-finger gripper and an RGB-D camera (MuJoCo), scene '" + scene_.label + "'";
  }
  sim::Simulation* simulation() override { return simulation_.get(); }

 private:
  static sim::SimulationOptions simOptions(const WorkcellOptions& options) {
    sim::SimulationOptions sim_options;
    sim_options.placement_seed = options.seed;
    return sim_options;
  }
  static Eigen::VectorXd toEigen(const sim::ArmJoints& q) { return Eigen::Map<const Eigen::VectorXd>(q.data(), 6); }

  sim::Scene scene_;
  std::unique_ptr<sim::Simulation> simulation_;
  sim::SimArmDriver arm_driver_;
  sim::SimGripperDriver gripper_driver_;
  sim::SimRgbdCamera camera_;
  planning::RobotModel robot_;
  planning::CollisionWorld collisions_;
  arm::WaypointStore waypoints_;
  smartmove::GraspLibrary grasps_;
  std::shared_ptr<smartmove::SmartMoveComponent> smartmove_;
  std::shared_ptr<faults::Injector> faults_;
};

}  // namespace

std::unique_ptr<Workcell> makeUr5SimWorkcell(const WorkcellOptions& options) {
  return std::make_unique<Ur5SimWorkcell>(options);
}

}  // namespace costar::workcell
