#include "core/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.hpp"

namespace omniloc {

void write_file_atomic(const std::string& path, std::string_view content) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  std::error_code ec;
  if (target.has_parent_path()) fs::create_directories(target.parent_path(), ec);
  if (ec) throw IoError("cannot create folder", target.parent_path().string(), ec.message());
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw IoError("cannot write", tmp, errno);
  const char* p = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      ::unlink(tmp.c_str());
      throw IoError("cannot write", tmp, err);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  // The data must be on disk before the rename makes it visible, and a full disk or an NFS
  // write-back error may only show at fsync or close: both are checked.
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    ::unlink(tmp.c_str());
    throw IoError("cannot write (fsync)", tmp, err);
  }
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw IoError("cannot write (close)", tmp, err);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw IoError("cannot rename " + tmp + " to", path, err);
  }
  // The rename itself is only durable once the folder is.
  fsync_dir(target.has_parent_path() ? target.parent_path().string() : std::string("."));
}

void fsync_dir(const std::string& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) throw IoError("cannot open folder (to sync it)", dir, errno);
  // EINVAL: file systems that cannot sync folders (some FUSE mounts); nothing more can be done there.
  if (::fsync(fd) != 0 && errno != EINVAL) {
    const int err = errno;
    ::close(fd);
    throw IoError("cannot sync folder", dir, err);
  }
  ::close(fd);
}

StreamFile::StreamFile(std::string path) : path_(std::move(path)) {
  f_ = std::fopen(path_.c_str(), "wbe");
  if (f_ == nullptr) throw IoError("cannot write", path_, errno);
}

StreamFile::~StreamFile() {
  if (f_ != nullptr) std::fclose(f_);
}

void StreamFile::write(std::string_view bytes) {
  if (err_ == 0 && !bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), f_) != bytes.size()) err_ = errno;
}

void StreamFile::close() {
  if (f_ == nullptr) return;
  // Buffered bytes reach the file here: a full disk may only show now.
  if (std::fclose(f_) != 0 && err_ == 0) err_ = errno;
  f_ = nullptr;
  if (err_ != 0) throw IoError("cannot write", path_, err_);
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw RuntimeFailure("cannot read " + path);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

}  // namespace omniloc
