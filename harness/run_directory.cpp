#include "harness/run_directory.hpp"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"

namespace omniloc::harness {

namespace fs = std::filesystem;

namespace {

std::string host_name() {
  char h[256] = {0};
  if (::gethostname(h, sizeof h - 1) != 0) return "host";
  std::string s;
  for (const char* p = h; *p; ++p) s += (*p == '-' || *p == '.') ? '_' : *p;  // '-' separates host and pid
  return s.empty() ? "host" : s;
}

bool process_alive(long pid) {
  if (pid <= 0) return false;
  return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM;
}

}  // namespace

std::string RunDirectory::staging_tag() { return host_name() + "-" + std::to_string(::getpid()); }

void remove_stale_partials(const std::string& parent) {
  std::error_code ec;
  if (!fs::is_directory(parent, ec)) return;
  const std::string host = host_name();
  for (fs::directory_iterator it(parent, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string n = it->path().filename().string();
    const auto at = n.find(".partial-");
    if (n.empty() || n[0] != '.' || at == std::string::npos) continue;
    // ".<name>.partial-<host>-<pid>[.old]": only folders of this host whose process is gone are
    // stale. Another host's (a cluster node sharing the folder) cannot be judged from here.
    std::string tag = n.substr(at + 9);
    if (tag.size() > 4 && tag.compare(tag.size() - 4, 4, ".old") == 0) tag.resize(tag.size() - 4);
    const auto dash = tag.rfind('-');
    const std::string who = dash == std::string::npos ? host : tag.substr(0, dash);  // old format: pid only
    const std::string pid = dash == std::string::npos ? tag : tag.substr(dash + 1);
    if (who != host || pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos || pid.size() > 9) continue;
    if (process_alive(std::stol(pid))) continue;
    std::error_code rm;
    fs::remove_all(it->path(), rm);
  }
}

RunDirectory::RunDirectory(std::string final_dir) : final_(std::move(final_dir)) {
  fs::path f(final_);
  if (f.filename().empty()) f = f.parent_path();
  final_ = f.string();
  const fs::path parent = f.has_parent_path() ? f.parent_path() : fs::path(".");
  // A run killed before commit leaves its hidden staging folder; the next run here clears it.
  remove_stale_partials(parent.string());
  staging_ = (parent / ("." + f.filename().string() + ".partial-" + staging_tag())).string();
  std::error_code ec;
  fs::remove_all(staging_, ec);
  // Watched before it exists: an interruption between the two leaves nothing behind.
  watch_slot_ = interrupt::watch_folder(staging_.c_str());
  fs::create_directories(staging_, ec);
  if (ec) throw IoError("cannot create folder", staging_, ec.message());
}

RunDirectory::~RunDirectory() {
  interrupt::unwatch_folder(watch_slot_);
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
  // Files were fsynced one by one (write_file_atomic); frames written by other writers and the
  // folder entries themselves are made durable before the folder becomes visible.
  fsync_dir(staging_);
  // From here on the staging folder is the whole result: an interruption must not remove it (nor
  // leave the previous results moved aside with nothing in their place).
  interrupt::unwatch_folder(watch_slot_);
  watch_slot_ = -1;
  const std::string old = staging_ + ".old";
  fs::remove_all(old, ec);
  if (fs::exists(final_, ec)) {
    fs::rename(final_, old, ec);
    if (ec) throw IoError("cannot move aside the old results", final_, ec.message());
  }
  fs::rename(staging_, final_, ec);
  if (ec) throw IoError("cannot rename " + staging_ + " to", final_, ec.message());
  committed_ = true;
  const fs::path f(final_);
  fsync_dir(f.has_parent_path() ? f.parent_path().string() : std::string("."));
  fs::remove_all(old, ec);
}

}  // namespace omniloc::harness
