#include "workcell/sim_workcell.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "arm/arm_component.h"
#include "arm/motion_planner.h"
#include "arm/robot_description.h"
#include "calibration/calibration_component.h"
#include "component/operation_table.h"
#include "core/json_file.h"
#include "core/paths.h"
#include "dds/remote_component.h"
#include "faults/injector.h"
#include "perception/hand_component.h"
#include "perception/perception_component.h"
#include "perception/pipeline.h"
#include "planning/collision_world.h"
#include "planning/robot_model.h"
#include "predicator/pattern.h"
#include "predicator/predicator.h"
#include "sim/arm_driver.h"
#include "sim/drivers.h"
#include "sim/simulation.h"
#include "smartmove/smartmove.h"
#include "testing/test_components.h"
#include "tool/power_tool.h"
#include "workcell/cell_simulation.h"
#include "workcell/grippers.h"
#include "workcell/remote_sim.h"
#include "workcell/sim_cell_description.h"

namespace costar::workcell {

namespace {

/// The workcell's fixed frames, as symbols: table_center (the workspace centre, on the table
/// top; found from the ArUco marker when perception is set up) and the robot's base.
class FixedFrames final : public component::TableComponent {
 public:
  explicit FixedFrames(std::vector<std::pair<std::string, world::Pose>> frames) : frames_(std::move(frames)) {
    component::ComponentDescription description;
    description.name = "workcell";
    description.type = "FixedFrames";
    for (const auto& [name, pose] : frames_) {
      description.symbols.push_back({name, world::SymbolKind::kFrame, "a fixed frame of the workcell"});
    }
    declare(std::move(description), {});  // no operations
  }
  world::Report report() const override {
    world::Report report;
    for (const auto& [name, pose] : frames_) {
      report.symbols.push_back({name, "", {}, world::FrameValue{"world", pose}});
    }
    return report;
  }

 private:
  std::vector<std::pair<std::string, world::Pose>> frames_;
};

/// The cell controller's speed and separation monitor (sim/speed_separation.h, docs/PERSON.md)
/// as a safety controller reports it, for the editor and for plans that wait on it: the
/// separation its sensor last read, the protective distance at the arm's speed, the speed
/// override, and whether it is slowing or holding the arm for the person; and its collaborative
/// mode for a hand-over (Collaborate on=true: power and force limiting, the arm at most 0.2 m/s
/// at any separation, stopped by contact outside the hand or a hand force above 140 N). In every
/// simulated cell: without a person in the scene it reports nothing and Collaborate fails, naming why.
class SeparationMonitor final : public component::TableComponent {
 public:
  explicit SeparationMonitor(sim::Simulation& simulation) : simulation_(simulation) {
    component::ComponentDescription description;
    description.name = "safety";
    description.type = "SpeedSeparationMonitor";
    description.symbols = {
        {"person_separation", world::SymbolKind::kNumber, "the separation arm-person the monitor last sensed (m)"},
        {"protective_distance", world::SymbolKind::kNumber, "ISO/TS 15066's S_p at the arm's present speed (m)"},
        {"arm_speed_scale", world::SymbolKind::kNumber, "the speed override, 0 (held) to 1 (full speed)"}};
    description.predicates = {{"arm_slowed_for_person", 0, "the monitor slows the arm for the person"},
                              {"arm_stopped_for_person", 0, "the monitor holds the arm still for the person"},
                              {"arm_collaborative", 0, "power and force limiting for a hand-over is on"}};
    component::OperationTable operations;
    operations.add({"Collaborate",
                    "Power and force limiting for a hand-over (on) or speed and separation monitoring (off): "
                    "on, the arm moves at most 0.2 m/s however near the person, and contact outside the hand or "
                    "above 140 N on it stops it.",
                    {{"on", component::ValueType::kBool, "collaborative mode on or off", true}},
                    component::OperationKind::kRobotAction},
                   [this](const component::ParamMap& params) {
                     if (!simulation_.separation()) {
                       return std::make_unique<component::FinishedOperation>(component::OperationResult::failure(
                           "no person in this cell's scene: collaborative mode is the speed and separation "
                           "monitor's, which watches a person (a scene with a \"person\", docs/PERSON.md)"));
                     }
                     simulation_.setCollaborative(params.at("on").asBool());
                     return std::make_unique<component::FinishedOperation>(component::OperationResult::success());
                   });
    declare(std::move(description), std::move(operations));
  }
  world::Report report() const override {
    world::Report report;
    const std::optional<sim::SeparationStatus> status = simulation_.separation();
    if (!status) {
      return report;
    }
    report.symbols.push_back({"person_separation", "", {}, world::NumberValue{status->sensed_separation, "m"}});
    report.symbols.push_back({"protective_distance", "", {}, world::NumberValue{status->protective_distance, "m"}});
    report.symbols.push_back({"arm_speed_scale", "", {}, world::NumberValue{status->scale, ""}});
    report.predicates.push_back({"arm_slowed_for_person", {}, status->state == "limited"});
    report.predicates.push_back({"arm_stopped_for_person", {}, status->state == "stopped"});
    report.predicates.push_back({"arm_collaborative", {}, status->collaborative});
    return report;
  }

