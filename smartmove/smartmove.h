#pragma once
// SmartMove (the paper, Sec. IV-C and Algorithm 2): operations that select their goal from the
// world state instead of coordinates in the plan.
//
//   SmartMove(object_class, predicates, grasp)    moves the tool to the cheapest feasible goal
//                                                 o * s * T over matching objects o, symmetries
//                                                 s of their class, and the class's grasp T
//   SmartGrasp(object_class, predicates, grasp)   the same goal, reached from a pre-grasp
//                                                 `approach` back along the tool axis by a
//                                                 straight line; closes; checks the part is held;
//                                                 lifts `retreat` straight up
//   SmartRelease(target_class | target, predicates) puts the held part on top of a matching
//                                                 object (or at a frame, or with target="table"
//                                                 at a free spot on the table that satisfies the
//                                                 predicates), lowering onto it in a straight
//                                                 line, opens, lifts
//   SmartPush(object_class, predicates, distance) when no grasp is feasible among crowded parts:
//                                                 pushes the most crowded matching part
//                                                 `distance` along the direction that leaves it
//                                                 the most room, with the closed fingers (moved
//                                                 collision-free above its far side, down, across,
//                                                 up); the plan then looks again
//   TeachGrasp(object_class, grasp)               stores the tool's pose relative to the nearest
//                                                 part of the class as a named grasp
//
// `predicates` is a ';'-separated list like "right_of(table_center); near(node_1)": each is
// applied to the object (as its first argument, or where "?" stands). The result of every
// operation lists every candidate with its cost or the reason it was rejected.
//
// Motion: SmartMove asks the cell's motion service (arm/motion_service.h) for where the arm is,
// IK solutions, collisions and plans, each query with its scene (planning::QueryScene): the
// contacts it allows (the fingers and the part they grasp, the part held and its support), the
// fingers as the motion will have them (the gripper's geometry, gripper/gripper_geometry.h),
// the part held left out. It changes nothing in the cell's collision world around a query; it
// keeps the known parts there (syncObstacles). It moves the arm with the arm's FollowJointPath
// operation and the gripper with the gripper's operations, as a plan would, so it needs neither
// component's class. Cancelling a SmartMove cancels the arm's motion.
// Predicate: holding(o) — the gripper holds part o (grasped by SmartGrasp, and still squeezing).
//
// One job a file: smartmove.cpp (this component: its operations, what it knows, the scenes of
// its queries), script (the step engine), candidate_search (the choice among parts, symmetries
// and shifted grasps), smart_grasp (SmartMove and SmartGrasp), smart_release, smart_push,
// teach_grasp.

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "arm/motion_service.h"
#include "component/operation_table.h"
#include "gripper/gripper_geometry.h"
#include "planning/collision_world.h"
#include "predicator/predicator.h"
#include "smartmove/grasps.h"
#include "smartmove/selection.h"
#include "world/object_class.h"
#include "world/world_state.h"

