#include "predicator/predicator.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace costar::predicator {

using component::OperationResult;
using component::ParamSpec;
using component::ValueType;

namespace {

bool samePose(const world::Pose& a, const world::Pose& b) { return a.matrix() == b.matrix(); }

const char* subComponentOf(Relation relation) { return isContactRelation(relation) ? "contact" : "geometry"; }

/// Cells of a uniform grid in x, y, for neighbour search.
struct CellKey {
  long x;
  long y;
  bool operator==(const CellKey&) const = default;
};
struct CellHash {
  std::size_t operator()(const CellKey& key) const {
    return std::hash<long>()(key.x) * 73856093u ^ std::hash<long>()(key.y) * 19349663u;
  }
};

}  // namespace

Predicator::Predicator(world::WorldState& world, std::vector<world::ObjectClass> classes, PredicatorConfig config)
    : world_(world), config_(std::move(config)) {
  for (auto& object : classes) {
    std::string name = object.name;
    classes_.emplace(std::move(name), std::move(object));
  }
  component::ComponentDescription description;
  description.name = config_.name;
  description.type = "Predicator";
  description.inputs = {"symbols"};
  for (const Relation relation : allRelations()) {
    description.predicates.push_back(
        {toString(relation), 2, std::string(toString(relation)) + "(a, b): see docs/PREDICATES.md"});
    world_.setEvaluator(toString(relation),
                        [this, relation](const world::WorldState&, std::span<const std::string> args) {
                          if (args.size() != 2 || !active(subComponentOf(relation))) {
                            return false;
                          }
                          const auto subject = place(args[0]);
                          const auto reference = place(args[1]);
                          return subject && reference && args[0] != args[1] &&
                                 relationHolds(relation, *subject, *reference, viewpointAxes(), config_.geometry);
                        });
  }
  // The force sub-component: force_above(N) from the arm's wrist sensor (its `wrench` symbol).
  description.predicates.push_back({"force_above", 1,
                                    "force_above(N): the wrist sensor's force (the wrench symbol) is above N newtons",
                                    /*numeric_arguments=*/true});
  world_.setEvaluator("force_above", [this](const world::WorldState& state, std::span<const std::string> args) {
    if (args.size() != 1 || !active("force")) {
      return false;
    }
    const world::Symbol* symbol = state.symbol("wrench");
    const world::WrenchValue* wrench = symbol != nullptr ? symbol->wrench() : nullptr;
    const auto threshold = component::parseValue(ValueType::kDouble, args[0]);
    return wrench != nullptr && threshold && wrench->force.norm() > threshold->asDouble();
  });
  ParamSpec sub_component{
      "sub_component", ValueType::kString, "which predicates", {}, {"geometry", "contact", "force"}};
  component::OperationTable operations;
  operations.add({"ActivatePredicates",
                  "Switches a group of the predicator's predicates on or off.",
                  {sub_component, {"active", ValueType::kBool, "on or off", true}},
                  component::OperationKind::kKnowledge},
                 [this](const component::ParamMap& params) { return activatePredicates(params); });
  declare(std::move(description), std::move(operations));
}

Eigen::Matrix3d Predicator::viewpointAxes() const {
  const auto pose = world_.worldPose(config_.viewpoint);
  return pose ? Eigen::Matrix3d(pose->linear()) : Eigen::Matrix3d::Identity();
}

std::optional<Placed> Predicator::place(const std::string& symbol) const {
  const auto pose = world_.worldPose(symbol);
  if (!pose) {
    return std::nullopt;
  }
  if (const auto it = objects_.find(symbol); it != objects_.end() && samePose(it->second.pose, *pose)) {
    return it->second.placed;
  }
  Placed placed{pose->translation(), {}};
  for (const auto& [class_name, object] : classes_) {
    const std::vector<std::string> args{symbol, class_name};
    if (world_.holds("is_a", args)) {
      placed.extent = worldBox(object.bounds(), *pose);
      break;
    }
  }
  return placed;
}

