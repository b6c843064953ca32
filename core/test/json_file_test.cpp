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

// A hostile tester saw "[json.exception.parse_error.101] parse error at line 2, ..." in the CLI's
// messages: the line and column stay, the library's internal prefix goes.
TEST(ParseJson, TextThatIsNotJsonGivesTheLineAndColumnWithoutTheLibrarysPrefix) {
  EXPECT_THROW(parseJson("{\n\"a\": }"), JsonSyntaxError);
  const std::string message = error("{\n\"a\": }");
  EXPECT_TRUE(message.starts_with("line 2, column 6: syntax error")) << message;
  EXPECT_EQ(message.find("json.exception"), std::string::npos) << message;
}

TEST(JsonErrorText, DropsTheLibrarysPrefixAndKeepsOtherMessages) {
  try {
    (void)nlohmann::json("text").get<double>();
    FAIL() << "a string read as a number did not throw";
  } catch (const nlohmann::json::exception& e) {
    EXPECT_EQ(jsonErrorText(e), "type must be number, but is string");
  }
  EXPECT_EQ(jsonErrorText(std::runtime_error("[not the library] x")), "[not the library] x");
}

}  // namespace
}  // namespace costar::core
