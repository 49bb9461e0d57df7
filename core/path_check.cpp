#include "core/path_check.hpp"

#include <limits.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "core/error.hpp"

namespace omniloc {

namespace {

// Writers put a temporary name beside the target (".NAME.partial-HOST-PID.old", "NAME.tmp.PID"):
// the target's own name must leave this many of NAME_MAX's characters for it.
constexpr std::size_t kTemporaryNameRoom = 100;

// What a stat mode is, for "a FIFO, not a regular file".
const char* kind_words(mode_t m) {
  if (S_ISREG(m)) return "a regular file";
  if (S_ISDIR(m)) return "a folder";
  if (S_ISFIFO(m)) return "a FIFO";
  if (S_ISCHR(m)) return "a character device";
  if (S_ISBLK(m)) return "a block device";
  if (S_ISSOCK(m)) return "a socket";
  return "neither a file nor a folder";
}

// Checks every path shares before the kernel is asked: an empty path names nothing, and a NUL
// (a JSON string may hold \u0000) would cut the C string the kernel sees, so another file would be
// checked than the one named.
std::string why_not_a_path(const std::string& path) {
  if (path.empty()) return "an empty path";
  if (path.find('\0') != std::string::npos) return "a NUL character in the path";
  return {};
}

}  // namespace

std::string why_not_readable_file(const std::string& path) {
  if (std::string why = why_not_a_path(path); !why.empty()) return why;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return std::strerror(errno);
  if (!S_ISREG(st.st_mode)) return std::string(kind_words(st.st_mode)) + ", not a regular file";
  if (::access(path.c_str(), R_OK) != 0) return std::strerror(errno);
  return {};
}

std::string why_not_readable_folder(const std::string& path) {
  if (std::string why = why_not_a_path(path); !why.empty()) return why;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return std::strerror(errno);
  if (!S_ISDIR(st.st_mode)) return std::string(kind_words(st.st_mode)) + ", not a folder";
  if (::access(path.c_str(), R_OK | X_OK) != 0) return std::strerror(errno);
  return {};
}

std::string why_not_writable(const std::string& path, bool folder, bool replace) {
  namespace fs = std::filesystem;
  if (std::string why = why_not_a_path(path); !why.empty()) return why;
  const std::string too_long = std::strerror(ENAMETOOLONG);
  if (path.size() >= PATH_MAX) return too_long + " (" + std::to_string(path.size()) + " characters; at most " + std::to_string(PATH_MAX - 1) + ")";
  fs::path p = fs::path(path).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();  // "out/" is the folder "out"
  // Names the kernel has not looked at yet (below a missing folder) are measured here.
  for (const auto& part : p)
    if (part.native().size() > NAME_MAX) return too_long + " (a name of " + std::to_string(part.native().size()) + " characters; at most " + std::to_string(NAME_MAX) + ")";
  if (p.filename().native().size() + kTemporaryNameRoom > NAME_MAX)
    return too_long + " (its last name has " + std::to_string(p.filename().native().size()) + " characters; at most " +
           std::to_string(NAME_MAX - kTemporaryNameRoom) + " leave room for the temporary name written beside it)";
  struct stat st {};
  if (::stat(p.c_str(), &st) == 0) {
    const bool replaceable = replace && (S_ISDIR(st.st_mode) || S_ISREG(st.st_mode));
    if (folder && !S_ISDIR(st.st_mode) && !replaceable) return std::string(kind_words(st.st_mode)) + ", not a folder";
    if (!folder && !S_ISREG(st.st_mode) && !replaceable) return std::string(kind_words(st.st_mode)) + ", not a regular file";
    // An existing folder that is kept is written into; one that is replaced, like a file, is
    // replaced by a new entry beside it in its parent.
    if (folder && S_ISDIR(st.st_mode) && !replace) {
      if (::access(p.c_str(), W_OK | X_OK) != 0) return std::string(std::strerror(errno)) + " (cannot write into " + p.string() + ")";
      return {};
    }
  } else if (errno != ENOENT) {
    return std::strerror(errno);  // a component that is a file, a loop of links, a folder without search permission
  }
  // The nearest folder that exists gets the new entries (a missing parent is created in it): it
  // must be one this process can write into. A name below it that is a dangling symbolic link
  // cannot be created through.
  fs::path parent = p.parent_path();
  while (!parent.empty()) {
    if (::stat(parent.c_str(), &st) == 0) break;
    if (errno != ENOENT) return std::strerror(errno);
    if (::lstat(parent.c_str(), &st) == 0) return parent.string() + " is a symbolic link to nothing";
    parent = parent.parent_path();
  }
  const std::string dir = parent.empty() ? std::string(".") : parent.string();
  if (::stat(dir.c_str(), &st) != 0) return std::strerror(errno);
  if (!S_ISDIR(st.st_mode)) return dir + " is " + kind_words(st.st_mode) + ", not a folder";
  if (::access(dir.c_str(), W_OK | X_OK) != 0) return std::string(std::strerror(errno)) + " (cannot write into " + dir + ")";
  return {};
}

std::string path_shown(const std::string& path) {
  std::string shown;
  for (char c : path) shown += c == '\0' ? std::string("\\u0000") : std::string(1, c);
  if (shown.size() > 200) shown = shown.substr(0, 100) + "...(" + std::to_string(path.size()) + " characters)..." + shown.substr(shown.size() - 60);
  return shown;
}

std::string path_value(const std::string& path, const std::string& why) { return "\"" + path_shown(path) + "\" (" + why + ")"; }

void require_readable_file(const std::string& path, const std::string& where, const std::string& what) {
  if (const std::string why = why_not_readable_file(path); !why.empty()) throw ConfigError(where, path_value(path, why), what);
}

void require_readable_folder(const std::string& path, const std::string& where, const std::string& what) {
  if (const std::string why = why_not_readable_folder(path); !why.empty()) throw ConfigError(where, path_value(path, why), what);
}

void require_writable(const std::string& path, const std::string& where, bool folder, bool replace) {
  if (const std::string why = why_not_writable(path, folder, replace); !why.empty())
    throw ConfigError(where, path_value(path, why), folder ? "a folder omniloc can create or write into" : "a file omniloc can create or replace");
}

}  // namespace omniloc
