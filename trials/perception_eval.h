#pragma once
// DetectObjects judged against the simulator's truth (the paper's perception, measured):
// random cluttered scenes (sim::clutteredScene, touching parts included), DetectObjects run as
// a plan runs it (the perception component on the simulated camera, simulated time stepped),
// each detection matched to the true parts, and per class precision, recall and pose error
// (symmetry-aware), identities kept while parts stay still and after small pushes, and the
// latency of every stage. `costar perception eval` and `costar perception detect` print these;
// docs/PERCEPTION.md, docs/BENCHMARKS.md.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/image.h"
#include "trials/perception_scenes.h"
#include "world/object_class.h"
#include "world/pose.h"

namespace costar::trials {

/// Within this of the truth a part counts as found accurately (the paper's task needs it).
inline constexpr double kPoseToleranceM = 0.005;
inline constexpr double kPoseToleranceDeg = 5.0;
/// Parts showing less of their camera-facing surface than this are not counted.
inline constexpr double kVisibleFraction = 0.3;

/// A true part as the camera saw it.
struct TruePart {
  std::string name;
  std::string object_class;
  world::Pose pose = world::Pose::Identity();
  /// Of its camera-facing surface, the fraction the filtered depth image shows.
  double visible_fraction = 0.0;
};

/// A detected object, as the perception component reports it.
struct DetectedPart {
  std::string name;
  std::string object_class;
  world::Pose pose = world::Pose::Identity();
  double confidence = 0.0;
};

/// One-to-one matching of detections to true parts.
struct Match {
  std::vector<int> detection_of_part;     // per part, -1: missed
  std::vector<int> part_of_detection;     // per detection, -1: a false detection
  std::vector<double> translation_error;  // per part (m), 0 when missed
  std::vector<double> rotation_error;     // per part (rad, the smallest over the class's symmetries)

  /// Found within kPoseToleranceM and kPoseToleranceDeg.
  bool accurate(std::size_t part) const;
};

/// Same class, centres within 2.5 cm, closest pairs first. The rotation error is measured
/// with the symmetries of the class in `classes`. @throws std::runtime_error for a part of a
/// class not in `classes`.
Match matchToTruth(const std::vector<DetectedPart>& detected, const std::vector<TruePart>& truth,
                   const std::vector<world::ObjectClass>& classes);

struct ClassScore {
  int visible = 0;           // part views counted
  int visible_found = 0;     // matched, any error
  int visible_accurate = 0;  // matched within tolerance
  int detections = 0;
  int false_positives = 0;
  std::vector<double> translation_mm;  // of the found ones
  std::vector<double> rotation_deg;

  double precision() const;
  double recall() const;
  double withinTolerance() const;
};

/// The scores of every detection round so far.
struct Scores {
  std::map<std::string, ClassScore> classes;
  int hidden_part_views = 0;
  /// One line per problem: a missed part, an inaccurate pose, a false detection, a lost name.
  std::vector<std::string> problems;

