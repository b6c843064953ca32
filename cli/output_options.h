#pragma once
// An output option never names a file the command reads: `costar run plan.xml --trace plan.xml`
// replaced the plan with its trace, `--waypoints W.json --trace W.json` every taught waypoint, and
// `costar trials plan.xml --json plan.xml` the plan with its results. Checked before anything runs.

#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

namespace costar::cli {

/// The files a command reads, each with what names it for people ("the plan", "--waypoints").
using NamedFiles = std::vector<std::pair<std::filesystem::path, std::string>>;

/// Whether `a` and `b` name the same file: the same file when both exist (links and other
/// spellings included), else the same absolute, normalised path.
inline bool sameFile(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code error;
  if (std::filesystem::exists(a, error) && std::filesystem::exists(b, error)) {
    const bool same = std::filesystem::equivalent(a, b, error);
    return !error && same;
  }
  const auto normal = [](const std::filesystem::path& path) {
    std::error_code failed;
    const std::filesystem::path canonical = std::filesystem::weakly_canonical(path, failed);
    return failed ? std::filesystem::absolute(path, failed).lexically_normal() : canonical;
  };
  return normal(a) == normal(b);
}

/// @throws std::invalid_argument "cannot write WHAT 'FILE': it is INPUT, which this command reads"
/// when `output` (not empty) is one of `inputs` (empty ones are skipped).
inline void refuseWritingAnInput(const std::filesystem::path& output, const std::string& what,
                                 const NamedFiles& inputs) {
  if (output.empty()) {
    return;
  }
  for (const auto& [input, name] : inputs) {
    if (!input.empty() && sameFile(output, input)) {
      throw std::invalid_argument("cannot write " + what + " '" + output.string() + "': it is " + name +
                                  ", which this command reads");
    }
  }
}

/// A validator for an output file's name: not empty (`costar run --trace ''` ran and wrote
/// nothing, without a word).
inline CLI::Validator aFileName() {
  return CLI::Validator(
      [](const std::string& text) -> std::string {
        return text.empty() ? std::string("needs a file name, not ''") : std::string();
      },
      "FILE");
}

}  // namespace costar::cli
