#include "perception/transform_votes.h"

#include <pcl/recognition/ransac_based/auxiliary.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace costar::perception {

namespace {

/// The centre SimpleOctree::Node::createChildren gives child `id` (x: 4, y: 2, z: 1) of a node
/// centred at `c` with bounds from `lo`: child 0's centre, then the others' by adding and taking
/// away the child's side in the order createChildren visits them (0, 1, 3, 2, 6, 7, 5, 4), each
/// coordinate here the same float operations in the same order.
void childCentre(const float lo[3], const float c[3], float side, int id, float out[3]) {
  const float x0 = 0.5f * (lo[0] + c[0]);
  const float y0 = 0.5f * (lo[1] + c[1]);
  const float z0 = 0.5f * (lo[2] + c[2]);
  out[0] = (id & 4) != 0 ? x0 + side : x0;
  switch (id) {
    case 0:
      out[1] = y0;
      out[2] = z0;
      break;
    case 1:
      out[1] = y0;
      out[2] = z0 + side;
      break;
    case 3:
      out[1] = y0 + side;
      out[2] = z0 + side;
      break;
    case 2:
      out[1] = y0 + side;
      out[2] = (z0 + side) - side;
      break;
    case 6:
      out[1] = y0 + side;
      out[2] = (z0 + side) - side;
      break;
    case 7:
      out[1] = y0 + side;
      out[2] = ((z0 + side) - side) + side;
      break;
    case 5:
      out[1] = (y0 + side) - side;
      out[2] = ((z0 + side) - side) + side;
      break;
    default:
      out[1] = (y0 + side) - side;
      out[2] = (((z0 + side) - side) + side) - side;
      break;
  }
}

}  // namespace

void OctreeAddressing::build(const float bounds[6], float voxel_size) {
  if (!(voxel_size > 0.0f)) {
    throw std::invalid_argument("OctreeAddressing: the voxel size must be positive");
  }
  voxel_size_ = voxel_size;
  // SimpleOctree::build, expression for expression.
  const float extent = std::max(std::max(bounds[1] - bounds[0], bounds[3] - bounds[2]), bounds[5] - bounds[4]);
  centre_[0] = static_cast<float>(0.5) * (bounds[0] + bounds[1]);
  centre_[1] = static_cast<float>(0.5) * (bounds[2] + bounds[3]);
  centre_[2] = static_cast<float>(0.5) * (bounds[4] + bounds[5]);
  const float arg = extent / voxel_size;
  levels_ = arg > 1 ? static_cast<int>(std::ceil(std::log(arg) / std::log(2.0)) + 0.5) : 0;
  if (levels_ > 21) {
    throw std::invalid_argument("OctreeAddressing: more than 21 levels");
  }
  const auto half_root_side = static_cast<float>(0.5f * std::pow(2.0, levels_) * voxel_size);
  for (int a = 0; a < 3; ++a) {
    bounds_[2 * a] = centre_[a] - half_root_side;
    bounds_[2 * a + 1] = centre_[a] + half_root_side;
  }
}

bool OctreeAddressing::locate(float x, float y, float z, std::uint64_t& path, float centre[3]) const {
  if (x < bounds_[0] || x > bounds_[1] || y < bounds_[2] || y > bounds_[3] || z < bounds_[4] || z > bounds_[5]) {
    return false;
  }
  const float p[3] = {x, y, z};
  float lo[3] = {bounds_[0], bounds_[2], bounds_[4]};
  float hi[3] = {bounds_[1], bounds_[3], bounds_[5]};
  float c[3] = {centre_[0], centre_[1], centre_[2]};
  path = 0;
  for (int level = 0; level < levels_; ++level) {
    const float side = static_cast<float>(0.5) * (hi[0] - lo[0]);
    int id = 0;
    if (p[0] >= c[0]) id |= 4;
    if (p[1] >= c[1]) id |= 2;
    if (p[2] >= c[2]) id |= 1;
    float next[3];
    childCentre(lo, c, side, id, next);
    for (int a = 0; a < 3; ++a) {
      if ((id & (4 >> a)) != 0) {
        lo[a] = c[a];
      } else {
        hi[a] = c[a];
      }
      c[a] = next[a];
    }
    path = path * 8 + static_cast<std::uint64_t>(id);
  }
  centre[0] = c[0];
  centre[1] = c[1];
  centre[2] = c[2];
  return true;
}

void TransformVotes::build(const float position_bounds[6], float position_cell, float rotation_cell) {
  positions_.build(position_bounds, position_cell);
  if (rotation_cell != rotations_.voxelSize()) {
    // RotationSpace's constructor: axis-angle vectors within pi, a little more.
    const float min = -(AUX_PI_FLOAT + 0.000000001f);
    const float max = AUX_PI_FLOAT + 0.000000001f;
    const float rotation_bounds[6] = {min, max, min, max, min, max};
    rotations_.build(rotation_bounds, rotation_cell);
    if (rotations_.levels() > 13) {
      throw std::invalid_argument("TransformVotes: the rotation cell is too small");
    }
    neighbour_paths_.clear();
  }
  space_of_.clear();
  cell_of_.clear();
  spaces_.clear();
  cells_.clear();
}

