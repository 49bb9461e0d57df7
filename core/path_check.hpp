#pragma once
// Why a path a user handed omniloc (on the command line or inside one of its files) cannot be used,
// in words, before anything is read or written. std::filesystem's throwing calls turn a name over
// NAME_MAX, a component that is a file or a symbolic-link loop into a raw "filesystem error" (exit 1),
// and opening a FIFO blocks forever; every reader of a user path asks here first instead.
//
// The words are the operating system's own for what the kernel refuses ("File name too long", "Not a
// directory", "Too many levels of symbolic links", "Permission denied", "No such file or directory")
// and ours for what it allows but omniloc cannot use ("a FIFO, not a regular file", "a character
// device, not a regular file", "a folder, not a regular file").
#include <string>

namespace omniloc {

/// Why `path` cannot be read as a regular file; empty when it can.
std::string why_not_readable_file(const std::string& path);

/// Why `path` cannot be read as a folder (listed and entered); empty when it can.
std::string why_not_readable_folder(const std::string& path);

/// Why a regular file (`folder` false) or a folder (`folder` true) cannot be written at `path`: a
/// FIFO, device or socket is there (never replaced: renaming /dev/null aside as root would remove
/// it), a file where a folder goes or the reverse (unless `replace`: the writer moves it aside), a
/// parent is not a folder or not writable, a name is over NAME_MAX or the path over PATH_MAX. Empty
/// when nothing seen now stands in the way (what only the write can tell, such as a full disk, the
/// writer says). Whether an existing target may be replaced at all is the caller's question
/// (-o and --overwrite).
std::string why_not_writable(const std::string& path, bool folder, bool replace = false);

/// `path` for a message: longer than 200 characters it is cut in the middle (a 5000-character name
/// must not bury the reason), a NUL is shown as \u0000.
std::string path_shown(const std::string& path);

/// `value` for a ConfigError about `path`: "\"path\" (why)", the path as path_shown gives it.
std::string path_value(const std::string& path, const std::string& why);

/// Throws ConfigError(where, path_value(path, why), what) unless `path` is a readable regular file.
void require_readable_file(const std::string& path, const std::string& where, const std::string& what);

/// Throws ConfigError(where, path_value(path, why), what) unless `path` is a readable folder.
void require_readable_folder(const std::string& path, const std::string& where, const std::string& what);

/// Throws ConfigError(where, path_value(path, why), "a folder (or file) omniloc can write there")
/// when why_not_writable says why not.
void require_writable(const std::string& path, const std::string& where, bool folder, bool replace = false);

}  // namespace omniloc
