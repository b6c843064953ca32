#pragma once
// JSON data files, read one way everywhere: a key given twice in one object is refused (the
// JSON library would keep the last one silently), and only a regular file of a sane size is
// read (core/files.h).

#include <filesystem>
#include <string_view>

#include <nlohmann/json.hpp>

namespace costar::core {

/// nlohmann::json::parse, refusing a key that appears twice in one object.
/// @throws nlohmann::json::parse_error for text that is not JSON (its message gives the line
/// and column); std::runtime_error "FIELD: key 'KEY' appears twice (a key may appear once in
/// an object)" for a duplicate, FIELD the object's place ("joints[2]", "(top level)").
nlohmann::json parseJson(std::string_view text);

/// readFile (regular files up to kMaxDataFileBytes) and parseJson.
/// @throws std::runtime_error "cannot read 'PATH': PROBLEM" when the file cannot be read, or
/// what parseJson throws.
nlohmann::json readJsonFile(const std::filesystem::path& path);

}  // namespace costar::core
