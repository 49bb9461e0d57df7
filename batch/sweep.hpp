#pragma once
// Running a sweep (batch/sweep_spec.hpp) here: every run is a child `omniloc run` process writing its
// own atomic results folder, so a crashing run is recorded as failed and the sweep goes on, and
// --resume simply skips folders that are complete. Runs hold a lock each, so shards and Slurm array
// tasks can share one folder. A shard (--shard I/N) records its own progress in
// progress/shard-I-of-N.json (I from 0, as in --shard I/N) and never writes the sweep's aggregate; the process that covers the
// whole sweep (a local sweep, --aggregate-only after shards) writes it once nothing is missing
// (batch/aggregate.hpp).
#include <iosfwd>
#include <string>

#include "batch/aggregate.hpp"
#include "batch/sweep_spec.hpp"

namespace omniloc::batch {

struct SweepOptions {
  int jobs = 1;
  int shard_index = 0, shard_count = 1;
  bool resume = false;
  bool aggregate_only = false;
  bool share_worlds = true;    ///< runs with the same SweepRun::world replay one recording of it (false: each draws its own)
  /// Each run finds its world in the world cache (harness/cache/world_cache.hpp; the folder is in the
  /// environment, OMNILOC_CACHE) instead of the sweep folder's recordings/; with share_worlds.
  bool world_cache = false;
  bool debug_view = false;  ///< every run writes view.jsonl (omniloc run --debug-view)
  std::size_t stop_after = 0;  ///< testing aid: stop launching after this many runs (0 = no limit)
  std::string out_dir;         ///< default results/sweeps/<name>
  std::string omniloc_exe;     ///< the binary to spawn for runs (default /proc/self/exe)
  std::ostream* progress = nullptr;
};

struct SweepOutcome {
  std::size_t ran = 0, skipped = 0, failed = 0, missing = 0;
  std::size_t expected = 0;          ///< runs of the sweep (all shards)
  bool aggregate_written = false;    ///< the final aggregate was written by this call
  std::string out_dir;
  std::string table;  ///< printed aggregate (or, for a shard, its progress)
};

SweepOutcome run_sweep(const SweepSpec& spec, const SweepOptions& options);

}  // namespace omniloc::batch
