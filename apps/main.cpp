// omniloc command line: validate, run, list, experiment (and more as capabilities land).
// Exit codes: 0 success, 1 runtime failure, 2 bad input (scenario, arguments) — nothing written.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <unistd.h>

#include "core/error.hpp"
#include "core/field.hpp"
#include "core/version.hpp"
#include "harness/experiment.hpp"
#include "harness/localizer_registry.hpp"
#include "harness/render_frame.hpp"
#include "harness/runner.hpp"
#include "harness/scenario.hpp"
#include "harness/slurm.hpp"
#include "harness/sweep.hpp"
#include "harness/vision_setup.hpp"
#include "sim/render/camera_config.hpp"
#include "sim/motion.hpp"

using namespace omniloc;

namespace {

const char* kUsage = R"(usage: omniloc <command> [options]

commands:
  run FILE [--seed N] [-o DIR] [--frames DIR] [--frames-every N] [--quiet]
                         run a scenario; results in results/runs/<scenario>/<seed>/
  render FILE --t SECONDS [--robot ID] [--seed N] [--labels | --points] -o frame.png
                         the panorama robot ID (default: the first localized) sees at time t
  calibrate FILE [-o map.json] [--seed N]
                         model-free mirror calibration with the scenario's camera; prints the
                         map's error against the true mirror by distance
  colour-calibrate FILE [-o table.lut] [--seed N]
                         learn the colour look-up table from labelled renders of the scenario's field
  validate FILE          check a scenario file or an experiment description (scenarios/experiments/);
                         exit 2 with the JSON path of the first problem
  list                   field presets, motion scripts, localizers, noise profiles, experiments
  sweep SWEEP.json [-j N] [--shard I/N] [--resume] [--aggregate-only] [-o DIR]
                         scenarios x localizers x parameters x seeds, in parallel; aggregate
                         with mean and 95 % interval in results/sweeps/<name>/aggregate.{csv,json}
  sweep SWEEP.json --slurm [--tasks N] [--partition P] [--time HH:MM:SS] [--cpus-per-task C]
        [--sbatch-arg ARG]... [--dry-run] [--resubmit-missing] [-o DIR]
                         a Slurm job array of N shards and a merge job (docs/cluster.md);
                         --dry-run only writes DIR/slurm/
  sweep SWEEP.json --status [--tasks N] [-o DIR]
                         runs done / failed / missing per shard, and the Slurm jobs' states;
                         exit 0 when every run is done, 1 otherwise
  experiment NAME [--seed N] [-o DIR] [--quick] [--config FILE]
                         run a named experiment (solver maps, cooperative simulation, ...);
                         --config: its description file instead of scenarios/experiments/NAME.json
  compare A B [--markdown] [--alpha P]
                         two result sets (runs, sweeps or folders of them, e.g. two commits) side by
                         side per metric: difference and whether it exceeds the seed-to-seed spread
                         (Welch's t); runs scripts/compare.py
  --version              the build: git describe, compiler, build type (also in every summary.json)
)";

struct Args {
  std::vector<std::string> positional;
  std::vector<std::pair<std::string, std::string>> options;
  std::vector<std::string> flags;
};

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

Args parse(int argc, char** argv, int first, const std::vector<std::string>& with_value, const std::vector<std::string>& flags) {
  Args a;
  for (int i = first; i < argc; ++i) {
    const std::string s = argv[i];
    bool known = false;
    for (const auto& o : with_value)
      if (s == o) {
        if (i + 1 >= argc) throw UsageError("option " + s + " needs a value");
        a.options.emplace_back(s, argv[++i]);
        known = true;
      }
    for (const auto& f : flags)
      if (s == f) {
        a.flags.push_back(s);
        known = true;
      }
    if (!known) {
      if (!s.empty() && s[0] == '-') throw UsageError("unknown option " + s);
      a.positional.push_back(s);
    }
  }
  return a;
}

std::string opt(const Args& a, const std::string& name, const std::string& def = "") {
  for (const auto& [k, v] : a.options)
    if (k == name) return v;
  return def;
}
bool flag(const Args& a, const std::string& name) {
  for (const auto& f : a.flags)
    if (f == name) return true;
  return false;
}
std::uint64_t parse_seed(const std::string& s) {
  try {
    std::size_t pos = 0;
    const unsigned long long v = std::stoull(s, &pos);
    if (pos != s.size()) throw std::invalid_argument(s);
    return v;
  } catch (const std::exception&) {
    throw UsageError("--seed needs a non-negative integer, got \"" + s + "\"");
  }
}

int cmd_validate(const Args& a) {
  if (a.positional.size() != 1) throw UsageError("validate takes one scenario file");
  // An experiment description (scenarios/experiments/*.json) names its experiment; the experiment checks it.
  if (std::ifstream in(a.positional[0]); in) {
    const Json j = Json::parse(in, nullptr, false);
    if (j.is_object() && j.contains("experiment") && j["experiment"].is_string()) {
      for (const auto& e : harness::experiments())
        if (e.name == j["experiment"].get<std::string>() && e.validate) {
          e.validate(a.positional[0]);
          std::cout << a.positional[0] << ": ok (description of experiment \"" << e.name << "\")\n";
          return 0;
        }
      throw ConfigError("/experiment", json_brief(j["experiment"]), "the name of an experiment that reads a description file (see omniloc list)");
    }
  }
  const auto s = harness::load_scenario(a.positional[0]);
  std::cout << a.positional[0] << ": ok (scenario \"" << s.name << "\", " << s.robots.size() << " robot(s), "
            << s.duration << " s, localizer " << s.localizer.value("type", "?") << ")\n";
  return 0;
}

int cmd_run(const Args& a) {
  if (a.positional.size() != 1) throw UsageError("run takes one scenario file");
  const auto s = harness::load_scenario(a.positional[0]);
  harness::RunOptions o;
  if (!opt(a, "--seed").empty()) o.seed = parse_seed(opt(a, "--seed"));
  o.out_dir = opt(a, "-o");
  o.frames_dir = opt(a, "--frames");
  if (!opt(a, "--frames-every").empty()) o.frames_every = std::max(1, std::atoi(opt(a, "--frames-every").c_str()));
  if (!flag(a, "--quiet")) o.log = &std::cerr;
  const auto r = harness::run_scenario(s, o);
  std::cout << "scenario " << s.name << ", seed " << r.seed << ", localizer " << r.summary["localizer"].get<std::string>()
            << ", noise " << s.noise.name << "\n"
            << r.table << "results: " << r.out_dir << "\n";
  return 0;
}

// Slurm submission and status (harness/slurm.hpp); every option is checked before anything is written.
int cmd_sweep_slurm(const Args& a, const harness::SweepSpec& spec) {
  auto count = [&](const std::string& name, int def) {
    const std::string v = opt(a, name);
    if (v.empty()) return def;
    if (v.find_first_not_of("0123456789") != std::string::npos || v.size() > 6) throw UsageError(name + " needs a positive integer, got \"" + v + "\"");
    return std::atoi(v.c_str());
  };
  if (flag(a, "--slurm") && flag(a, "--status")) throw UsageError("--status and --slurm are separate commands");
  if (flag(a, "--status")) {
    const auto st = harness::sweep_status(spec, opt(a, "-o"), count("--tasks", 0));
    std::cout << st.text;
    return st.complete() ? 0 : 1;
  }
  harness::SlurmOptions so;
  so.tasks = count("--tasks", 0);
  if (!opt(a, "--tasks").empty() && so.tasks == 0) throw UsageError("--tasks needs a positive integer, got \"0\"");
  so.partition = opt(a, "--partition");
  so.time_limit = opt(a, "--time");
  so.cpus_per_task = count("--cpus-per-task", 1);
  for (const auto& [k, v] : a.options)
    if (k == "--sbatch-arg") so.sbatch_args.push_back(v);
  so.dry_run = flag(a, "--dry-run");
  so.resubmit_missing = flag(a, "--resubmit-missing");
  so.out_dir = opt(a, "-o");
  const auto r = harness::submit_slurm(spec, a.positional[0], so);
  std::cout << r.message;
  return 0;
}

int cmd_sweep(const Args& a) {
  if (a.positional.size() != 1) throw UsageError("sweep takes one sweep file");
  const auto spec = harness::load_sweep(a.positional[0]);
  if (flag(a, "--slurm") || flag(a, "--status")) return cmd_sweep_slurm(a, spec);
  for (const char* o : {"--tasks", "--partition", "--time", "--cpus-per-task", "--sbatch-arg"})
    if (!opt(a, o).empty()) throw UsageError(std::string(o) + " needs --slurm");
  for (const char* f : {"--dry-run", "--resubmit-missing"})
    if (flag(a, f)) throw UsageError(std::string(f) + " needs --slurm");
  harness::SweepOptions o;
  const std::string j = opt(a, "-j", "1");
  o.jobs = std::atoi(j.c_str());
  if (o.jobs < 1 || o.jobs > 256) throw UsageError("-j needs a worker count in [1, 256], got \"" + j + "\"");
  const std::string shard = opt(a, "--shard");
  if (!shard.empty()) {
    const auto slash = shard.find('/');
    if (slash == std::string::npos) throw UsageError("--shard needs I/N, got \"" + shard + "\"");
    o.shard_index = std::atoi(shard.substr(0, slash).c_str());
    o.shard_count = std::atoi(shard.substr(slash + 1).c_str());
    if (o.shard_count < 1 || o.shard_index < 0 || o.shard_index >= o.shard_count)
      throw UsageError("--shard I/N needs 0 <= I < N, got \"" + shard + "\"");
  }
  o.resume = flag(a, "--resume");
  o.aggregate_only = flag(a, "--aggregate-only");
  if (!opt(a, "--stop-after").empty()) o.stop_after = std::stoul(opt(a, "--stop-after"));
  o.out_dir = opt(a, "-o");
  o.progress = &std::cerr;
  std::cerr << "sweep " << spec.name << ": " << spec.runs.size() << " runs, " << o.jobs << " worker(s)"
            << (o.shard_count > 1 ? ", shard " + shard : std::string()) << "\n";
  const auto r = harness::run_sweep(spec, o);
  std::cout << r.table << "ran " << r.ran << ", skipped " << r.skipped << ", failed " << r.failed << ", missing " << r.missing
            << "\nresults: " << r.out_dir << "\n";
  return r.failed > 0 ? 1 : 0;
}

int cmd_render(const Args& a) {
  if (a.positional.size() != 1) throw UsageError("render takes one scenario file");
  const auto s = harness::load_scenario(a.positional[0]);
  const std::string out = opt(a, "-o");
  if (out.empty()) throw UsageError("render needs -o frame.png");
  double t = 0;
  try {
    t = std::stod(opt(a, "--t", "0"));
  } catch (const std::exception&) {
    throw UsageError("--t needs a time in seconds");
  }
  const int robot = opt(a, "--robot").empty() ? s.localized_robots().front() : std::atoi(opt(a, "--robot").c_str());
  const std::uint64_t seed = opt(a, "--seed").empty() ? s.seed : parse_seed(opt(a, "--seed"));
  harness::render_to_png(s, t, robot, seed, flag(a, "--labels"), out, flag(a, "--points"));
  std::cout << "wrote " << out << "\n";
  return 0;
}

int cmd_calibrate(const Args& a) {
  if (a.positional.size() != 1) throw UsageError("calibrate takes one scenario file");
  const auto s = harness::load_scenario(a.positional[0]);
  const auto cfg = sim::CameraConfig::from_json(s.camera, "/camera");
  const std::uint64_t seed = opt(a, "--seed").empty() ? 1 : parse_seed(opt(a, "--seed"));
  Json report;
  auto r = harness::calibrate_camera(cfg, seed, &report);
  const std::string out = opt(a, "-o", "results/cache/calibration_" + harness::camera_tag(cfg) + ".json");
  r.map.save(out);
  std::printf("directions used %d, rejected %d\n%10s %12s %12s %12s\n", r.directions_used, r.directions_rejected, "distance m", "mean err cm",
              "p95 err cm", "max err cm");
  for (const auto& row : report["error_by_distance"])
    std::printf("%10.1f %12.2f %12.2f %12.2f\n", row["distance_m"].get<double>(), 100 * row["mean_error_m"].get<double>(),
                100 * row["p95_error_m"].get<double>(), 100 * row["max_error_m"].get<double>());
  std::cout << "wrote " << out << "\n";
  return 0;
}

int cmd_colour_calibrate(const Args& a) {
  if (a.positional.size() != 1) throw UsageError("colour-calibrate takes one scenario file");
  const auto s = harness::load_scenario(a.positional[0]);
  const auto cfg = sim::CameraConfig::from_json(s.camera, "/camera");
  const std::uint64_t seed = opt(a, "--seed").empty() ? 1 : parse_seed(opt(a, "--seed"));
  const ColourTable t = harness::colour_calibrate(cfg, s.field, seed);
  const std::string out = opt(a, "-o", "results/cache/colour_" + harness::camera_tag(cfg) + "_" + s.field.fingerprint() + ".lut");
  t.save(out);
  std::cout << "wrote " << out << "\n";
  return 0;
}

int cmd_list() {
  std::cout << "field presets:";
  for (const auto& n : Field::preset_names()) std::cout << " " << n;
  std::cout << "\nmotion scripts:";
  for (const auto& n : sim::MotionScript::types()) std::cout << " " << n;
  std::cout << "\nnoise profiles:";
  for (const auto& n : harness::NoiseProfile::names()) std::cout << " " << n;
  std::cout << "\nlocalizers:\n";
  for (const auto& l : harness::localizers()) std::cout << "  " << l.type << " - " << l.description << "\n";
  std::cout << "experiments:\n";
  for (const auto& e : harness::experiments()) std::cout << "  " << e.name << " - " << e.description << "\n";
  return 0;
}

// The comparison is statistics over result files, written in Python beside the report
// (scripts/compare.py); the CLI only forwards, so both entry points give the same table.
int cmd_compare(int argc, char** argv) {
  const std::string script = std::string(OMNILOC_SOURCE_DIR) + "/scripts/compare.py";
  const char* py = ::access("/usr/bin/python3", X_OK) == 0 ? "/usr/bin/python3" : "python3";
  std::vector<char*> args{const_cast<char*>(py), const_cast<char*>(script.c_str())};
  for (int i = 2; i < argc; ++i) args.push_back(argv[i]);
  args.push_back(nullptr);
  ::execvp(py, args.data());
  std::cerr << "failed: cannot run " << py << " " << script << "\n";
  return 1;
}

int cmd_experiment(const Args& a) {
  if (a.positional.size() != 1) throw UsageError("experiment takes one name (see omniloc list)");
  for (const auto& e : harness::experiments()) {
    if (e.name != a.positional[0]) continue;
    harness::ExperimentArgs ea;
    if (!opt(a, "--seed").empty()) ea.seed = parse_seed(opt(a, "--seed"));
    ea.out_dir = opt(a, "-o", "results/experiments/" + e.name);
    ea.quick = flag(a, "--quick");
    ea.config = opt(a, "--config");
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
  if (cmd == "compare") return cmd_compare(argc, argv);
  try {
    if (cmd == "validate") return cmd_validate(parse(argc, argv, 2, {}, {}));
    if (cmd == "run") return cmd_run(parse(argc, argv, 2, {"--seed", "-o", "--frames", "--frames-every"}, {"--quiet"}));
    if (cmd == "list") return cmd_list();
    if (cmd == "calibrate") return cmd_calibrate(parse(argc, argv, 2, {"-o", "--seed"}, {}));
    if (cmd == "colour-calibrate") return cmd_colour_calibrate(parse(argc, argv, 2, {"-o", "--seed"}, {}));
    if (cmd == "render") return cmd_render(parse(argc, argv, 2, {"--t", "--robot", "--seed", "-o"}, {"--labels", "--points"}));
    if (cmd == "sweep")
      return cmd_sweep(parse(argc, argv, 2, {"-j", "--shard", "-o", "--stop-after", "--tasks", "--partition", "--time", "--cpus-per-task", "--sbatch-arg"},
                             {"--resume", "--aggregate-only", "--slurm", "--dry-run", "--status", "--resubmit-missing"}));
    if (cmd == "experiment") return cmd_experiment(parse(argc, argv, 2, {"--seed", "-o", "--config"}, {"--quick"}));
    throw UsageError("unknown command \"" + cmd + "\"");
  } catch (const ConfigError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const UsageError& e) {
    std::cerr << "error: " << e.what() << "\n" << kUsage;
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "failed: " << e.what() << "\n";
    return 1;
  }
}
