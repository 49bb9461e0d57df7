#pragma once
// Error budget (issue 17): the tracking path with every error source off, then each source alone,
// then all together, for each localizer. Tells which error dominates on a real robot.
// Description file: scenarios/experiments/error_budget.json.
#include <iosfwd>
#include <string>
#include <vector>

#include "core/json_reader.hpp"
#include "experiments/experiment.hpp"

namespace omniloc::experiments {

struct ErrorSource {
  std::string name;
  Json set;  ///< JSON pointer -> value, applied after the baseline
};

struct ErrorBudgetConfig {
  std::string description;
  std::string scenario_file;  ///< resolved against the description file's folder
  Json scenario;              ///< its contents, read once
  double duration = 60.0, quick_duration = 20.0;
  int seeds = 3, quick_seeds = 1;
  Json localizers;            ///< array of {"type": ...}
  Json baseline;              ///< JSON pointer -> value
  std::vector<ErrorSource> sources;
  /// The scenario of one row: the file, the baseline, the source's assignments ("" = the baseline row).
  Json scenario_for(const ErrorSource* source, double duration) const;
};

ErrorBudgetConfig load_error_budget(const std::string& file);
void validate_error_budget(const std::string& file);
int run_error_budget(const ExperimentArgs& args, std::ostream& out);

}  // namespace omniloc::experiments
