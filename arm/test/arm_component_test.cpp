// The Arm component against an ideal driver (it follows trajectories exactly): what it plans,
// what it refuses and why, cancelling, teaching, waypoints and predicates.

#include "arm/arm_component.h"
#include "arm/robot_description.h"
#include "arm/ur5_kinematics.h"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <functional>

#include "arm/test/published_arms.h"
#include "component/registry.h"
#include "core/paths.h"

namespace costar::arm {
namespace {

using component::OperationResult;
using component::OperationState;

/// Follows the trajectory exactly; records every trajectory it is given.
class IdealDriver final : public ArmDriver {
 public:
  IdealDriver(const SimClock& clock, JointVector start) : clock_(clock), hold_(start) {}
  ArmState read() const override {
    if (!trajectory_) {
      return {hold_, {}};
    }
    const TrajectoryPoint point = trajectory_->sample(clock_.now() - start_ - held_back);
    return {point.position, point.velocity};
  }
  void execute(std::shared_ptr<const JointTrajectory> trajectory, TimePoint start) override {
    trajectory_ = std::move(trajectory);
    start_ = start;
    held_back = Duration::zero();
    executed.push_back(trajectory_);
  }
  Duration heldBack() const override { return held_back; }
  std::vector<std::shared_ptr<const JointTrajectory>> executed;
  /// A speed override holding the trajectory back (a person near the arm), as a controller reports it.
  Duration held_back = Duration::zero();

 private:
  const SimClock& clock_;
  JointVector hold_;
  std::shared_ptr<const JointTrajectory> trajectory_;
  TimePoint start_{};
};

const JointVector kHome = {0.0, -2.3, 1.9, -M_PI / 2 + 0.4, -M_PI / 2, 0.0};
const world::Pose kBase(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()));

/// A TCP pose in the world, pointing straight down.
world::Pose toolDown(double x, double y, double z, double yaw = 0.0) {
  return world::poseFromXyzRpy(x, y, z, M_PI, 0, yaw);
}

class ArmTest : public ::testing::Test {
 protected:
  /// `waypoint_file`: where the arm's waypoints are kept (none: in memory).
  explicit ArmTest(std::filesystem::path waypoint_file = {})
      : waypoints(std::move(waypoint_file), /*persist=*/true, 6),
        robot(planning::RobotModel::fromUrdf(arm::loadRobotDescription(arm::robotDescriptionFile("ur5")).urdf,
                                             std::filesystem::path(COSTAR_GRIPPER_MODEL_DIR) / "parallel-2f.urdf",
                                             "tool0", "base_link", "tcp")),
        collisions(robot, kBase, {.padding = 0.005}, {kHome.eigen()}),
        driver(clock, kHome),
        arm(
            driver, clock, collisions, waypoints, [this](const std::string& frame) { return frame_lookup(frame); },
            std::make_shared<Ur5Kinematics>(published::ur5Dh(), published::ur5Limits()), config()) {
    collisions.setBox("table", world::Pose(Eigen::Translation3d(0.4, 0, -0.02)), {1.4, 1.2, 0.04});
    collisions.allow("base_link", "table");
  }

  static ArmConfig config() {
    ArmConfig c;
    c.base_in_world = kBase;
    c.home = kHome;
    c.tcp_in_flange = world::Pose(Eigen::Translation3d(0, 0, 0.14));
    return c;
  }

  std::optional<world::Pose> frame_lookup(const std::string& frame) {
    if (frame == "table_center") {
      return world::Pose(Eigen::Translation3d(0.5, 0, 0));
    }
    return std::nullopt;
  }

  OperationResult run(const std::string& operation, component::ParamMap params = {}) {
    for (const auto& spec : arm.description().operation(operation)->params) {
      if (spec.default_value) {
        params.try_emplace(spec.name, *spec.default_value);
      }
    }
    const auto id = arm.start(operation, params);
    for (int tick = 0; tick < 3000; ++tick) {
      const OperationResult result = arm.poll(id);
      if (result.state != OperationState::kRunning) {
        return result;
      }
      clock.advanceBy(std::chrono::milliseconds(10));
    }
    return OperationResult::failure("test: did not finish");
  }

