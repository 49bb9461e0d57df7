#include "core/install_paths.hpp"

#include <cstdlib>
#include <system_error>

namespace omniloc {

std::filesystem::path share_dir() {
  namespace fs = std::filesystem;
  if (const char* env = std::getenv("OMNILOC_SHARE_DIR"); env && *env) return fs::path(env);
  // /proc/self/exe, not argv[0]: the binary may be started through PATH or a symbolic link, and the
  // package's layout is relative to where the file really is.
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = (exe.parent_path() / ".." / "share" / "omniloc").lexically_normal();
    if (fs::is_directory(installed / "data" / "fields", ec)) return installed;
  }
  return source_dir();
}

std::filesystem::path source_dir() { return std::filesystem::path(OMNILOC_SOURCE_DIR); }

}  // namespace omniloc
