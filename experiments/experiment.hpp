#pragma once
// Experiments that are not a simulated match (solver accuracy maps, the paper-001 cooperative
// simulation, benchmarks of filters): `omniloc experiment NAME [--seed N] [-o DIR] [--quick]`.
// Each writes its tables (JSON/CSV) and a printed summary into DIR, atomically. The layer sits above
// the harness (apps -> experiments -> harness); each experiment is split into configuration,
// computation (plain result structs) and report (docs/extending.md, "Add an experiment").
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

namespace omniloc::experiments {

struct ExperimentArgs {
  std::uint64_t seed = 1;
  std::string out_dir;   ///< results/experiments/<name> by default
  bool quick = false;    ///< a smaller version for tests and the default job
  std::string config;    ///< the experiment's description file; empty: the one shipped in scenarios/experiments/
};

struct ExperimentInfo {
  std::string name;
  std::string description;
  /// Runs the experiment, writes files under args.out_dir, prints a paper-format table to `out`.
  /// Returns 0 on success.
  std::function<int(const ExperimentArgs& args, std::ostream& out)> run;
  /// Checks a description file of this experiment (throws ConfigError naming the JSON path); empty
  /// when the experiment reads none. Files under scenarios/experiments/ name their experiment in
  /// the key "experiment".
  std::function<void(const std::string& file)> validate = {};
};

/// All experiments (experiments/experiment_registry.cpp holds the list).
const std::vector<ExperimentInfo>& all();

}  // namespace omniloc::experiments
