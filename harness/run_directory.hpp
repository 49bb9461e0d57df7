#pragma once
// A results folder written all at once: files are collected in memory-backed staging under a
// temporary sibling folder and the folder is renamed into place at commit(), so a killed run never
// leaves a folder that looks complete. SIGINT, SIGTERM and SIGHUP remove the staging folder
// (core/interrupt.hpp); after kill -9 it stays until the next run into the same parent clears it.
#include <string>
#include <string_view>

namespace omniloc::harness {

/// Removes hidden staging folders (".<name>.partial-<host>-<pid>") in `parent` left by processes of
/// this host that no longer exist (a run killed with kill -9). Live ones are left alone.
void remove_stale_partials(const std::string& parent);

class RunDirectory {
 public:
  explicit RunDirectory(std::string final_dir);
  ~RunDirectory();  ///< removes the staging folder if commit() was not reached
  RunDirectory(const RunDirectory&) = delete;
  RunDirectory& operator=(const RunDirectory&) = delete;

  /// Writes a file into the staging folder (relative name, may contain sub-folders).
  void write(const std::string& name, std::string_view content);
  /// Path of the staging folder (for writers that need a real path, e.g. PNG frames).
  const std::string& staging() const { return staging_; }
  /// Atomically replaces final_dir with the staged folder.
  void commit();
  const std::string& final_dir() const { return final_; }
  /// "<host>-<pid>": the suffix of this process's staging folders, so a later process can tell
  /// whether a left-over one belongs to a live process.
  static std::string staging_tag();

 private:
  std::string final_, staging_;
  bool committed_ = false;
  int watch_slot_ = -1;  ///< core/interrupt's slot: SIGINT / SIGTERM / SIGHUP remove the staging folder
};

}  // namespace omniloc::harness
