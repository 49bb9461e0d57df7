#pragma once
// The aggregate of a sweep: per scenario x localizer x parameters, the mean and interval (mean_ci95's
// rule) over seeds of every number in the runs' summary.json. Computed from the finished run folders in run
// order, so it does not depend on -j, sharding or interruptions; written (runs.csv, aggregate.csv,
// aggregate.json) only when it is final: every run of the sweep done or failed, by the process that
// covers the whole sweep (a local sweep, or the merge after Slurm shards), never by a shard.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "batch/sweep_spec.hpp"

namespace omniloc::batch {

/// The interval rule, the same as python/omniloc/core/stats.py's interval() (docs/results.md
/// "Intervals", chosen by the coverage measured by scripts/interval_coverage.py): with n >= 5 seeds
/// the 95 % Student t interval of the mean, its lower bound clipped at 0 when no value is negative
/// ("t95"); with 2 to 4 seeds no interval is reliable, so low / high are the seeds' minimum and
/// maximum ("range"); one seed: low = high = the value ("none").
inline constexpr const char* kT95Interval = "t95";
inline constexpr const char* kRangeInterval = "range";
inline constexpr const char* kNoInterval = "none";
inline constexpr std::size_t kMinTSeeds = 5;
struct Interval {
  double mean = 0, low = 0, high = 0;
  std::size_t n = 0;
  const char* kind = kNoInterval;  ///< kT95Interval, kRangeInterval or kNoInterval
};
Interval mean_ci95(const std::vector<double>& v);
/// How the terminal prints it, as the Python tools do: "m [lo, hi] (n=5, t95)",
/// "m (seeds' range lo to hi, n=3)", "m (n=1, no interval)".
std::string interval_text(const Interval& iv, int digits);

/// Whether run `r` has a finished folder (its summary.json is written last, by rename).
bool run_finished(const std::filesystem::path& dir, const SweepRun& r);

/// The localizer name run `r` carries in runs.csv, the aggregate and progress lines (docs/protocol.md
/// "Which name"): an external client's finished run, the name it recorded in summary.json (the
/// entry's label, else the client's ready.name); otherwise the sweep's row label.
std::string run_localizer_name(const std::filesystem::path& dir, const SweepRun& r);

struct AggregateOutcome {
  std::size_t expected = 0, done = 0, failed = 0, missing = 0;
  bool written = false;  ///< the final files were written (nothing missing)
  std::string table;     ///< the printed aggregate (also when not written: what is there so far)
};

/// Takes the census of `dir` and, when no run is missing, writes the final runs.csv,
/// aggregate.csv and aggregate.json atomically (aggregate.json records expected / done / failed).
/// With runs missing it writes nothing final and removes final files a different, earlier state of
/// the folder left (they would no longer describe it).
AggregateOutcome write_final_aggregate(const SweepSpec& spec, const std::filesystem::path& dir);

}  // namespace omniloc::batch
