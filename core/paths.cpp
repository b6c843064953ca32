#include "core/paths.h"

#include <cstdlib>

namespace costar {

std::filesystem::path dataRoot() {
  if (const char* override_dir = std::getenv("COSTAR_DATA_DIR"); override_dir != nullptr && *override_dir != '\0') {
    return override_dir;
  }
  return COSTAR_SOURCE_DIR;
}

}  // namespace costar
