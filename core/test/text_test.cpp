#include "core/text.h"

#include <gtest/gtest.h>

#include <string>

namespace costar {
namespace {

TEST(Utf8, CharactersOfOneToFourBytesAreRead) {
  EXPECT_EQ(utf8Length("a"), 1u);
  EXPECT_EQ(utf8Length("\xC3\xA9"), 2u);          // é
  EXPECT_EQ(utf8Length("\xE2\x82\xAC"), 3u);      // €
  EXPECT_EQ(utf8Length("\xF0\x9F\xA4\x96"), 4u);  // U+1F916
  EXPECT_EQ(invalidUtf8At("caf\xC3\xA9 \xE2\x82\xAC"), std::nullopt);
  EXPECT_EQ(invalidUtf8At(""), std::nullopt);
}

TEST(Utf8, BytesThatAreNoCharacterAreFound) {
  EXPECT_EQ(utf8Length("\xFF"), 0u);
  EXPECT_EQ(utf8Length("\xC0\x80"), 0u);          // an overlong NUL
  EXPECT_EQ(utf8Length("\xED\xA0\x80"), 0u);      // U+D800, a UTF-16 surrogate
  EXPECT_EQ(utf8Length("\xF4\x90\x80\x80"), 0u);  // beyond U+10FFFF
  EXPECT_EQ(utf8Length("\xE2\x82"), 0u);          // cut short
  EXPECT_EQ(invalidUtf8At("teach a\xFF"), 7u);
  EXPECT_EQ(invalidUtf8At("\xC3\xA9\xE2\x82"), 2u);
}

}  // namespace
}  // namespace costar
