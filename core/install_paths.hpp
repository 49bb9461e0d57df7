// Where omniloc finds its shipped files at run time, so that an installed or merely unpacked package
// (docs/package.md) works from any working directory without the source tree.
#pragma once

#include <filesystem>

namespace omniloc {

/// The folder that holds data/, scenarios/, results/reference/, scripts/ and clients/, looked up in
/// this order (the first that applies wins; the result is not checked beyond what is said here):
///   1. $OMNILOC_SHARE_DIR when set and not empty;
///   2. <folder of /proc/self/exe>/../share/omniloc when it holds data/fields (a package installed
///      under /usr or unpacked anywhere: bin/omniloc beside share/omniloc);
///   3. the source tree the binary was built from (source_dir(): a build tree).
/// Looked up at every call (a readlink and a stat; callers read files there anyway), so a test may
/// set $OMNILOC_SHARE_DIR at any time.
std::filesystem::path share_dir();

/// The source tree this binary was built from (what tests, benchmarks and the fuzz target read
/// scenarios and data from). Only core/install_paths.cpp is compiled with its path.
std::filesystem::path source_dir();

}  // namespace omniloc
