#include "batch/slurm.hpp"

#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/version.hpp"
#include "external/client_process.hpp"
#include "external/external_config.hpp"
#include "external/sha256.hpp"

namespace omniloc::batch {

namespace fs = std::filesystem;

namespace {

// Default array size when --tasks is not given: small enough for sites that cap array sizes or
// running jobs per user, large enough to spread a paper-sized study; docs/cluster.md sizes it.
constexpr int kDefaultTasks = 32;

// One shell word: single quotes, inner quotes as '\'' (paths with spaces survive in the scripts).
std::string shq(const std::string& s) {
  if (!s.empty() && s.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-./=:,+%@") == std::string::npos)
    return s;
  std::string o = "'";
  for (char c : s) o += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return o + "'";
}

bool on_path(const std::string& name) { return external::resolve_program(name, fs::current_path().string()).has_value(); }

struct Captured {
  int status = -1;  ///< wait status; -1 when the program could not be started
  std::string out, err;
  bool ok() const { return status >= 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0; }
};

// Runs a program found on PATH (no shell, so options need no quoting) and collects its output.
// Both pipes are drained together so a chatty stderr cannot block the child.
Captured capture(const std::vector<std::string>& argv) {
  Captured c;
  int out[2], err[2];
  if (::pipe(out) != 0) return c;
  if (::pipe(err) != 0) {
    ::close(out[0]);
    ::close(out[1]);
    return c;
  }
  const pid_t pid = ::fork();
  if (pid < 0) {
    for (int fd : {out[0], out[1], err[0], err[1]}) ::close(fd);
    return c;
  }
  if (pid == 0) {
    ::dup2(out[1], 1);
    ::dup2(err[1], 2);
    for (int fd : {out[0], out[1], err[0], err[1]}) ::close(fd);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execvp(args[0], args.data());
    ::_exit(127);
  }
  ::close(out[1]);
  ::close(err[1]);
  std::array<pollfd, 2> fds{{{out[0], POLLIN, 0}, {err[0], POLLIN, 0}}};
  std::string* sinks[2] = {&c.out, &c.err};
  int open_fds = 2;
  char buf[4096];
  while (open_fds > 0) {
    if (::poll(fds.data(), fds.size(), -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (int k = 0; k < 2; ++k) {
      if (fds[k].fd < 0 || !(fds[k].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      const ssize_t n = ::read(fds[k].fd, buf, sizeof buf);
      if (n > 0) {
        sinks[k]->append(buf, static_cast<std::size_t>(n));
      } else if (n == 0 || errno != EINTR) {
        ::close(fds[k].fd);
        fds[k].fd = -1;
        --open_fds;
      }
    }
  }
  for (auto& f : fds)
    if (f.fd >= 0) ::close(f.fd);
  while (::waitpid(pid, &c.status, 0) < 0 && errno == EINTR) {
  }
  return c;
}

std::string trim(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  std::size_t i = 0;
  while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
  return s.substr(i);
}

std::string utc_now() {
  std::time_t t = std::time(nullptr);
  std::tm tm{};
  ::gmtime_r(&t, &tm);
  char b[32];
  std::strftime(b, sizeof b, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return b;
}

std::string join_ints(const std::vector<int>& v, const char* sep = ",") {
  std::string o;
  for (int x : v) o += (o.empty() ? "" : sep) + std::to_string(x);
  return o;
}

fs::path results_dir(const SweepSpec& spec, const std::string& out_dir) {
  return fs::absolute(out_dir.empty() ? "results/sweeps/" + spec.name : out_dir).lexically_normal();
}

// The runs as they will be executed: ids and the full scenario JSON after overrides. A sweep file
// that is unchanged while a scenario file it names was edited gives another hash.
std::string runs_hash(const SweepSpec& spec) {
  std::string all;
  for (const auto& r : spec.runs) all += r.id + "\n" + r.scenario.dump() + "\n";
  return sha256_hex(all);
}

Json read_submission(const fs::path& folder) {
  const fs::path f = folder / "submission.json";
  if (!fs::exists(f)) return Json();
  try {
    return Json::parse(read_file(f.string()));
  } catch (const Json::parse_error& e) {
    throw ConfigError(f.string(), "invalid JSON", std::string("the submission record omniloc wrote (") + e.what() + ")");
  }
}

bool is_active(const std::string& state) {
  static const std::set<std::string> active = {"PENDING",   "RUNNING",  "CONFIGURING", "COMPLETING",    "SUSPENDED",
                                                "REQUEUED",  "RESIZING", "SIGNALING",   "STAGE_OUT",     "REQUEUE_HOLD",
                                                "REQUEUE_FED", "RESV_DEL_HOLD", "STOPPED"};
  return active.count(state) > 0;
}

struct JobState {
  std::string state, reason;
};

// States of one job (every element of an array: key "<array>_<task>", else "<job>") from squeue,
// falling back to scontrol for jobs squeue no longer lists. Both forget a job MinJobAge after it
// ends (5 minutes by default); there is no accounting database to ask (sacct needs slurmdbd).
void query_job(const std::string& id, std::map<std::string, JobState>& states) {
  if (on_path("squeue")) {
    const Captured c = capture({"squeue", "-h", "-r", "-t", "all", "-j", id, "-o", "%i|%T|%r"});
    bool any = false;
    if (c.ok()) {
      std::stringstream ss(c.out);
      std::string line;
      while (std::getline(ss, line)) {
        const auto a = line.find('|'), b = line.find('|', a == std::string::npos ? a : a + 1);
        if (a == std::string::npos || b == std::string::npos) continue;
        states[trim(line.substr(0, a))] = {trim(line.substr(a + 1, b - a - 1)), trim(line.substr(b + 1))};
        any = true;
      }
    }
    if (any) return;
  }
  if (on_path("scontrol")) {
    const Captured c = capture({"scontrol", "-o", "show", "job", id});
    if (!c.ok()) return;
    std::stringstream ss(c.out);
    std::string line;
    while (std::getline(ss, line)) {
      std::map<std::string, std::string> kv;
      std::stringstream ws(line);
      std::string w;
      while (ws >> w) {
        const auto eq = w.find('=');
        if (eq != std::string::npos && !kv.count(w.substr(0, eq))) kv[w.substr(0, eq)] = w.substr(eq + 1);
      }
      if (!kv.count("JobState")) continue;
      const std::string key = kv.count("ArrayJobId") ? kv["ArrayJobId"] + "_" + kv["ArrayTaskId"] : kv["JobId"];
      states[key] = {kv["JobState"], kv.count("Reason") ? kv["Reason"] : ""};
    }
  }
}

std::string describe(const JobState& s) {
  return s.reason.empty() || s.reason == "None" || s.reason == "(null)" ? s.state : s.state + " (" + s.reason + ")";
}

// Parses `sbatch --parsable` output: "<jobid>" or "<jobid>;<cluster>".
std::string parse_job_id(const Captured& c, const std::string& what) {
  const std::string out = trim(c.out);
  const std::string id = out.substr(0, out.find(';'));
  if (!c.ok() || id.empty() || id.find_first_not_of("0123456789") != std::string::npos)
    throw RuntimeFailure("sbatch refused the " + what + ": " + (trim(c.err).empty() ? out : trim(c.err)));
  return id;
}


}  // namespace

std::string sha256_hex(const std::string& bytes) { return external::sha256_hex(bytes); }

std::vector<int> SweepStatus::incomplete_shards() const {
  std::vector<int> v;
  for (const auto& s : shards)
    if (s.failed > 0 || s.missing > 0) v.push_back(s.shard);
  return v;
}

void check_slurm_options(const SweepSpec& spec, const SlurmOptions& o) {
  const std::size_t runs = spec.runs.size();
  if (o.tasks < 0 || static_cast<std::size_t>(o.tasks) > runs)
    throw ConfigError("--tasks", std::to_string(o.tasks), "an array size in [1, " + std::to_string(runs) + "] (the sweep has " +
                                                              std::to_string(runs) + " runs; more tasks would be empty)");
  if (o.cpus_per_task < 1 || o.cpus_per_task > 256)
    throw ConfigError("--cpus-per-task", std::to_string(o.cpus_per_task), "a core count in [1, 256]");
  if (o.gpus_per_task < 0 || o.gpus_per_task > 16)
    throw ConfigError("--gpus-per-task", std::to_string(o.gpus_per_task), "a GPU count in [0, 16]");
  static const std::regex time_re(R"(^([0-9]+-)?[0-9]{1,3}:[0-5][0-9]:[0-5][0-9]$)");
  if (!o.time_limit.empty() && !std::regex_match(o.time_limit, time_re))
    throw ConfigError("--time", "\"" + o.time_limit + "\"", "a time limit per task as HH:MM:SS or D-HH:MM:SS");
  static const std::regex part_re(R"(^[A-Za-z0-9_.,-]+$)");
  if (!o.partition.empty() && !std::regex_match(o.partition, part_re))
    throw ConfigError("--partition", "\"" + o.partition + "\"", "a partition name (letters, digits, _ . - ,)");
  for (const auto& a : o.sbatch_args)
    if (a.size() < 2 || a[0] != '-' || a.find_first_of(" \t\r\n") != std::string::npos)
      throw ConfigError("--sbatch-arg", "\"" + a + "\"", "one sbatch option without spaces, such as --mem=4G or --account=proj42");
}

SweepStatus sweep_status(const SweepSpec& spec, const std::string& out_dir, int tasks) {
  SweepStatus st;
  const fs::path dir = results_dir(spec, out_dir);
  const Json sub = read_submission(dir / "slurm");
  st.tasks = tasks > 0 ? tasks : sub.is_object() ? sub.value("tasks", 1) : 1;
  st.tasks = std::max(1, st.tasks);
  st.shards.resize(static_cast<std::size_t>(st.tasks));
  for (int k = 0; k < st.tasks; ++k) st.shards[static_cast<std::size_t>(k)].shard = k;
  for (const auto& r : spec.runs) {
    ShardStatus& s = st.shards[r.index % static_cast<std::size_t>(st.tasks)];
    ++s.runs;
    if (fs::exists(dir / "runs" / r.id / "summary.json")) {
      ++s.done;
      ++st.done;
    } else if (fs::exists(dir / "failed" / (r.id + ".json"))) {
      ++s.failed;
      ++st.failed;
      s.failed_ids.push_back(r.id);
    } else {
      ++s.missing;
      ++st.missing;
      s.missing_ids.push_back(r.id);
    }
  }

  // Slurm's view: every recorded submission, the latest one deciding a shard's state.
  std::string merge_line;
  if (sub.is_object() && sub.contains("submissions") && sub["tasks"] == st.tasks) {
    std::map<std::string, JobState> states;
    for (const auto& s : sub["submissions"]) {
      for (const char* key : {"array_job", "merge_job"})
        if (s.contains(key)) query_job(s[key].get<std::string>(), states);
    }
    for (const auto& s : sub["submissions"]) {
      const std::string a = s.value("array_job", "");
      for (const auto& k : s.value("shards", std::vector<int>())) {
        if (k < 0 || k >= st.tasks) continue;
        const auto it = states.find(a + "_" + std::to_string(k));
        st.shards[static_cast<std::size_t>(k)].slurm_state =
            it == states.end() ? "" : a + "_" + std::to_string(k) + " " + describe(it->second);
      }
      const std::string m = s.value("merge_job", "");
      if (!m.empty()) {
        const auto it = states.find(m);
        st.merge_state = it == states.end() ? "" : describe(it->second);
        if (const char* self = std::getenv("SLURM_JOB_ID"); self && m == self) st.merge_state = "RUNNING (this job)";
        merge_line = "merge job " + m + ": " + (st.merge_state.empty() ? "unknown to squeue/scontrol (finished long ago, or no Slurm here)" : st.merge_state) + "\n";
      }
    }
    // The merge job runs --status itself: it is not "still running" in its own report.
    const char* self = std::getenv("SLURM_JOB_ID");
    for (const auto& [id, s] : states)
      if (is_active(s.state) && !(self && id == self)) st.active_jobs.push_back(id);
  }

  std::ostringstream t;
  t << "sweep " << spec.name << ": " << spec.runs.size() << " runs in " << st.tasks << " shard(s), results " << dir.string() << "\n"
    << "done " << st.done << ", failed " << st.failed << ", missing " << st.missing << "\n";
  char line[256];
  std::snprintf(line, sizeof line, "%-9s %6s %6s %7s %8s  %s\n", "shard", "runs", "done", "failed", "missing", "slurm task");
  t << line;
  for (const auto& s : st.shards) {
    const std::string name = std::to_string(s.shard) + "/" + std::to_string(st.tasks);
    std::snprintf(line, sizeof line, "%-9s %6zu %6zu %7zu %8zu  %s\n", name.c_str(), s.runs, s.done, s.failed, s.missing,
                  s.slurm_state.empty() ? "-" : s.slurm_state.c_str());
    t << line;
    for (const auto& id : s.failed_ids) t << "    failed: " << id << " (" << (dir / "failed" / (id + ".json")).string() << ")\n";
    for (std::size_t i = 0; i < s.missing_ids.size() && i < 3; ++i) t << "    missing: " << s.missing_ids[i] << "\n";
    if (s.missing_ids.size() > 3) t << "    ... and " << s.missing_ids.size() - 3 << " more missing\n";
  }
  t << merge_line;
  // Only the merge (or a local sweep that ran everything) writes the aggregate (batch/aggregate.hpp).
  std::error_code ec;
  t << (fs::exists(dir / "aggregate.json", ec) ? "aggregate: final (aggregate.json, aggregate.csv, runs.csv)\n"
                                               : "aggregate: none yet (written by the merge once no run is missing)\n");
  if (!st.active_jobs.empty()) t << "still queued or running: " << st.active_jobs.size() << " job(s)\n";
  if (st.complete()) {
    t << "complete: every run finished\n";
  } else if (st.active_jobs.empty()) {
    t << "incomplete shards: " << join_ints(st.incomplete_shards()) << "; resubmit them with: omniloc sweep " << spec.source
      << (out_dir.empty() ? "" : " -o " + out_dir) << " --slurm --resubmit-missing (or run each: omniloc sweep " << spec.source
      << " --shard I/" << st.tasks << " --resume" << (out_dir.empty() ? "" : " -o " + out_dir) << ")\n";
  }
  st.text = t.str();
  return st;
}

namespace {

// Where a submission goes and what its scripts run, all absolute.
struct SubmitPaths {
  fs::path dir;       ///< the sweep's results folder
  fs::path folder;    ///< <results>/slurm
  fs::path spec_abs;  ///< the sweep file
  std::string exe;    ///< the binary the tasks run
};

// N: the first submission's when resubmitting, else --tasks or the default.
int array_size(const SweepSpec& spec, const SlurmOptions& o, const Json& sub, const fs::path& dir) {
  if (!o.resubmit_missing) return o.tasks != 0 ? o.tasks : static_cast<int>(std::min<std::size_t>(spec.runs.size(), kDefaultTasks));
  if (!sub.is_object())
    throw ConfigError("--resubmit-missing", "\"" + dir.string() + "\"", "a results folder with slurm/submission.json (submit with --slurm first)");
  const int tasks = sub.value("tasks", 0);
  if (o.tasks != 0 && o.tasks != tasks)
    throw ConfigError("--tasks", std::to_string(o.tasks), std::to_string(tasks) + " (the array size of the first submission: runs are sharded by it)");
  return tasks;
}

// Which shards: all of them, or those with runs missing or failed. Refused while anything of an
// earlier submission is still queued or running (its runs would look missing and be done twice).
std::vector<int> shards_to_submit(const SweepSpec& spec, const SlurmOptions& o, const Json& sub, const fs::path& dir, int tasks) {
  std::vector<int> shards;
  if (!o.dry_run && sub.is_object()) {
    const SweepStatus st = sweep_status(spec, dir.string(), tasks);
    if (!st.active_jobs.empty()) {
      std::string ids;
      for (const auto& id : st.active_jobs) ids += (ids.empty() ? "" : " ") + id;
      throw RuntimeFailure("jobs of an earlier submission into " + dir.string() + " are still queued or running (" + ids +
                           "); wait for them (omniloc sweep SPEC --status) or scancel them first");
    }
    if (o.resubmit_missing) shards = st.incomplete_shards();
  } else if (o.resubmit_missing) {
    shards = sweep_status(spec, dir.string(), tasks).incomplete_shards();
  }
  if (!o.resubmit_missing)
    for (int k = 0; k < tasks; ++k) shards.push_back(k);
  return shards;
}

// Options go in #SBATCH lines so that `sbatch array.sbatch` by hand is the same job.
std::string common_header(const SlurmOptions& o, const SubmitPaths& p) {
  // Tasks work in the folder omniloc was called from, whoever submits the scripts and from where:
  // relative paths (results/cache of calibration maps and colour tables) then mean the same thing.
  std::string common = "#SBATCH --chdir=" + fs::current_path().string() + "\n";
  if (!o.partition.empty()) common += "#SBATCH --partition=" + o.partition + "\n";
  if (!o.time_limit.empty()) common += "#SBATCH --time=" + o.time_limit + "\n";
  for (const auto& a : o.sbatch_args) common += "#SBATCH " + a + "\n";
  const std::string env_sh = (p.folder / "env.sh").string();
  const std::string prologue =
      "set -euo pipefail\n"
      "# Site set-up (module load ..., conda activate ...) goes in env.sh, kept across resubmissions.\n"
      "if [ -f " + shq(env_sh) + " ]; then source " + shq(env_sh) + "; fi\n"
      "echo \"omniloc task on $(hostname) at $(date -u +%FT%TZ): job ${SLURM_JOB_ID:-?}, array task ${SLURM_ARRAY_TASK_ID:-none}\"\n";
  return common + prologue;
}

std::string shard_command_tail(const SlurmOptions& o, const SubmitPaths& p) {
  std::string tail = " --resume -j " + std::to_string(o.cpus_per_task) + " -o " + shq(p.dir.string());
  for (const auto& a : o.task_args) tail += " " + shq(a);
  return tail;
}

// --gpus-per-task: the GPUs as a generic resource, and rendering on them through EGL. Slurm sets
// CUDA_VISIBLE_DEVICES to the task's GPUs, which the EGL device choice follows (egl_device.hpp).
// (#SBATCH lines count only before the script's first command, so the two parts go apart.)
std::string gpu_request(const SlurmOptions& o) {
  return o.gpus_per_task > 0 ? "#SBATCH --gres=gpu:" + std::to_string(o.gpus_per_task) + "\n" : "";
}
std::string gpu_rendering(const SlurmOptions& o) {
  if (o.gpus_per_task <= 0) return "";
  return "# Render on the task's GPUs (an OMNILOC_GL_BACKEND set in env.sh is kept); the -j runs share them.\n"
         "export OMNILOC_GL_BACKEND=\"${OMNILOC_GL_BACKEND:-egl}\"\n";
}

std::string array_script(const SweepSpec& spec, const SlurmOptions& o, const SubmitPaths& p, int tasks) {
  return "#!/bin/bash\n"
         "# omniloc sweep " + spec.name + ": array task I runs every " + std::to_string(tasks) + "-th run starting at run I\n"
         "# (--shard I/N) and skips runs already finished (--resume), so a task killed by scancel, a node\n"
         "# failure or the time limit loses only the run it was writing, and resubmitting it\n"
         "# (sbatch --array=2,5 array.sbatch, or omniloc sweep --slurm --resubmit-missing) redoes only the rest.\n"
         "#SBATCH --job-name=omniloc-" + spec.name + "\n"
         "#SBATCH --array=0-" + std::to_string(tasks - 1) + "\n"
         "#SBATCH --cpus-per-task=" + std::to_string(o.cpus_per_task) + "\n" + gpu_request(o) +
         "#SBATCH --output=" + (p.folder / "logs" / "task-%A_%a.log").string() + "\n" + common_header(o, p) +
         "# N is fixed here, not read from SLURM_ARRAY_TASK_COUNT: a resubmitted subset has another count.\n"
         "N=" + std::to_string(tasks) + "\n"
         "# llvmpipe would start one rendering thread per core of the whole node; the task owns only its\n"
         "# --cpus-per-task cores, shared by its -j runs (an LP_NUM_THREADS set in env.sh is kept).\n"
         "export LP_NUM_THREADS=\"${LP_NUM_THREADS:-1}\"\n" + gpu_rendering(o) +
         "exec " + shq(p.exe) + " sweep " + shq(p.spec_abs.string()) + " --shard \"${SLURM_ARRAY_TASK_ID}/${N}\"" +
         shard_command_tail(o, p) + "\n";
}

std::string merge_script(const SweepSpec& spec, const SlurmOptions& o, const SubmitPaths& p) {
  const std::string report = (p.folder / "report.txt").string();
  const std::string sweep = shq(p.exe) + " sweep " + shq(p.spec_abs.string());
  return "#!/bin/bash\n"
         "# omniloc sweep " + spec.name + ": after every array task succeeded (afterok), aggregate all runs and\n"
         "# write the report (the aggregate table and the status per shard) to report.txt. It fails when\n"
         "# runs are still missing, so an incomplete sweep is never reported as done.\n"
         "#SBATCH --job-name=omniloc-" + spec.name + "-merge\n"
         "#SBATCH --cpus-per-task=1\n"
         "#SBATCH --output=" + (p.folder / "logs" / "merge-%j.log").string() + "\n" + common_header(o, p) +
         "tmp=" + shq(report) + ".tmp.$$\n" +
         sweep + " --aggregate-only -o " + shq(p.dir.string()) + " >\"$tmp\"\n"
         "status=0\n" +
         sweep + " --status -o " + shq(p.dir.string()) + " >>\"$tmp\" || status=$?\n"
         "mv -f \"$tmp\" " + shq(report) + "\n"
         "cat " + shq(report) + "\n"
         "exit $status\n";
}

std::string array_submit_command(const SlurmOptions& o, const SubmitPaths& p, const std::vector<int>& shards) {
  return "sbatch --parsable" + (o.resubmit_missing ? " --array=" + join_ints(shards) : std::string()) + " " +
         shq((p.folder / "array.sbatch").string());
}

std::string merge_submit_command(const SubmitPaths& p) {
  return "sbatch --parsable --dependency=afterok:<ARRAY_JOB_ID> --kill-on-invalid-dep=yes " + shq((p.folder / "merge.sbatch").string());
}

std::string commands_file(const SweepSpec& spec, const SlurmOptions& o, const SubmitPaths& p, int tasks, const std::vector<int>& shards) {
  const std::string sweep = shq(p.exe) + " sweep " + shq(p.spec_abs.string());
  std::string commands = "# omniloc sweep " + spec.name + ": " + std::to_string(spec.runs.size()) + " runs in " + std::to_string(tasks) +
                         " shards, written by omniloc " + build_info().version + " at " + utc_now() + "\n"
                         "# Submit (what omniloc sweep --slurm runs; the merge waits for every array task to succeed and is\n"
                         "# cancelled, not left pending, when one fails):\n" +
                         array_submit_command(o, p, shards) + "\n" + merge_submit_command(p) + "\n"
                         "# The shards, one command each, for any other engine (each needs the results folder, the binary\n"
                         "# and the data; run them in any order, anywhere, any number at once):\n";
  for (int k = 0; k < tasks; ++k)
    commands += sweep + " --shard " + std::to_string(k) + "/" + std::to_string(tasks) + shard_command_tail(o, p) + "\n";
  commands += "# Then, once: aggregate and check\n" + sweep + " --aggregate-only -o " + shq(p.dir.string()) + "\n" + sweep +
              " --status -o " + shq(p.dir.string()) + "\n";
  return commands;
}

// submission.json's description of the sweep and this submission's settings; earlier submissions are kept.
void describe_submission(Json& sub, const SweepSpec& spec, const SlurmOptions& o, const SubmitPaths& p, const std::string& rhash,
                         int tasks) {
  std::string spec_bytes;
  try {
    spec_bytes = read_file(p.spec_abs.string());
  } catch (const std::exception&) {
  }
  if (!sub.is_object()) sub = Json::object();
  sub["sweep"] = spec.name;
  sub["spec"] = p.spec_abs.string();
  sub["spec_sha256"] = sha256_hex(spec_bytes);
  sub["runs_sha256"] = rhash;
  sub["runs"] = spec.runs.size();
  sub["tasks"] = tasks;
  sub["results"] = p.dir.string();
  sub["omniloc"] = build_info_json();
  sub["omniloc_exe"] = p.exe;
  sub["cpus_per_task"] = o.cpus_per_task;
  sub["gpus_per_task"] = o.gpus_per_task;
  sub["partition"] = o.partition;
  sub["time"] = o.time_limit;
  sub["sbatch_args"] = o.sbatch_args;
  // The external clients the runs start (docs/protocol.md): which program and script, by hash.
  // Each distinct localizer object once: describing hashes its files.
  std::set<std::string> seen;
  Json clients = Json::array();
  for (const auto& r : spec.runs) {
    const Json loc = r.scenario.value("localizer", Json());
    if (!seen.insert(loc.dump()).second) continue;
    if (Json c = external::describe_client(loc); !c.is_null() && std::find(clients.begin(), clients.end(), c) == clients.end())
      clients.push_back(std::move(c));
  }
  if (!clients.empty()) sub["external_clients"] = clients;
  if (!sub.contains("submissions")) sub["submissions"] = Json::array();
}

void write_submission_folder(const SubmitPaths& p, const std::string& array_sbatch, const std::string& merge_sbatch,
                             const std::string& commands, const Json& sub) {
  fs::create_directories(p.folder / "logs");
  write_file_atomic((p.folder / "array.sbatch").string(), array_sbatch);
  write_file_atomic((p.folder / "merge.sbatch").string(), merge_sbatch);
  write_file_atomic((p.folder / "commands.txt").string(), commands);
  const std::string env_sh = (p.folder / "env.sh").string();
  if (!fs::exists(env_sh))
    write_file_atomic(env_sh, "# Sourced by array.sbatch and merge.sbatch before omniloc runs (bash). Site set-up goes here, e.g.\n"
                              "# module load gcc/12 mesa\n");
  write_file_atomic((p.folder / "submission.json").string(), sub.dump(2) + "\n");
}

// Submits the array and the merge job after it and records both in submission.json. A refused
// merge job still leaves the array job recorded (it is queued), then throws.
void submit_jobs(const SlurmOptions& o, const SubmitPaths& p, Json& sub, SlurmSubmission& out) {
  std::vector<std::string> a1 = {"sbatch", "--parsable"};
  if (o.resubmit_missing) a1.push_back("--array=" + join_ints(out.shards));
  a1.push_back((p.folder / "array.sbatch").string());
  out.array_job = parse_job_id(capture(a1), "array job");
  Json record{{"array_job", out.array_job}, {"shards", out.shards}, {"submitted_at", utc_now()},
              {"kind", o.resubmit_missing ? "resubmit-missing" : "full"}};
  std::string merge_error;
  try {
    out.merge_job = parse_job_id(capture({"sbatch", "--parsable", "--dependency=afterok:" + out.array_job, "--kill-on-invalid-dep=yes",
                                          (p.folder / "merge.sbatch").string()}),
                                 "merge job");
    record["merge_job"] = out.merge_job;
  } catch (const RuntimeFailure& e) {
    merge_error = e.what();
  }
  sub["submissions"].push_back(record);
  write_file_atomic((p.folder / "submission.json").string(), sub.dump(2) + "\n");
  if (!merge_error.empty())
    throw RuntimeFailure(merge_error + " (array job " + out.array_job + " is queued; submit the merge by hand: " + merge_submit_command(p) +
                         ")");
}

std::string submitted_message(const SweepSpec& spec, const std::string& spec_path, const SlurmOptions& o, const SubmitPaths& p,
                              const SlurmSubmission& out) {
  std::ostringstream m;
  m << "submitted sweep " << spec.name << " (" << spec.runs.size() << " runs): array job " << out.array_job << " with "
    << out.shards.size() << " of " << out.tasks << " tasks (" << join_ints(out.shards) << "), merge job " << out.merge_job
    << " after it\nfollow with:\n  squeue -j " << out.array_job << "," << out.merge_job << "\n  omniloc sweep " << spec_path
    << (o.out_dir.empty() ? "" : " -o " + o.out_dir) << " --status\n  tail -f " << (p.folder / "logs").string() << "/task-" << out.array_job
    << "_*.log\nreport when done: " << (p.folder / "report.txt").string() << "\n";
  return m.str();
}

}  // namespace

SlurmSubmission submit_slurm(const SweepSpec& spec, const std::string& spec_path, const SlurmOptions& o) {
  check_slurm_options(spec, o);
  SubmitPaths p;
  p.dir = results_dir(spec, o.out_dir);
  p.folder = p.dir / "slurm";
  p.spec_abs = fs::absolute(spec_path).lexically_normal();
  p.exe = fs::absolute(o.omniloc_exe.empty() ? fs::read_symlink("/proc/self/exe") : fs::path(o.omniloc_exe)).string();
  const std::string rhash = runs_hash(spec);
  Json sub = read_submission(p.folder);

  // A results folder belongs to one sweep: runs are found by id, so runs of an edited sweep would
  // silently mix with the old ones.
  if (sub.is_object() && sub.value("runs_sha256", "") != rhash)
    throw ConfigError("-o", "\"" + p.dir.string() + "\"",
                      "the results folder of this sweep (its slurm/submission.json was written for other runs: the sweep or a "
                      "scenario it names changed since; submit into another -o folder)");
  SlurmSubmission out;
  out.folder = p.folder.string();
  out.tasks = array_size(spec, o, sub, p.dir);
  if (!o.dry_run && !on_path("sbatch"))
    throw RuntimeFailure("sbatch is not on PATH: run this on the cluster's login node, or use --dry-run to only write " + p.folder.string());
  out.shards = shards_to_submit(spec, o, sub, p.dir, out.tasks);
  if (out.shards.empty()) {
    out.message = "nothing to resubmit: every run of " + spec.name + " in " + p.dir.string() + " is done\n";
    return out;
  }

  const std::string array_sbatch = array_script(spec, o, p, out.tasks);
  const std::string merge_sbatch = merge_script(spec, o, p);
  const std::string commands = commands_file(spec, o, p, out.tasks, out.shards);
  describe_submission(sub, spec, o, p, rhash, out.tasks);
  write_submission_folder(p, array_sbatch, merge_sbatch, commands, sub);
  if (o.dry_run) {
    out.message = "wrote " + p.folder.string() + " (dry run, nothing submitted): array.sbatch, merge.sbatch, env.sh, commands.txt, submission.json\n"
                  "submit with:\n  cd " + shq(p.folder.string()) + "\n  " + array_submit_command(o, p, out.shards) + "\n  " +
                  merge_submit_command(p) + "\n";
    return out;
  }
  submit_jobs(o, p, sub, out);
  out.message = submitted_message(spec, spec_path, o, p, out);
  return out;
}

}  // namespace omniloc::batch
