#include "world/world_state.h"

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
  return it != predicate_index_.end() && it->second.first > 0 && it->second.second == 0;
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
