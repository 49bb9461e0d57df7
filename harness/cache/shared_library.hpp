#pragma once
// Where a shared library the process will dlopen lives and what it links, read from the file
// without loading it: the world cache's key names the rendering libraries that draw a world's pixels
// (harness/cache/world_cache.cpp; docs/recording.md "World cache").
#include <string>
#include <vector>

namespace omniloc {

/// The file the dynamic loader would open for `soname`: the first of LD_LIBRARY_PATH's folders and
/// then the system's library folders that has it, with links resolved; "" when none has it.
std::string find_shared_library(const std::string& soname);

/// The DT_NEEDED entries (sonames of the libraries it links) of the 64-bit little-endian ELF file at
/// `path`, in file order; empty when the file is missing, not such an ELF file, or malformed (every
/// offset is checked against the file's size).
std::vector<std::string> elf_needed(const std::string& path);

/// "<path> <bytes> <mtime>" of a file, or "none" when it cannot be read: a library replaced by a
/// package update changes its size or time.
std::string file_identity(const std::string& path);

}  // namespace omniloc
