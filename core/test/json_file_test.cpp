#include "core/json_file.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace costar::core {
namespace {

std::string error(const std::string& text) {
  try {
    parseJson(text);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(ParseJson, AKeyGivenTwiceIsRefusedNamingTheKeyAndWhere) {
  EXPECT_EQ(error(R"({"a": 1, "a": 2})"), "(top level): key 'a' appears twice (a key may appear once in an object)");
  EXPECT_EQ(error(R"({"joints": [{"max": 1}, {"min": 0, "max": 1, "max": 2}]})"),
            "joints[1]: key 'max' appears twice (a key may appear once in an object)");
  EXPECT_EQ(error(R"({"a": {"b": [1, [2, 3], {"c": {"d": 0, "d": 0}}]}})"),
            "a.b[2].c: key 'd' appears twice (a key may appear once in an object)");
}

TEST(ParseJson, TheSameKeyInDifferentObjectsIsFine) {
  const nlohmann::json json = parseJson(R"({"parts": [{"name": "a"}, {"name": "b"}], "name": "c"})");
  EXPECT_EQ(json["parts"][1]["name"], "b");
  EXPECT_EQ(json["name"], "c");
}

TEST(ParseJson, TextThatIsNotJsonGivesTheLibrarysLineAndColumn) {
  EXPECT_THROW(parseJson("{\n\"a\": }"), nlohmann::json::parse_error);
  EXPECT_NE(error("{\n\"a\": }").find("line 2, column 6"), std::string::npos) << error("{\n\"a\": }");
}

}  // namespace
}  // namespace costar::core
