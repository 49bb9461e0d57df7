#include "apps/commands.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "core/install_paths.hpp"

namespace omniloc::app {

// Adding a command: its file (option table and body, declared in commands.hpp) and a line here; a
// command of the results package is the line alone, with `.python = true`.
const std::vector<CommandEntry>& commands() {
  static const std::vector<CommandEntry> table = {
      {.name = "run",
       .usage = {{"FILE [--seed N] [-o DIR [--overwrite]] [--frames DIR] [--frames-every N] [--debug-view] [--quiet]\n"
                  "[--draw-each | --cache DIR | --no-cache]",
                  "run a scenario; results in results/runs/<scenario>/<seed>/; its world comes\n"
                  "from the world cache when it was drawn before (docs/recording.md \"World cache\")"}},
       .options = &kRun, .run = cmd_run, .shipped_inputs = true},
      {.name = "record",
       .usage = {{"FILE [--seed N] [--images] [-o DIR [--overwrite]] [--quiet]",
                  "simulate and perceive a scenario once, no localizer: a recording of every\n"
                  "frame a localizer is given (docs/recording.md), in results/recordings/<scenario>/<seed>/"}},
       .options = &kRecord, .run = cmd_record, .shipped_inputs = true},
      {.name = "replay",
       .usage = {{"RECORDING --localizer JSON|FILE [--seed N] [-o DIR [--overwrite]] [--debug-view] [--quiet]",
                  "run any localizer on a recording: the same run folder as `run` gives"}},
       .options = &kReplay, .run = cmd_replay},
      {.name = "render",
       .usage = {{"FILE --t SECONDS [--robot ID] [--seed N] [--labels | --points] -o frame.png",
                  "the panorama robot ID (default: the first localized) sees at time t"}},
       .options = &kRender, .run = cmd_render},
      {.name = "calibrate",
       .usage = {{"FILE [-o map.json] [--seed N]",
                  "model-free mirror calibration with the scenario's camera; prints the\n"
                  "map's error against the true mirror by distance"}},
       .options = &kCalibrate, .run = cmd_calibrate},
      {.name = "colour-calibrate",
       .usage = {{"FILE [-o table.lut] [--seed N]", "learn the colour look-up table from labelled renders of the scenario's field"}},
       .options = &kColourCalibrate, .run = cmd_colour_calibrate},
      {.name = "validate",
       .usage = {{"FILE...",
                  "check a scenario, a sweep file or an experiment description (scenarios/experiments/);\n"
                  "exit 2 with the JSON path of the first problem"}},
       .options = &kValidate, .run = cmd_validate, .shipped_inputs = true},
      {.name = "gl-devices",
       .usage = {{"",
                  "the EGL devices of this machine and the device each GL back-end renders on\n"
                  "(OMNILOC_GL_BACKEND, OMNILOC_EGL_DEVICE: docs/camera.md \"GPUs\")"}},
       .options = &kGlDevices, .run = cmd_gl_devices},
      {.name = "list",
       .usage = {{"", "field presets, motion scripts, event kinds, localizers, noise profiles, experiments"}},
       .options = &kList, .run = cmd_list},
      {.name = "schema",
       .usage = {{"[--sweep | --markdown] [-o FILE]",
                  "the JSON Schema of scenario files (for editors), or the parameter\n"
                  "reference docs/localizers.md generated from the same lists"}},
       .options = &kSchema, .run = cmd_schema},
      {.name = "sweep",
       .usage = {{"SWEEP.json [-j N] [--shard I/N] [--resume] [--aggregate-only] [--draw-each]\n"
                  "[--cache DIR | --no-cache] [--localizer JSON|FILE]... [-o DIR]",
                  "scenarios x localizers x parameters x seeds, in parallel; aggregate\n"
                  "with mean and interval (docs/results.md \"Intervals\": t95 from 5 seeds,\n"
                  "else the seeds' range) in results/sweeps/<name>/aggregate.{csv,json}"},
                 {"SWEEP.json --slurm [--tasks N] [--partition P] [--time HH:MM:SS] [--cpus-per-task C]\n"
                  "[--gpus-per-task G] [--sbatch-arg ARG]... [--dry-run] [--resubmit-missing] [-o DIR]",
                  "a Slurm job array of N shards and a merge job (docs/cluster.md);\n"
                  "--dry-run only writes DIR/slurm/"},
                 {"SWEEP.json --status [--tasks N] [-o DIR]",
                  "runs done / failed / missing per shard, and the Slurm jobs' states;\n"
                  "exit 0 when every run is done, 1 otherwise"}},
       .options = &kSweep, .run = cmd_sweep, .shipped_inputs = true},
      {.name = "experiment",
       .usage = {{"NAME [--seed N] [-o DIR] [--quick] [--config FILE]",
                  "run a named experiment (solver maps, cooperative simulation, ...);\n"
                  "--config: its description file instead of scenarios/experiments/NAME.json"}},
       .options = &kExperiment, .run = cmd_experiment},
      {.name = "cache",
       .usage = {{"list|size|prune [--older-than DAYS] [--max-size SIZE] [--cache DIR]",
                  "the world cache: what it holds, its size, and removing old entries"}},
       .options = &kCache, .run = cmd_cache},
      {.name = "compare",
       .usage = {{"A B [--markdown] [--alpha P]",
                  "two result sets (runs, sweeps or folders of them, e.g. two commits) side by\n"
                  "side per metric: difference and whether it exceeds the seed-to-seed spread\n"
                  "(Welch's t)"}},
       .python = true},
      {.name = "gate",
       .usage = {{"RESULTS --rules FILE [--baseline DIR] [--alpha P] [--junit FILE] [--benchmark-json FILE]",
                  "pass or fail results against limits and a baseline (docs/ci.md): exit 0 all\n"
                  "hold, 1 a rule or regression failed, 2 bad input"}},
       .python = true},
      {.name = "report",
       .usage = {{"RESULTS... -o DIR [--baseline RESULTS] [--title TEXT]", "report.md and a self-contained report.html"}},
       .python = true},
      {.name = "paper-table",
       .usage = {{"RESULTS --paper ID [--rows ROWS]", "one published table beside ours (results/reference/papers.json)"}},
       .python = true},
      {.name = "global-start",
       .usage = {{"RESULTS [--markdown]", "global starts judged per run: found, wrong, none (docs/global_localization.md)"}},
       .python = true},
      {.name = "view",
       .usage = {{"RUN_DIR [-o FILE.html] [--recording DIR]",
                  "one self-contained HTML page to step through a run frame by frame\n"
                  "(docs/viewer.md)"}},
       .python = true},
      {.name = "export",
       .usage = {{"RUN_DIR|RECORDING|SWEEP_DIR -o FILE.mcap [--recording DIR] [--no-images]",
                  "an MCAP file that Foxglove opens, with Foxglove's schemas: field, poses, line\n"
                  "points, particles, images, per-frame numbers, events (docs/viewer.md)"}},
       .python = true},
  };
  return table;
}

namespace {

// The column where what a command does starts; a synopsis that reaches it puts that on the next line.
constexpr std::size_t kDoesColumn = 25;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

void print_usage(const CommandEntry& c, const Usage& u, std::string& out) {
  const std::vector<std::string> synopsis = lines_of(u.synopsis);
  std::string head = "  " + c.name;
  if (!synopsis.empty() && !synopsis.front().empty()) head += " " + synopsis.front();
  for (std::size_t i = 1; i < synopsis.size(); ++i) head += "\n" + std::string(c.name.size() + 3, ' ') + synopsis[i];
  const bool same_line = synopsis.size() <= 1 && head.size() + 2 <= kDoesColumn;
  const std::vector<std::string> does = lines_of(u.does);
  for (std::size_t i = 0; i < does.size(); ++i) {
    if (i == 0 && same_line) out += head + std::string(kDoesColumn - head.size(), ' ');
    else out += (i == 0 ? head + "\n" : std::string()) + std::string(kDoesColumn, ' ');
    out += does[i] + "\n";
  }
}

}  // namespace

std::string usage_text() {
  std::string out = "usage: omniloc <command> [options]\n\ncommands:\n";
  std::vector<std::string> python;
  for (const auto& c : commands()) {
    for (const auto& u : c.usage) print_usage(c, u, out);
    if (c.python) python.push_back(c.name);
  }
  std::string names;
  for (std::size_t i = 0; i < python.size(); ++i) names += (i == 0 ? "" : i + 1 == python.size() ? " and " : ", ") + python[i];
  out += "  (" + names + " are the Python results package, python/omniloc:\n   docs/architecture.md)\n";
  out += "  COMMAND --help         that command's options\n";
  out += "  --version              the build: git describe, compiler, build type (also in every summary.json)\n";
  return out;
}

// Commands written in Python are the results package (share_dir()/python/omniloc,
// docs/architecture.md): the CLI only forwards, so both entry points behave the same. `prog`
// ("omniloc compare") goes to the module in OMNILOC_<NAME>_PROG so its --help and errors name the
// command the user typed.
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

}  // namespace omniloc::app
