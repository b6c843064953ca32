#include "core/json_file.h"

#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/files.h"

namespace costar::core {

namespace {

/// Where the parser is: one entry per open object or array, outermost first.
class Place {
 public:
  void open(bool object) { frames_.push_back({object, {}, {}, 0}); }
  void close() {
    frames_.pop_back();
    if (!frames_.empty() && !frames_.back().object) {
      ++frames_.back().index;  // the array's element is complete
    }
  }
  void key(const std::string& key) {
    Frame& frame = frames_.back();
    if (!frame.keys.insert(key).second) {
      throw std::runtime_error(where(frames_.size()) + ": key '" + key +
                               "' appears twice (a key may appear once in an object)");
    }
    frame.key = key;
  }
  /// A value that is neither an object nor an array.
  void value() {
    if (!frames_.empty() && !frames_.back().object) {
      ++frames_.back().index;
    }
  }

 private:
  struct Frame {
    bool object = false;
    std::set<std::string> keys;
    std::string key;        // an object's current key
    std::size_t index = 0;  // an array's current element
  };

  /// The field of the innermost `depth` frames: "joints[2].origin".
  std::string where(std::size_t depth) const {
    std::string field;
    for (std::size_t i = 0; i + 1 < depth; ++i) {
      const Frame& frame = frames_[i];
      // Appended piece by piece: GCC 12 warns (falsely, -Wrestrict) of "[" + std::to_string(...).
      if (frame.object) {
        field += field.empty() ? "" : ".";
        field += frame.key;
      } else {
        field += '[';
        field += std::to_string(frame.index);
        field += ']';
      }
    }
    return field.empty() ? "(top level)" : field;
  }

  std::vector<Frame> frames_;
};

}  // namespace

nlohmann::json parseJson(std::string_view text) {
  Place place;
  const nlohmann::json::parser_callback_t check = [&place](int /*depth*/, nlohmann::json::parse_event_t event,
                                                           nlohmann::json& parsed) {
    switch (event) {
      case nlohmann::json::parse_event_t::object_start:
        place.open(true);
        break;
      case nlohmann::json::parse_event_t::array_start:
        place.open(false);
        break;
      case nlohmann::json::parse_event_t::object_end:
      case nlohmann::json::parse_event_t::array_end:
        place.close();
        break;
      case nlohmann::json::parse_event_t::key:
        place.key(parsed.get_ref<const std::string&>());
        break;
      case nlohmann::json::parse_event_t::value:
        place.value();
        break;
    }
    return true;
  };
  try {
    return nlohmann::json::parse(text.begin(), text.end(), check);
  } catch (const nlohmann::json::parse_error& error) {
    std::string message = jsonErrorText(error);
    constexpr std::string_view kPrefix = "parse error at ";
    if (message.starts_with(kPrefix)) {
      message.erase(0, kPrefix.size());
    }
    throw JsonSyntaxError(message);
  }
}

std::string jsonErrorText(const std::exception& error) {
  std::string message = error.what();
  if (message.starts_with("[json.exception.")) {
    const auto end = message.find("] ");
    if (end != std::string::npos) {
      message.erase(0, end + 2);
    }
  }
  return message;
}

nlohmann::json readJsonFile(const std::filesystem::path& path) { return parseJson(readFile(path)); }

}  // namespace costar::core
