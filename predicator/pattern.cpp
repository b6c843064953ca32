#include "predicator/pattern.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>

namespace costar::predicator {

namespace {

std::string trim(std::string text) {
  const auto first = text.find_first_not_of(" \t\n");
  if (first == std::string::npos) {
    return {};
  }
  const auto last = text.find_last_not_of(" \t\n");
  return text.substr(first, last - first + 1);
}

bool isName(const std::string& text) {
  return !text.empty() && std::all_of(text.begin(), text.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '?';
  });
}

}  // namespace

std::vector<Pattern> parsePredicateList(const std::string& text) {
  std::vector<Pattern> patterns;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(';', start), text.size());
    const std::string item = trim(text.substr(start, end - start));
    start = end + 1;
    if (item.empty()) {
      continue;
    }
    Pattern pattern;
    const auto open = item.find('(');
    if (open == std::string::npos) {
      pattern.predicate = item;
    } else {
      if (item.back() != ')') {
        throw std::invalid_argument("'" + item + "' must look like name(arg, ...)");
      }
      pattern.predicate = trim(item.substr(0, open));
      const std::string inside = item.substr(open + 1, item.size() - open - 2);
      std::size_t a = 0;
      while (a <= inside.size()) {
        const std::size_t b = std::min(inside.find(',', a), inside.size());
        const std::string arg = trim(inside.substr(a, b - a));
        if (!arg.empty() || b < inside.size()) {
          if (!isName(arg)) {
            throw std::invalid_argument("'" + arg + "' in '" + item + "' is not a symbol name");
          }
          pattern.args.push_back(arg);
        }
        a = b + 1;
      }
    }
    if (!isName(pattern.predicate) || pattern.predicate.find('?') != std::string::npos) {
      throw std::invalid_argument("'" + pattern.predicate + "' is not a predicate name");
    }
    const auto wildcards = std::count(pattern.args.begin(), pattern.args.end(), "?");
    if (wildcards == 0) {
      pattern.args.insert(pattern.args.begin(), "?");  // the object is the first argument
    } else if (wildcards > 1) {
      throw std::invalid_argument("'" + item + "' has more than one '?'");
    }
    patterns.push_back(std::move(pattern));
  }
  return patterns;
}

std::string checkPatternList(std::string_view text, const PatternCheck& check) {
  try {
    for (const auto& pattern : parsePredicateList(std::string(text))) {
      if (check) {
        if (std::string problem = check(pattern); !problem.empty()) {
          return problem;
        }
      }
    }
    return {};
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
}

std::string checkPatternAgainst(const Pattern& pattern,
                                const std::map<std::string, component::PredicateDecl, std::less<>>& declared,
                                const std::function<bool(const std::string&)>& known_reference) {
  const auto it = declared.find(pattern.predicate);
  if (it == declared.end()) {
    std::string known;
    for (const auto& [name, decl] : declared) {
      known += (known.empty() ? "" : ", ") + name;
    }
    return "unknown predicate '" + pattern.predicate + "' (known: " + known + ")";
  }
  if (pattern.args.size() != it->second.arity) {
    return "predicate '" + pattern.predicate + "' takes " + std::to_string(it->second.arity) + " argument(s), " +
           std::to_string(pattern.args.size()) + " given (the part counts as one)";
  }
  for (const auto& arg : pattern.args) {
    if (arg != "?" && !known_reference(arg)) {
      return "unknown reference frame '" + arg + "' in " + pattern.predicate + "(...)";
    }
  }
  return {};
}

}  // namespace costar::predicator