namespace costar::smartmove {

struct SmartMoveConfig {
  std::string name = "smartmove";
  double approach = 0.10;          // m, default of the operations' approach parameter
  double retreat = 0.10;           // m, straight up after grasping or releasing
  double default_speed = 0.5;      // fraction of the arm's top speed
  double approach_speed = 0.15;    // fraction, for the straight approach and retreat
  double place_clearance = 0.004;  // m between the part and its support when released
  /// SmartRelease target="table": spots searched on this part of the table, this far apart.
  Eigen::Vector2d table_min{0.30, -0.40};
  Eigen::Vector2d table_max{0.70, 0.40};
  double table_spot_step = 0.03;
  /// A spot qualifies only if the predicates also hold this far from it in x and y, so that the
  /// part, once put down and detected again (placement and perception error), still satisfies
  /// them rather than sitting in the predicates' dead band.
  double table_spot_margin = 0.02;
  /// misplaced(o): the part SmartRelease put down last, seen again, is more than
  /// misplaced_distance from where it was put (m). It is found by place (perception renames a
  /// part that moved): the part of its class nearest where it was put, within misplaced_search,
  /// that is not where a part of the class was believed to be at the release (a part seen where
  /// one was: not the one put down; the part put down, before it is seen again: its old belief).
  /// Perception's error is a few mm; a part held off where its grasp was planned (moved as the
  /// fingers closed) lands 1-3 cm off, one that slipped out farther.
  double misplaced_distance = 0.012;
  double misplaced_search = 0.15;
  /// A person's hands as perception reports them (frames at the hand's centre, x toward the
  /// fingertips, z up: perception/hand_component.h): obstacles no motion is planned through, the
  /// hand a box of `hand_size` centred on the frame, the forearm one of `forearm_size` behind it
  /// (along -x, from the wrist). SmartRelease target=HAND may touch the hand, not the forearm.
  std::vector<std::string> person_frames = {"hand_1"};
  Eigen::Vector3d hand_size{0.26, 0.12, 0.08};
  Eigen::Vector3d forearm_size{0.30, 0.10, 0.10};
  /// Robot links that may touch the part being grasped (the gripper): the robot
  /// description's links.gripper (arm/robot_description.h).
  std::vector<std::string> gripper_links;
  /// The gripper's fingers (one implementation per kind of gripper): grasps are planned with
  /// the fingers as the grasp will have them (a parallel gripper opened only as far as the part
  /// needs plus `grasp_margin`, and opened that far before a grasp and to release; an adaptive
  /// gripper in the grasp's mode, closed part way where the open fingers do not fit among
  /// neighbours). Not modelled: the robot model's finger shapes stay and the gripper opens fully.
  std::shared_ptr<const gripper::GripperGeometry> gripper = gripper::rigidGripperGeometry();
  /// The robot link whose shapes are the fingers.
  std::string finger_link = "fingers";
  /// m added to the part's width between the fingers: covers perception error (a few mm, a few
  /// degrees of yaw) and the fingers' tracking.
  double grasp_margin = 0.016;
  /// When no centred grasp is feasible, grasps shifted across the fingers (along the tool's x)
  /// are tried, nearest the centre first: in steps of grasp_shift_step up to grasp_shift_max,
  /// keeping the pads grasp_shift_keep inside the part's end (a link gripped off its middle, a
  /// node off its centre line). Where the gripper's geometry says how far the fingers reach.
  double grasp_shift_step = 0.01;
  double grasp_shift_max = 0.04;
  double grasp_shift_keep = 0.003;
  /// m the finger pads reach past the tool centre point along the approach (the simulated
  /// 2-finger gripper's 40 mm pads are centred on it): how far they rise to clear a part before
  /// SmartGrasp centre="true" turns them, and which of a part's boxes lie between them.
  double finger_reach = 0.02;
  CostWeights weights;
};

/// Parses "right_of(table_center); near(node_1)" into patterns with "?" for the object
/// (predicator/pattern.h). @throws std::invalid_argument naming the problem.
using predicator::parsePredicateList;

/// Obstacle name of a known part in the collision world.
std::string partObstacle(const std::string& object);

/// The fingers' boxes as collision shapes of the finger link.
std::vector<planning::CollisionShape> fingerShapes(const std::vector<gripper::OrientedBox>& boxes);

/// Checks one predicate pattern of a plan before it runs (known predicate, right number of
/// arguments, known reference frames): empty when fine, else the problem.
using PatternCheck = predicator::PatternCheck;

class SmartMoveComponent final : public component::TableComponent {
 public:
  /// Everything passed by reference must outlive the component. `motion`: the cell's motion
  /// service for the arm; `arm` and `gripper`: the components SmartMove moves through their
  /// operations (the arm's FollowJointPath; the gripper's Open and Close). `collisions`: the
  /// cell's collision world, where SmartMove keeps the known parts (syncObstacles); the motion
  /// service plans in it. @throws std::invalid_argument when config.gripper is null.
  SmartMoveComponent(const arm::MotionService& motion, component::Component& arm, component::Component& gripper,
                     world::WorldState& world, planning::CollisionWorld& collisions,
                     std::vector<world::ObjectClass> classes, GraspLibrary& grasps, SmartMoveConfig config = {});

