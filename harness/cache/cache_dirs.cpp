#include "harness/cache/cache_dirs.hpp"

#include <string>

#include "core/cache_root.hpp"
#include "omniloc_world_fingerprint.hpp"

namespace omniloc::harness {

std::string build_cache_dir(const char* kind) {
  const std::string dir = cache::dir(kind);
  return dir.empty() ? dir : dir + "/" + std::string(OMNILOC_WORLD_FINGERPRINT).substr(0, 16);
}

}  // namespace omniloc::harness
