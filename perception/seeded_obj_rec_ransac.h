#pragma once
// ObjRecRANSAC (Papazov & Burschka 2010) for one object class, on PCL's octrees, with its
// random sampling seeded by the caller and nothing printed. PCL's own ObjRecRANSAC seeds its
// sampling with the time and prints its progress to stdout from the compiled library (the
// installed library is built verbose); the steps here that would go through those functions
// (hashing the model's point pairs, turning the sampled scene pairs into hypotheses, grouping
// them in the rigid transform space) are done on the same PCL structures with the same
// arithmetic, so the hypotheses are PCL's. Used by ClassPoseEstimator (pose_estimation.h);
// PCL stays inside the .cpp.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "world/pose.h"

namespace costar::perception {

class SeededObjRecRansac {
 public:
  struct Parameters {
    float pair_width = 0.04f;  // m between the two points of a pair
    float voxel_size = 0.005f;
    /// A hypothesis needs this fraction of the model's octree leaves seen where it puts them ...
    float visibility = 0.2f;
    /// ... and at most this fraction in front of what the scene shows.
    float penalty_fraction = 0.02f;
    /// The positions a hypothesis may put the model's centre: the scene's bounds enlarged by
    /// this fraction of their largest side.
    float scene_bounds_enlargement = 1.0f;
  };

  /// Hashes the model's oriented point pairs (points and normals in the object frame, one
  /// normal per point; milliseconds). @throws std::invalid_argument when the model has no
  /// points or the normals do not match them.
  SeededObjRecRansac(const std::vector<Eigen::Vector3f>& points, const std::vector<Eigen::Vector3f>& normals,
                     Parameters parameters);
  ~SeededObjRecRansac();
  SeededObjRecRansac(const SeededObjRecRansac&) = delete;
  SeededObjRecRansac& operator=(const SeededObjRecRansac&) = delete;

  /// One accepted hypothesis per occupied cell of the rigid transform space.
  struct Candidate {
    world::Pose pose;  // object -> the scene's frame
    float match = 0.0f;
  };

  /// ObjRecRANSAC's recognition up to and including the grouping of hypotheses, with point
  /// pairs sampled from `seed`: the best hypothesis of every occupied rotation space that passes
  /// the visibility and penalty tests. The final conflict graph is left out: it ranks hypotheses
  /// by the scene pixels they explain, and a scene cut down to one class's points has no table
  /// to contradict a hypothesis that slides off the object; the caller verifies the candidates
  /// against the whole depth image. `points` and `normals` (one each) are in the camera's
  /// optical frame (ObjRecRANSAC projects the scene along z). Deterministic for the same input.
  std::vector<Candidate> candidates(const std::vector<Eigen::Vector3f>& points,
                                    const std::vector<Eigen::Vector3f>& normals, double success_probability,
                                    float relative_object_size, std::uint32_t seed);

  /// Full leaves of the model's octree (at the voxel size): the scale of one instance.
  std::size_t modelLeaves() const;

 private:
  class Recognizer;
  std::unique_ptr<Recognizer> recognizer_;
};

}  // namespace costar::perception