  /// Scores one round (`where` names it in the problems).
  void add(const std::vector<DetectedPart>& detected, const std::vector<TruePart>& truth, const Match& match,
           const std::string& where);
  int visiblePartViews() const;
  /// Of all visible part views, those found within tolerance (1 when none).
  double foundWithinTolerance() const;
};

struct PerceptionEvalOptions {
  int scenes = 10;
  std::uint64_t seed = 1;  // of the scenes, pushes and sensor noise
  int repeats = 10;        // DetectObjects per scene while the parts stay still
  int long_run = 0;        // extra repeats on the first scene
  int pushes = 2;          // per scene: one part moved 1-2 cm and turned up to 10 degrees
  int frames = 15;         // per DetectObjects (the median filter's N)
  double touching = 0.4;   // chance that a part is placed against another
  /// Links lying across nodes per scene (trials/perception_scenes.h: stackLinksOnNodes).
  int stacked = 0;
  /// Chance that a scene has the cell's arm posed over the parts (hiding some of them in part,
  /// its gripper among them) instead of at home: its points must give no detection.
  double arm_over = 0.0;
  /// The simulated cell (workcells/NAME.json): its robot, gripper and camera, and its model
  /// (perception_model).
  std::string workcell = "ur5-sim";
  /// The SVM to use instead of the cell's (to compare models on the same scenes); empty: the cell's.
  std::filesystem::path model;
  /// A PNG per scene (detections drawn; the SVM's labels) and the scene files (scene_NNN.json,
  /// scene_NNN_push_K.json: `perception detect` runs them again) in this folder; empty: none.
  std::filesystem::path pictures;
};

/// How one scene went, for progress lines.
struct SceneReport {
  int scene = 0;  // from 1
  int parts = 0;
  int touching_parts = 0;
  int stacked_parts = 0;
  bool arm_over = false;
  int accurate_first_look = 0;
  int names_kept = 0;  // while still
  int name_checks = 0;
  int repeats = 0;
  int pushes_all_names_kept = 0;
  double last_detection_ms = 0.0;
};

struct PerceptionEvalSummary {
  PerceptionEvalOptions options;
  Scores scores;
  int parts = 0;
  int parts_placed_touching = 0;
  int parts_stacked = 0;    // links put across nodes
  int scenes_arm_over = 0;  // scenes with the arm posed over the parts
  /// Per stage of DetectObjects (median_filter, crop_plane, normals, features, svm, pose_wall,
  /// objrecransac_cpu, icp_check_cpu, total): one value (ms) per run.
  std::map<std::string, std::vector<double>> latency_ms;
  // Identities.
  int repeat_checks = 0, repeat_stable = 0;
  int scenes_with_repeats = 0, scenes_all_stable = 0;
  int long_run_checks = 0, long_run_stable = 0;
  int push_checks = 0, push_stable = 0;
  int pushed_part_checks = 0, pushed_part_stable = 0;
  double seconds = 0.0;

  nlohmann::json toJson() const;
  /// The report `costar perception eval` prints after its progress lines.
  std::string text() const;
};

/// The stages in the order they run, as latency_ms names them.
const std::vector<std::string>& latencyStages();

/// Runs the evaluation. @throws std::runtime_error when a data file is missing or a
/// DetectObjects fails.
PerceptionEvalSummary evaluatePerception(const PerceptionEvalOptions& options,
                                         const std::function<void(const SceneReport&)>& progress = {});

/// How `perception eval` looked at a scene (scene_NNN_look.json beside its scene file), so that
/// `perception detect --look` looks at it again the same way: the cell, the camera's noise seed
/// and, when the cell's arm stood over the parts, where it stood and where its fingers were sent.
struct SceneLook {
  std::string workcell;
  std::uint64_t noise_seed = 0;
  std::optional<ArmOverPose> arm_over;
};
nlohmann::json sceneLookJson(const SceneLook& look);
/// @throws std::runtime_error naming the file and the field for a file that is not a look.
SceneLook loadSceneLook(const std::filesystem::path& file);

/// DetectObjects once on a scene file, as a plan runs it, against the simulator's truth.
struct SceneDetection {
  std::vector<DetectedPart> detected;
  std::vector<TruePart> truth;
  Match match;
  double milliseconds = 0.0;  // the pipeline's (frame capture not included)
  /// The camera image with the detections drawn (green within tolerance, red not, orange a
  /// false detection, yellow a missed part's outline), enlarged on the table.
  RgbImage picture;
};
/// With `look`: the camera's noise and the arm as `perception eval` had them at the scene's first
/// look (`seed`, when given, still places the parts); `workcell` must be the look's.
SceneDetection detectInScene(const std::filesystem::path& scene, std::optional<std::uint64_t> seed, int frames,
                             const std::string& workcell = "ur5-sim", const std::optional<SceneLook>& look = {});

/// Percentile (0..100) by linear interpolation; 0 for none.
double percentile(std::vector<double> values, double p);

}  // namespace costar::trials