  bool holds(const std::string& predicate, std::vector<std::string> args = {}) {
    world::WorldState state;
    state.update("arm", arm.report());
    return state.holds(predicate, args);
  }

  SimClock clock;
  WaypointStore waypoints;
  planning::RobotModel robot;
  planning::CollisionWorld collisions;
  IdealDriver driver;
  ArmComponent arm;
};

TEST_F(ArmTest, ImplementsTheAbstractArmAndReportsItsEndpoint) {
  component::ComponentRegistry registry;
  EXPECT_NO_THROW(registry.add(std::shared_ptr<component::Component>(&arm, [](auto*) {})));
  world::WorldState state;
  state.update("arm", arm.report());
  ASSERT_NE(state.symbol("endpoint"), nullptr);
  EXPECT_LT((state.symbol("endpoint")->frame()->pose.translation() - Eigen::Vector3d(0.1728, 0.1092, 0.3365)).norm(),
            1e-3);
  EXPECT_FALSE(holds("arm_moving"));
}

TEST_F(ArmTest, MovesToATaughtPoseWaypointWithinTheLimitsAndSaysWhereItIs) {
  waypoints.put({"above_part", Waypoint::Kind::kPose, {}, toolDown(0.5, -0.2, 0.15), "world"});
  const OperationResult result = run("Move", {{"waypoint", "above_part"}, {"speed", 0.5}});
  ASSERT_EQ(result.state, OperationState::kSuccess) << result.reason;
  EXPECT_TRUE(arm.endpoint().isApprox(toolDown(0.5, -0.2, 0.15), 1e-6));
  EXPECT_TRUE(holds("at_waypoint", {"above_part"}));
  ASSERT_EQ(driver.executed.size(), 1u);
  EXPECT_NO_THROW(driver.executed[0]->validate(published::ur5Limits()));
  // Moving took time on the clock, within the speed-scaled limits.
  EXPECT_GT(toSeconds(driver.executed[0]->duration()), 0.5);
}

TEST_F(ArmTest, WaypointsRelativeToAFrameFollowTheFrame) {
  waypoints.put({"over_center", Waypoint::Kind::kPose, {}, toolDown(0.0, 0.0, 0.2), "table_center"});
  ASSERT_EQ(run("Move", {{"waypoint", "over_center"}}).state, OperationState::kSuccess);
  EXPECT_TRUE(arm.endpoint().translation().isApprox(Eigen::Vector3d(0.5, 0, 0.2), 1e-6));
  waypoints.put({"on_the_moon", Waypoint::Kind::kPose, {}, toolDown(0, 0, 0.2), "moon"});
  EXPECT_EQ(run("Move", {{"waypoint", "on_the_moon"}}).reason,
            "waypoint 'on_the_moon' is relative to 'moon', which is not known now");
}

TEST_F(ArmTest, UnknownUnreachableAndCollidingGoalsFailWithAReason) {
  EXPECT_EQ(run("Move", {{"waypoint", "nowhere"}}).reason, "unknown waypoint 'nowhere' (none taught yet)");
  waypoints.put({"far", Waypoint::Kind::kPose, {}, toolDown(1.5, 0, 0.2), "world"});
  EXPECT_EQ(run("Move", {{"waypoint", "far"}}).reason,
            "Move to 'far': the pose is out of reach (no inverse kinematics solution within the joint limits)");
  waypoints.put({"in_table", Waypoint::Kind::kPose, {}, toolDown(0.5, 0, -0.05), "world"});
  const OperationResult in_table = run("Move", {{"waypoint", "in_table"}});
  EXPECT_EQ(in_table.state, OperationState::kFailure);
  EXPECT_NE(in_table.reason.find("would touch table"), std::string::npos) << in_table.reason;
  EXPECT_TRUE(driver.executed.empty());  // nothing moved
}

TEST_F(ArmTest, ABlockedStraightMotionIsPlannedAroundTheObstacle) {
  const JointVector left = {1.2, -2.0, 2.0, -M_PI / 2, -M_PI / 2, 0.0};
  const JointVector right = {-1.2, -2.0, 2.0, -M_PI / 2, -M_PI / 2, 0.0};
  waypoints.put({"left", Waypoint::Kind::kJoints, left, {}, "world"});
  waypoints.put({"right", Waypoint::Kind::kJoints, right, {}, "world"});
  ASSERT_EQ(run("Move", {{"waypoint", "left"}}).state, OperationState::kSuccess);
  collisions.setBox("post", world::Pose(Eigen::Translation3d(0.31, 0.11, 0.12)), {0.04, 0.04, 0.24});
  const OperationResult result = run("Move", {{"waypoint", "right"}});
  ASSERT_EQ(result.state, OperationState::kSuccess) << result.reason;
  EXPECT_TRUE(holds("at_waypoint", {"right"}));
  // The executed motion never touched the post: sample it finely.
  const auto& trajectory = *driver.executed.back();
  for (Duration t{}; t <= trajectory.duration(); t += std::chrono::milliseconds(5)) {
    const JointVector q = trajectory.sample(t).position;
    EXPECT_FALSE(collisions.check(q.eigen()).has_value());
  }
}

TEST_F(ArmTest, MoveRelativeFollowsAStraightLine) {
  waypoints.put({"start", Waypoint::Kind::kPose, {}, toolDown(0.45, 0.1, 0.1), "world"});
  ASSERT_EQ(run("Move", {{"waypoint", "start"}}).state, OperationState::kSuccess);
  const OperationResult result =
      run("MoveRelative", {{"offset", *component::parseValue(component::ValueType::kPose, "0;0;0.15")}});
  ASSERT_EQ(result.state, OperationState::kSuccess) << result.reason;
  EXPECT_TRUE(arm.endpoint().isApprox(toolDown(0.45, 0.1, 0.25), 1e-6));
  // Every sample of the motion is on the vertical line through the start.
  const auto& trajectory = *driver.executed.back();
  Ur5Kinematics kinematics(published::ur5Dh(), published::ur5Limits());
  for (Duration t{}; t <= trajectory.duration(); t += std::chrono::milliseconds(10)) {
    const world::Pose tcp = kBase * kinematics.forward(trajectory.sample(t).position) * config().tcp_in_flange;
    EXPECT_LT((tcp.translation().head<2>() - Eigen::Vector2d(0.45, 0.1)).norm(), 1e-3);
  }
  const OperationResult into_table =
      run("MoveRelative", {{"offset", *component::parseValue(component::ValueType::kPose, "0;0;-0.3")}});
  EXPECT_NE(into_table.reason.find("the straight line is blocked"), std::string::npos) << into_table.reason;
}

TEST_F(ArmTest, CancellingDeceleratesAlongThePathAndStops) {
  const auto id = arm.start("Home", {{"speed", 1.0}});
  waypoints.put({"far_side", Waypoint::Kind::kJoints, {2.5, -2.0, 2.0, -M_PI / 2, -M_PI / 2, 0.0}, {}, "world"});
  const auto move = arm.start("Move", {{"waypoint", "far_side"}, {"speed", 1.0}});
  EXPECT_EQ(arm.poll(id).state, OperationState::kFailure);  // the second motion took over
  clock.advanceBy(std::chrono::milliseconds(500));
  EXPECT_TRUE(holds("arm_moving"));
  arm.cancel(move);
  ASSERT_EQ(driver.executed.size(), 3u);
  const auto& stop = *driver.executed.back();
  EXPECT_LT(toSeconds(stop.duration()), 1.0);
  clock.advanceBy(stop.duration() + std::chrono::milliseconds(10));
  EXPECT_FALSE(holds("arm_moving"));
}

TEST_F(ArmTest, AMotionHeldBackByTheControllersSpeedOverrideWaitsForItAndStopsWhereTheArmIs) {
  waypoints.put({"far_side", Waypoint::Kind::kJoints, {2.5, -2.0, 2.0, -M_PI / 2, -M_PI / 2, 0.0}, {}, "world"});
  const auto move = arm.start("Move", {{"waypoint", "far_side"}, {"speed", 1.0}});
  const Duration nominal = driver.executed.back()->duration();
  // The override held the arm back by as long as the motion takes and more than settle_time:
  // the motion waits instead of failing as if the arm were blocked.
  driver.held_back = nominal + config().settle_time + std::chrono::seconds(1);
  clock.advanceBy(nominal + config().settle_time + std::chrono::milliseconds(500));
  EXPECT_EQ(arm.poll(move).state, OperationState::kRunning);
  // Cancelled there, the arm stops from where the controller is along the path (not from where
  // the clock alone would put it: the end).
  const JointVector here = driver.read().position;
  arm.cancel(move);
  const auto& stop = *driver.executed.back();
  EXPECT_LT((stop.initialPosition().eigen() - here.eigen()).norm(), 1e-9);
  // Released, a motion arrives and succeeds.
  const auto again = arm.start("Move", {{"waypoint", "far_side"}, {"speed", 1.0}});
  clock.advanceBy(driver.executed.back()->duration() + std::chrono::milliseconds(10));
  EXPECT_EQ(arm.poll(again).state, OperationState::kSuccess);
}

TEST_F(ArmTest, TeachSavesWhereTheArmIsAndJoggingMovesIt) {
  ASSERT_EQ(run("JogJoint", {{"joint", 1}, {"degrees", 20.0}}).state, OperationState::kSuccess);
  EXPECT_NEAR(driver.read().position[0], 20.0 * M_PI / 180.0, 1e-9);
  ASSERT_EQ(run("Teach", {{"waypoint", "taught"}, {"kind", "pose"}, {"frame", "table_center"}}).state,
            OperationState::kSuccess);
  ASSERT_EQ(run("Teach", {{"waypoint", "taught_joints"}, {"kind", "joints"}, {"frame", "world"}}).state,
            OperationState::kSuccess);
  EXPECT_TRUE(holds("at_waypoint", {"taught"}));
  EXPECT_TRUE(holds("at_waypoint", {"taught_joints"}));
  ASSERT_EQ(run("JogCartesian", {{"axis", "z"}, {"amount", 0.05}, {"frame", "world"}}).state, OperationState::kSuccess);
  EXPECT_FALSE(holds("at_waypoint", {"taught"}));
  ASSERT_EQ(run("Move", {{"waypoint", "taught"}}).state, OperationState::kSuccess);
  EXPECT_TRUE(holds("at_waypoint", {"taught"}));
  ASSERT_EQ(run("RenameWaypoint", {{"waypoint", "taught"}, {"new_name", "renamed"}}).state, OperationState::kSuccess);
  EXPECT_TRUE(holds("at_waypoint", {"renamed"}));
  EXPECT_EQ(run("DeleteWaypoint", {{"waypoint", "taught"}}).reason, "unknown waypoint 'taught'");
  ASSERT_EQ(run("DeleteWaypoint", {{"waypoint", "renamed"}}).state, OperationState::kSuccess);
  EXPECT_FALSE(waypoints.find("renamed").has_value());
  EXPECT_EQ(run("Teach", {{"waypoint", "bad name!"}, {"kind", "pose"}, {"frame", "world"}}).reason,
            "cannot save the waypoint: waypoint name 'bad name!' may contain only letters, digits, '_' and '-'");
}

// JogCartesian's amount is metres along x/y/z and degrees about roll/pitch/yaw: its one range
// [-90, 90] let a plan ask for a 90 m jog, refused only when it ran (a hostile tester).
TEST_F(ArmTest, AJogOfMoreThanTwentyCentimetresIsRefusedWhenThePlanIsValidated) {
  const component::OperationSpec* jog = arm.description().operation("JogCartesian");
  ASSERT_NE(jog, nullptr);
  const auto problem = [jog](const std::string& axis, double amount) {
    return jog->checkParams({{"axis", component::Value(axis)}, {"amount", component::Value(amount)}});
  };
  EXPECT_EQ(problem("x", 90.0), "amount 90 along x: JogCartesian moves at most 0.2 m at a time");
  EXPECT_EQ(problem("z", -0.25), "amount -0.25 along z: JogCartesian moves at most 0.2 m at a time");
  EXPECT_EQ(problem("z", 0.2), "");
  EXPECT_EQ(problem("yaw", 90.0), "");
}

// A waypoint named "endpoint" hid the arm's tool pose from the editor (it showed the taught pose
// while the arm moved) and could be neither moved to nor deleted there; "camera" and
// "table_center" were listed twice.
TEST_F(ArmTest, AWaypointCannotTakeTheNameOfASymbolOrFrameTheCellKnows) {
  EXPECT_EQ(run("Teach", {{"waypoint", "endpoint"}, {"kind", "pose"}, {"frame", "world"}}).reason,
            "cannot save the waypoint: 'endpoint' is the arm's own symbol (the tool centre point, in the world); "
            "choose another name");
  EXPECT_EQ(run("Teach", {{"waypoint", "table_center"}, {"kind", "joints"}, {"frame", "world"}}).reason,
            "cannot save the waypoint: 'table_center' names a frame the cell knows already (a calibrated frame or a "
            "part); choose another name");
  EXPECT_EQ(run("Teach", {{"waypoint", "world"}, {"kind", "pose"}, {"frame", "world"}}).reason,
            "cannot save the waypoint: 'world' is the frame every pose is given in; choose another name");
  EXPECT_FALSE(waypoints.find("endpoint") || waypoints.find("table_center") || waypoints.find("world"));
  ASSERT_EQ(run("Teach", {{"waypoint", "here"}, {"kind", "pose"}, {"frame", "world"}}).state, OperationState::kSuccess);
  EXPECT_EQ(run("RenameWaypoint", {{"waypoint", "here"}, {"new_name", "endpoint"}}).reason,
            "cannot rename 'here': 'endpoint' is the arm's own symbol (the tool centre point, in the world); choose "
            "another name");
  EXPECT_TRUE(waypoints.find("here").has_value());
  // Taught again under its own name: an update, not a clash.
  EXPECT_EQ(run("Teach", {{"waypoint", "here"}, {"kind", "pose"}, {"frame", "world"}}).state, OperationState::kSuccess);
}

// How another component moves the arm: it plans with a motion service of its own (the cell's,
// here one on the same driver and collision world) and hands the plan's waypoints to the arm's
// FollowJointPath, with the contacts the plan allowed passed to the query alone.
TEST_F(ArmTest, FollowsAPathPlannedByTheMotionServiceExactlyAsItWouldItsOwn) {
  const MotionPlanner service(driver, clock, collisions,
                              std::make_shared<Ur5Kinematics>(published::ur5Dh(), published::ur5Limits()), config());
  const JointVector goal = {0.6, -1.8, 1.6, -M_PI / 2, -M_PI / 2, 0.0};
  const MotionPlan plan = service.planToJoints(service.joints(), goal, 0.4);
  ASSERT_TRUE(plan.ok()) << plan.failure;
  const OperationResult result = run(std::string(kFollowJointPath), followParams(plan, "to the goal"));
  ASSERT_EQ(result.state, OperationState::kSuccess) << result.reason;
  EXPECT_LT(maxAbsDifference(driver.read().position, goal), 1e-9);
  // Timed again by the arm from the waypoints and the speed: the very same trajectory.
  ASSERT_EQ(driver.executed.size(), 1u);
  EXPECT_EQ(driver.executed[0]->duration(), plan.trajectory->duration());
  for (Duration t{}; t <= plan.trajectory->duration(); t += std::chrono::milliseconds(7)) {
    EXPECT_EQ(driver.executed[0]->sample(t).position, plan.trajectory->sample(t).position);
  }
  // Not a node type: the abstract Arm's plans never see it.
  EXPECT_EQ(arm.description().operation(kFollowJointPath)->kind, component::OperationKind::kInternal);
}

// An arm sent to a joint limit reads a hair beyond it (the iiwa's joint 5 at 2.96706 rad +
// 2e-7 after a grasp, seed 1835 of the 3-finger assembly); the next motion from there must be
// planned, starting on the limit. Further beyond it, the plan fails naming the joint.
TEST_F(ArmTest, AMotionStartingAHairBeyondAJointLimitStartsOnTheLimit) {
  const double limit = published::ur5Limits().max_position[5];
  for (const double beyond : {2e-7, 5e-4, 0.01}) {
    JointVector start = kHome;
    start[5] = limit + beyond;
    const IdealDriver at_limit(clock, start);
    const MotionPlanner service(at_limit, clock, collisions,
                                std::make_shared<Ur5Kinematics>(published::ur5Dh(), published::ur5Limits()), config());
    JointVector goal = kHome;
    goal[5] = limit - 0.5;
    const MotionPlan joints = service.planToJoints(service.joints(), goal, 0.4);
    const MotionPlan line = service.planLine(
        service.joints(), service.toolAt(start) * world::Pose(Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitZ())), 0.4);
    if (beyond < 1e-3) {
      ASSERT_TRUE(joints.ok()) << joints.failure;
      EXPECT_EQ(joints.path.front()[5], limit);
      EXPECT_LT(maxAbsDifference(joints.trajectory->sample(Duration{}).position, start), 1e-3);
      ASSERT_TRUE(line.ok()) << line.failure;
      EXPECT_EQ(line.path.front()[5], limit);
    } else {
      EXPECT_FALSE(joints.ok());
      EXPECT_NE(joints.failure.find("joint 6 of the start is"), std::string::npos) << joints.failure;
      EXPECT_NE(joints.failure.find("above its maximum"), std::string::npos) << joints.failure;
      EXPECT_FALSE(line.ok());
    }
  }
}

