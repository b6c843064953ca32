#pragma once
// Checking a JSON data file field by field, with errors that name the field: "joints[2].max:
// must be a finite number, not \"fast\"". Shared by the description readers (arm/, workcell/).

#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <string>

namespace costar::core::json_fields {

/// A problem with one field. @throws std::runtime_error "FIELD: PROBLEM".
[[noreturn]] inline void fail(const std::string& field, const std::string& problem) {
  throw std::runtime_error(field + ": " + problem);
}

/// A value as it appears in the file, cut to about 60 bytes for an error message. The cut never
/// splits a UTF-8 character, so the message can itself be put into JSON.
inline std::string shown(const nlohmann::json& value) {
  std::string text = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (text.size() <= 60) {
    return text;
  }
  std::size_t cut = 57;
  while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0U) == 0x80U) {
    --cut;  // back to the first byte of the character the cut would split
  }
  return text.substr(0, cut) + "...";
}

/// `field.key`, or `key` at the top level.
inline std::string join(const std::string& field, const std::string& key) {
  return field.empty() ? key : field + "." + key;
}

/// @throws std::runtime_error naming the first key of `object` that is not in `known`.
inline void onlyKnown(const nlohmann::json& object, const std::string& field, const std::set<std::string>& known) {
  for (const auto& [key, value] : object.items()) {
    if (!known.contains(key)) {
      std::string list;
      for (const std::string& name : known) {
        list += (list.empty() ? "" : ", ") + name;
      }
      fail(join(field, key), "unknown field (known: " + list + ")");
    }
  }
}

}  // namespace costar::core::json_fields
