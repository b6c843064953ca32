#pragma once
// Durable file writes: nothing already saved is lost when the process dies mid-save.

#include <filesystem>
#include <string_view>

namespace costar {

/// Writes `content` to a temporary file beside `path`, fsyncs it, renames it over `path`
/// and fsyncs the folder. Readers see the old or the new content, never a mix.
/// @throws std::runtime_error naming the file and the system error.
void writeFileAtomically(const std::filesystem::path& path, std::string_view content);

}  // namespace costar