TEST_F(ArmTest, FollowJointPathRefusesABadPathOrOneFromElsewhereAndCancelStopsIt) {
  const auto follow = [this](const std::string& path) {
    return run(std::string(kFollowJointPath), {{"path", path}, {"label", "approach"}});
  };
  EXPECT_EQ(follow("[[0,0,0,0,0,0]]").reason, "approach: the path has 1 point(s); it needs a start and a goal");
  EXPECT_EQ(follow("{}").reason, "approach: the path is not a JSON array of joint configurations");
  EXPECT_EQ(follow("[[0,0,0,0,0,0],[0,0,0,0,0]]").reason, "approach: path point 2 is not a list of 6 angles");
  EXPECT_EQ(follow("[[0,0,0,0,0,0],[0,0,\"x\",0,0,0]]").reason,
            "approach: path point 2: joint 3 is not a finite number");
  // Planned from somewhere the arm is not: it would jump there.
  JointVector elsewhere = kHome;
  elsewhere[0] += 0.3;
  const OperationResult jump = follow(pathParam({elsewhere, kHome}));
  EXPECT_NE(jump.reason.find("approach: the path starts 0.300 rad from where the arm is"), std::string::npos)
      << jump.reason;
  EXPECT_TRUE(driver.executed.empty());  // nothing moved
  // Cancelling decelerates along the path, as for every motion.
  JointVector far = kHome;
  far[0] += 2.0;
  const auto id = arm.start(std::string(kFollowJointPath), {{"path", pathParam({kHome, far})}, {"speed", 1.0}});
  clock.advanceBy(std::chrono::milliseconds(500));
  EXPECT_TRUE(holds("arm_moving"));
  arm.cancel(id);
  ASSERT_EQ(driver.executed.size(), 2u);
  clock.advanceBy(driver.executed.back()->duration() + std::chrono::milliseconds(10));
  EXPECT_FALSE(holds("arm_moving"));
}

