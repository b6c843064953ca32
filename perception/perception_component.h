#pragma once
// The perception component (the paper's Sec. IV): DetectObjects, a knowledge operation the
// user places in a plan where the camera has a clear view. It captures N frames at the
// camera's frame rate across polls (so it takes simulated time), then, in the poll that gets
// the last frame, runs the pipeline (perception/pipeline.h), setCanonicalOrientation and
// persistenceUpdate, and replaces its report:
//   symbols     one frame per object ("node_3", parent "world", pose of the object frame in
//               the robot base frame: camera calibration x camera pose; its `color` the mean
//               RGB of the object's points), and one object-class symbol per class ("node",
//               "link")
//   predicates  is_a(object, class)    the object is of that class, and
//               visible(object)        it was seen by the latest DetectObjects (objects kept
//                                      by keep_for without being re-seen have neither: only
//                                      their name and last frame are remembered)
// The class symbol names the data file (data/objects/<class>.json) that gives SmartMove the
// class's symmetries and axis priority. It reads camera frames only, never simulator ground
// truth.
//
// Between detections it watches the camera: every report (every tick of a run) reads the
// stream's status (RgbdCamera::streamStatus, cheap) and throws when the stream stopped (its
// newest frame older than camera_max_age), sends empty frames or frames without any valid
// depth, or does not answer; a report that throws stops the cell (ComponentRegistry), so a
// camera that breaks after the last frame a DetectObjects used is not left unnoticed.

#include <functional>
#include <memory>
#include <mutex>
#include <optional>

#include "camera/rgbd.h"
#include "component/operation_table.h"
#include "core/clock.h"
#include "perception/persistence.h"
#include "perception/pipeline.h"

namespace costar::perception {

struct PerceptionConfig {
  std::string name = "perception";
  /// Data files (default: under dataRoot()).
  PipelineFiles files = PipelineFiles::under();
  /// The workspace centre in the world; when absent, read from files.workspace_file.
  std::optional<world::Pose> table_center;
  PipelineOptions pipeline;
  /// Persistence: an object missed by up to keep_for detections in a row keeps its name for
  /// when it is seen again; meanwhile it is reported as a frame only (no is_a, no visible), so
  /// SmartMove, the Predicator and the obstacles see only what the last detection saw.
  PersistenceOptions persistence{.max_distance = 0.03, .keep_for = 2};
  /// Frames per DetectObjects (the median filter's N); the operation's `frames` parameter
  /// overrides it.
  int frames = 15;
  /// Where the camera is in the world as calibrated (calibration/): when set, every frame is
  /// seen from this pose instead of the one it carries, so a new calibration takes effect at
  /// the next frame.
  std::function<world::Pose()> camera_pose;
  /// The camera's health between detections: the oldest its newest frame may be (a 30 Hz
  /// stream that missed 6 frames). Zero: not watched (frames are still checked as taken).
  Duration camera_max_age = std::chrono::milliseconds(200);
};

/// Loads the pipeline `config` describes: its files and options, the workspace centre from
/// config.table_center or else the workspace file. Several components may share the result
/// (one detection at a time). @throws std::runtime_error naming a missing or inconsistent file.
std::shared_ptr<Pipeline> loadPipeline(const PerceptionConfig& config);

class PerceptionComponent final : public component::TableComponent {
 public:
  /// Loads the pipeline's data files. The camera and clock must outlive the component.
  /// @throws std::runtime_error naming a missing or inconsistent file.
  PerceptionComponent(camera::RgbdCamera& camera, const Clock& clock, PerceptionConfig config = {});
  /// Shares an already loaded pipeline (e.g. one per process); config.pipeline is then
  /// ignored except for the workspace, which is applied to `pipeline`'s options only if set here.
  PerceptionComponent(camera::RgbdCamera& camera, const Clock& clock, std::shared_ptr<Pipeline> pipeline,
                      PerceptionConfig config = {});

  world::Report report() const override;

  /// The objects known after the latest detection (names, classes, world poses).
  std::vector<TrackedObject> objects() const;
  /// The latest detection's raw result (detections, stage times); empty before the first.
  std::optional<PipelineResult> lastResult() const;
  Pipeline& pipeline() { return *pipeline_; }

 private:
  friend class DetectObjectsOperation;
  /// @throws std::runtime_error naming what is wrong when the camera's stream is not healthy.
  void checkCamera() const;
  /// Runs the pipeline on `frames` and updates the state; returns the operation's result.
  component::OperationResult process(const std::vector<camera::RgbdFrame>& frames);

  camera::RgbdCamera& camera_;
  const Clock& clock_;
  PerceptionConfig config_;
  std::shared_ptr<Pipeline> pipeline_;
  mutable std::mutex mutex_;
  PersistenceFilter persistence_;
  std::optional<PipelineResult> last_result_;
  TimePoint last_stamp_{};
};

}  // namespace costar::perception
