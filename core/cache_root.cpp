#include "core/cache_root.hpp"

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <mutex>

namespace omniloc::cache {

namespace fs = std::filesystem;

namespace {

std::atomic<bool> g_unwritable{false};

std::string absolute_env(const char* name) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v != '/') return "";
  return v;
}

}  // namespace

std::string root() {
  if (const char* v = std::getenv("OMNILOC_CACHE")) {
    const std::string s = v;
    if (s.empty() || s == "off" || s == "0") return "";
    std::error_code ec;
    const fs::path p = fs::absolute(s, ec);
    return (ec ? fs::path(s) : p).lexically_normal().string();
  }
  if (const std::string xdg = absolute_env("XDG_CACHE_HOME"); !xdg.empty()) return (fs::path(xdg) / "omniloc").lexically_normal().string();
  if (const std::string home = absolute_env("HOME"); !home.empty()) return (fs::path(home) / ".cache" / "omniloc").lexically_normal().string();
  return "";
}

std::string dir(const char* kind) {
  const std::string r = root();
  return r.empty() ? r : (fs::path(r) / kind).string();
}

void report_unwritable(const std::string& why) {
  static std::once_flag said;
  g_unwritable.store(true);
  std::call_once(said, [&] {
    std::cerr << "omniloc: warning: the cache " << root() << " cannot be written (" << why << "); going on without it\n";
  });
}

bool unwritable() { return g_unwritable.load(); }

}  // namespace omniloc::cache
