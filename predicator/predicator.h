#pragma once
// Predicator (the paper, Sec. III-A): a component made of sub-components that produce
// descriptive predicates from the symbols of the other components, and the queries task plans
// and SmartMove ask of the world: is this true; which symbols satisfy all (or any) of these.
//
// Sub-components (each can be switched off and on at run time with ActivatePredicates):
//   geometry  left_of, right_of, in_front_of, behind, above, below — of every object relative to
//             each configured reference (default: table_center), and on demand relative to any
//             symbol
//   contact   near, on — between objects
//   force     force_above(N) — the arm's wrist force (its `wrench` symbol) above N newtons,
//             evaluated on demand (N is a number, not a symbol)
// Objects are the symbols that some component classifies with is_a(object, class); their
// extent comes from the class's shape (data/objects).
//
// Updates cost O(objects moved): the relations of an object are recomputed only when it or a
// reference moved, and near/on only against its neighbours (a spatial hash), never all pairs.

#include <map>
#include <set>
#include <string>
#include <vector>

#include "component/operation_table.h"
#include "predicator/geometry.h"
#include "predicator/pattern.h"
#include "world/object_class.h"
#include "world/world_state.h"

namespace costar::predicator {

struct PredicatorConfig {
  std::string name = "predicator";
  GeometryOptions geometry;
  /// References whose relations are reported (and so appear in the world state and editor).
  std::vector<std::string> references = {"table_center"};
  /// The frame whose axes say what left, front and up are.
  std::string viewpoint = "table_center";
};

enum class MatchMode { kAll, kAny };

class Predicator final : public component::TableComponent {
 public:
  /// Registers the geometric predicates' evaluators in `world`, which must outlive this.
  Predicator(world::WorldState& world, std::vector<world::ObjectClass> classes, PredicatorConfig config = {});

  world::Report report() const override;

  /// Whether predicate(args) holds now (reported by any component, or evaluated).
  bool test(const std::string& predicate, const std::vector<std::string>& args) const;
  /// The symbols that satisfy all (or any) patterns when put in place of "?" (sorted).
  /// @throws std::invalid_argument for a pattern without exactly one "?".
  std::vector<std::string> match(const std::vector<Pattern>& patterns, MatchMode mode = MatchMode::kAll) const;

  bool active(const std::string& sub_component) const { return !inactive_.contains(sub_component); }
  /// Relations recomputed by the last report() (for the benchmark and tests).
  std::size_t lastRecomputed() const { return recomputed_; }

 private:
  struct ObjectState {
    std::string object_class;
    world::Pose pose;
    Placed placed;
  };
  std::unique_ptr<component::RunningOperation> activatePredicates(const component::ParamMap& params);
  std::optional<Placed> place(const std::string& symbol) const;
  Eigen::Matrix3d viewpointAxes() const;
  void refresh() const;

  world::WorldState& world_;
  std::map<std::string, world::ObjectClass> classes_;
  PredicatorConfig config_;
  std::set<std::string> inactive_;

  // Incremental state, updated by report().
  mutable std::map<std::string, ObjectState> objects_;
  mutable std::map<std::string, world::Pose> reference_poses_;
  mutable std::map<std::string, std::vector<world::Predicate>> facts_;  // by subject object
  mutable std::size_t recomputed_ = 0;
};

}  // namespace costar::predicator
