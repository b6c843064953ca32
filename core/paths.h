#pragma once
// Where costar finds its data files (object classes, workcell models, example scenes).

#include <filesystem>

namespace costar {

/// The repository root holding data/, sim/models/ and examples/: $COSTAR_DATA_DIR if set,
/// else the source tree this binary was built from.
std::filesystem::path dataRoot();

}  // namespace costar
