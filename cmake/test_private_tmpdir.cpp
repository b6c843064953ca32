// Linked into every costar_test executable: before main, the process gets a temporary folder of
// its own (TMPDIR points into it), removed when it exits. CTest runs tests in parallel, one
// process each; tests that wrote a fixed name under /tmp (a scene, a waypoint file) read each
// other's files when two ran at once (SmartMoveSim's scene in a CI run with -j2).
#include <stdlib.h>  // NOLINT(modernize-deprecated-headers): mkdtemp, setenv (POSIX)

#include <filesystem>
#include <string>
#include <system_error>

namespace {

class PrivateTmpdir {
 public:
  PrivateTmpdir() {
    std::error_code error;
    const std::filesystem::path parent = std::filesystem::temp_directory_path(error);
    std::string pattern = ((error ? std::filesystem::path("/tmp") : parent) / "costar_test.XXXXXX").string();
    if (mkdtemp(pattern.data()) != nullptr) {
      folder_ = pattern;
      setenv("TMPDIR", folder_.c_str(), 1);
    }
  }
  ~PrivateTmpdir() {
    if (!folder_.empty()) {
      std::error_code ignored;
      std::filesystem::remove_all(folder_, ignored);
    }
  }
  PrivateTmpdir(const PrivateTmpdir&) = delete;
  PrivateTmpdir& operator=(const PrivateTmpdir&) = delete;
  PrivateTmpdir(PrivateTmpdir&&) = delete;
  PrivateTmpdir& operator=(PrivateTmpdir&&) = delete;

 private:
  std::string folder_;
};

const PrivateTmpdir private_tmpdir;

}  // namespace
