#pragma once
// Error budget (docs/error_budget.md): the tracking path with every error source off, then each source alone,
// then all together, for each localizer. Tells which error dominates on a real robot.
// Description file: scenarios/experiments/error_budget.json.
//
// Configuration: load_error_budget (the description file, every row checked as a scenario).
// Computation: compute_error_budget (one sweep over rows x localizers x seeds, means per cell).
// Report: write_error_budget_report (README.md, budget.csv, error_budget.json).
#include <cstdint>
#include <iosfwd>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/json_reader.hpp"
#include "experiments/experiment.hpp"

namespace omniloc::harness {
class RunDirectory;
}

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

/// One cell of the table: one row (error source) and one localizer.
/// One finished run (seed) of a cell: what the means are taken over, kept so that the report can
/// give each row an interval over the seeds (docs/error_budget.md "Full mode with seeds") and a reader can see whether a seed matters.
struct ErrorBudgetSeed {
  std::uint64_t seed = 0;
  double rmse_cm = 0, p50_cm = 0, theta_rmse_deg = 0;
  long wrong_frames = 0;
};

struct ErrorBudgetCell {
  int runs = 0, failed = 0;
  int no_estimate = 0;  ///< finished runs whose localizer answered no frame: no error to average, said as such
  double rmse_cm = 0, p50_cm = 0, theta_rmse_deg = 0;  ///< means over the runs that finished
  long wrong_frames = 0;                                ///< summed over them
  std::vector<ErrorBudgetSeed> per_seed;                ///< the finished runs, by seed
};

struct ErrorBudgetResult {
  std::string config_file;
  double duration = 0;  ///< s per run
  int seeds = 0;
  std::uint64_t first_seed = 1;
  bool quick = false;
  std::string sweep_dir;                ///< where the runs are
  int failed_runs = 0;
  std::vector<std::string> rows;        ///< the baseline row's name, then the sources'
  std::vector<std::string> localizers;  ///< labels, in the sweep's order
  std::map<std::pair<std::string, std::string>, ErrorBudgetCell> cells;  ///< by {row, localizer}
  ErrorBudgetCell cell(const std::string& row, const std::string& localizer) const;  ///< an empty cell when absent
};

/// Writes every row's scenario and the sweep description into `dir` (the sweep reads them from its
/// staging folder), runs the sweep (child processes, one per core; progress lines to `progress`) and
/// averages each cell's summaries over the seeds.
ErrorBudgetResult compute_error_budget(const ErrorBudgetConfig& c, const std::string& config_file, const ExperimentArgs& args,
                                       harness::RunDirectory& dir, std::ostream& progress);
/// README.md (the table in markdown, also printed to `out`), budget.csv and error_budget.json.
void write_error_budget_report(const ErrorBudgetConfig& c, const ErrorBudgetResult& r, harness::RunDirectory& dir, std::ostream& out);

int run_error_budget(const ExperimentArgs& args, std::ostream& out);

}  // namespace omniloc::experiments