const std::array<std::uint64_t, 26>& TransformVotes::neighbourPaths(std::uint64_t path, const float centre[3]) {
  if (neighbour_paths_.size() >= kMaxRemembered) {
    neighbour_paths_.clear();
  }
  const auto [at, added] = neighbour_paths_.try_emplace(path);
  if (!added) {
    return at->second;
  }
  // SimpleOctree::insertNeighbors looks at the centre plus or minus half a cell in each
  // direction: the leaves there (the leaf itself, when rounding puts the point on its side).
  const float s = static_cast<float>(0.5) * rotations_.voxelSize();
  std::size_t k = 0;
  for (int dx = 1; dx >= -1; --dx) {
    for (int dy = 1; dy >= -1; --dy) {
      for (int dz = 1; dz >= -1; --dz) {
        if (dx == 0 && dy == 0 && dz == 0) {
          continue;
        }
        const float x = dx > 0 ? centre[0] + s : (dx < 0 ? centre[0] - s : centre[0]);
        const float y = dy > 0 ? centre[1] + s : (dy < 0 ? centre[1] - s : centre[1]);
        const float z = dz > 0 ? centre[2] + s : (dz < 0 ? centre[2] - s : centre[2]);
        std::uint64_t found = kOutside;
        float unused[3];
        if (!rotations_.locate(x, y, z, found, unused)) {
          found = kOutside;
        }
        at->second[k++] = found;
      }
    }
  }
  return at->second;
}

void TransformVotes::add(const float position[3], const float rigid_transform[12]) {
  std::uint64_t position_path = 0;
  float position_centre[3];
  if (!positions_.locate(position[0], position[1], position[2], position_path, position_centre)) {
    return;
  }
  // PCL makes the position leaf (and its rotation space) before it looks at the rotation.
  const auto [at, new_space] = space_of_.try_emplace(position_path, static_cast<int>(spaces_.size()));
  const int space = at->second;
  if (new_space) {
    spaces_.push_back({{position_centre[0], position_centre[1], position_centre[2]}, {}});
  }
  // RigidTransformSpace::addRigidTransform's axis-angle vector.
  float angle = 0.0f;
  float axis_angle[3];
  pcl::recognition::aux::rotationMatrixToAxisAngle(rigid_transform, axis_angle, angle);
  pcl::recognition::aux::mult3(axis_angle, angle);
  std::uint64_t rotation_path = 0;
  float rotation_centre[3];
  if (!rotations_.locate(axis_angle[0], axis_angle[1], axis_angle[2], rotation_path, rotation_centre)) {
    return;
  }
  const std::uint64_t key = (static_cast<std::uint64_t>(space) << 40) | rotation_path;
  const auto [cell_at, new_cell] = cell_of_.try_emplace(key, static_cast<int>(cells_.size()));
  const int cell = cell_at->second;
  if (new_cell) {
    cells_.emplace_back();
    spaces_[static_cast<std::size_t>(space)].cells.push_back(cell);
    // SimpleOctree::insertNeighbors: the full leaves found there, each made a neighbour both ways.
    for (const std::uint64_t neighbour_path : neighbourPaths(rotation_path, rotation_centre)) {
      if (neighbour_path == kOutside) {
        continue;
      }
      const auto found = cell_of_.find((static_cast<std::uint64_t>(space) << 40) | neighbour_path);
      if (found == cell_of_.end()) {
        continue;
      }
      const int neighbour = found->second;
      auto& mine = cells_[static_cast<std::size_t>(cell)].neighbours;
      if (std::find(mine.begin(), mine.end(), neighbour) == mine.end()) {
        mine.push_back(neighbour);
      }
      auto& theirs = cells_[static_cast<std::size_t>(neighbour)].neighbours;
      if (std::find(theirs.begin(), theirs.end(), cell) == theirs.end()) {
        theirs.push_back(cell);
      }
    }
  }
  Cell& entry = cells_[static_cast<std::size_t>(cell)];
  pcl::recognition::aux::add3(entry.axis_angle, axis_angle);
  pcl::recognition::aux::add3(entry.translation, rigid_transform + 9);
  ++entry.votes;
}

std::vector<TransformVotes::Winner> TransformVotes::winners() const {
  std::vector<Winner> out;
  out.reserve(spaces_.size());
  for (const Space& space : spaces_) {
    int best = -1;
    int most = 0;
    for (const int cell : space.cells) {
      const Cell& entry = cells_[static_cast<std::size_t>(cell)];
      int votes = entry.votes;
      for (const int neighbour : entry.neighbours) {
        votes += cells_[static_cast<std::size_t>(neighbour)].votes;
      }
      if (votes > most) {
        most = votes;
        best = cell;
      }
    }
    if (best < 0) {
      continue;
    }
    // RotationSpaceCell::Entry::computeAverageRigidTransform.
    const Cell& entry = cells_[static_cast<std::size_t>(best)];
    float axis_angle[3] = {entry.axis_angle[0], entry.axis_angle[1], entry.axis_angle[2]};
    float translation[3] = {entry.translation[0], entry.translation[1], entry.translation[2]};
    if (entry.votes >= 2) {
      const float factor = 1.0f / static_cast<float>(entry.votes);
      pcl::recognition::aux::mult3(axis_angle, factor);
      pcl::recognition::aux::mult3(translation, factor);
    }
    Winner winner;
    winner.centre = space.centre;
    pcl::recognition::aux::axisAngleToRotationMatrix(axis_angle, winner.rigid_transform.data());
    pcl::recognition::aux::copy3(translation, winner.rigid_transform.data() + 9);
    out.push_back(winner);
  }
  return out;
}

}  // namespace costar::perception
