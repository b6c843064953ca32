#include "core/image.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <string>

namespace costar {
namespace {

TEST(Png, WritesAndReadsBackTheSamePixels) {
  RgbImage image(7, 3);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 7; ++x) {
      image.at(x, y)[0] = static_cast<std::uint8_t>(x * 30);
      image.at(x, y)[1] = static_cast<std::uint8_t>(y * 80);
      image.at(x, y)[2] = 200;
    }
  }
  const auto path = std::filesystem::temp_directory_path() / "costar_image_test.png";
  writePng(path, image);
  const RgbImage back = readPng(path);
  EXPECT_EQ(back.width, 7);
  EXPECT_EQ(back.height, 3);
  EXPECT_EQ(back.pixels, image.pixels);
  std::filesystem::remove(path);
}

TEST(Png, ErrorsNameTheFile) {
  try {
    writePng("/nonexistent-dir/x.png", RgbImage(2, 2));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.png"), std::string::npos);
  }
  EXPECT_THROW(readPng("/nonexistent.png"), std::runtime_error);
}

TEST(Png, APictureOnAFullDiskIsAnErrorNotAFileWritten) {
  // /dev/full takes the open and fails every write: small images fail only at the close.
  for (const int size : {2, 600}) {
    try {
      writePng("/dev/full", RgbImage(size, size));
      ADD_FAILURE() << size << " px: no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "cannot write '/dev/full': No space left on device") << size << " px";
    }
  }
}

// Found by scripts/hostile_cli.sh: `sim snapshot --out FIFO` waited forever for a reader.
TEST(Png, APictureToAPipeNobodyReadsIsAnErrorNotAWaitForever) {
  const auto pipe = std::filesystem::temp_directory_path() /
                    ("costar_image_test_pipe_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  std::filesystem::remove(pipe);
  ASSERT_EQ(::mkfifo(pipe.c_str(), 0600), 0);
  try {
    writePng(pipe, RgbImage(2, 2));
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "cannot write '" + pipe.string() + "': No such device or address");
  }
  std::filesystem::remove(pipe);
}

}  // namespace
}  // namespace costar
