#include "core/files.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace costar {
namespace {

class FilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = std::filesystem::temp_directory_path() / ("costar_files_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(folder_);
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  static std::string contents(const std::filesystem::path& file) {
    std::ifstream in(file);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  }

  /// The message writer() throws, or "" when it does not throw.
  template <typename F>
  static std::string error(F&& writer) {
    try {
      writer();
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  }

  std::filesystem::path folder_;
};

TEST_F(FilesTest, AnOutputToAFullDeviceIsAnErrorNamingThePathAndTheSystemsWords) {
  EXPECT_EQ(error([] { writeOutputFile("/dev/full", "text\n"); }), "cannot write '/dev/full': No space left on device");
}

TEST_F(FilesTest, AnOutputInAFolderThatCannotBeWrittenIsAnError) {
  if (::geteuid() == 0) {
    // root writes everywhere: a folder that is missing gives the same refusal.
    EXPECT_NE(error([&] { writeOutputFile(folder_ / "missing" / "r.json", "{}"); }).find("No such file or directory"),
              std::string::npos);
    return;
  }
  std::filesystem::permissions(folder_, std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
  const std::string message = error([&] { writeOutputFile(folder_ / "r.json", "{}"); });
  std::filesystem::permissions(folder_, std::filesystem::perms::owner_all);
  EXPECT_NE(message.find("Permission denied"), std::string::npos) << message;
}

// Found by scripts/hostile_cli.sh: the error named the temporary file ('r.json.tmp.1234'), not
// the file the user asked for.
TEST_F(FilesTest, AnOutputInAMissingFolderNamesTheFileAsGiven) {
  const auto file = folder_ / "missing" / "r.json";
  EXPECT_EQ(error([&] { writeOutputFile(file, "{}"); }),
            "cannot write '" + file.string() + "': No such file or directory");
  EXPECT_EQ(error([&] { writeFileAtomically(file, "{}"); }),
            "cannot write '" + file.string() + "': No such file or directory");
}

TEST_F(FilesTest, AnOutputThatIsAFolderIsRefused) {
  EXPECT_EQ(error([&] { writeOutputFile(folder_, "{}"); }), "cannot write '" + folder_.string() + "': it is a folder");
}

TEST_F(FilesTest, AnOutputFileIsReplacedWholeAndADeviceWrittenThrough) {
  const std::filesystem::path file = folder_ / "r.json";
  writeOutputFile(file, "first, longer\n");
  writeOutputFile(file, "second\n");
  EXPECT_EQ(contents(file), "second\n");
  EXPECT_NO_THROW(writeOutputFile("/dev/null", "anything"));
}

TEST_F(FilesTest, AppendedTextIsInTheFileAtOnceWithoutAClose) {
  const std::filesystem::path file = folder_ / "trace.jsonl";
  AppendingFile out(file, AppendingFile::Mode::kTruncate);
  out.append("{\"a\": 1}\n");
  EXPECT_EQ(contents(file), "{\"a\": 1}\n");  // what SIGKILL would leave
  out.append("{\"b\": 2}\n");
  out.close();
  EXPECT_EQ(contents(file), "{\"a\": 1}\n{\"b\": 2}\n");
  AppendingFile more(file, AppendingFile::Mode::kAppend);
  more.append("{\"c\": 3}\n");
  more.close();
  EXPECT_EQ(contents(file), "{\"a\": 1}\n{\"b\": 2}\n{\"c\": 3}\n");
}

TEST_F(FilesTest, AppendingToAFullDeviceIsAnError) {
  AppendingFile out("/dev/full", AppendingFile::Mode::kAppend);
  EXPECT_EQ(error([&] { out.append("line\n"); }), "cannot write '/dev/full': No space left on device");
}

TEST_F(FilesTest, WritingToAPipeNobodyReadsIsAnErrorNotAWaitForever) {
  const std::filesystem::path pipe = folder_ / "pipe";
  ASSERT_EQ(::mkfifo(pipe.c_str(), 0600), 0);
  EXPECT_EQ(error([&] { writeOutputFile(pipe, "{}"); }),
            "cannot write '" + pipe.string() + "': No such device or address");
  EXPECT_EQ(error([&] { AppendingFile out(pipe, AppendingFile::Mode::kTruncate); }),
            "cannot write '" + pipe.string() + "': No such device or address");
}

TEST_F(FilesTest, ReadingADeviceAPipeOrAFolderIsRefusedAtOnce) {
  EXPECT_EQ(error([] { readFile("/dev/zero"); }),
            "cannot read '/dev/zero': not a regular file (a device, pipe or socket)");
  const std::filesystem::path pipe = folder_ / "pipe";
  ASSERT_EQ(::mkfifo(pipe.c_str(), 0600), 0);
  EXPECT_EQ(error([&] { readFile(pipe); }),
            "cannot read '" + pipe.string() + "': not a regular file (a device, pipe or socket)");
  EXPECT_EQ(error([&] { readFile(folder_); }), "cannot read '" + folder_.string() + "': it is a folder");
  EXPECT_EQ(error([&] { readFile(folder_ / "none.json"); }),
            "cannot read '" + (folder_ / "none.json").string() + "': No such file or directory");
}

TEST_F(FilesTest, AFileAboveTheCapIsRefusedAndOneBelowItRead) {
  const std::filesystem::path file = folder_ / "big.json";
  std::ofstream(file) << std::string(2000, ' ');
  EXPECT_EQ(error([&] { readFile(file, "scene file", 1000); }),
            "cannot read scene file '" + file.string() +
                "': it holds 2000 bytes, more than the 1000 bytes a data file may have");
  EXPECT_EQ(readFile(file, {}, 2000).size(), 2000u);
}

TEST_F(FilesTest, AFingerprintTellsContentsApart) {
  EXPECT_EQ(fingerprint(""), "fnv1a64:cbf29ce484222325");  // FNV-1a's offset basis
  EXPECT_EQ(fingerprint("a"), "fnv1a64:af63dc4c8601ec8c");
  EXPECT_NE(fingerprint("{\"x\": 1}"), fingerprint("{\"x\": 2}"));
}

// Every test process writes under a temporary folder of its own (cmake/test_private_tmpdir.cpp):
// two SmartMoveSim tests run at once by CTest -j2 read each other's scene from one fixed
// /tmp name, and a CI run failed on it.
TEST(TestProcess, WritesUnderATemporaryFolderOfItsOwn) {
  const std::filesystem::path folder = std::filesystem::temp_directory_path();
  EXPECT_TRUE(folder.filename().string().starts_with("costar_test.")) << folder;
  EXPECT_TRUE(std::filesystem::is_directory(folder)) << folder;
}

}  // namespace
}  // namespace costar
