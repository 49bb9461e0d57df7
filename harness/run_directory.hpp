#pragma once
// A results folder written all at once: files are collected in memory-backed staging under a
// temporary sibling folder and the folder is renamed into place at commit(), so a killed run never
// leaves a folder that looks complete.
#include <string>
#include <string_view>

namespace omniloc::harness {

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

 private:
  std::string final_, staging_;
  bool committed_ = false;
};

}  // namespace omniloc::harness