/// The arm with its waypoints in a file, as in a workcell.
class ArmWithAWaypointFile : public ArmTest {
 protected:
  ArmWithAWaypointFile() : ArmTest(freshFile()) {}
  static std::filesystem::path freshFile() {
    const auto folder = std::filesystem::temp_directory_path() / ("costar_arm_waypoints_" + std::to_string(::getpid()));
    std::filesystem::remove_all(folder);
    std::filesystem::create_directories(folder);
    return folder / "waypoints.json";
  }
  ~ArmWithAWaypointFile() override { std::filesystem::remove_all(waypoints.file().parent_path()); }

  /// Runs `change` on the file in another process, as `costar teach` beside the editor would.
  void inAnotherProcess(const std::function<void(WaypointStore&)>& change) {
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      try {
        WaypointStore other(waypoints.file(), /*persist=*/true, 6);
        change(other);
      } catch (...) {
        ::_exit(1);
      }
      ::_exit(0);
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  }

  bool offers(const std::string& name) {
    world::WorldState state;
    state.update("arm", arm.report());
    return state.symbol(name) != nullptr;
  }
};

// Issue 27: the server kept offering (and moving to) waypoints as it had read them at start-up.
TEST_F(ArmWithAWaypointFile, TheArmFollowsWaypointsAnotherProcessTeachesAndDeletes) {
  EXPECT_FALSE(offers("taught_elsewhere"));
  inAnotherProcess([](WaypointStore& other) {
    other.put({"taught_elsewhere", Waypoint::Kind::kPose, {}, toolDown(0.5, -0.2, 0.15), "world"});
  });
  EXPECT_TRUE(offers("taught_elsewhere"));
  const OperationResult moved = run("Move", {{"waypoint", "taught_elsewhere"}, {"speed", 0.5}});
  ASSERT_EQ(moved.state, OperationState::kSuccess) << moved.reason;
  EXPECT_TRUE(arm.endpoint().isApprox(toolDown(0.5, -0.2, 0.15), 1e-6));
  // Taught here, deleted there: this arm teaches beside the other process without losing it.
  ASSERT_EQ(run("Teach", {{"waypoint", "taught_here"}, {"kind", "joints"}}).state, OperationState::kSuccess);
  inAnotherProcess([](WaypointStore& other) {
    if (!other.remove("taught_elsewhere")) {
      throw std::runtime_error("not in the file");
    }
  });
  EXPECT_FALSE(offers("taught_elsewhere"));
  EXPECT_TRUE(offers("taught_here"));
  const OperationResult gone = run("Move", {{"waypoint", "taught_elsewhere"}});
  EXPECT_EQ(gone.state, OperationState::kFailure);
  EXPECT_EQ(gone.reason, "unknown waypoint 'taught_elsewhere' (known: taught_here)");
}

