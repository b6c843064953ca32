#pragma once
// Predicate patterns as a plan writes them ("right_of(table_center); near(?, node_1)"), and
// the check a workcell makes of them before a plan runs. Light: needs no robot, so a plan can
// be validated from a workcell's description alone.

#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "component/component.h"

namespace costar::predicator {

/// One term of a query: predicate(args) with "?" for the symbol sought.
struct Pattern {
  std::string predicate;
  std::vector<std::string> args;
};

/// Parses "right_of(table_center); near(node_1)" into patterns with "?" for the object.
/// @throws std::invalid_argument naming the problem.
std::vector<Pattern> parsePredicateList(const std::string& text);

/// Checks one pattern: empty when fine, else the problem.
using PatternCheck = std::function<std::string(const Pattern&)>;

/// Checks a written list of patterns: its syntax, then `check` (if set) on each pattern.
/// Empty when valid, else the first problem.
std::string checkPatternList(std::string_view text, const PatternCheck& check);

/// The workcell's check of one pattern: the predicate is declared, with that many arguments
/// (the part counts as one), and every other argument is "?" or a known reference (a frame
/// that exists now, or an object class). Names of detected parts are not known before the
/// plan runs and are refused.
std::string checkPatternAgainst(const Pattern& pattern,
                                const std::map<std::string, component::PredicateDecl, std::less<>>& declared,
                                const std::function<bool(const std::string&)>& known_reference);

}  // namespace costar::predicator
