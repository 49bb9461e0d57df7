#pragma once
// gzip (RFC 1952) in memory through zlib: a recording's frames.jsonl.gz (docs/recording.md), which
// any gzip tool and Python's gzip module read.
#include <cstddef>
#include <string>
#include <string_view>

namespace omniloc::harness {

/// The gzip stream of `bytes` (zlib level 6, the gzip tool's default).
std::string gzip_compress(std::string_view bytes);
/// The bytes of a gzip stream; throws std::runtime_error when it is not one, is cut short or would
/// exceed `max_bytes`.
std::string gzip_decompress(std::string_view gz, std::size_t max_bytes);

}  // namespace omniloc::harness
