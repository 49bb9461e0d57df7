// omniloc command line: validate, run, list, experiment (and more as capabilities land).
// Exit codes: 0 success, 1 runtime failure, 2 bad input (scenario, arguments) — nothing written.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "apps/cache_command.hpp"
#include "core/cache_root.hpp"
#include "core/cli_args.hpp"
#include "core/error.hpp"
#include "core/json_parse.hpp"
#include "core/path_check.hpp"
#include "core/field.hpp"
#include "core/install_paths.hpp"
#include "core/version.hpp"
#include "experiments/experiment.hpp"
#include "harness/localizer_registry.hpp"
#include "core/atomic_file.hpp"
#include "harness/render_frame.hpp"
#include "harness/scenario_schema.hpp"
#include "external/external_config.hpp"
#include "harness/recording/recording_writer.hpp"
#include "harness/recording/recording_source.hpp"
#include "harness/recording/replay_scenario.hpp"
#include "harness/runner.hpp"
#include "harness/cache/world_cache.hpp"
#include "harness/scenario.hpp"
#include "batch/slurm.hpp"
#include "batch/sweep.hpp"
#include "batch/sweep_spec.hpp"
#include "harness/vision_setup.hpp"
#include "sim/render/camera_config.hpp"
#include "sim/render/egl_device.hpp"
#include "sim/render/gl_context.hpp"
#include "sim/motion.hpp"

using namespace omniloc;

