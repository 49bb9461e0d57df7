#pragma once
// Which build made a result: every summary.json, aggregate.json and report records it, so results
// of two commits can be told apart and compared (`omniloc --version`, omniloc compare).
#include <string>

#include "core/json_reader.hpp"

namespace omniloc {

struct BuildInfo {
  std::string version;     ///< `git describe --always --dirty` of the source tree at build time ("unknown" without git)
  std::string compiler;    ///< e.g. "GNU 12.2.0"
  std::string build_type;  ///< CMake build type, e.g. "Release"
};

const BuildInfo& build_info();

/// {"version": ..., "compiler": ..., "build_type": ...}: the "omniloc" block of result files.
Json build_info_json();
/// {"cpu": model name, "cores": hardware threads}: the machine a run ran on (no date: the result
/// files stay byte-identical between reruns; their times are the files' own).
Json host_info_json();

/// One line for `omniloc --version`.
std::string version_line();

}  // namespace omniloc
