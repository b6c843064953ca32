#include "world/world_state.h"

#include <algorithm>
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
  reports_.insert_or_assign(source, std::move(report));
  rebuildIndex();
}

void WorldState::removeSource(const std::string& source) {
  if (reports_.erase(source) > 0) {
    rebuildIndex();
  }
}

void WorldState::rebuildIndex() {
  symbol_index_.clear();
  predicate_index_.clear();
  for (const auto& [source, report] : reports_) {
    for (const auto& symbol : report.symbols) {
      symbol_index_[symbol.name] = &symbol;
    }
    for (const auto& predicate : report.predicates) {
      auto& votes = predicate_index_[predicateKey(predicate.name, predicate.args)];
      (predicate.value ? votes.first : votes.second) += 1;
    }
  }
  ++version_;
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
  std::vector<const Predicate*> found;
  for (const auto& [source, report] : reports_) {
    for (const auto& predicate : report.predicates) {
      if (name.empty() || predicate.name == name) {
        found.push_back(&predicate);
      }
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
