#pragma once
// ObjRecRANSAC's vote in the rigid transform space (PCL's RigidTransformSpace: a position
// octree whose every occupied leaf holds a rotation octree of axis-angle cells) without its
// octrees' nodes. PCL allocates eight nodes per level on the way down to every new leaf, a
// std::map per rotation cell and a std::set of neighbours per leaf, and frees them all again
// after every run: most of ObjRecRANSAC's time on a cluster went there. Here a leaf is found by
// the same comparisons against the same node centres (replayed in the same float arithmetic as
// SimpleOctree::createChildren), so every leaf, every neighbour relation (SimpleOctree's, which
// depends on the order leaves were made in) and every vote count and average is PCL's, bit for
// bit (test TransformVotes.AreTheSameAsPclsRigidTransformSpace). Internal to perception/.

#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace costar::perception {

/// The leaves of PCL's SimpleOctree built on `bounds` with `voxel_size` (SimpleOctree::build's
/// arithmetic), addressed by their path from the root.
class OctreeAddressing {
 public:
  void build(const float bounds[6], float voxel_size);
  /// The path of the leaf that SimpleOctree::createLeaf / getFullLeaf reach for (x, y, z) and that
  /// leaf's centre; false outside the root's bounds.
  bool locate(float x, float y, float z, std::uint64_t& path, float centre[3]) const;
  float voxelSize() const { return voxel_size_; }
  int levels() const { return levels_; }

 private:
  float voxel_size_ = 0.0f;
  int levels_ = 0;
  float bounds_[6] = {};
  float centre_[3] = {};
};

class TransformVotes {
 public:
  /// PCL's RigidTransformSpace::build(position_bounds, position_cell, rotation_cell): empty.
  /// The rotation octree's neighbour lookups are remembered from one build to the next with the
  /// same rotation cell (the octree is the same).
  void build(const float position_bounds[6], float position_cell, float rotation_cell);
  /// One hypothesis: the model's centre under it at `position`, its 3x4 transform (rotation row
  /// by row, then translation) as PCL keeps it. Positions outside the bounds are dropped.
  void add(const float position[3], const float rigid_transform[12]);

  /// One occupied position cell: its centre and the average transform of its rotation cell
  /// with the most votes (its own and its neighbours', as RotationSpace::getTransformWithMostVotes).
  struct Winner {
    std::array<float, 3> centre{};
    std::array<float, 12> rigid_transform{};
  };
  /// Every occupied position cell in the order it was first voted for.
  std::vector<Winner> winners() const;

 private:
  struct Cell {
    float axis_angle[3] = {0.0f, 0.0f, 0.0f};
    float translation[3] = {0.0f, 0.0f, 0.0f};
    int votes = 0;
    std::vector<int> neighbours;  // indices into cells_, each once (the leaf itself may be one)
  };
  struct Space {
    std::array<float, 3> centre{};
    std::vector<int> cells;  // in the order they were made
  };
  static constexpr std::uint64_t kOutside = ~std::uint64_t{0};
  static constexpr std::size_t kMaxRemembered = 1 << 16;
  /// The paths of the leaves SimpleOctree::insertNeighbors looks up for the rotation leaf at
  /// `path` (centred at `centre`), kOutside where outside the octree; remembered.
  const std::array<std::uint64_t, 26>& neighbourPaths(std::uint64_t path, const float centre[3]);

  OctreeAddressing positions_;
  OctreeAddressing rotations_;
  std::unordered_map<std::uint64_t, int> space_of_;
  std::unordered_map<std::uint64_t, int> cell_of_;  // (space, rotation path) -> index into cells_
  std::vector<Space> spaces_;
  std::vector<Cell> cells_;
  std::unordered_map<std::uint64_t, std::array<std::uint64_t, 26>> neighbour_paths_;
};

}  // namespace costar::perception
