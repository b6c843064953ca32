#pragma once
// The world state a task plan sees: exactly the union of the symbols and predicates that
// the components report (the paper, Sec. III-A). Symbols are 6-DOF frames, joint
// configurations, object classes and measurements (a wrench, a tool's speed); predicates are
// named relations over symbol names.

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <variant>
#include <vector>

#include "core/clock.h"
#include "world/pose.h"

namespace costar::world {

/// A coordinate frame: pose relative to `parent` ("world" is the root).
struct FrameValue {
  std::string parent = "world";
  Pose pose = Pose::Identity();
};

/// A joint configuration (radians / metres per joint).
struct JointsValue {
  std::vector<std::string> joint_names;
  std::vector<double> positions;
};

/// An object class, e.g. "node" or "link", with what perception and SmartMove need to know.
struct ObjectClassValue {
  std::string description;
};

/// A force and a torque (N, N m) in the axes of `frame`, the torque about its origin: the arm's
/// `wrench`, what the tool pushes its surroundings with, in the tool frame at the tool centre point.
struct WrenchValue {
  std::string frame;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();
};

/// One measured quantity with its unit (a power tool's speed in rpm).
struct NumberValue {
  double value = 0.0;
  std::string unit;
};

enum class SymbolKind { kFrame, kJoints, kObjectClass, kWrench, kNumber };
const char* toString(SymbolKind kind);

struct Symbol {
  std::string name;
  std::string source;  // the component that reports it
  TimePoint stamp{};
  std::variant<FrameValue, JointsValue, ObjectClassValue, WrenchValue, NumberValue> value;
  /// The colour seen on the object a frame stands for (perception: the mean RGB of its points,
  /// in [0, 1]); absent for other symbols.
  std::optional<Eigen::Vector3d> color;

  SymbolKind kind() const { return static_cast<SymbolKind>(value.index()); }
  const FrameValue* frame() const { return std::get_if<FrameValue>(&value); }
  const JointsValue* joints() const { return std::get_if<JointsValue>(&value); }
  const WrenchValue* wrench() const { return std::get_if<WrenchValue>(&value); }
  const NumberValue* number() const { return std::get_if<NumberValue>(&value); }
};

struct Predicate {
  std::string name;
  std::vector<std::string> args;
  bool value = true;
  std::string source;

  /// "name(arg1,arg2)".
  std::string str() const;
};

/// What one component reports: its symbols and predicates, replacing what it reported before.
struct Report {
  std::vector<Symbol> symbols;
  std::vector<Predicate> predicates;
};

/// Evaluates a derived predicate (e.g. left_of for any reference frame) from the symbols.
using PredicateEvaluator = std::function<bool(const class WorldState&, std::span<const std::string> args)>;

/// The union of every source's report. Not thread-safe: one thread updates and reads it
/// (the executor's); others get copies.
class WorldState {
 public:
  /// The wildcard of match() patterns: "?" stands for any symbol.
  static constexpr std::string_view kWildcard = "?";

  /// Replaces everything `source` reported. Symbols and predicates get `source` stamped in.
  void update(const std::string& source, Report report);
  void removeSource(const std::string& source);

  const Symbol* symbol(std::string_view name) const;
  std::vector<const Symbol*> symbols() const;

  /// True when some source reports name(args) with value true and none reports it false, or,
  /// for a derived predicate not reported, when its evaluator says so.
  bool holds(std::string_view name, std::span<const std::string> args) const;

  /// Registers how to evaluate a derived predicate on demand (the Predicator's geometric
  /// predicates: any reference frame, not only those it reports).
  void setEvaluator(const std::string& predicate, PredicateEvaluator evaluator);
  bool isDerived(std::string_view predicate) const { return evaluators_.contains(std::string(predicate)); }

  /// The symbols that make name(args) hold when put in place of the one "?" in `args`
  /// (sorted). With no "?", the empty list or {""} when it holds.
  /// @throws std::invalid_argument when `args` has more than one "?".
  std::vector<std::string> match(std::string_view name, std::span<const std::string> args) const;
  /// Every predicate reported with this name (all of them if `name` is empty).
  std::vector<const Predicate*> predicates(std::string_view name = {}) const;
  /// The same without copying, for one name (empty list when none).
  const std::vector<const Predicate*>& predicatesNamed(const std::string& name) const;

  /// Pose of a frame symbol in "world", composing parents; nullopt when the frame or one of
  /// its parents is unknown (or the parents form a loop).
  std::optional<Pose> worldPose(std::string_view frame) const;

  /// Grows on every update; lets readers skip work when nothing changed.
  std::uint64_t version() const { return version_; }

 private:
  void unindex(const Report& report);
  void index(const Report& report);

  std::map<std::string, Report, std::less<>> reports_;
  // Indexes kept up to date source by source: an update costs the size of that source's report.
  std::unordered_map<std::string, const Symbol*> symbol_index_;             // name -> symbol
  std::unordered_map<std::string, std::pair<int, int>> predicate_index_;    // "name(args)" -> votes
  std::unordered_map<std::string, std::vector<const Predicate*>> by_name_;  // name -> predicates
  std::unordered_map<std::string, PredicateEvaluator> evaluators_;
  std::uint64_t version_ = 0;
};

/// "name(a,b)": the key a predicate is indexed under.
std::string predicateKey(std::string_view name, std::span<const std::string> args);

}  // namespace costar::world
