#pragma once
// The cache folders of this build (docs/recording.md section 9). A world's key already holds the build
// fingerprint; distance tables, calibration maps and colour tables are named by what they are of (a
// field, a camera), not by the code that computed them, so they are kept in a folder named after this
// build's fingerprint: two clones or two commits' builds sharing one cache root never read each
// other's, and a world drawn by this build is drawn with this build's calibration.
#include <string>

namespace omniloc::harness {

/// <cache root>/<kind>/<the first 16 hex digits of this build's world fingerprint>, or "" when caching
/// is off (core/cache_root.hpp). `kind`: "fieldmaps" or "vision".
std::string build_cache_dir(const char* kind);

}  // namespace omniloc::harness