void Predicator::refresh() const {
  recomputed_ = 0;
  // The objects now: symbols classified by is_a with a known class and a pose.
  std::map<std::string, ObjectState> now;
  for (const world::Predicate* is_a : world_.predicatesNamed("is_a")) {
    if (is_a->args.size() != 2 || !is_a->value) {
      continue;
    }
    const auto object_class = classes_.find(is_a->args[1]);
    const auto pose = world_.worldPose(is_a->args[0]);
    if (object_class == classes_.end() || !pose) {
      continue;
    }
    now[is_a->args[0]] = {object_class->first, *pose,
                          Placed{pose->translation(), worldBox(object_class->second.bounds(), *pose)}};
  }
  // References that moved invalidate every object's geometry facts.
  bool references_moved = false;
  std::map<std::string, world::Pose> references;
  for (const auto& reference : config_.references) {
    if (const auto pose = world_.worldPose(reference)) {
      references[reference] = *pose;
      const auto previous = reference_poses_.find(reference);
      references_moved = references_moved || previous == reference_poses_.end() || !samePose(previous->second, *pose);
    }
  }
  references_moved = references_moved || references.size() != reference_poses_.size();
  reference_poses_ = references;

  // Where each changed object is, or was (for one that is gone, its neighbours' facts about
  // it go).
  std::vector<std::pair<std::string, Eigen::Vector3d>> moved;
  for (const auto& [name, state] : now) {
    const auto previous = objects_.find(name);
    if (references_moved || previous == objects_.end() || !samePose(previous->second.pose, state.pose)) {
      moved.emplace_back(name, state.placed.position);
      if (previous != objects_.end()) {
        moved.emplace_back(name, previous->second.placed.position);
      }
    }
  }
  for (const auto& [name, state] : objects_) {
    if (!now.contains(name)) {
      moved.emplace_back(name, state.placed.position);
    }
  }
  objects_ = std::move(now);
  if (moved.empty()) {
    return;
  }

  // Neighbour grid for the contact relations: a cell is wider than the largest object plus
  // the near distance, so every contact partner is in the 3 x 3 cells around.
  double largest = 0.0;
  for (const auto& [class_name, object] : classes_) {
    largest = std::max(largest, object.bounds().sizes().norm());
  }
  const double cell = largest + config_.geometry.near_distance;
  const auto key = [cell](const Eigen::Vector3d& p) {
    return CellKey{static_cast<long>(std::floor(p.x() / cell)), static_cast<long>(std::floor(p.y() / cell))};
  };
  std::unordered_map<CellKey, std::vector<const std::string*>, CellHash> grid;
  for (const auto& [name, state] : objects_) {
    grid[key(state.placed.position)].push_back(&name);
  }
  const auto neighbours = [&](const Eigen::Vector3d& position, auto&& visit) {
    const CellKey center = key(position);
    for (long dx = -1; dx <= 1; ++dx) {
      for (long dy = -1; dy <= 1; ++dy) {
        if (const auto it = grid.find({center.x + dx, center.y + dy}); it != grid.end()) {
          for (const std::string* name : it->second) {
            visit(*name);
          }
        }
      }
    }
  };
  const Eigen::Matrix3d axes = viewpointAxes();
  const GeometryOptions& options = config_.geometry;
  const bool geometry = active("geometry");
  const bool contact = active("contact");
  const auto isContactFact = [](const world::Predicate& fact) {
    return fact.name == toString(Relation::kNear) || fact.name == toString(Relation::kOn);
  };
  const auto addContacts = [&](const std::string& subject, const std::string& other) {
    for (const Relation relation : {Relation::kNear, Relation::kOn}) {
      ++recomputed_;
      if (relationHolds(relation, objects_.at(subject).placed, objects_.at(other).placed, axes, options)) {
        facts_[subject].push_back({toString(relation), {subject, other}, true, ""});
      }
    }
  };

  std::set<std::string> changed;
  for (const auto& [name, position] : moved) {
    changed.insert(name);
  }
  // 1. A changed object's own facts: recomputed whole (or dropped when it is gone).
  for (const std::string& name : changed) {
    facts_.erase(name);
    const auto it = objects_.find(name);
    if (it == objects_.end()) {
      continue;
    }
    std::vector<world::Predicate>& facts = facts_[name];
    if (geometry) {
      for (const auto& [reference, pose] : reference_poses_) {
        const Placed target{pose.translation(), {}};
        for (const Relation relation : allRelations()) {
          if (!isContactRelation(relation)) {
            ++recomputed_;
            if (relationHolds(relation, it->second.placed, target, axes, options)) {
              facts.push_back({toString(relation), {name, reference}, true, ""});
            }
          }
        }
      }
    }
    if (contact) {
      neighbours(it->second.placed.position, [&](const std::string& other) {
        if (other != name) {
          addContacts(name, other);
        }
      });
    }
  }
  // 2. Neighbours' facts about a changed object, near where it is and where it was: only the
  //    pairs with it are recomputed.
  if (contact) {
    std::set<std::string> neighbours_done;
    for (const auto& [name, position] : moved) {
      neighbours(position, [&](const std::string& other) {
        if (changed.contains(other) || !neighbours_done.insert(other + "/" + name).second) {
          return;
        }
        auto& facts = facts_[other];
        std::erase_if(facts, [&](const world::Predicate& fact) { return isContactFact(fact) && fact.args[1] == name; });
        if (objects_.contains(name)) {
          addContacts(other, name);
        }
      });
    }
  }
}

world::Report Predicator::report() const {
  refresh();
  world::Report report;
  for (const auto& [subject, facts] : facts_) {
    report.predicates.insert(report.predicates.end(), facts.begin(), facts.end());
  }
  return report;
}

bool Predicator::test(const std::string& predicate, const std::vector<std::string>& args) const {
  return world_.holds(predicate, args);
}

std::vector<std::string> Predicator::match(const std::vector<Pattern>& patterns, MatchMode mode) const {
  std::vector<std::string> result;
  bool first = true;
  for (const Pattern& pattern : patterns) {
    if (std::count(pattern.args.begin(), pattern.args.end(), world::WorldState::kWildcard) != 1) {
      throw std::invalid_argument("each pattern needs exactly one '?': " +
                                  world::predicateKey(pattern.predicate, pattern.args));
    }
    const std::vector<std::string> found = world_.match(pattern.predicate, pattern.args);
    if (first) {
      result = found;
      first = false;
    } else if (mode == MatchMode::kAll) {
      std::vector<std::string> both;
      std::set_intersection(result.begin(), result.end(), found.begin(), found.end(), std::back_inserter(both));
      result = std::move(both);
    } else {
      std::vector<std::string> either;
      std::set_union(result.begin(), result.end(), found.begin(), found.end(), std::back_inserter(either));
      result = std::move(either);
    }
  }
  return result;
}

std::unique_ptr<component::RunningOperation> Predicator::activatePredicates(const component::ParamMap& params) {
  const std::string sub_component = params.at("sub_component").asString();
  if (params.at("active").asBool()) {
    inactive_.erase(sub_component);
  } else {
    inactive_.insert(sub_component);
  }
  reference_poses_.clear();  // recompute everything at the next report
  objects_.clear();
  facts_.clear();
  return std::make_unique<component::FinishedOperation>(OperationResult::success());
}

}  // namespace costar::predicator
