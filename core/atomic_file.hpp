#pragma once
// Results are written atomically: into a temporary file beside the target, flushed, then renamed,
// so an interrupted run never leaves a half file that looks whole.
#include <string>
#include <string_view>

namespace omniloc {

/// Writes `content` to `path` atomically (temp file + fsync + rename). Creates parent folders.
/// Throws RuntimeFailure naming the path on any I/O error.
void write_file_atomic(const std::string& path, std::string_view content);

/// fsyncs a folder, so renames and new entries in it survive a crash; throws RuntimeFailure.
void fsync_dir(const std::string& dir);

/// Reads a whole file; throws RuntimeFailure naming the path when it cannot.
std::string read_file(const std::string& path);

}  // namespace omniloc