TEST(WaypointStore, PersistsAtomicallyAndReloads) {
  const auto file = std::filesystem::temp_directory_path() / "costar_waypoints_test" / "waypoints.json";
  std::filesystem::remove_all(file.parent_path());
  {
    WaypointStore store(file);
    store.put({"a", Waypoint::Kind::kJoints, {1, 2, 3, 4, 5, 6}, {}, "world"});
    store.put({"b", Waypoint::Kind::kPose, {}, world::poseFromXyzRpy(0.1, 0.2, 0.3, 0.4, 0.5, 0.6), "table_center"});
    store.rename("a", "c");
    EXPECT_THROW(store.rename("zzz", "d"), std::invalid_argument);
    EXPECT_THROW(store.rename("b", "c"), std::invalid_argument);
  }
  WaypointStore reloaded(file);
  ASSERT_EQ(reloaded.all().size(), 2u);
  EXPECT_EQ(reloaded.find("c")->joints[5], 6.0);
  EXPECT_EQ(reloaded.find("b")->frame, "table_center");
  EXPECT_TRUE(reloaded.find("b")->pose.isApprox(world::poseFromXyzRpy(0.1, 0.2, 0.3, 0.4, 0.5, 0.6), 1e-12));
  EXPECT_TRUE(reloaded.remove("c"));
  EXPECT_FALSE(reloaded.remove("c"));
  EXPECT_EQ(WaypointStore(file).all().size(), 1u);
  std::filesystem::remove_all(file.parent_path());
}

}  // namespace
}  // namespace costar::arm
