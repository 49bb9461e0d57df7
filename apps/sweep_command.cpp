// `omniloc sweep`: many runs in parallel on this machine, or as a Slurm job array, and their status.
#include "apps/commands.hpp"

#include <cstdlib>
#include <iostream>

#include "apps/cache_command.hpp"
#include "apps/command_support.hpp"
#include "batch/slurm.hpp"
#include "batch/sweep.hpp"
#include "batch/sweep_spec.hpp"
#include "core/cache_root.hpp"
#include "core/path_check.hpp"

namespace omniloc::app {

const cli::Command kSweep{"sweep", "SWEEP.json", 1, 1,
                          "Scenarios x localizers x parameters x seeds, in parallel; aggregate with mean and interval\n"
                          "(t95 from 5 seeds, else the seeds' range: docs/results.md \"Intervals\")\n"
                          "in results/sweeps/<name>/aggregate.{csv,json}.",
                          {{"-j", "N", "parallel runs (integer in [1, 256], default 1)"},
                           {"--shard", "I/N", "run only runs with index % N == I (0 <= I < N)"},
                           {"--resume", "", "skip runs already finished; runs another live process holds are skipped too"},
                           {"--aggregate-only", "", "run nothing, aggregate what is in the folder"},
                           {"--draw-each", "", "simulate and render every run itself (by default each world is drawn once per machine,\n"
                                               "kept in the world cache and replayed into every run of it: docs/recording.md)"},
                           {"--cache", "DIR", "the cache root (default: OMNILOC_CACHE, else $XDG_CACHE_HOME/omniloc or ~/.cache/omniloc)"},
                           {"--no-cache", "", "no cache at all (as OMNILOC_CACHE=off): runs that differ only in a built-in vision\n"
                                              "localizer share one recording in the sweep folder (recordings/), the others draw their own"},
                           {"--stop-after", "N", "run at most N runs (integer >= 0; 0: all)"},
                           {"--debug-view", "", "every run also writes view.jsonl for `omniloc view` (docs/viewer.md)"},
                           {"--localizer", "JSON|FILE", "run these localizers instead of the file's (repeatable; inline JSON or a file holding\n"
                                                        "one localizer object or an array of them; give it again with --resume)"},
                           {"-o", "DIR", "sweep folder (default results/sweeps/<name>)"},
                           {"--slurm", "", "submit as a Slurm job array of --tasks shards plus a merge job (docs/cluster.md)"},
                           {"--tasks", "N", "Slurm array tasks (shards), integer in [1, 100000]"},
                           {"--partition", "P", "Slurm partition"},
                           {"--time", "HH:MM:SS", "Slurm time limit per array task"},
                           {"--cpus-per-task", "C", "cores per array task (its -j), integer in [1, 1024], default 1"},
                           {"--gpus-per-task", "G", "GPUs per array task (--gres=gpu:G; renders with egl), integer in [0, 16], default 0"},
                           {"--sbatch-arg", "ARG", "extra sbatch argument, repeatable (e.g. --account=X)"},
                           {"--dry-run", "", "with --slurm: write DIR/slurm/ without submitting"},
                           {"--resubmit-missing", "", "with --slurm: submit only the shards with missing or failed runs"},
                           {"--status", "", "runs done / failed / missing per shard and the Slurm jobs' states; exit 0 when complete"}}};

namespace {

// Where a sweep's folder is without -o, named for messages about it.
const char* kDefaultSweepFolder = "the sweep folder (results/sweeps/<name>; -o DIR chooses another)";

// Slurm submission and status (batch/slurm.hpp); every option is checked before anything is written.
int cmd_sweep_slurm(const cli::Args& a, const batch::SweepSpec& spec) {
  if (a.has("--slurm") && a.has("--status")) throw UsageError("--status and --slurm are separate commands");
  if (!a.value("-o").empty()) require_writable(a.value("-o"), "-o", true);
  else require_writable("results/sweeps/" + spec.name, kDefaultSweepFolder, true);
  const int tasks = static_cast<int>(a.integer("--tasks", 0, 1, 100000));
  if (a.has("--status")) {
    const auto st = batch::sweep_status(spec, a.value("-o"), tasks);
    std::cout << st.text;
    return st.complete() ? 0 : 1;
  }
  batch::SlurmOptions so;
  so.tasks = tasks;
  so.partition = a.value("--partition");
  so.time_limit = a.value("--time");
  so.cpus_per_task = static_cast<int>(a.integer("--cpus-per-task", 1, 1, 1024));
  so.gpus_per_task = static_cast<int>(a.integer("--gpus-per-task", 0, 0, 1024));
  for (const auto& [k, v] : a.values)
    if (k == "--sbatch-arg") so.sbatch_args.push_back(v);
  so.dry_run = a.has("--dry-run");
  so.resubmit_missing = a.has("--resubmit-missing");
  so.out_dir = a.value("-o");
  // The tasks' worlds: one world cache for the whole submission (its absolute path), unless none.
  if (a.has("--draw-each") && (a.has("--cache") || a.has("--no-cache"))) throw UsageError("--draw-each uses no cache: leave out --cache / --no-cache");
  if (a.has("--draw-each")) {
    so.task_args = {"--draw-each"};
  } else {
    const harness::WorldCacheOptions co = app::cache_options(a);
    so.task_args = co.dir.empty() ? std::vector<std::string>{"--no-cache"} : std::vector<std::string>{"--cache", cache::root()};
  }
  const auto r = batch::submit_slurm(spec, a.positional[0], so);
  std::cout << r.message;
  return 0;
}

// --localizer of sweep (repeatable): each an object or an array of them, inline or in a file; null
// when not given (the sweep file's own localizers).
Json sweep_localizers(const cli::Args& a) {
  Json all = Json();
  for (const auto& [k, v] : a.values) {
    if (k != "--localizer") continue;
    if (all.is_null()) all = Json::array();
    for (Json& l : localizer_values(v, "sweep", true)) all.push_back(std::move(l));
  }
  return all;
}

}  // namespace

int cmd_sweep(const cli::Args& a) {
  if ((a.has("--slurm") || a.has("--status")) && a.has("--localizer"))
    throw UsageError("--localizer does not reach Slurm's shards: write the localizers into the sweep file's \"localizers\"");
  if (a.has("--slurm") || a.has("--status")) return cmd_sweep_slurm(a, batch::load_sweep(a.positional[0]));
  for (const char* o : {"--tasks", "--partition", "--time", "--cpus-per-task", "--gpus-per-task", "--sbatch-arg", "--dry-run", "--resubmit-missing"})
    if (a.has(o)) throw UsageError(std::string(o) + " needs --slurm");
  batch::SweepOptions o;
  o.jobs = static_cast<int>(a.integer("-j", 1, 1, 256));
  const std::string shard = a.value("--shard");
  if (a.has("--shard")) {
    const auto slash = shard.find('/');
    long long i = -1, n = 0;
    if (slash == std::string::npos || !cli::parse_int(shard.substr(0, slash), i) || !cli::parse_int(shard.substr(slash + 1), n) || n < 1 ||
        n > 100000 || i < 0 || i >= n)
      throw UsageError("--shard needs I/N with integers 0 <= I < N <= 100000, got \"" + shard + "\"");
    o.shard_index = static_cast<int>(i);
    o.shard_count = static_cast<int>(n);
  }
  o.resume = a.has("--resume");
  o.aggregate_only = a.has("--aggregate-only");
  o.share_worlds = !a.has("--draw-each");
  if (a.has("--draw-each") && (a.has("--cache") || a.has("--no-cache"))) throw UsageError("--draw-each uses no cache: leave out --cache / --no-cache");
  // The runs (child processes) find the cache through the environment, by an absolute path.
  const harness::WorldCacheOptions co = app::cache_options(a);
  o.world_cache = o.share_worlds && !co.dir.empty();
  const std::string root = cache::root();
  ::setenv("OMNILOC_CACHE", root.empty() ? "off" : root.c_str(), 1);
  o.stop_after = static_cast<std::size_t>(a.integer("--stop-after", 0, 0, 1000000000));
  o.debug_view = a.has("--debug-view");
  o.out_dir = a.value("-o");
  if (!o.out_dir.empty()) require_writable(o.out_dir, "-o", true);
  const auto spec = batch::load_sweep(a.positional[0], sweep_localizers(a));
  if (o.out_dir.empty()) require_writable("results/sweeps/" + spec.name, kDefaultSweepFolder, true);
  o.progress = &std::cerr;
  std::cerr << "sweep " << spec.name << ": " << spec.runs.size() << " runs, " << o.jobs << " worker(s)"
            << (o.shard_count > 1 ? ", shard " + shard : std::string())
            << (o.world_cache ? ", worlds from the cache in " + co.dir : !o.share_worlds ? ", every run draws its world" : ", no world cache")
            << "\n";
  const auto r = batch::run_sweep(spec, o);
  std::cout << r.table << "ran " << r.ran << ", skipped " << r.skipped << ", failed " << r.failed << ", missing " << r.missing
            << "\nresults: " << r.out_dir << (r.aggregate_written ? " (final aggregate: aggregate.json, aggregate.csv, runs.csv)" : "") << "\n";
  // A whole sweep (not a shard) that could not write its final aggregate is not done.
  const bool whole = o.shard_count == 1 || o.aggregate_only;
  return r.failed > 0 || (whole && !r.aggregate_written) ? 1 : 0;
}

}  // namespace omniloc::app
