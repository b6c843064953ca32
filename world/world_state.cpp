#include "world/world_state.h"

#include <algorithm>
#include <set>
#include <stdexcept>

namespace costar::world {

const char* toString(SymbolKind kind) {
  switch (kind) {
    case SymbolKind::kFrame:
      return "frame";
    case SymbolKind::kJoints:
      return "joints";
    case SymbolKind::kObjectClass:
      return "class";
    case SymbolKind::kWrench:
      return "wrench";
    case SymbolKind::kNumber:
      return "number";
  }
  return "?";
}

std::string predicateKey(std::string_view name, std::span<const std::string> args) {
  std::string key(name);
  key += '(';
  for (std::size_t i = 0; i < args.size(); ++i) {
    key += (i == 0 ? "" : ",") + args[i];
  }
  key += ')';
  return key;
}

std::string Predicate::str() const { return (value ? "" : "not ") + predicateKey(name, args); }

void WorldState::update(const std::string& source, Report report) {
  for (auto& symbol : report.symbols) {
    symbol.source = source;
  }
  for (auto& predicate : report.predicates) {
    predicate.source = source;
  }
  auto it = reports_.find(source);
  if (it == reports_.end()) {
    it = reports_.emplace(source, Report{}).first;
  } else {
    unindex(it->second);
  }
  it->second = std::move(report);
  index(it->second);
  ++version_;
}

void WorldState::removeSource(const std::string& source) {
  const auto it = reports_.find(source);
  if (it != reports_.end()) {
    unindex(it->second);
    reports_.erase(it);
    ++version_;
  }
}

void WorldState::unindex(const Report& report) {
  for (const auto& symbol : report.symbols) {
    const auto found = symbol_index_.find(symbol.name);
    if (found != symbol_index_.end() && found->second == &symbol) {
      symbol_index_.erase(found);
      // Another source may report the same name: let it show again.
      for (const auto& [other_source, other] : reports_) {
        if (&other != &report) {
          for (const auto& candidate : other.symbols) {
            if (candidate.name == symbol.name) {
              symbol_index_[symbol.name] = &candidate;
            }
          }
        }
      }
    }
  }
  std::set<std::string_view> names;
  for (const auto& predicate : report.predicates) {
    const std::string key = predicateKey(predicate.name, predicate.args);
    auto& votes = predicate_index_[key];
    (predicate.value ? votes.first : votes.second) -= 1;
    if (votes.first == 0 && votes.second == 0) {
      predicate_index_.erase(key);
    }
    names.insert(predicate.name);
  }
  // The report's predicates are contiguous: drop them from each name's list in one pass.
  if (!report.predicates.empty()) {
    const Predicate* first = report.predicates.data();
    const Predicate* last = first + report.predicates.size();
    for (const std::string_view name : names) {
      auto& named = by_name_[std::string(name)];
      std::erase_if(named, [first, last](const Predicate* p) { return p >= first && p < last; });
    }
  }
}

void WorldState::index(const Report& report) {
  for (const auto& symbol : report.symbols) {
    symbol_index_[symbol.name] = &symbol;
  }
  for (const auto& predicate : report.predicates) {
    auto& votes = predicate_index_[predicateKey(predicate.name, predicate.args)];
    (predicate.value ? votes.first : votes.second) += 1;
    by_name_[predicate.name].push_back(&predicate);
  }
}

const std::vector<const Predicate*>& WorldState::predicatesNamed(const std::string& name) const {
  static const std::vector<const Predicate*> kNone;
  const auto it = by_name_.find(name);
  return it == by_name_.end() ? kNone : it->second;
}

const Symbol* WorldState::symbol(std::string_view name) const {
  const auto it = symbol_index_.find(std::string(name));
  return it == symbol_index_.end() ? nullptr : it->second;
}

std::vector<const Symbol*> WorldState::symbols() const {
  std::vector<const Symbol*> all;
  for (const auto& [source, report] : reports_) {
    for (const auto& symbol : report.symbols) {
      all.push_back(&symbol);
    }
  }
  return all;
}

bool WorldState::holds(std::string_view name, std::span<const std::string> args) const {
  const auto it = predicate_index_.find(predicateKey(name, args));
  if (it != predicate_index_.end()) {
    return it->second.first > 0 && it->second.second == 0;
  }
  const auto evaluator = evaluators_.find(std::string(name));
  return evaluator != evaluators_.end() && evaluator->second(*this, args);
}

void WorldState::setEvaluator(const std::string& predicate, PredicateEvaluator evaluator) {
  evaluators_[predicate] = std::move(evaluator);
}

std::vector<std::string> WorldState::match(std::string_view name, std::span<const std::string> args) const {
  const auto wildcard = std::find(args.begin(), args.end(), kWildcard);
  if (wildcard == args.end()) {
    return holds(name, args) ? std::vector<std::string>{""} : std::vector<std::string>{};
  }
  if (std::find(wildcard + 1, args.end(), kWildcard) != args.end()) {
    throw std::invalid_argument("a predicate pattern may have one '?' only");
  }
  const auto position = static_cast<std::size_t>(wildcard - args.begin());
  std::vector<std::string> candidates;
  if (isDerived(name)) {
    for (const auto& [symbol_name, symbol] : symbol_index_) {
      candidates.push_back(symbol_name);
    }
  } else {
    for (const Predicate* predicate : predicates(name)) {
      if (predicate->args.size() == args.size()) {
        candidates.push_back(predicate->args[position]);
      }
    }
  }
  std::sort(candidates.begin(), candidates.end());
  candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
  std::vector<std::string> found;
  std::vector<std::string> filled(args.begin(), args.end());
  for (const auto& candidate : candidates) {
    filled[position] = candidate;
    if (holds(name, filled)) {
      found.push_back(candidate);
    }
  }
  return found;
}

std::vector<const Predicate*> WorldState::predicates(std::string_view name) const {
  if (!name.empty()) {
    return predicatesNamed(std::string(name));
  }
  std::vector<const Predicate*> found;
  for (const auto& [source, report] : reports_) {
    for (const auto& predicate : report.predicates) {
      found.push_back(&predicate);
    }
  }
  return found;
}

std::optional<Pose> WorldState::worldPose(std::string_view frame) const {
  Pose pose = Pose::Identity();
  std::string current(frame);
  for (int depth = 0; depth < 64; ++depth) {
    if (current == "world") {
      return pose;
    }
    const Symbol* symbol = this->symbol(current);
    if (symbol == nullptr || symbol->frame() == nullptr) {
      return std::nullopt;
    }
    pose = symbol->frame()->pose * pose;
    current = symbol->frame()->parent;
  }
  return std::nullopt;  // a loop of parents
}

}  // namespace costar::world
