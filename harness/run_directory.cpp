#include "harness/run_directory.hpp"

#include <unistd.h>

#include <filesystem>

#include "core/atomic_file.hpp"
#include "core/error.hpp"

namespace omniloc::harness {

namespace fs = std::filesystem;

RunDirectory::RunDirectory(std::string final_dir) : final_(std::move(final_dir)) {
  fs::path f(final_);
  if (f.filename().empty()) f = f.parent_path();
  final_ = f.string();
  staging_ = (f.parent_path() / ("." + f.filename().string() + ".partial-" + std::to_string(::getpid()))).string();
  std::error_code ec;
  fs::remove_all(staging_, ec);
  fs::create_directories(staging_, ec);
  if (ec) throw RuntimeFailure("cannot create " + staging_ + ": " + ec.message());
}

RunDirectory::~RunDirectory() {
  if (!committed_) {
    std::error_code ec;
    fs::remove_all(staging_, ec);
  }
}

void RunDirectory::write(const std::string& name, std::string_view content) {
  write_file_atomic((fs::path(staging_) / name).string(), content);
}

void RunDirectory::commit() {
  std::error_code ec;
  const std::string old = staging_ + ".old";
  fs::remove_all(old, ec);
  if (fs::exists(final_)) {
    fs::rename(final_, old, ec);
    if (ec) throw RuntimeFailure("cannot move old results " + final_ + " aside: " + ec.message());
  }
  fs::rename(staging_, final_, ec);
  if (ec) throw RuntimeFailure("cannot rename " + staging_ + " to " + final_ + ": " + ec.message());
  committed_ = true;
  fs::remove_all(old, ec);
}

}  // namespace omniloc::harness