  world::Report report() const override;

  /// Puts every known part (symbols classified by is_a) in the collision world as a box, and
  /// removes parts that are gone; the part held is left out. Call before planning (the
  /// workcell does it before every tick).
  void syncObstacles();

  /// The opening a grasp with the tool centre point at `tcp` needs for a part of `object_class`
  /// at `object`: the part's width between the fingers (its extent along the tool's y) plus
  /// grasp_margin, at most the gripper's stroke; nullopt when the part is wider than the stroke;
  /// 0 (open fully) for a gripper without a width (GripperGeometry::graspOpening).
  std::optional<double> graspOpening(const world::Pose& tcp, const world::Pose& object,
                                     const world::ObjectClass& object_class) const;

  /// Sets what plan validation checks of each predicate pattern (the workcell knows which
  /// predicates are declared and which frames exist). Call before the node types are made.
  void setPatternCheck(PatternCheck check) { *pattern_check_ = std::move(check); }

  /// The part held since the last SmartGrasp, if the gripper still holds something.
  const std::optional<std::string>& held() const { return held_; }
  /// The part misplaced(o) holds for (SmartMoveConfig::misplaced_distance), if any.
  std::optional<std::string> misplacedPart() const;

  /// Objects of a class that satisfy every pattern, with the patterns that others fail.
  struct Matches {
    std::vector<std::pair<std::string, world::Pose>> objects;
    std::vector<std::pair<std::string, std::string>> rejected;  // object, reason
  };
  Matches matching(const std::string& object_class, const std::vector<predicator::Pattern>& patterns,
                   const std::string& exclude = {}) const;

  /// The candidate search of SmartMove (approach 0) and SmartGrasp (no motion).
  /// `mode`: the gripper mode the grasp needs (its fingers are planned so; empty: as they are).
  Selection selectGrasp(const std::string& object_class, const std::vector<predicator::Pattern>& patterns,
                        const world::Pose& grasp, double approach, double speed, const std::string& mode = {});

 private:
  // The operations' handlers (one table, declared in the constructor), each in its own file.
  std::unique_ptr<component::RunningOperation> beginMoveOrGrasp(bool grasping, const component::ParamMap& params);
  std::unique_ptr<component::RunningOperation> beginRelease(const component::ParamMap& params);
  std::unique_ptr<component::RunningOperation> beginTeachGrasp(const component::ParamMap& params);
  std::unique_ptr<component::RunningOperation> beginPush(const component::ParamMap& params);
  const world::ObjectClass* objectClass(const std::string& name) const;

  // What every motion query is given.
  /// The scene of a motion query: the gripper's links may touch `objects` (parts, or a
  /// support), the fingers stand as `stance` says (as the cell has them where the gripper's
  /// geometry does not model it), the part held is left out.
  arm::QueryScene scene(const std::vector<std::string>& objects = {}, const gripper::FingerStance& stance = {}) const;
  ArmModel armModel() const;
  /// Runs a plan with the arm's FollowJointPath (called `what` in messages), or an operation
  /// that fails with the plan's reason.
  std::unique_ptr<component::RunningOperation> follow(const arm::MotionPlan& plan, const std::string& what);
  /// Starts a joint-space motion to the IK solution for `pose` nearest `seed` that is free with
  /// the fingers standing as `stance` (the arm's operation named `what`), or an operation that
  /// fails with `none` and the reason.
  std::unique_ptr<component::RunningOperation> moveToFreeConfiguration(const world::Pose& pose,
                                                                       const arm::JointVector& seed, double speed,
                                                                       const std::string& what, const std::string& none,
                                                                       const gripper::FingerStance& stance = {});
  /// The gripper's Open to stand as `stance` says (fully open where it says nothing the
  /// gripper has), and Close with the grip force `force` (N): steps of a script.
  std::unique_ptr<component::RunningOperation> openGripper(const gripper::FingerStance& stance);
  std::unique_ptr<component::RunningOperation> closeGripper(double force);

