#pragma once
// What perception knows about an object class: the class itself (data/objects/NAME.json:
// boxes, symmetries, axis priority), its perception parameters (data/perception/classes.json:
// ObjRecRANSAC pair width and voxel size, SVM label) and a model generated from the boxes:
// samples of the outer surface with outward normals, and a closest-point grid for ICP.
//
// Adding a class is a data-only change: a new data/objects/NAME.json (tools/make_object_models.py)
// and, when the defaults below do not suit it, an entry in data/perception/classes.json; then
// `costar perception collect` and `costar perception train` teach the SVM the new label.

#include <Eigen/Geometry>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "perception/cloud.h"
#include "world/object_class.h"

namespace costar::perception {

/// Per-class parameters of the pipeline (data/perception/classes.json, "classes": {NAME: {...}}).
struct ClassParameters {
  /// Label the SVM gives points of this class (background is 0). Unique, positive.
  int svm_label = 0;
  /// ObjRecRANSAC's oriented-point-pair width (m): about half the extent of the visible part
  /// of the object. Default: 0.7 x the smallest side of the class's bounding box, at least 2 cm.
  double pair_width = 0.0;
  /// ObjRecRANSAC's octree leaf size (m) for the model and the scene. Default 6 mm.
  double voxel_size = 0.006;
  /// Spacing of the surface samples given to ObjRecRANSAC as its model (m). Sparser models
  /// hash fewer point pairs, so each scene pair yields fewer hypotheses (faster); the
  /// hypotheses are refined by ICP anyway. Default 12 mm.
  double recognition_spacing = 0.012;
  /// Spacing of the model's surface samples for ICP and scoring (m). Default 2 mm.
  double sample_spacing = 0.002;
  /// Lower bound of ObjRecRANSAC's "relative object size" (the expected fraction of a
  /// scene that one instance covers; it sets the number of samples). The pose estimator
  /// raises it per cluster from the cluster's size. Default 0.1.
  double relative_object_size = 0.1;
  /// ObjRecRANSAC's acceptance tests (protected members without setters in PCL): the fraction
  /// of the model's surface a hypothesis must explain (PCL: 0.2) and the fraction of model
  /// points allowed in front of the scene (PCL: 0.02). Low values keep more candidates; each
  /// is verified against the depth image afterwards. Defaults 0.01 and 0.3.
  double visibility = 0.01;
  double penalty_fraction = 0.3;
};

/// Nearest model surface sample for any point near the model: a regular grid in the object
/// frame, each cell holding the index of the sample nearest to its centre (-1: none).
struct SurfaceGrid {
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();  // corner of cell (0,0,0), object frame, m
  float resolution = 0.002f;                         // m
  Eigen::Vector3i dims = Eigen::Vector3i::Zero();
  std::vector<int> nearest;

  /// Index of the surface sample nearest to `point` (object frame), or -1 outside the grid.
  int lookup(const Eigen::Vector3f& point) const {
    const Eigen::Vector3f cell = (point - origin) / resolution;
    const int x = static_cast<int>(cell.x());
    const int y = static_cast<int>(cell.y());
    const int z = static_cast<int>(cell.z());
    if (cell.x() < 0 || cell.y() < 0 || cell.z() < 0 || x >= dims.x() || y >= dims.y() || z >= dims.z()) {
      return -1;
    }
    return nearest[(static_cast<std::size_t>(z) * dims.y() + y) * dims.x() + x];
  }
};

struct ObjectModel {
  world::ObjectClass object_class;
  ClassParameters parameters;
  /// Samples of the outer surface of the union of the class's boxes, object frame, with
  /// outward normals (Cloud::normals).
  Cloud surface;
  SurfaceGrid grid;
  /// Points filling the object's volume on a grid of about 5 mm (object frame): for testing
  /// whether two detections claim the same space.
  std::vector<Eigen::Vector3f> interior;
  /// Radius of the smallest sphere about the object frame's origin that holds the object (m).
  double radius = 0.0;

  const std::string& name() const { return object_class.name; }
};

/// Samples the outer surface of the union of `boxes` on a grid of `spacing` (m): every face
/// of every box, keeping the samples that no other box covers. Normals point outward.
Cloud sampleOuterSurface(const std::vector<world::Box>& boxes, double spacing);

/// Points inside the union of `boxes` on a regular grid of `spacing` (m), cell centres.
std::vector<Eigen::Vector3f> sampleInterior(const std::vector<world::Box>& boxes, double spacing);

/// Builds the grid of nearest surface samples around `surface` (object frame) with a margin
/// (m) around the samples' bounds.
SurfaceGrid buildSurfaceGrid(const Cloud& surface, float resolution, float margin);

/// Builds a class's model with `parameters` (zeros in pair_width are replaced by defaults).
ObjectModel buildObjectModel(const world::ObjectClass& object_class, const ClassParameters& parameters);

/// Reads data/perception/classes.json (`classes_file`) and the classes in `objects_dir`, and
/// builds a model per class, sorted by name. Classes without an entry get default parameters
/// and the next free SVM label. @throws std::runtime_error naming the file and the problem
/// (unreadable files, duplicate or non-positive labels, an entry for an unknown class).
std::vector<ObjectModel> loadObjectModels(const std::filesystem::path& objects_dir,
                                          const std::filesystem::path& classes_file);

}  // namespace costar::perception
