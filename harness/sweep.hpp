#pragma once
// Sweeps: the cross product of scenarios x localizers x parameter values x seeds. Every run is a
// child `omniloc run` process writing its own atomic results folder, so a crashing run is recorded
// as failed and the sweep goes on, and --resume simply skips folders that are complete. The
// aggregate is computed from the finished folders in run order, never from wall-clock order, so it
// does not depend on -j, sharding or interruptions.
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "core/json_reader.hpp"

namespace omniloc::harness {

struct SweepRun {
  std::size_t index = 0;
  std::string id;              ///< stable folder name: <scenario>__<localizer>__<params>__s<seed>
  std::string scenario_name;
  std::string localizer_label;
  std::string params_label;
  std::uint64_t seed = 0;
  Json scenario;               ///< the scenario JSON with overrides applied
  std::string group() const { return scenario_name + "|" + localizer_label + "|" + params_label; }
};

struct SweepSpec {
  std::string name;
  std::string source;
  std::vector<SweepRun> runs;
};

/// Reads a sweep file; every scenario/localizer/override combination is validated here, before any run.
SweepSpec load_sweep(const std::string& path);

struct SweepOptions {
  int jobs = 1;
  int shard_index = 0, shard_count = 1;
  bool resume = false;
  bool aggregate_only = false;
  std::size_t stop_after = 0;  ///< testing aid: stop launching after this many runs (0 = no limit)
  std::string out_dir;         ///< default results/sweeps/<name>
  std::string omniloc_exe;     ///< the binary to spawn for runs (default /proc/self/exe)
  std::ostream* progress = nullptr;
};

struct SweepOutcome {
  std::size_t ran = 0, skipped = 0, failed = 0, missing = 0;
  std::string out_dir;
  std::string table;  ///< printed aggregate
};

SweepOutcome run_sweep(const SweepSpec& spec, const SweepOptions& options);

/// Mean and 95 % confidence interval (Student t) of a sample.
struct Interval {
  double mean = 0, low = 0, high = 0;
  std::size_t n = 0;
};
Interval mean_ci95(const std::vector<double>& v);

}  // namespace omniloc::harness