 private:
  sim::Simulation& simulation_;
};

/// The perception pipeline (models and SVM loaded from the data files, about half a second),
/// loaded once per thread and SVM file (each cell has its own) and shared by the workcells that
/// thread creates: trials create one workcell per trial, and a pipeline runs one detection at a
/// time.
std::shared_ptr<perception::Pipeline> threadPipeline(const perception::PerceptionConfig& config) {
  thread_local std::map<std::filesystem::path, std::shared_ptr<perception::Pipeline>> pipelines;
  std::shared_ptr<perception::Pipeline>& pipeline = pipelines[config.files.svm_file];
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

/// The robot's planning model: its URDF with the gripper's mounted on the flange.
planning::RobotModel planningModel(const arm::RobotDescription& robot, const GripperModel& gripper) {
  return planning::RobotModel::fromUrdf(robot.urdf, dataRoot() / gripper.urdf, robot.urdf_tool_link,
                                        robot.urdf_base_link, gripper.tcp_link);
}

/// `file` relative to the data root when under it (as typed in the repository), else whole.
std::string relativeToDataRoot(const std::filesystem::path& file) {
  std::error_code error;
  const std::filesystem::path relative = std::filesystem::relative(file, dataRoot(), error);
  return !error && !relative.empty() && *relative.begin() != ".." ? relative.string() : file.string();
}

/// A number in a message: 4 significant digits.
std::string shortNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", value);
  return text;
}

std::string joinNames(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) {
    text += (text.empty() ? "'" : ", '") + name + "'";
  }
  return "[" + text + "]";
}

/// Checks that the robot description's kinematics and limits are those of the model the planner
/// and the simulator use (the arm's URDF with the gripper's on its flange): an edited
/// description would otherwise be applied in part (the IK solves for the edited arm, the
/// simulator and the collision checks move the model's). The generated models carry the
/// fingerprint of their description (arm/robot_description.h); a description beside hand-made
/// models (the UR5's) has only this check. Forward kinematics are compared at the home
/// configuration and at 8 fixed ones spread over the limits.
/// @throws std::runtime_error naming the description, the model and the difference.
void checkDescriptionMatchesModel(const arm::RobotDescription& robot, const arm::Kinematics& kinematics,
                                  const world::Pose& tcp_in_flange, const planning::RobotModel& model) {
  const std::string file = relativeToDataRoot(robot.file);
  const std::string urdf = relativeToDataRoot(robot.urdf);
  const auto fail = [&](const std::string& problem) {
    throw std::runtime_error("robot description '" + file + "' does not match its model '" + urdf + "': " + problem +
                             " (was either edited?)");
  };
  if (model.jointNames() != robot.joint_names) {
    fail("the joints are " + joinNames(model.jointNames()) + " in the model, " + joinNames(robot.joint_names) +
         " in the description");
  }
  const arm::JointLimits& limits = robot.limits;
  constexpr double kTolerance = 1e-6;
  for (int j = 0; j < robot.jointCount(); ++j) {
    const std::string joint = "joint " + std::to_string(j + 1) + " ('" + robot.joint_names[j] + "')";
    if (limits.min_position[j] < model.lowerLimits()[j] - kTolerance ||
        limits.max_position[j] > model.upperLimits()[j] + kTolerance) {
      fail(joint + " turns through [" + shortNumber(limits.min_position[j]) + ", " +
           shortNumber(limits.max_position[j]) + "] rad, beyond the model's [" + shortNumber(model.lowerLimits()[j]) +
           ", " + shortNumber(model.upperLimits()[j]) + "]");
    }
    if (limits.max_velocity[j] > model.velocityLimits()[j] + kTolerance) {
      fail(joint + " is allowed " + shortNumber(limits.max_velocity[j]) + " rad/s, the model " +
           shortNumber(model.velocityLimits()[j]));
    }
  }
  std::vector<arm::JointVector> configurations{robot.home};
  for (int k = 1; k <= 8; ++k) {
    arm::JointVector q(robot.jointCount());
    for (int j = 0; j < robot.jointCount(); ++j) {
      const double low = std::max(limits.min_position[j], -std::numbers::pi);
      const double high = std::min(limits.max_position[j], std::numbers::pi);
      const double fraction = std::fmod(0.618034 * k + 0.414214 * j, 1.0);  // spread, not random
      q[j] = low + fraction * (high - low);
    }
    configurations.push_back(q);
  }
  for (const arm::JointVector& q : configurations) {
    const world::Pose described = kinematics.forward(q) * tcp_in_flange;
    const world::Pose modelled = model.forward(q.eigen());
    const double apart = (described.translation() - modelled.translation()).norm();
    const double turned = world::rotationAngle(described, modelled);
    if (apart > 1e-4 || turned > 1e-4) {
      std::string joints;
      for (int j = 0; j < q.size(); ++j) {
        joints += (j == 0 ? "" : ", ") + shortNumber(q[j]);
      }
      char difference[64];
      std::snprintf(difference, sizeof difference, "%.1f mm and %.2f degrees", apart * 1000.0,
                    turned * 180.0 / std::numbers::pi);
      fail("at joints [" + joints + "] rad the tool is " + difference + " apart");
    }
  }
}

/// The gripper's links that may touch a part being grasped, after the robot's, each once.
std::vector<std::string> gripperLinks(const arm::RobotDescription& robot, const GripperModel& gripper) {
  std::vector<std::string> links = robot.gripper_links;
  for (const std::string& link : gripper.links) {
    if (std::find(links.begin(), links.end(), link) == links.end()) {
      links.push_back(link);
    }
  }
  return links;
}

/// How long the executor waits for the host of a remote component when the cell is built.
constexpr std::chrono::seconds kHostWait{5};

/// The components served by hosts: WorkcellOptions::remote (a file) or else the description's
/// `remote`; nullopt when every component runs here. @throws std::invalid_argument naming the
/// file and the field.
std::optional<dds::RemoteConfig> remoteComponents(const WorkcellOptions& options, const SimCellDescription& cell) {
  std::optional<dds::RemoteConfig> remote;
  std::string where;
  if (!options.remote.empty()) {
    where = options.remote.string();
    nlohmann::json json;
    try {
      json = core::readJsonFile(options.remote);
    } catch (const core::JsonSyntaxError& error) {
      throw std::invalid_argument(where + ": " + error.what());
    }
    remote = dds::remoteConfigFromJson(json, where);
  } else if (!cell.remote.is_null()) {
    where = "workcell description '" + cell.file.string() + "': remote";
    remote = dds::remoteConfigFromJson(cell.remote, where);
  } else {
    return std::nullopt;
  }
  const std::vector<std::string>& known = remotableSimComponents();
  for (const std::string& name : remote->components) {
    if (std::find(known.begin(), known.end(), name) == known.end()) {
      throw std::invalid_argument(where + ": components: '" + name + "' of " + cell.name +
                                  " cannot run in a host (gripper and perception can: the others share the cell's "
                                  "planner, world or simulation)");
    }
  }
  remote->lockstep = true;
  return remote;
}

/// The generic simulated workcell: everything comes from the cell's description.
class SimWorkcell final : public Workcell {
 public:
  SimWorkcell(SimCellDescription cell, const WorkcellOptions& options)
      : Workcell(std::make_unique<SimClock>()),
        cell_(std::move(cell)),
        gripper_model_(gripperModel(cell_.gripper)),
        robot_description_(arm::loadRobotDescription(arm::robotDescriptionFile(cell_.robot))),
        scene_(sim::loadScene(options.scene.empty() ? cell_.scene : options.scene)),
        simulation_(sim::Simulation::create(scene_, simOptions(options, robot_description_, cell_))),
        arm_driver_(*simulation_),
        gripper_driver_(*simulation_),
        camera_(*simulation_, options.seed.value_or(scene_.seed)),
        robot_(planningModel(robot_description_, gripper_model_)),
        collisions_(robot_, cell_.robot_base, {.padding = 0.005, .resolution = 0.01},
                    {toEigen(robot_description_.home)}),
        waypoints_(!options.waypoints.empty()
                       ? options.waypoints
                       : (options.memory_only ? cell_.waypoints : defaultWaypointFile(cell_.name)),
                   /*persist=*/!options.memory_only, robot_description_.jointCount()),
        grasps_(dataRoot() / "data/grasps.json",
                options.memory_only ? std::filesystem::path() : defaultGraspFile(cell_.name), gripper_model_.grasps),
        faults_(options.faults) {
    simulation_->attach(static_cast<SimClock&>(clock()));
    // Components served by hosts, in lockstep with this simulation: its clock on rt/clock, the
    // hosts' driver calls answered from it (workcell/remote_sim.h).
    const std::optional<dds::RemoteConfig> remote = remoteComponents(options, cell_);
    if (remote) {
      remote_ = dds::RemoteClient::create(*remote);
      remote_->publishClock(clock().now());
      static_cast<SimClock&>(clock()).addStepListener([this](TimePoint, TimePoint to) {
        remote_->publishClock(to);
        publishRobotState(to);
      });
    }
    const auto served = [&remote](const std::string& name) { return remote && remote->isRemote(name); };
    if (faults_) {
      faults_->attach(clock());
    }
    // The drivers and components as the cell uses them: wrapped by the fault injector, if any.
    arm::ArmDriver& arm_driver = faults_ ? faults_->wrap(arm_driver_) : arm_driver_;
    // The gripper's driver: the 2-finger fingers or the adaptive gripper the simulation drives,
    // either wrapped by the fault injector, if any.
    GripperDrivers gripper_drivers;
    if (gripper_model_.adaptive.empty()) {
      gripper_drivers.parallel = faults_ ? &faults_->wrap(gripper_driver_) : &gripper_driver_;
    } else {
      gripper::AdaptiveGripperDriver* adaptive = simulation_->adaptiveGripper();
      gripper_drivers.adaptive = faults_ && adaptive != nullptr ? &faults_->wrap(*adaptive) : adaptive;
    }
    // The fingers as the cell reads them: the 2-finger's through the fault injector, the
    // adaptive gripper's from the simulation.
    finger_drivers_ = {gripper_drivers.parallel, simulation_->adaptiveGripper()};
    camera::RgbdCamera* taken = faults_ ? &faults_->wrap(camera_) : &camera_;
    if (remote_) {
      // With components on the domain, its frames go there as ROS 2 images too.
      published_camera_ = imagePublishingCamera(*taken, *remote_, "camera_optical_frame");
      taken = published_camera_.get();
    }
    camera::RgbdCamera& camera = *taken;
    const auto add = [this](std::shared_ptr<component::Component> component) {
      components().add(faults_ ? faults_->wrap(std::move(component)) : std::move(component));
    };
    collisions_.setBox("table", world::Pose(Eigen::Translation3d(cell_.table_centre)), cell_.table_size);
    collisions_.allow(robot_description_.base_link, "table");  // the robot stands on it
    // The tool stays above the table top, within the cell.
    collisions_.setWorkspace(cell_.workspace);

    arm::ArmConfig arm_config;
    arm_config.type = robot_description_.type;
    arm_config.base_in_world = cell_.robot_base;
    arm_config.home = robot_description_.home;
    arm_config.tcp_in_flange = gripper_model_.tcp_in_flange;
    // The gripper's body is mounted on the flange link (planning::mountUrdf); its fingers are its
    // own links. The description's gripper_links add the wrist (SmartMove lets them touch the part
    // grasped), which free-drive must keep a whole look-ahead off the table.
    arm_config.gripper_links = {robot_description_.urdf_tool_link};
    for (const std::string& link : gripper_model_.links) {
      arm_config.gripper_links.push_back(link);
    }
    arm_config.joint_names = robot_description_.joint_names;
    arm_config.joint_labels = robot_description_.joint_labels;
    const std::shared_ptr<const arm::Kinematics> kinematics = arm::makeKinematics(robot_description_);
    checkDescriptionMatchesModel(robot_description_, *kinematics, arm_config.tcp_in_flange, robot_);
    auto arm = std::make_shared<arm::ArmComponent>(
        arm_driver, clock(), collisions_, waypoints_,
        [this](const std::string& frame) { return components().world().worldPose(frame); }, kinematics, arm_config,
        arm::ForceControl{&simulation_->forceTorqueSensor(), &simulation_->cartesianController(),
                          simulation_->toolPayload()});
    // The cell's motion service: what SmartMove asks (IK, collisions, plans); it moves the arm
    // through the arm's operations.
    motion_ = std::make_unique<arm::MotionPlanner>(arm_driver, clock(), collisions_, kinematics, arm_config);
    // SmartMove reaches the gripper through its operations, as the tree does: the same (possibly
    // fault-injected) component the registry holds.
    std::shared_ptr<component::Component> gripper;
    if (served("gripper")) {
      gripper = remote_->connect("gripper", kHostWait);
    } else {
      gripper = gripper_model_.make_component(gripper_drivers, clock());
    }
    if (faults_) {
      gripper = faults_->wrap(std::move(gripper));
    }
    add(arm);
    components().add(gripper);
    // HandEyeCalibration: the camera's pose comes from it (the drawings until calibrated); it
    // moves the arm as SmartMove does.
    calibration_ = makeCalibration(options, *arm, arm_config.tcp_in_flange, camera);
    add(calibration_);
    if (remote_) {
      // Readings are answered ahead with the calls that ask them (dds::DriverReading), except
      // under an injected fault: a faulty driver's reading records when the fault took effect.
      remote_->setDriverServer(
          simDriverServer(gripper_drivers.parallel, gripper_drivers.adaptive, camera,
                          [calibration = calibration_.get()] { return calibration->cameraPose(); }),
          faults_ ? std::vector<dds::DriverReading>{} : simDriverReadings());
    }
    add(std::make_shared<FixedFrames>(std::vector<std::pair<std::string, world::Pose>>{
        {"table_center", tableCenter()}, {"robot_base", cell_.robot_base}}));
    // In every simulated cell, so that a plan for a person beside the arm validates in any: its
    // readings and Collaborate need a person in the scene.
    add(std::make_shared<SeparationMonitor>(*simulation_));
    // The power tool on its driver (the simulator's); its shape is an object class SmartGrasp
    // picks it up by. The stand and the workpiece are obstacles the planner knows.
    std::vector<world::ObjectClass> classes = simulation_->objectClasses();
    if (sim::SimPowerTool* tool = simulation_->powerTool(); tool != nullptr && tool->setup()) {
      const sim::PowerToolSetup& setup = *tool->setup();
      tool::PowerToolOptions tool_options;
      tool_options.docked_pose = setup.dockedPose();
      add(std::make_shared<tool::PowerTool>(*tool, clock(), setup.tool, tool_options));
      classes.push_back(setup.tool.objectClass());
      if (scene_.power_tool) {
        collisions_.setBox("tool_stand", setup.stand * Eigen::Translation3d(0, 0, setup.tool.stand_size.z() / 2),
                           setup.tool.stand_size);
      }
    }
    if (scene_.workpiece) {
      collisions_.setBox(
          "workpiece",
          sim::workpieceTop(*scene_.workpiece) * Eigen::Translation3d(0, 0, -scene_.workpiece->size.z() / 2),
          scene_.workpiece->size);
    }
    if (options.test_oracle_perception) {
      add(std::make_shared<testing::OraclePerception>([simulation = simulation_.get()] {
        std::vector<testing::TruePart> parts;
        for (const sim::PartState& part : simulation->parts()) {
          parts.push_back({part.name, part.object_class, part.pose});
        }
        return parts;
      }));
    } else {
      // DetectObjects: the camera's frames only, never the simulator's true poses.
      perception::PerceptionConfig perception_config;
      perception_config.table_center = tableCenter();
      if (!cell_.perception_model.empty()) {
        perception_config.files.svm_file = cell_.perception_model;
      }
      perception_config.camera_pose = [calibration = calibration_.get()] { return calibration->cameraPose(); };
      if (served("perception")) {
        add(remote_->connect("perception", kHostWait));
      } else {
        add(std::make_shared<perception::PerceptionComponent>(camera, clock(), threadPipeline(perception_config),
                                                              perception_config));
      }
      // The person's hand as the camera sees it (hand_1, gesture(hand_1, offer), in_zone); in a
      // scene without a person it takes no frames (nothing there is skin-coloured) and reports no hand.
      perception::HandComponentConfig hand_config;
      hand_config.detector.table_center = tableCenter();
      hand_config.camera_pose = perception_config.camera_pose;
      hand_config.watch = scene_.person.has_value();
      add(std::make_shared<perception::HandComponent>(camera, clock(), hand_config));
    }
    smartmove::SmartMoveConfig smartmove_config;
    smartmove_config.gripper_links = gripperLinks(robot_description_, gripper_model_);
    smartmove_config.gripper = gripper_model_.geometry;
    smartmove_config.finger_link = gripper_model_.finger_link;
    smartmove_ = std::make_shared<smartmove::SmartMoveComponent>(*motion_, *arm, *gripper, components().world(),
                                                                 collisions_, classes, grasps_, smartmove_config);
    add(smartmove_);
    // Last: it derives its predicates from what the others report.
    add(std::make_shared<predicator::Predicator>(components().world(), classes));
    if (faults_) {
      faults_->checkTargets();
    }
    // The safety stop (a component failed, a driver's readings cannot be trusted): the arm
    // decelerates along its path and stops; the fingers keep their last command.
    components().setOnStop([arm](const std::string&) { arm->stop(); });
    smartmove_->setPatternCheck([this](const predicator::Pattern& pattern) { return checkPattern(pattern); });
    registerNodes();
    smartmove_->syncObstacles();
    syncFingers();
  }

