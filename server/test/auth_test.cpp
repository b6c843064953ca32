// The API token: random, kept in a private file, compared in constant time.

#include "server/auth.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>

namespace costar::server {
namespace {

std::filesystem::path tempDir() {
  const auto dir = std::filesystem::temp_directory_path() / ("costar_auth_test_" + randomToken().substr(0, 8));
  std::filesystem::create_directories(dir);
  return dir;
}

TEST(Token, RandomTokensAre64HexDigitsAndDiffer) {
  const std::string a = randomToken();
  const std::string b = randomToken();
  EXPECT_EQ(a.size(), 64u);
  EXPECT_EQ(a.find_first_not_of("0123456789abcdef"), std::string::npos);
  EXPECT_NE(a, b);
}

TEST(Token, FileIsCreatedPrivateAndReadBack) {
  const auto dir = tempDir();
  const auto file = dir / "token";
  const std::string token = tokenFromFile(file);
  struct stat info {};
  ASSERT_EQ(::stat(file.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0600u);
  EXPECT_EQ(tokenFromFile(file), token);
  std::filesystem::remove_all(dir);
}

TEST(Token, RefusesFilesOthersCanReadShortTokensAndLinks) {
  const auto dir = tempDir();
  const auto open_file = dir / "open";
  std::ofstream(open_file) << "0123456789abcdef0123\n";
  std::filesystem::permissions(open_file, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write |
                                              std::filesystem::perms::group_read | std::filesystem::perms::others_read);
  EXPECT_THROW(tokenFromFile(open_file), std::runtime_error);

  const auto short_file = dir / "short";
  std::ofstream(short_file) << "abc\n";
  std::filesystem::permissions(short_file, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  EXPECT_THROW(tokenFromFile(short_file), std::runtime_error);

  const auto link = dir / "link";
  std::filesystem::create_symlink(short_file, link);
  EXPECT_THROW(tokenFromFile(link), std::runtime_error);
  std::filesystem::remove_all(dir);
}

TEST(Token, ComparisonAndBearerHeader) {
  EXPECT_TRUE(sameToken("secret-token-1234", "secret-token-1234"));
  EXPECT_FALSE(sameToken("secret-token-1235", "secret-token-1234"));
  EXPECT_FALSE(sameToken("secret", "secret-token-1234"));
  EXPECT_FALSE(sameToken("", ""));
  EXPECT_EQ(bearerToken("Bearer abc"), "abc");
  EXPECT_EQ(bearerToken("bearer abc  "), "abc");
  EXPECT_EQ(bearerToken("Basic abc"), "");
  EXPECT_EQ(bearerToken("Bearer "), "");
  EXPECT_EQ(bearerToken(""), "");
}

}  // namespace
}  // namespace costar::server