namespace {

// Seeds are stored in JSON (as doubles by some readers): beyond 2^53 they would not survive a round trip.
constexpr std::uint64_t kMaxSeed = 1ULL << 53;

const char* kUsage = R"(usage: omniloc <command> [options]

commands:
  run FILE [--seed N] [-o DIR [--overwrite]] [--frames DIR] [--frames-every N] [--debug-view] [--quiet]
      [--draw-each | --cache DIR | --no-cache]
                         run a scenario; results in results/runs/<scenario>/<seed>/; its world comes
                         from the world cache when it was drawn before (docs/recording.md "World cache")
  record FILE [--seed N] [--images] [-o DIR [--overwrite]] [--quiet]
                         simulate and perceive a scenario once, no localizer: a recording of every
                         frame a localizer is given (docs/recording.md), in results/recordings/<scenario>/<seed>/
  replay RECORDING --localizer JSON|FILE [--seed N] [-o DIR [--overwrite]] [--debug-view] [--quiet]
                         run any localizer on a recording: the same run folder as `run` gives
  render FILE --t SECONDS [--robot ID] [--seed N] [--labels | --points] -o frame.png
                         the panorama robot ID (default: the first localized) sees at time t
  calibrate FILE [-o map.json] [--seed N]
                         model-free mirror calibration with the scenario's camera; prints the
                         map's error against the true mirror by distance
  colour-calibrate FILE [-o table.lut] [--seed N]
                         learn the colour look-up table from labelled renders of the scenario's field
  validate FILE...       check a scenario, a sweep file or an experiment description (scenarios/experiments/);
                         exit 2 with the JSON path of the first problem
  gl-devices             the EGL devices of this machine and the device each GL back-end renders on
                         (OMNILOC_GL_BACKEND, OMNILOC_EGL_DEVICE: docs/camera.md "GPUs")
  list                   field presets, motion scripts, event kinds, localizers, noise profiles, experiments
  schema [--sweep | --markdown] [-o FILE]
                         the JSON Schema of scenario files (for editors), or the parameter
                         reference docs/localizers.md generated from the same lists
  sweep SWEEP.json [-j N] [--shard I/N] [--resume] [--aggregate-only] [--draw-each]
        [--cache DIR | --no-cache] [--localizer JSON|FILE]... [-o DIR]
                         scenarios x localizers x parameters x seeds, in parallel; aggregate
                         with mean and interval (docs/results.md "Intervals": t95 from 5 seeds,
                         else the seeds' range) in results/sweeps/<name>/aggregate.{csv,json}
  sweep SWEEP.json --slurm [--tasks N] [--partition P] [--time HH:MM:SS] [--cpus-per-task C]
        [--gpus-per-task G] [--sbatch-arg ARG]... [--dry-run] [--resubmit-missing] [-o DIR]
                         a Slurm job array of N shards and a merge job (docs/cluster.md);
                         --dry-run only writes DIR/slurm/
  sweep SWEEP.json --status [--tasks N] [-o DIR]
                         runs done / failed / missing per shard, and the Slurm jobs' states;
                         exit 0 when every run is done, 1 otherwise
  experiment NAME [--seed N] [-o DIR] [--quick] [--config FILE]
                         run a named experiment (solver maps, cooperative simulation, ...);
                         --config: its description file instead of scenarios/experiments/NAME.json
  cache list|size|prune [--older-than DAYS] [--max-size SIZE] [--cache DIR]
                         the world cache: what it holds, its size, and removing old entries
  compare A B [--markdown] [--alpha P]
                         two result sets (runs, sweeps or folders of them, e.g. two commits) side by
                         side per metric: difference and whether it exceeds the seed-to-seed spread
                         (Welch's t)
  gate RESULTS --rules FILE [--baseline DIR] [--alpha P] [--junit FILE] [--benchmark-json FILE]
                         pass or fail results against limits and a baseline (docs/ci.md): exit 0 all
                         hold, 1 a rule or regression failed, 2 bad input
  report RESULTS... -o DIR [--baseline RESULTS] [--title TEXT]
                         report.md and a self-contained report.html
  paper-table RESULTS --paper ID [--rows ROWS]
                         one published table beside ours (results/reference/papers.json)
  global-start RESULTS [--markdown]
                         global starts judged per run: found, wrong, none (docs/global_localization.md)
  view RUN_DIR [-o FILE.html] [--recording DIR]
                         one self-contained HTML page to step through a run frame by frame
                         (docs/viewer.md)
  (compare, gate, report, paper-table, global-start and view are the Python results package, python/omniloc:
   docs/architecture.md)
  COMMAND --help         that command's options
  --version              the build: git describe, compiler, build type (also in every summary.json)
)";

using cli::UsageError;

// One table per command: `omniloc CMD --help` prints it, the parser accepts exactly these options.
// Adding an option is adding a row here and reading it in the command.
const cli::Command kRun{"run", "FILE", 1, 1, "Run a scenario; results in results/runs/<scenario>/<seed>/ (or -o DIR).",
                        {{"--seed", "N", "seed (integer >= 0; default: the scenario's)"},
                         {"-o", "DIR", "results folder; must not exist or be empty unless --overwrite"},
                         {"--overwrite", "", "replace what is at -o DIR (a previous result, or anything else)"},
                         {"--frames", "DIR", "write the camera frames as PNG into DIR"},
                         {"--frames-every", "N", "with --frames: every N-th frame (integer in [1, 1000000])"},
                         {"--debug-view", "", "also write view.jsonl: per frame, the line points and blobs the localizer was given and the\n"
                                             "covariance and particles it held, for `omniloc view` (docs/viewer.md)"},
                         {"--draw-each", "", "simulate and render this run itself instead of replaying its world from the world cache\n"
                                             "(the results are the same byte for byte: docs/recording.md \"World cache\")"},
                         {"--cache", "DIR", "the cache root (default: OMNILOC_CACHE, else $XDG_CACHE_HOME/omniloc or ~/.cache/omniloc)"},
                         {"--no-cache", "", "neither read nor fill any cache (as OMNILOC_CACHE=off)"},
                         {"--quiet", "", "no progress log on stderr"}}};
const cli::Command kRecord{"record", "FILE", 1, 1,
                           "Simulate and perceive a scenario once, without a localizer, and write a recording of everything\n"
                           "a localizer is given (docs/recording.md); results/recordings/<scenario>/<seed>/ (or -o DIR).",
                           {{"--seed", "N", "seed (integer >= 0; default: the scenario's)"},
                            {"--images", "", "also keep every frame's image (lossless PNG, for clients that read pixels)"},
                            {"-o", "DIR", "recording folder; must not exist or be empty unless --overwrite"},
                            {"--overwrite", "", "replace what is at -o DIR"},
                            {"--quiet", "", "no progress log on stderr"}}};
const cli::Command kReplay{"replay", "RECORDING", 1, 1,
                           "Run a localizer on a recording's frames: the run folder `omniloc run` writes for the recorded\n"
                           "scenario and seed with that localizer, without simulating or rendering (docs/recording.md).",
                           {{"--localizer", "JSON|FILE", "the localizer, as a scenario's \"localizer\" object: inline JSON or a file holding it (required)"},
                            {"--seed", "N", "seed of the localizer's random stream (default: the recording's seed)"},
                            {"--debug-view", "", "also write view.jsonl: per frame, the line points and blobs the localizer was given and the\n"
                                              "covariance and particles it held, for `omniloc view` (docs/viewer.md)"},
                            {"-o", "DIR", "results folder; must not exist or be empty unless --overwrite"},
                            {"--overwrite", "", "replace what is at -o DIR"},
                            {"--quiet", "", "no progress log on stderr"}}};
const cli::Command kRender{"render", "FILE", 1, 1, "Render the panorama robot ID sees at time t.",
                           {{"--t", "SECONDS", "time in [0, the scenario's duration] (default 0)"},
                            {"--robot", "ID", "robot id (default: the first localized robot)"},
                            {"--seed", "N", "seed (default: the scenario's)"},
                            {"--labels", "", "draw the classified colours"},
                            {"--points", "", "draw the detected line points"},
                            {"-o", "FILE.png", "output picture (required); an existing file only with --overwrite"},
                            {"--overwrite", "", "replace an existing -o file"}}};
const cli::Command kCalibrate{"calibrate", "FILE", 1, 1,
                              "Model-free mirror calibration with the scenario's camera; prints the map's error against the true mirror.",
                              {{"-o", "MAP.json", "output map (default: the cache's vision/calibration_v2_<camera>.json, which runs use); an existing file only with --overwrite"},
                               {"--overwrite", "", "replace an existing -o file"},
                               {"--seed", "N", "seed (default 1)"},
                               {"--image-centre", "", "assume the mirror axis at the image centre instead of estimating it from the rim (saved only with -o)"}}};
const cli::Command kColourCalibrate{"colour-calibrate", "FILE", 1, 1, "Learn the colour look-up table from labelled renders of the scenario's field.",
                                    {{"-o", "TABLE.lut", "output table (default: the cache's vision/colour_v2_<camera>_<field>.lut, which runs use); an existing file only with --overwrite"},
                                     {"--overwrite", "", "replace an existing -o file"},
                                     {"--seed", "N", "seed (default 1)"}}};
const cli::Command kValidate{"validate", "FILE...", 1, 1000000,
                             "Check scenario, sweep or experiment description files without running anything;\n"
                             "exit 2 with the JSON path of the first problem. With several files each is checked in\n"
                             "its own process and a line \"[exit N] FILE\" (or \"[signal S] FILE\") follows it; the exit\n"
                             "code is then 0 when all passed, 2 when some had input errors, 1 when any failed otherwise.",
                             {}};
const cli::Command kGlDevices{"gl-devices", "", 0, 0,
                               "The EGL devices of this machine (EGL_EXT_device_enumeration) and the device each GL back-end\n"
                               "renders on under the current OMNILOC_EGL_DEVICE; exit 1 when \"egl\" cannot render.",
                               {}};
const cli::Command kList{"list", "", 0, 0, "Field presets, motion scripts, event kinds, localizers, noise profiles, experiments.", {}};
const cli::Command kSchema{"schema", "", 0, 0, "The JSON Schema of scenario files (or of sweep files), or (--markdown) the parameter reference docs/localizers.md.",
                           {{"--markdown", "", "the parameter reference instead of the schema"},
                            {"--sweep", "", "the JSON Schema of sweep files instead"},
                            {"-o", "FILE", "write to FILE (atomically) instead of standard output"}}};
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
const cli::Command kExperiment{"experiment", "NAME", 1, 1, "Run a named experiment (omniloc list).",
                               {{"--seed", "N", "seed"},
                                {"-o", "DIR", "output folder (default results/experiments/NAME); must not exist or be empty unless --overwrite"},
                                {"--overwrite", "", "replace what is at -o DIR"},
                                {"--quick", "", "the reduced version"},
                                {"--config", "FILE", "description file instead of scenarios/experiments/NAME.json"}}};

// -o must not silently destroy what the user did not ask to replace: an existing file, or a folder
// with anything in it, is only replaced with --overwrite. Checked before any work, as is whether
// the result (a `folder` or a file) can be written there at all.
void check_output_target(const cli::Args& a, bool folder) {
  const std::string out = a.value("-o");
  if (out.empty()) return;
  require_writable(out, "-o", folder, true);
  if (a.has("--overwrite")) return;
  std::error_code ec;
  const auto st = std::filesystem::symlink_status(out, ec);
  if (ec || !std::filesystem::exists(st)) return;
  if (std::filesystem::is_directory(st) && std::filesystem::is_empty(out, ec) && !ec) return;
  throw UsageError("-o " + out + " exists and is " + (std::filesystem::is_directory(st) ? "a folder with content" : "a file") +
                   "; give --overwrite to replace it, or another -o");
}

int validate_one(const std::string& file) {
  // The strict reader first: depth, size, duplicate keys, NUL bytes, numbers out of range.
  const Json j = read_json_strict(file, file);
  // An experiment description (scenarios/experiments/*.json) names its experiment; the experiment checks it.
  {
    if (j.is_object() && j.contains("experiment") && j["experiment"].is_string()) {
      for (const auto& e : experiments::all())
        if (e.name == j["experiment"].get<std::string>() && e.validate) {
          e.validate(file);
          std::cout << file << ": ok (description of experiment \"" << e.name << "\")\n";
          return 0;
        }
      throw ConfigError("/experiment", json_brief(j["experiment"]), "the name of an experiment that reads a description file (see omniloc list)");
    }
  }
  // A sweep file lists scenarios (and has no robots of its own): every combination is validated.
  if (j.is_object() && j.contains("scenarios") && !j.contains("robots")) {
    const auto spec = batch::load_sweep(file);
    std::cout << file << ": ok (sweep \"" << spec.name << "\", " << spec.runs.size() << " run(s))\n";
    return 0;
  }
  const auto s = harness::parse_scenario(j, std::filesystem::path(file).stem().string(), file);
  std::cout << file << ": ok (scenario \"" << s.name << "\", " << s.robots.size() << " robot(s), "
            << s.duration << " s, localizer " << s.localizer.value("type", "?") << ")\n";
  return 0;
}

// The same exit codes as main() for one file.
int validate_one_guarded(const std::string& file) {
  try {
    return validate_one(file);
  } catch (const ConfigError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "failed: " << e.what() << "\n";
    return 1;
  }
}

int cmd_validate(const cli::Args& a) {
  if (a.positional.size() == 1) return validate_one(a.positional[0]);
  // Several files: each in a forked child, so one crashing input cannot hide the verdict on the
  // others and is reported as the signal it died of (the mutation test drives thousands this way
  // without paying the program's start-up, ~0.2 s of shared-library loading, per file).
  int worst = 0;
  for (const auto& file : a.positional) {
    std::cout.flush();
    std::cerr.flush();
    const pid_t pid = ::fork();
    if (pid < 0) throw RuntimeFailure(std::string("cannot fork: ") + std::strerror(errno));
    if (pid == 0) {
      const int code = validate_one_guarded(file);
      std::cout.flush();
      std::cerr.flush();
      ::_exit(code);
    }
    int st = 0;
    while (::waitpid(pid, &st, 0) < 0 && errno == EINTR) {
    }
    if (WIFSIGNALED(st)) {
      std::cout << "[signal " << WTERMSIG(st) << "] " << file << "\n";
      worst = 1;
    } else {
      const int code = WIFEXITED(st) ? WEXITSTATUS(st) : 1;
      std::cout << "[exit " << code << "] " << file << "\n";
      if (code != 0 && code != 2) worst = 1;
      else if (code == 2 && worst == 0) worst = 2;
    }
  }
  return worst;
}

int cmd_gl_devices(const cli::Args&) {
  std::vector<sim::EglDeviceDesc> devs;
  try {
    devs = sim::egl_devices();
  } catch (const RuntimeFailure& e) {
    std::cout << "no EGL device enumeration: " << e.what() << "\n";
  }
  std::cout << devs.size() << " EGL device(s)\n";
  for (const auto& d : devs)
    std::cout << "  " << d.index << ": " << (d.software ? "software" : "hardware") << (d.cuda_device >= 0 ? ", CUDA device " + std::to_string(d.cuda_device) : "")
              << (d.drm_node.empty() ? "" : ", " + d.drm_node) << "\n    " << d.extensions << "\n";
  int rc = 0;
  for (const std::string& backend : sim::gl_backends()) {
    try {
      const auto ctx = sim::make_gl_context(backend);
      std::cout << backend << " renders on " << ctx->device().line() << "\n";
    } catch (const RuntimeFailure& e) {
      std::cout << backend << " cannot render: " << e.what() << "\n";
      if (backend == "egl") rc = 1;
    }
  }
  return rc;
}

int cmd_run(const cli::Args& a) {
  const auto s = harness::load_scenario(a.positional[0]);
  harness::RunOptions o;
  if (a.has("--seed")) o.seed = a.unsigned_integer("--seed", 0, kMaxSeed);
  o.out_dir = a.value("-o");
  check_output_target(a, true);
  o.frames_dir = a.value("--frames");
  if (!o.frames_dir.empty()) require_writable(o.frames_dir, "--frames", true);
  o.frames_every = static_cast<int>(a.integer("--frames-every", o.frames_every, 1, 1000000));
  o.debug_view = a.has("--debug-view");
  if (!a.has("--quiet")) o.log = &std::cerr;
  if (a.has("--draw-each") && (a.has("--cache") || a.has("--no-cache"))) throw UsageError("--draw-each uses no cache: leave out --cache / --no-cache");
  harness::WorldCacheOptions co = app::cache_options(a);
  co.log = o.log;
  harness::WorldCache cache(co);
  const auto r = a.has("--draw-each") ? harness::run_scenario(s, o) : harness::run_with_world_cache(s, o, cache);
  std::cout << "scenario " << s.name << ", seed " << r.seed << ", localizer " << r.summary["localizer"].get<std::string>()
            << ", noise " << s.noise.name << "\n"
            << r.table << "results: " << r.out_dir << "\n";
  return 0;
}

int cmd_record(const cli::Args& a) {
  const auto s = harness::load_scenario(a.positional[0]);
  harness::RecordOptions o;
  if (a.has("--seed")) o.seed = a.unsigned_integer("--seed", 0, kMaxSeed);
  o.out_dir = a.value("-o");
  check_output_target(a, true);
  o.images = a.has("--images");
  if (!a.has("--quiet")) o.log = &std::cerr;
  const auto r = harness::record_scenario(s, o);
  const double minutes = std::max(1e-9, s.duration / 60.0);
  std::cout << "scenario " << s.name << ", seed " << r.seed << ": " << r.frames << " frames, frames.jsonl.gz " << r.frames_bytes / 1024
            << " KiB (" << static_cast<long long>(static_cast<double>(r.frames_bytes) / minutes / 1024) << " KiB per minute; "
            << r.frames_text_bytes / 1024 << " KiB of JSON lines)";
  if (o.images)
    std::cout << ", images " << r.image_bytes / (1024 * 1024) << " MiB ("
              << static_cast<long long>(static_cast<double>(r.image_bytes) / minutes / (1024 * 1024)) << " MiB per minute)";
  std::cout << "\nrecording: " << r.out_dir << "\n";
  return 0;
}

// One --localizer value: inline JSON (starting with '{', or '[' where `arrays`) or a file holding it;
// the localizer objects it holds, each with its external paths made absolute.
std::vector<Json> localizer_values(const std::string& v, const std::string& command, bool arrays) {
  const auto first = v.find_first_not_of(" \t\n");
  if (first == std::string::npos)
    throw UsageError(command + " needs --localizer JSON|FILE (e.g. --localizer '{\"type\": \"matching\"}')");
  const bool inline_json = v[first] == '{' || (arrays && v[first] == '[');
  Json j = inline_json ? parse_json_strict(v, "--localizer") : read_json_strict(v, "--localizer");
  std::vector<Json> out = arrays && j.is_array() ? std::vector<Json>(j.begin(), j.end()) : std::vector<Json>{j};
  for (Json& l : out) {
    if (!l.is_object())
      throw ConfigError("--localizer", json_brief(l), std::string("a localizer object {\"type\": ...}") + (arrays ? " (or an array of them)" : ""));
    external::anchor_external_paths(l);
  }
  return out;
}

Json localizer_argument(const std::string& v) { return localizer_values(v, "replay", false).front(); }

int cmd_replay(const cli::Args& a) {
  const Json localizer = localizer_argument(a.value("--localizer"));
  check_output_target(a, true);
  harness::RecordingHeader header = harness::RecordingHeader::read(a.positional[0]);
  const harness::Scenario s = harness::replay_scenario(header, localizer);
  harness::RecordingSource source(std::move(header));  // reads and checks every frame before any work
  harness::RunOptions o;
  o.seed = a.has("--seed") ? a.unsigned_integer("--seed", 0, kMaxSeed) : source.header().seed;
  o.out_dir = a.value("-o");
  o.replay = true;
  o.debug_view = a.has("--debug-view");
  if (!a.has("--quiet")) o.log = &std::cerr;
  Json provenance = Json::object();
  if (!source.header().render.is_null()) provenance["render"] = source.header().render;
  provenance["replay"] = {{"recording", std::filesystem::absolute(a.positional[0]).lexically_normal().string()},
                          {"format", source.header().format},
                          {"recorded_seed", source.header().seed},
                          {"recorded_with", harness::recorded_with(source.header())}};
  const auto r = harness::run_frames(s, *o.seed, source, o, provenance);
  std::cout << "replay of " << a.positional[0] << " (scenario " << s.name << ", seed " << r.seed << "), localizer "
            << r.summary["localizer"].get<std::string>() << "\n"
            << r.table << "results: " << r.out_dir << "\n";
  return 0;
}

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

int cmd_render(const cli::Args& a) {
  const std::string out = a.value("-o");
  if (out.empty()) throw UsageError("render needs -o frame.png");
  check_output_target(a, false);
  const auto s = harness::load_scenario(a.positional[0]);
  const double t = a.number("--t", 0.0, 0.0, s.duration);
  const int robot = static_cast<int>(a.integer("--robot", s.localized_robots().front(), 0, 99));
  if (!s.robot(robot)) throw UsageError("--robot needs the id of a robot of the scenario, got " + std::to_string(robot));
  const std::uint64_t seed = a.unsigned_integer("--seed", s.seed, kMaxSeed);
  harness::render_to_png(s, t, robot, seed, a.has("--labels"), out, a.has("--points"));
  std::cout << "wrote " << out << "\n";
  return 0;
}

int cmd_calibrate(const cli::Args& a) {
  check_output_target(a, false);  // an explicit -o; the default is the shared cache, which calibrating refreshes
  const std::uint64_t seed = a.unsigned_integer("--seed", 1, kMaxSeed);
  const auto s = harness::load_scenario(a.positional[0]);
  const auto cfg = sim::CameraConfig::from_json(s.camera, "/camera");
  Json report;
  const bool image_centre = a.has("--image-centre");
  auto r = harness::calibrate_camera(cfg, seed, &report, image_centre ? harness::CentreSource::kImageCentre : harness::CentreSource::kRim);
  // An image-centre map is a comparison, not what runs should pick up from the cache.
  // Runs compute the seed-1 map when the cache has none; another seed's map goes only where -o says.
  if (!a.has("-o") && seed != 1 && !image_centre) throw UsageError("calibrate --seed " + std::to_string(seed) + " needs -o MAP.json: the cache holds the seed-1 map every run computes");
  const std::string out = a.value("-o", image_centre ? std::string() : harness::calibration_cache_file(cfg));
  if (!out.empty()) r.map.save(out);
  std::printf("directions used %d, rejected %d\n", r.directions_used, r.directions_rejected);
  const auto& c = report["centre_px"];
  const auto& t = report["true_centre_px"];
  if (image_centre)
    std::printf("mirror centre: image centre (%.2f, %.2f) assumed; true (%.2f, %.2f), off by %.2f px\n", c[0].get<double>(), c[1].get<double>(),
                t[0].get<double>(), t[1].get<double>(), report["centre_error_px"].get<double>());
  else
    std::printf("mirror centre: estimated (%.2f, %.2f) from the rim (radius %.2f px, rms %.3f px, %d points, %d rejected);\n"
                "               true (%.2f, %.2f), radius %.2f px: off by %.3f px\n",
                c[0].get<double>(), c[1].get<double>(), report["rim_radius_px"].get<double>(), report["rim_rms_px"].get<double>(),
                report["rim_points"].get<int>(), report["rim_rejected"].get<int>(), t[0].get<double>(), t[1].get<double>(),
                report["true_rim_radius_px"].get<double>(), report["centre_error_px"].get<double>());
  std::printf("%10s %12s %12s %12s\n", "distance m", "mean err cm", "p95 err cm", "max err cm");
  for (const auto& row : report["error_by_distance"])
    std::printf("%10.1f %12.2f %12.2f %12.2f\n", row["distance_m"].get<double>(), 100 * row["mean_error_m"].get<double>(),
                100 * row["p95_error_m"].get<double>(), 100 * row["max_error_m"].get<double>());
  if (!out.empty()) std::cout << "wrote " << out << "\n";
  return 0;
}

int cmd_colour_calibrate(const cli::Args& a) {
  check_output_target(a, false);  // an explicit -o; the default is the shared cache
  const std::uint64_t seed = a.unsigned_integer("--seed", 1, kMaxSeed);
  const auto s = harness::load_scenario(a.positional[0]);
  const auto cfg = sim::CameraConfig::from_json(s.camera, "/camera");
  const ColourTable t = harness::colour_calibrate(cfg, s.field, seed);
  if (!a.has("-o") && seed != 1) throw UsageError("colour-calibrate --seed " + std::to_string(seed) + " needs -o TABLE.lut: the cache holds the seed-1 table every run computes");
  const std::string out = a.value("-o", harness::colour_table_cache_file(cfg, s.field));
  if (out.empty()) throw UsageError("colour-calibrate needs -o TABLE.lut when the cache is off");
  t.save(out);
  std::cout << "wrote " << out << "\n";
  return 0;
}

int cmd_schema(const cli::Args& a) {
  if (a.has("--markdown") && a.has("--sweep")) throw UsageError("--markdown and --sweep: choose one");
  const std::string text = a.has("--markdown") ? harness::parameter_reference()
                           : a.has("--sweep")  ? batch::sweep_schema().dump(2) + "\n"
                                               : harness::scenario_schema().dump(2) + "\n";
  const std::string out = a.value("-o");
  if (!out.empty()) require_writable(out, "-o", false);
  if (out.empty()) {
    std::cout << text;
  } else {
    write_file_atomic(out, text);
    std::cerr << "wrote " << out << "\n";
  }
  return 0;
}

int cmd_list() {
  std::cout << "field presets:";
  for (const auto& n : Field::preset_names()) std::cout << " " << n;
  std::cout << "\nmotion scripts:";
  for (const auto& n : sim::MotionScript::types()) std::cout << " " << n;
  std::cout << "\nnoise profiles:";
  for (const auto& n : harness::NoiseProfile::names()) std::cout << " " << n;
  std::cout << "\nevents:";
  for (const auto& n : harness::event_type_names()) std::cout << " " << n;
  std::cout << "\nlocalizers:\n";
  for (const auto& l : harness::localizers()) std::cout << "  " << l.type << " - " << l.description << "\n";
  std::cout << "experiments:\n";
  for (const auto& e : experiments::all()) std::cout << "  " << e.name << " - " << e.description << "\n";
  // Where the lists above came from (an installed package's share/omniloc or the source tree).
  std::cout << "shared files: " << share_dir().string() << "\n" << "data: " << data_dir() << "\n";
  return 0;
}

// Commands written in Python (compare, gate, report, paper-table, view) are the results package
// (share_dir()/python/omniloc, docs/architecture.md): the CLI only forwards, so both entry points
// behave the same. `prog` ("omniloc compare") goes to the module in OMNILOC_<NAME>_PROG so its --help
// and errors name the command the user typed. Returns only when the interpreter cannot be started.
int exec_python_module(const std::string& module, const std::string& prog, int argc, char** argv) {
  const std::string python_dir = (share_dir() / "python").string();
  const char* py = ::access("/usr/bin/python3", X_OK) == 0 ? "/usr/bin/python3" : "python3";
  const std::string dotted = "omniloc.commands." + module;
  std::vector<char*> args{const_cast<char*>(py), const_cast<char*>("-m"), const_cast<char*>(dotted.c_str())};
  for (int i = 2; i < argc; ++i) args.push_back(argv[i]);
  args.push_back(nullptr);
  const char* old_path = std::getenv("PYTHONPATH");
  const std::string path = old_path && *old_path ? python_dir + ":" + old_path : python_dir;
  ::setenv("PYTHONPATH", path.c_str(), 1);
  std::string var = module;  // "paper_table" -> OMNILOC_PAPER_TABLE_PROG
  for (char& c : var) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  ::setenv(("OMNILOC_" + var + "_PROG").c_str(), prog.c_str(), 1);
  ::execvp(py, args.data());
  std::cerr << "failed: cannot run " << py << " -m " << dotted << "\n";
  return 1;
}

// A relative input file that is not there from the working directory but is a shipped one
// (share_dir()/scenarios/...) is taken from there, so `omniloc run scenarios/quickstart.json` works
// from any folder once the package is installed. Said on stderr: a file of the same name in the
// working directory would otherwise silently win or lose.
std::string shipped_or_given(const std::string& file) {
  namespace fs = std::filesystem;
  const fs::path p(file);
  std::error_code ec;
  if (p.empty() || p.is_absolute() || fs::exists(p, ec)) return file;
  const fs::path shipped = (share_dir() / p).lexically_normal();
  if (!fs::is_regular_file(shipped, ec)) return file;
  std::cerr << "omniloc: using " << shipped.string() << "\n";
  return shipped.string();
}

int cmd_experiment(const cli::Args& a) {
  check_output_target(a, true);
  for (const auto& e : experiments::all()) {
    if (e.name != a.positional[0]) continue;
    experiments::ExperimentArgs ea;
    if (a.has("--seed")) ea.seed = a.unsigned_integer("--seed", 0, kMaxSeed);
    ea.out_dir = a.value("-o", "results/experiments/" + e.name);
    ea.quick = a.has("--quick");
    ea.config = a.value("--config");
    if (!ea.config.empty()) require_readable_file(ea.config, "--config", "an experiment description file (JSON)");
    return e.run(ea, std::cout);
  }
  throw UsageError("unknown experiment \"" + a.positional[0] + "\" (see omniloc list)");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    std::cout << kUsage;
    return argc < 2 ? 2 : 0;
  }
  const std::string cmd = argv[1];
  if (cmd == "--version" || cmd == "version") {
    std::cout << version_line() << "\n";
    return 0;
  }
  for (const char* py_cmd : {"compare", "gate", "report", "paper-table", "global-start", "view"})
    if (cmd == py_cmd) {
      std::string module = cmd;
      std::replace(module.begin(), module.end(), '-', '_');
      return exec_python_module(module, "omniloc " + cmd, argc, argv);
    }
  struct Entry {
    const cli::Command* spec;
    int (*run)(const cli::Args&);
  };
  const Entry commands[] = {{&kValidate, cmd_validate},
                            {&kRun, cmd_run},
                            {&kRecord, cmd_record},
                            {&kReplay, cmd_replay},
                            {&kGlDevices, cmd_gl_devices},
                            {&kList, [](const cli::Args&) { return cmd_list(); }},
                            {&kSchema, cmd_schema},
                            {&kCalibrate, cmd_calibrate},
                            {&kColourCalibrate, cmd_colour_calibrate},
                            {&kRender, cmd_render},
                            {&kSweep, cmd_sweep},
                            {&kExperiment, cmd_experiment},
                            {&app::kCache, app::cmd_cache}};
  try {
    for (const auto& c : commands) {
      if (c.spec->name != cmd) continue;
      cli::Args a = cli::parse(*c.spec, argc, argv, 2);
      if (a.help) {
        std::cout << cli::help_text(*c.spec);
        return 0;
      }
      // The one place input files of these commands are named: shipped ones are found from anywhere.
      if (c.spec == &kRun || c.spec == &kValidate || c.spec == &kRecord || c.spec == &kSweep)
        for (auto& file : a.positional) file = shipped_or_given(file);
      return c.run(a);
    }
    std::cerr << "error: unknown command \"" << cmd << "\"\n" << kUsage;
    return 2;
  } catch (const ConfigError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const UsageError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "failed: " << e.what() << "\n";
    return 1;
  }
}