  // The candidate search (candidate_search.cpp).
  /// How far (m along the tool's x) a grasp at `tcp` may shift and keep fingers reaching
  /// `reach` either side of the tool's axis on the part.
  std::vector<double> graspShifts(const world::Pose& tcp, const world::Pose& object,
                                  const world::ObjectClass& object_class, double reach) const;
  /// A start at `start` (the IK solution nearest `goal_joints` free in `scene`) and a straight
  /// line from there to `goal`: empty when both are found (in `from` and `line`), else why not,
  /// `names.start` or `names.line` first (`reason` keeps the first contact seen so far).
  struct StraightNames {
    const char* start;
    const char* line;
  };
  std::string straightOnto(const world::Pose& start, const world::Pose& goal, const arm::JointVector& goal_joints,
                           const arm::QueryScene& scene, std::string& reason, const StraightNames& names,
                           arm::JointVector& from, arm::MotionPlan& line) const;
  /// The objects `matches` rejected, added to `selection` as rejected candidates, and its
  /// failure summarized (no part known at all: "detect the parts first").
  static void addRejected(Selection& selection, const Matches& matches);
  /// `centred` (none feasible) with the shifted grasps of its candidates tried after it.
  Selection withShiftedGrasps(Selection centred, const world::ObjectClass& object_class, double reach,
                              const FeasibilityCheck& feasible);
  /// Half the part's width between the fingers of a grasp with the tool centre point at `tcp`
  /// (its extent along the tool's y, either side of the TCP), of its boxes that reach within
  /// finger_reach past the TCP along the approach.
  double partHalfWidth(const world::Pose& tcp, const world::Pose& object, const world::ObjectClass& object_class) const;

  // SmartGrasp centre="true" (smart_grasp.cpp): after the close, open fully, rise `rise` m,
  // turn by `turn` about the tool axis, go down and close, which centres the part along the
  // pads too; `opening` (m) is the turned grasp's, to release it.
  struct Centring {
    world::Pose turn = world::Pose::Identity();
    double rise = 0.0;
    double opening = 0.0;
  };
  /// How to square up the part of the `chosen` grasp, or nullopt and why not (the gripper has
  /// no width, the grasp is off the part's centre, the part does not fit the fingers turned, a
  /// neighbour is in the way).
  std::optional<Centring> planCentring(const Candidate& chosen, const world::Pose& object_pose,
                                       const world::ObjectClass& object_class, std::string& why);

  // SmartRelease on the table (smart_release.cpp).
  /// Why a spot on the table does not satisfy `pattern` (empty if it does).
  std::string spotFailsPattern(const Eigen::Vector3d& spot, const predicator::Pattern& pattern) const;

  const arm::MotionService& motion_;
  component::Component& arm_;
  component::Component& gripper_;
  world::WorldState& world_;
  planning::CollisionWorld& collisions_;
  std::vector<world::ObjectClass> classes_;
  GraspLibrary& grasps_;
  SmartMoveConfig config_;
  const gripper::GripperGeometry& fingers_;  // config_.gripper's

  std::optional<std::string> held_;
  std::string held_class_;
  world::Pose held_grasp_ = world::Pose::Identity();  // the TCP in the held part's frame
  double held_opening_ = 0.0;                         // the opening of its grasp, m (0: fully)
  std::string held_mode_;                             // the gripper mode it was grasped in
  double held_finger_position_ = 0.0;                 // where its fingers release to in that mode (0: open)
  /// The part SmartRelease put down last: its class, where it was put (the part's frame in the
  /// world), and where the parts of its class were believed to be then (the part itself where it
  /// was seen before it was grasped); cleared by the next grasp.
  struct PutDown {
    std::string object_class;
    world::Pose pose = world::Pose::Identity();
    std::vector<Eigen::Vector3d> known;
  };
  std::optional<PutDown> put_;
  std::vector<std::string> obstacles_;
  std::shared_ptr<PatternCheck> pattern_check_ = std::make_shared<PatternCheck>();
};

}  // namespace costar::smartmove
