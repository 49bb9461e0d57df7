#pragma once
// gzip (RFC 1952) in memory through zlib: a recording's frames.jsonl.gz (docs/recording.md), which
// any gzip tool and Python's gzip module read.
#include <cstddef>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>

namespace omniloc::harness {

/// The gzip stream of `bytes` (zlib level 6, the gzip tool's default).
std::string gzip_compress(std::string_view bytes);
/// The bytes of a gzip stream; throws std::runtime_error when it is not one, is cut short or would
/// exceed `max_bytes`.
std::string gzip_decompress(std::string_view gz, std::size_t max_bytes);

/// A gzip file read piece by piece: memory stays flat in the file's length (a recording's frames are
/// replayed while they are decompressed). Errors are std::runtime_error with gzip_decompress's words.
class GzipFileReader {
 public:
  /// Throws std::runtime_error when the file cannot be opened.
  explicit GzipFileReader(const std::string& path);
  ~GzipFileReader();
  GzipFileReader(const GzipFileReader&) = delete;
  GzipFileReader& operator=(const GzipFileReader&) = delete;
  /// Up to `n` decompressed bytes into `out`; 0 once the stream has ended (and nothing follows it).
  std::size_t read(char* out, std::size_t n);

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace omniloc::harness
