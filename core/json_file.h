#pragma once
// JSON data files, read one way everywhere: a key given twice in one object is refused (the
// JSON library would keep the last one silently), and only a regular file of a sane size is
// read (core/files.h).

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace costar::core {

/// Text that is not JSON: "line 2, column 19: syntax error while parsing object key -
/// unexpected ','; expected string literal" (the JSON library's own words, without its
/// "[json.exception.parse_error.101] parse error at " prefix).
class JsonSyntaxError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An exception's message as a person should read it: a JSON library exception loses its
/// "[json.exception.type_error.302] " prefix ("type must be number, but is string"); any other
/// message is returned as it is.
std::string jsonErrorText(const std::exception& error);

/// nlohmann::json::parse, refusing a key that appears twice in one object.
/// @throws JsonSyntaxError for text that is not JSON (its message gives the line and column);
/// std::runtime_error "FIELD: key 'KEY' appears twice (a key may appear once in an object)" for
/// a duplicate, FIELD the object's place ("joints[2]", "(top level)").
nlohmann::json parseJson(std::string_view text);

/// readFile (regular files up to kMaxDataFileBytes) and parseJson.
/// @throws std::runtime_error "cannot read 'PATH': PROBLEM" when the file cannot be read, or
/// what parseJson throws.
nlohmann::json readJsonFile(const std::filesystem::path& path);

}  // namespace costar::core
