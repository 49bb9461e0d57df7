#pragma once
// The scenario a replay of a recording runs (docs/recording.md): the recorded scenario with another
// localizer, or, for a log not made by omniloc, one built from its header.
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>

#include "core/json_reader.hpp"
#include "harness/recording/format/header.hpp"
#include "harness/scenario.hpp"

namespace omniloc::harness {

struct ReplayOptions {
  Json localizer;                     ///< the localizer to run ({"type": ...}), as in a scenario
  std::optional<std::uint64_t> seed;  ///< the localizer's random stream; default the recording's seed
  std::string out_dir;                ///< default: results/runs/<scenario>/<seed>
  std::ostream* log = nullptr;
};

/// The scenario a replay runs: the recorded one with `localizer` in place of its own (or, for a log
/// not made by omniloc, one built from the header). Checks that the robots and field agree.
Scenario replay_scenario(const RecordingHeader& header, const Json& localizer);

}  // namespace omniloc::harness
