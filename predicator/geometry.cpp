#include "predicator/geometry.h"

#include <array>

namespace costar::predicator {

namespace {

constexpr std::array<std::pair<Relation, const char*>, 8> kNames = {{{Relation::kLeftOf, "left_of"},
                                                                     {Relation::kRightOf, "right_of"},
                                                                     {Relation::kInFrontOf, "in_front_of"},
                                                                     {Relation::kBehind, "behind"},
                                                                     {Relation::kAbove, "above"},
                                                                     {Relation::kBelow, "below"},
                                                                     {Relation::kNear, "near"},
                                                                     {Relation::kOn, "on"}}};

}  // namespace

const char* toString(Relation relation) {
  for (const auto& [r, name] : kNames) {
    if (r == relation) {
      return name;
    }
  }
  return "?";
}

std::optional<Relation> relationFromName(std::string_view name) {
  for (const auto& [r, known] : kNames) {
    if (name == known) {
      return r;
    }
  }
  return std::nullopt;
}

const std::vector<Relation>& allRelations() {
  static const std::vector<Relation> all = [] {
    std::vector<Relation> relations;
    for (const auto& [r, name] : kNames) {
      relations.push_back(r);
    }
    return relations;
  }();
  return all;
}

bool isContactRelation(Relation relation) { return relation == Relation::kNear || relation == Relation::kOn; }

Eigen::AlignedBox3d worldBox(const Eigen::AlignedBox3d& local, const world::Pose& pose) {
  Eigen::AlignedBox3d box;
  for (int corner = 0; corner < 8; ++corner) {
    box.extend(pose * local.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner)));
  }
  return box;
}

bool relationHolds(Relation relation, const Placed& subject, const Placed& reference, const Eigen::Matrix3d& axes,
                   const GeometryOptions& options) {
  const Eigen::Vector3d offset = axes.transpose() * (subject.position - reference.position);
  switch (relation) {
    case Relation::kLeftOf:
      return offset.y() > options.lateral_margin;
    case Relation::kRightOf:
      return offset.y() < -options.lateral_margin;
    case Relation::kInFrontOf:
      return offset.x() > options.lateral_margin;
    case Relation::kBehind:
      return offset.x() < -options.lateral_margin;
    case Relation::kAbove:
      return offset.z() > options.vertical_margin;
    case Relation::kBelow:
      return offset.z() < -options.vertical_margin;
    case Relation::kNear: {
      if (!subject.extent.isEmpty() && !reference.extent.isEmpty()) {
        // Gap between the boxes: zero when they overlap.
        const Eigen::Vector3d gap = (subject.extent.min() - reference.extent.max())
                                        .cwiseMax(reference.extent.min() - subject.extent.max())
                                        .cwiseMax(0.0);
        return gap.norm() < options.near_distance;
      }
      const Eigen::Vector3d a = subject.extent.isEmpty() ? subject.position : subject.extent.center();
      const Eigen::Vector3d b = reference.extent.isEmpty() ? reference.position : reference.extent.center();
      return (a - b).norm() < options.near_distance;
    }
    case Relation::kOn: {
      if (subject.extent.isEmpty() || reference.extent.isEmpty()) {
        return false;
      }
      const double gap = subject.extent.min().z() - reference.extent.max().z();
      const Eigen::Vector2d centre = subject.position.head<2>();
      const bool over = (centre.array() >= reference.extent.min().head<2>().array()).all() &&
                        (centre.array() <= reference.extent.max().head<2>().array()).all();
      return std::abs(gap) <= options.on_gap && over && subject.position.z() > reference.position.z();
    }
  }
  return false;
}

}  // namespace costar::predicator
