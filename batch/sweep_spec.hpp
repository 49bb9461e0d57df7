#pragma once
// A sweep's list of runs: the cross product of scenarios x localizers x parameter values x seeds,
// read from a sweep file and validated whole before any run (docs/extending.md, "Add a sweep").
#include <cstdint>
#include <string>
#include <vector>

#include "core/json_reader.hpp"

namespace omniloc::batch {

struct SweepRun {
  std::size_t index = 0;
  std::string id;              ///< stable folder name: <scenario>__<localizer>__<params>__s<seed>
  std::string scenario_name;
  std::string localizer_label;
  std::string params_label;
  std::uint64_t seed = 0;
  Json scenario;               ///< the scenario JSON with overrides applied
  /// A recording this run replays (a {"recording": DIR} entry of "scenarios"), absolute; empty: the
  /// world is simulated.
  std::string recording;
  /// Runs with the same non-empty `world` differ only in their localizer: the sweep draws their world
  /// once (omniloc record into the sweep folder's recordings/<world>/) and replays it into each.
  std::string world;
  std::string group() const { return scenario_name + "|" + localizer_label + "|" + params_label; }
};

struct SweepSpec {
  std::string name;
  std::string source;
  std::vector<SweepRun> runs;
};

/// Reads a sweep file; every scenario/localizer/override combination is validated here, before any run.
/// Runs that differ only in a built-in localizer that needs vision get a shared `world` (external
/// clients and localizers without vision run live: a client may want images, and a localizer without
/// a camera sees a world no exposure search paused).
/// `localizers`: null, or an array of localizer objects that replaces the file's "localizers" and
/// every entry's (omniloc sweep --localizer); its errors name "--localizer/<i>".
SweepSpec load_sweep(const std::string& path, const Json& localizers = Json());

/// JSON Schema (draft 2020-12) of sweep files (`omniloc schema --sweep`): every key load_sweep reads,
/// a localizer entry as in a scenario (docs/localizers.md) plus its row "label".
Json sweep_schema();

}  // namespace omniloc::batch
