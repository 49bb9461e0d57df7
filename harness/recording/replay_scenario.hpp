#pragma once
// The scenario a replay of a recording runs (docs/recording.md): the recorded scenario with another
// localizer, or, for a log not made by omniloc, one built from its header.
#include "core/json_reader.hpp"
#include "harness/localizer_spec.hpp"
#include "harness/recording/format/header.hpp"
#include "harness/scenario.hpp"

namespace omniloc::harness {

/// The scenario a replay runs: the recorded one with `localizer` in place of its own (or, for a log
/// not made by omniloc, one built from the header). Checks that the robots and field agree. Errors in
/// the recorded scenario name the recording; errors in the localizer (LocalizerError) its own path.
Scenario replay_scenario(const RecordingHeader& header, const LocalizerSpec& localizer);

}  // namespace omniloc::harness
