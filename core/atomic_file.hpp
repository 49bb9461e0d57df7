#pragma once
// Results are written atomically: into a temporary file beside the target, flushed, then renamed,
// so an interrupted run never leaves a half file that looks whole.
#include <cstdio>
#include <string>
#include <string_view>

namespace omniloc {

/// Writes `content` to `path` atomically (temp file + fsync + rename). Creates parent folders.
/// Throws RuntimeFailure naming the path on any I/O error.
void write_file_atomic(const std::string& path, std::string_view content);

/// fsyncs a folder, so renames and new entries in it survive a crash; throws RuntimeFailure.
void fsync_dir(const std::string& dir);

/// A file written piece by piece, for what is too large to hold in memory first (view.jsonl inside a
/// run's staging folder, which is renamed into place as a whole). The first failure is kept with the
/// system's words and thrown by close() (or the destructor's caller never sees a half file: the
/// staging folder is removed).
class StreamFile {
 public:
  /// Throws IoError when the file cannot be created.
  explicit StreamFile(std::string path);
  ~StreamFile();
  StreamFile(const StreamFile&) = delete;
  StreamFile& operator=(const StreamFile&) = delete;
  void write(std::string_view bytes);
  /// Flushes and closes; throws IoError naming the file and the cause of the first failure.
  void close();

 private:
  std::string path_;
  std::FILE* f_ = nullptr;
  int err_ = 0;
};

/// Reads a whole file; throws RuntimeFailure naming the path when it cannot.
std::string read_file(const std::string& path);

}  // namespace omniloc
