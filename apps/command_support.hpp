#pragma once
// What several commands share: the seed limit, the -o check, shipped input files and the
// --localizer option of replay and sweep.
#include <cstdint>
#include <string>
#include <vector>

#include "core/cli_args.hpp"
#include "core/json_reader.hpp"

namespace omniloc::app {

using cli::UsageError;

/// Seeds are stored in JSON (as doubles by some readers): beyond 2^53 they would not survive a round trip.
constexpr std::uint64_t kMaxSeed = 1ULL << 53;

/// -o must not silently destroy what the user did not ask to replace: an existing file, or a folder
/// with anything in it, is only replaced with --overwrite. Checked before any work, as is whether
/// the result (a `folder` or a file) can be written there at all.
void check_output_target(const cli::Args& a, bool folder);

/// A relative input file that is not there from the working directory but is a shipped one
/// (share_dir()/scenarios/...) is taken from there, so `omniloc run scenarios/quickstart.json` works
/// from any folder once the package is installed. Said on stderr: a file of the same name in the
/// working directory would otherwise silently win or lose.
std::string shipped_or_given(const std::string& file);

/// One --localizer value: inline JSON (starting with '{', or '[' where `arrays`) or a file holding it;
/// the localizer objects it holds, each with its external paths made absolute.
std::vector<Json> localizer_values(const std::string& v, const std::string& command, bool arrays);

}  // namespace omniloc::app
