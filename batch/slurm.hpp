#pragma once
// Sweeps on a Slurm cluster: a job array whose task I runs `omniloc sweep SPEC --shard I/N --resume`
// and a merge job that aggregates once every task has succeeded. Nothing here runs a simulation:
// the shards are ordinary sweep processes (batch/sweep.hpp), so a Slurm sweep gives the same
// run folders and byte-identical aggregates as a local one, and a task killed at any point loses
// only the run it was writing (run folders are committed by rename).
//
// The submission folder, <results>/slurm/, holds everything a cluster user needs to read, submit
// by hand or resubmit: array.sbatch, merge.sbatch, env.sh (module loads; never overwritten),
// commands.txt (the exact sbatch commands and one command per shard, for any other engine),
// submission.json (omniloc version, hashes of the sweep, N, job ids of every submission) and
// logs/ (one log per array task and per merge job). Paths in the scripts are absolute: the results
// folder, the binary and the data must be on a file system every node sees.
#include <cstddef>
#include <string>
#include <vector>

#include "batch/sweep.hpp"

namespace omniloc::batch {

struct SlurmOptions {
  int tasks = 0;                         ///< array size N (0: min(runs, 32)); at most the number of runs
  std::string partition;                 ///< --partition (empty: the cluster's default)
  std::string time_limit;                ///< per task, [D-]HH:MM:SS (empty: the partition's default)
  int cpus_per_task = 1;                 ///< cores per task; the shard runs with -j of this many
  /// GPUs per task (--gres=gpu:N; 0: none). With GPUs the task renders with "egl" (OMNILOC_GL_BACKEND)
  /// and its -j runs share them (docs/cluster.md "GPUs").
  int gpus_per_task = 0;
  std::vector<std::string> sbatch_args;  ///< extra sbatch options, one "--opt=value" each, written as #SBATCH lines
  bool dry_run = false;                  ///< write the folder, do not call sbatch
  bool resubmit_missing = false;         ///< only the shards with missing or failed runs, N as first submitted
  std::string out_dir;                   ///< the sweep's results folder (default results/sweeps/<name>)
  std::string omniloc_exe;               ///< binary the tasks run (default: this one, /proc/self/exe)
  /// Options every task's sweep gets besides its shard: where its worlds come from (`--cache DIR`
  /// with the submitting machine's absolute path, `--no-cache` or `--draw-each`), so the tasks of one
  /// submission share one world cache (docs/recording.md section 9).
  std::vector<std::string> task_args;
};

/// Checks the options against the sweep (before anything is written); throws ConfigError naming
/// the option. Called by submit_slurm, public so the CLI can fail with exit 2 before any work.
void check_slurm_options(const SweepSpec& spec, const SlurmOptions& options);

struct SlurmSubmission {
  std::string folder;                   ///< <results>/slurm
  int tasks = 0;                        ///< N
  std::vector<int> shards;              ///< the array indices submitted (all, or the resubmitted ones)
  std::string array_job, merge_job;     ///< Slurm job ids (empty for a dry run or nothing to resubmit)
  std::string message;                  ///< what was done and how to follow it, for the terminal
};

/// Writes the submission folder and (unless dry_run) submits the array and the merge job with
/// sbatch. With resubmit_missing, submits only the shards that have missing or failed runs, and
/// refuses while jobs of an earlier submission of this folder are still pending or running.
/// Throws ConfigError for bad options or a sweep that changed since the folder's first submission,
/// RuntimeFailure when sbatch is missing or refuses.
SlurmSubmission submit_slurm(const SweepSpec& spec, const std::string& spec_path, const SlurmOptions& options);

struct ShardStatus {
  int shard = 0;
  std::size_t runs = 0, done = 0, failed = 0, missing = 0;
  std::vector<std::string> failed_ids, missing_ids;
  std::string slurm_state;  ///< state of this shard's latest array task from squeue/scontrol ("" when unknown)
};

struct SweepStatus {
  int tasks = 1;  ///< N: from submission.json, else the --tasks given, else 1
  std::vector<ShardStatus> shards;
  std::size_t done = 0, failed = 0, missing = 0;
  std::vector<std::string> active_jobs;  ///< job ids (array tasks, merge) still pending, running or completing
  std::string merge_state;               ///< latest merge job's state and reason ("" when unknown)
  std::string text;                      ///< the table printed by `omniloc sweep SPEC --status`
  bool complete() const { return missing == 0 && failed == 0; }
  std::vector<int> incomplete_shards() const;
};

/// Reads the results folder (run folders, failed markers, slurm/submission.json) and, when squeue or
/// scontrol is on PATH, the state of the folder's Slurm jobs. Writes nothing. `tasks` overrides N
/// when the folder has no submission.json (0: use the file, else 1).
SweepStatus sweep_status(const SweepSpec& spec, const std::string& out_dir, int tasks = 0);

/// SHA-256 of a byte string as 64 lowercase hex digits (FIPS 180-4); identifies a sweep's content.
std::string sha256_hex(const std::string& bytes);

}  // namespace omniloc::batch