  void beforeTick() override {
    Workcell::beforeTick();
    smartmove_->syncObstacles();
    syncFingers();
  }

  /// The fingers' collision shapes as the gripper reads them (as the cell sees it, faults
  /// included), set when they moved: the cell's model of where they are, which every motion
  /// query starts from (SmartMove's say where a motion will have them).
  void syncFingers() {
    const std::optional<gripper::FingerStance> stance = gripper_model_.read_stance(finger_drivers_);
    if (!stance || (synced_stance_ && sameStance(*synced_stance_, *stance))) {
      return;
    }
    if (const auto boxes = gripper_model_.geometry->fingerBoxes(*stance)) {
      collisions_.setLinkShapes(gripper_model_.finger_link, smartmove::fingerShapes(*boxes));
    }
    synced_stance_ = stance;
  }

  /// Stances the fingers' shapes need not be set again for: the same mode and position, an
  /// opening within 0.1 mm.
  static bool sameStance(const gripper::FingerStance& a, const gripper::FingerStance& b) {
    const bool same_opening =
        a.opening.has_value() == b.opening.has_value() && (!a.opening || std::abs(*a.opening - *b.opening) <= 1e-4);
    return same_opening && a.mode == b.mode && a.position == b.position;
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

  nlohmann::json robotDrawing() const override {
    const auto text = [](const std::filesystem::path& file) {
      std::ifstream in(file);
      if (!in) {
        throw std::runtime_error("cannot read '" + file.string() + "'");
      }
      return std::string(std::istreambuf_iterator<char>(in), {});
    };
    const std::filesystem::path gripper_urdf = dataRoot() / gripper_model_.urdf;
    nlohmann::json joints = nlohmann::json::array();
    for (int j = 0; j < robot_description_.jointCount(); ++j) {
      joints.push_back(
          {{"name", robot_description_.joint_names[j]},
           {"label", j < static_cast<int>(robot_description_.joint_labels.size()) ? robot_description_.joint_labels[j]
                                                                                  : std::string()},
           {"lower", robot_description_.limits.min_position[j]},
           {"upper", robot_description_.limits.max_position[j]}});
    }
    // The fingers are drawn from the gripper's reading where the page knows how (in place of the
    // finger link's shapes); a gripper whose fingers are not modelled keeps its URDF shapes.
    nlohmann::json gripper = {
        {"key", gripper_model_.key}, {"grasps", gripper_model_.grasps}, {"finger_links", nlohmann::json::array()}};
    if (!gripper_model_.adaptive.empty()) {
      gripper["kind"] = "adaptive";
      std::ifstream in(gripper::gripperDescriptionFile(gripper_model_.adaptive));
      gripper["description"] = nlohmann::json::parse(in);
      gripper["finger_links"].push_back(gripper_model_.finger_link);
    } else {
      gripper["kind"] = "parallel";
      gripper::FingerStance closed;
      closed.opening = 0.0;
      const auto stroke = gripper_model_.geometry->stroke();
      const auto boxes = gripper_model_.geometry->fingerBoxes(closed);
      if (stroke && boxes) {
        gripper["max_opening"] = *stroke;
        nlohmann::json finger = nlohmann::json::array();  // the +y finger closed; the other mirrors it
        for (const gripper::OrientedBox& box : *boxes) {
          const Eigen::Vector3d c = box.pose.translation();
          if (c.y() > 0.0) {
            finger.push_back({{"centre", {c.x(), c.y(), c.z()}}, {"size", {box.size.x(), box.size.y(), box.size.z()}}});
          }
        }
        gripper["finger_boxes"] = std::move(finger);
        gripper["finger_links"].push_back(gripper_model_.finger_link);
      }
    }
    // What the scene fixes on the table beside the parts (the workpiece with its marked area,
    // the power tool's stand): boxes the page draws where the planner avoids them.
    nlohmann::json fixtures = nlohmann::json::array();
    const auto fixture = [&fixtures](const std::string& name, const world::Pose& pose, const Eigen::Vector3d& size,
                                     const Eigen::Vector3d& rgb) {
      const Eigen::Quaterniond turn(pose.linear());
      const Eigen::Vector3d& at = pose.translation();
      fixtures.push_back({{"name", name},
                          {"p", {at.x(), at.y(), at.z()}},
                          {"q", {turn.x(), turn.y(), turn.z(), turn.w()}},
                          {"size", {size.x(), size.y(), size.z()}},
                          {"rgb", {rgb.x(), rgb.y(), rgb.z()}}});
    };
    if (scene_.workpiece) {
      const world::Pose top = sim::workpieceTop(*scene_.workpiece);
      const Eigen::Vector3d& size = scene_.workpiece->size;
      fixture("workpiece", top * Eigen::Translation3d(0, 0, -size.z() / 2), size, {0.72, 0.56, 0.36});
      const Eigen::Vector2d& marked = scene_.workpiece->marked;
      fixture("marked area", top * Eigen::Translation3d(0, 0, 0.0005), {marked.x(), marked.y(), 0.001},
              {0.3, 0.55, 0.85});
    }
    if (const sim::SimPowerTool* tool = simulation_->powerTool();
        tool != nullptr && tool->setup() && scene_.power_tool) {
      const sim::PowerToolSetup& setup = *tool->setup();
      fixture("tool stand", setup.stand * Eigen::Translation3d(0, 0, setup.tool.stand_size.z() / 2),
              setup.tool.stand_size, {0.45, 0.47, 0.5});
    }
    // The power tool's shape (its object class's boxes, in the tool frame) and where it sits in
    // the hand: the tool frame in the tool centre point's, from the grasp SmartGrasp picks it up
    // by. The page draws it at the tool centre point while the tool reads held.
    nlohmann::json power_tool;
    if (const sim::SimPowerTool* tool = simulation_->powerTool(); tool != nullptr && tool->setup()) {
      const world::ObjectClass shape = tool->setup()->tool.objectClass();
      if (const std::optional<smartmove::Grasp> grasp = grasps_.defaultFor(shape.name)) {
        nlohmann::json boxes = nlohmann::json::array();
        for (const world::Box& box : shape.boxes) {
          boxes.push_back({{"centre", {box.center.x(), box.center.y(), box.center.z()}},
                           {"size", {2 * box.half_size.x(), 2 * box.half_size.y(), 2 * box.half_size.z()}}});
        }
        const world::Pose held = grasp->tcp_in_object.inverse();
        const Eigen::Quaterniond turn(held.linear());
        const Eigen::Vector3d& at = held.translation();
        const Eigen::Vector3d rgb =
            shape.colors.empty() ? Eigen::Vector3d(0.9, 0.45, 0.1) : shape.colors.front().second;
        power_tool = {
            {"name", shape.name},
            {"label", shape.description},
            {"boxes", std::move(boxes)},
            {"rgb", {rgb.x(), rgb.y(), rgb.z()}},
            {"grasp", grasp->name},
            {"held_in_tcp", {{"p", {at.x(), at.y(), at.z()}}, {"q", {turn.x(), turn.y(), turn.z(), turn.w()}}}}};
      }
    }
    const Eigen::Quaterniond q(cell_.robot_base.linear());
    const Eigen::Vector3d& p = cell_.robot_base.translation();
    nlohmann::json drawing = {
        {"fixtures", std::move(fixtures)},
        {"urdf",
         planning::mountUrdf(text(robot_description_.urdf), text(gripper_urdf), robot_description_.urdf_tool_link,
                             robot_description_.urdf.string() + "' + '" + gripper_urdf.string())},
        {"name", robot_description_.name},
        {"label", robot_description_.label},
        {"base_link", robot_description_.urdf_base_link},
        {"flange_link", robot_description_.urdf_tool_link},
        {"tcp_link", gripper_model_.tcp_link},
        {"base_in_world", {{"p", {p.x(), p.y(), p.z()}}, {"q", {q.x(), q.y(), q.z(), q.w()}}}},
        {"joints", std::move(joints)},
        {"gripper", std::move(gripper)},
        {"table",
         {{"centre", {cell_.table_centre.x(), cell_.table_centre.y(), cell_.table_centre.z()}},
          {"size", {cell_.table_size.x(), cell_.table_size.y(), cell_.table_size.z()}}}}};
    if (!power_tool.is_null()) {
      drawing["power_tool"] = std::move(power_tool);
    }
    return drawing;
  }

  /// The arm's joints and the wrist's wrench as ROS 2 types, for ROS 2 tools on the domain
  /// (the simulator's readings, read without side effects).
  void publishRobotState(TimePoint now) {
    dds::JointStateSample joints;
    joints.stamp = now;
    joints.names = robot_description_.joint_names;
    const sim::ArmJoints position = simulation_->armPositions();
    const sim::ArmJoints velocity = simulation_->armVelocities();
    for (int j = 0; j < position.size(); ++j) {
      joints.position.push_back(position[j]);
      joints.velocity.push_back(velocity[j]);
    }
    remote_->publishJointState(joints);
    const arm::ForceTorqueReading reading = simulation_->forceTorqueSensor().read();
    dds::WrenchSample wrench;
    wrench.stamp = now;
    wrench.frame_id = robot_description_.urdf_tool_link;
    wrench.force = {reading.wrench.force.x(), reading.wrench.force.y(), reading.wrench.force.z()};
    wrench.torque = {reading.wrench.torque.x(), reading.wrench.torque.y(), reading.wrench.torque.z()};
    remote_->publishWrench(wrench);
  }

  std::string name() const override { return cell_.name; }
  std::string description() const override { return cell_.label + ", scene '" + scene_.label + "'"; }
  sim::Simulation* simulation() override { return simulation_.get(); }
  const arm::MotionService* motion() const override { return motion_.get(); }

 private:
  static sim::SimulationOptions simOptions(const WorkcellOptions& options, const arm::RobotDescription& robot,
                                           const SimCellDescription& cell) {
    sim::SimulationOptions sim_options = cellSimulation(cell).options;
    sim_options.robot = robot;
    sim_options.placement_seed = options.seed;
    sim_options.spare_classes = options.spare_parts;
    if (options.camera_move) {
      sim::CameraOffset offset;
      offset.random = true;
      offset.distance = options.camera_move->distance;
      offset.angle_deg = options.camera_move->angle_deg;
      offset.seed = options.camera_move->seed;
      sim_options.camera_offset = sim::cameraOffsetPose(offset, options.seed.value_or(1));
    }
    return sim_options;
  }

  /// The calibration component with the cell's saved calibration (the marker's shipped one
  /// when none was saved).
  std::shared_ptr<calibration::CalibrationComponent> makeCalibration(const WorkcellOptions& options,
                                                                     component::Component& arm,
                                                                     const world::Pose& tcp_in_flange,
                                                                     camera::RgbdCamera& camera) {
    const std::filesystem::path file =
        !options.calibration.empty()
            ? options.calibration
            : (options.memory_only ? std::filesystem::path() : defaultCalibrationFile(cell_.name));
    calibration::CellCalibration initial = calibration::loadCalibration(file).value_or(calibration::CellCalibration{});
    // The shipped marker calibration must be one, whether or not a saved one replaces it.
    const auto shipped = calibration::loadCalibration(cell_.calibration);
    if (!shipped || !shipped->marker_in_flange) {
      throw std::runtime_error("workcell description '" + cell_.file.string() + "': calibration: '" +
                               cell_.calibration.string() +
                               "' holds no marker calibration (\"marker\": {\"marker_in_flange\": ...}, as `costar "
                               "calibrate marker` writes)");
    }
    if (!initial.marker_in_flange) {
      initial.marker_in_flange = shipped->marker_in_flange;
      initial.marker_method = shipped->marker_method;
      initial.marker_residuals = shipped->marker_residuals;
      initial.marker_views = shipped->marker_views;
    }
    calibration::CalibrationConfig config;
    config.file = options.memory_only ? std::filesystem::path() : file;
    config.seed = options.seed.value_or(scene_.seed);
    // The drawings of the gripper.
    config.marker_in_flange_guess = gripper_model_.marker_in_flange_guess;
    config.tcp_in_flange = tcp_in_flange;
    config.solve.marker_size = sim::Simulation::kGripperMarkerSize;
    config.marker_id = sim::Simulation::kGripperMarkerId;
    config.keep_out = cell_.part_area;
    return std::make_shared<calibration::CalibrationComponent>(
        *motion_, arm, camera, clock(), simulation_->rgbdNominalPose(), std::move(initial), config);
  }
  static Eigen::VectorXd toEigen(const sim::ArmJoints& q) { return q.eigen(); }

  SimCellDescription cell_;
  const GripperModel& gripper_model_;
  arm::RobotDescription robot_description_;
  sim::Scene scene_;
  std::unique_ptr<sim::Simulation> simulation_;
  sim::SimArmDriver arm_driver_;
  sim::SimGripperDriver gripper_driver_;
  GripperDrivers finger_drivers_;                       // what the cell reads the fingers from
  std::optional<gripper::FingerStance> synced_stance_;  // the fingers' stance in the collision world
  sim::SimRgbdCamera camera_;
  planning::RobotModel robot_;
  planning::CollisionWorld collisions_;
  arm::WaypointStore waypoints_;
  smartmove::GraspLibrary grasps_;
  std::unique_ptr<arm::MotionPlanner> motion_;
  std::shared_ptr<smartmove::SmartMoveComponent> smartmove_;
  std::shared_ptr<calibration::CalibrationComponent> calibration_;
  std::shared_ptr<faults::Injector> faults_;
  std::shared_ptr<dds::RemoteClient> remote_;             // the hosts of remote components, or null
  std::unique_ptr<camera::RgbdCamera> published_camera_;  // with remote_: the camera, its frames published
};

}  // namespace

std::unique_ptr<Workcell> makeSimWorkcell(const SimCellDescription& cell, const WorkcellOptions& options) {
  return std::make_unique<SimWorkcell>(cell, options);
}

}  // namespace costar::workcell
