#include "harness/sweep.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <cstring>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <mutex>
#include <ostream>
#include <set>
#include <thread>

#include "external/external_config.hpp"
#include "core/atomic_file.hpp"
#include "core/json_parse.hpp"
#include "harness/run_directory.hpp"
#include "core/version.hpp"
#include "harness/scenario.hpp"

namespace omniloc::harness {

namespace fs = std::filesystem;

namespace {

// Largest number of scenario combinations a sweep may hold: every one is validated before any run.
constexpr std::size_t kMaxCombinations = 10000;
// Largest number of runs (combinations x seeds): the run list is held in memory with each run's scenario.
constexpr std::size_t kMaxRuns = 1000000;

std::string sanitize(const std::string& s) {
  std::string o;
  for (char c : s) o += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '.' || c == '=' || c == '+') ? c : '_';
  return o.empty() ? "_" : o;
}

Json read_json_file(const std::string& path, const std::string& what_path) { return read_json_strict(path, what_path); }

// Student t 0.975 quantiles for 1..30 degrees of freedom, then the normal value.
double t975(std::size_t df) {
  static const double t[] = {0,     12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
                             2.201, 2.179,  2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080,
                             2.074, 2.069,  2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042};
  return df <= 30 ? t[df] : 1.96;
}

void flatten(const Json& j, const std::string& prefix, std::map<std::string, double>& out) {
  if (j.is_number()) {
    out[prefix] = j.get<double>();
  } else if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) flatten(it.value(), prefix.empty() ? it.key() : prefix + "/" + it.key(), out);
  }
}

std::map<std::string, double> run_metrics(const Json& summary) {
  std::map<std::string, double> m;
  if (summary.contains("robots"))
    for (const auto& r : summary["robots"]) {
      Json copy = r;
      const int id = copy.value("robot", 0);
      copy.erase("robot");
      flatten(copy, "r" + std::to_string(id), m);
    }
  if (summary.contains("metrics")) flatten(summary["metrics"], "", m);
  return m;
}

// One CSV field per RFC 4180: quoted when it holds a comma, quote or line break, inner quotes
// doubled (parameters such as occlusion={"fraction":0.5} hold all of them).
std::string csv_field(const std::string& v) {
  if (v.find_first_of(",\"\r\n") == std::string::npos) return v;
  std::string o = "\"";
  for (char c : v) o += c == '"' ? std::string("\"\"") : std::string(1, c);
  return o + "\"";
}

std::string csv_row(std::initializer_list<std::string> fields) {
  std::string o;
  for (const auto& f : fields) o += (o.empty() ? "" : ",") + csv_field(f);
  return o + "\n";
}

std::string fmt(double v) {
  char b[64];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

std::string fmt_duration(double s) {
  char b[32];
  if (s >= 3600) std::snprintf(b, sizeof b, "%dh%02dm", static_cast<int>(s / 3600), static_cast<int>(std::fmod(s, 3600) / 60));
  else if (s >= 60) std::snprintf(b, sizeof b, "%dm%02ds", static_cast<int>(s / 60), static_cast<int>(std::fmod(s, 60)));
  else std::snprintf(b, sizeof b, "%.0fs", s);
  return b;
}

// Runs one child `omniloc run`; returns its wait status. `lock_fd` (the run's lock, opened
// close-on-exec) is handed to the child as a plain descriptor, so the lock stays held as long as
// either process lives.
int spawn_run(const std::string& exe, const std::string& spec, const std::string& out, const std::string& log, int lock_fd) {
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    // The child dies with the thread that forked it (the sweep's worker): after kill -9 of the sweep
    // no orphan keeps running beside a later --resume. If the parent died before prctl took effect,
    // getppid() already differs.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);
    if (lock_fd >= 0) (void)::dup(lock_fd);  // dup() clears FD_CLOEXEC on the copy
    int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) fd = ::open("/dev/null", O_WRONLY);
    if (fd >= 0) {
      ::dup2(fd, 1);
      ::dup2(fd, 2);
      ::close(fd);
    }
    // --overwrite: the sweep owns runs/<id>/ and replaces a previous result of the same run.
    ::execl(exe.c_str(), exe.c_str(), "run", spec.c_str(), "-o", out.c_str(), "--overwrite", "--quiet", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return status;
}

std::string tail_of(const std::string& path, std::size_t max_chars) {
  std::string s;
  try {
    s = read_file(path);
  } catch (...) {
    return "";
  }
  return s.size() > max_chars ? s.substr(s.size() - max_chars) : s;
}

}  // namespace

Interval mean_ci95(const std::vector<double>& v) {
  Interval iv;
  iv.n = v.size();
  if (v.empty()) return iv;
  double s = 0;
  for (double x : v) s += x;
  iv.mean = s / v.size();
  if (v.size() < 2) {
    iv.low = iv.high = iv.mean;
    return iv;
  }
  double s2 = 0;
  for (double x : v) s2 += (x - iv.mean) * (x - iv.mean);
  const double half = t975(v.size() - 1) * std::sqrt(s2 / (v.size() - 1)) / std::sqrt(static_cast<double>(v.size()));
  iv.low = iv.mean - half;
  iv.high = iv.mean + half;
  return iv;
}

namespace {

using Combo = std::vector<std::pair<std::string, Json>>;       // JSON pointer -> value
using Localizers = std::vector<std::pair<std::string, Json>>;  // label, localizer JSON (null = scenario's own)

// One entry of "scenarios": the scenario file read, with the localizers and parameter combinations it runs with.
struct ScenarioEntry {
  std::string name;
  Json json;
  Localizers locs;
  std::vector<Combo> combos;
};

// "localizers": [{"type": ...}, ...] at `at`.
Localizers parse_localizers(const Json& l, const std::string& at) {
  if (!l.is_array() || l.empty()) throw ConfigError(at, json_brief(l), "a non-empty array of {\"type\": ...} objects");
  Localizers locs;
  for (std::size_t i = 0; i < l.size(); ++i) {
    Json lj = l[i];
    if (!lj.is_object() || !lj.contains("type")) throw ConfigError(json_child(at, i), json_brief(lj), "an object {\"type\": ...}");
    const bool external = lj["type"] == "external";
    // An external localizer's row is named after its script unless labelled (docs/protocol.md).
    std::string label = lj.value("label", external ? external::default_label(lj) : lj["type"].is_string() ? lj["type"].get<std::string>() : std::string("?"));
    lj.erase("label");
    external::anchor_external_paths(lj);
    locs.emplace_back(sanitize(label), lj);
  }
  return locs;
}

// "parameters": {pointer: [values]} at `at`: the cross product of all of them, appended to `base_combos`.
std::vector<Combo> parse_combos(const Json& pj, const std::string& at, const std::vector<Combo>& base_combos) {
  if (!pj.is_object()) throw ConfigError(at, json_brief(pj), "an object {\"/json/pointer\": [values, ...]}");
  std::vector<Combo> combos = base_combos;
  for (auto it = pj.begin(); it != pj.end(); ++it) {
    const std::string pp = json_child(at, it.key());
    if (it.key().empty() || it.key()[0] != '/') throw ConfigError(pp, "\"" + it.key() + "\"", "a JSON pointer such as /robots/0/motion/speed");
    if (!it.value().is_array() || it.value().empty()) throw ConfigError(pp, json_brief(it.value()), "a non-empty array of values");
    // The cross product grows multiplicatively; refuse it before building it (each combination
    // is validated as a scenario below, about 10 ms apiece).
    if (combos.size() * it.value().size() > kMaxCombinations)
      throw ConfigError(pp, "an array of " + std::to_string(it.value().size()) + " values, making " +
                                std::to_string(combos.size() * it.value().size()) + " combinations",
                        "at most " + std::to_string(kMaxCombinations) + " parameter combinations per scenario entry");
    std::vector<Combo> next;
    for (const auto& c : combos)
      for (const auto& v : it.value()) {
        auto c2 = c;
        c2.emplace_back(it.key(), v);
        next.push_back(c2);
      }
    combos = next;
  }
  return combos;
}

// Entry `sp` of "scenarios": a path, or {"file": ..., "parameters": ..., "localizers": ...}.
ScenarioEntry read_scenario_entry(const Json& entry, const std::string& sp, const fs::path& base, const Localizers& locs,
                                  const std::vector<Combo>& combos) {
  ScenarioEntry sc{"", Json(), locs, combos};
  const Json* file = &entry;
  std::string fp = sp;
  if (entry.is_object()) {
    JsonReader er(entry, sp);
    er.allow("comment");
    file = er.raw("file", true);
    fp = json_child(sp, "file");
    if (const Json* l = er.raw("localizers")) sc.locs = parse_localizers(*l, json_child(sp, "localizers"));
    if (const Json* pj = er.raw("parameters")) sc.combos = parse_combos(*pj, json_child(sp, "parameters"), combos);
    er.finish();
  }
  if (!file->is_string())
    throw ConfigError(fp, json_brief(*file), "a scenario file path (relative to the sweep file), or {\"file\": path, \"parameters\": ..., \"localizers\": ...}");
  fs::path p = file->get<std::string>();
  if (p.is_relative()) p = base / p;
  if (!fs::exists(p)) throw ConfigError(fp, json_brief(*file), "an existing scenario file (looked for " + p.string() + ")");
  sc.json = read_json_file(p.string(), fp);
  sc.name = sc.json.is_object() && sc.json.contains("name") && sc.json["name"].is_string() ? sc.json["name"].get<std::string>() : p.stem().string();
  return sc;
}

std::vector<ScenarioEntry> read_scenario_entries(const Json& scen, const fs::path& base, const Localizers& locs,
                                                 const std::vector<Combo>& combos) {
  if (!scen.is_array() || scen.empty()) throw ConfigError("/scenarios", json_brief(scen), "a non-empty array of scenario file paths");
  std::vector<ScenarioEntry> scenarios;
  for (std::size_t i = 0; i < scen.size(); ++i)
    scenarios.push_back(read_scenario_entry(scen[i], json_child("/scenarios", i), base, locs, combos));
  return scenarios;
}

// "seeds": absent (seed 1), a list, or {"first": ..., "count": ...}.
std::vector<std::uint64_t> read_seeds(const Json* sj) {
  std::vector<std::uint64_t> seeds;
  if (!sj) {
    seeds = {1};
  } else if (sj->is_array()) {
    for (std::size_t i = 0; i < sj->size(); ++i) {
      if (!(*sj)[i].is_number_unsigned() || (*sj)[i].get<std::uint64_t>() > (1ULL << 53))
        throw ConfigError(json_child("/seeds", i), json_brief((*sj)[i]), "an integer seed in [0, 2^53] (what a scenario's seed accepts)");
      seeds.push_back((*sj)[i].get<std::uint64_t>());
    }
  } else {
    JsonReader s(*sj, "/seeds");
    const auto first = s.integer("first", 1, 0, 1LL << 52);
    const auto count = s.integer("count", std::nullopt, 1, 100000);
    s.finish();
    for (long long k = 0; k < count; ++k) seeds.push_back(static_cast<std::uint64_t>(first + k));
  }
  if (seeds.empty()) throw ConfigError("/seeds", "[]", "at least one seed");
  if (seeds.size() > 1000000) throw ConfigError("/seeds", std::to_string(seeds.size()) + " seeds", "at most 1000000 seeds");
  return seeds;
}

void check_sweep_size(const std::vector<ScenarioEntry>& scenarios, std::size_t seed_count) {
  std::size_t total = 0;
  for (const auto& sc : scenarios) total += sc.locs.size() * sc.combos.size();
  if (total > kMaxCombinations)
    throw ConfigError("/scenarios", std::to_string(total) + " scenario x localizer x parameter combinations",
                      "at most " + std::to_string(kMaxCombinations) + " (split the sweep)");
  if (total * seed_count > kMaxRuns)
    throw ConfigError("/seeds", std::to_string(total * seed_count) + " runs (" + std::to_string(total) + " combinations x " +
                                    std::to_string(seed_count) + " seeds)",
                      "at most " + std::to_string(kMaxRuns) + " runs in one sweep (split it)");
}

// The scenario with the combination's values written in; `label` gets "leaf=value,..." of them.
Json apply_combo(const Json& scenario, const Combo& combo, std::string& label) {
  Json patched = scenario;
  for (const auto& [ptr, v] : combo) {
    try {
      patched[Json::json_pointer(ptr)] = v;
    } catch (const std::exception& e) {
      throw ConfigError("/parameters" + ptr, json_brief(v), std::string("a pointer into the scenario (") + e.what() + ")");
    }
    const std::string leaf = ptr.substr(ptr.find_last_of('/') + 1);
    label += (label.empty() ? "" : ",") + leaf + "=" + v.dump();
  }
  return patched;
}

// Validates every combination once, before any run, then adds one run per seed.
void add_runs(const std::string& path, const std::vector<ScenarioEntry>& scenarios, const std::vector<std::uint64_t>& seeds,
              SweepSpec& spec) {
  std::set<std::string> ids;
  for (const auto& sc : scenarios)
    for (const auto& [llabel, lj] : sc.locs)
      for (const auto& combo : sc.combos) {
        std::string plabel;
        Json patched = apply_combo(sc.json, combo, plabel);
        if (!lj.is_null()) patched["localizer"] = lj;
        if (patched.contains("localizer")) external::anchor_external_paths(patched["localizer"]);
        const Json own = patched.value("localizer", Json::object());
        const std::string loc_label = !lj.is_null() ? llabel
                                      : own.value("type", Json()) == "external"
                                          ? own.value("label", external::default_label(own))
                                          : sanitize(own.value("type", std::string("odometry_only")));
        try {
          parse_scenario(patched, sc.name);
        } catch (const ConfigError& e) {
          throw ConfigError("sweep " + path + ", scenario \"" + sc.name + "\", localizer \"" + loc_label + "\"" +
                                (plabel.empty() ? "" : ", " + plabel) + ": " + (e.path().empty() ? "/" : e.path()),
                            e.value(), e.expected());
        }
        for (std::uint64_t seed : seeds) {
          SweepRun run;
          run.index = spec.runs.size();
          run.scenario_name = sc.name;
          run.localizer_label = loc_label;
          run.params_label = plabel.empty() ? "default" : plabel;
          run.seed = seed;
          run.scenario = patched;
          run.scenario["seed"] = seed;
          run.scenario["name"] = sc.name;
          run.id = sanitize(sc.name) + "__" + loc_label + "__" + sanitize(run.params_label) + "__s" + std::to_string(seed);
          if (!ids.insert(run.id).second) throw ConfigError("/", run.id, "distinct runs (two combinations give the same run id; add \"label\"s)");
          spec.runs.push_back(std::move(run));
        }
      }
}

}  // namespace

SweepSpec load_sweep(const std::string& path) {
  SweepSpec spec;
  spec.source = path;
  const Json j = read_json_file(path, "sweep file");
  JsonReader r(j, "");
  r.allow("comment");
  spec.name = r.string("name", fs::path(path).stem().string());
  spec.name = sanitize(spec.name);

  // Sweep-wide localizers and parameters apply to every scenario entry; an entry written as
  // {"file": ..., "parameters": {...}, "localizers": [...]} adds its own parameters to the sweep's and
  // replaces the sweep's localizers, so one file can hold rows that vary different things (the paper suite).
  Localizers locs = {{"", Json()}};
  if (const Json* l = r.raw("localizers")) locs = parse_localizers(*l, "/localizers");
  std::vector<Combo> combos = {{}};
  if (const Json* pj = r.raw("parameters")) combos = parse_combos(*pj, "/parameters", combos);
  const std::vector<ScenarioEntry> scenarios = read_scenario_entries(*r.raw("scenarios", true), fs::path(path).parent_path(), locs, combos);
  const std::vector<std::uint64_t> seeds = read_seeds(r.raw("seeds"));
  r.finish();

  check_sweep_size(scenarios, seeds.size());
  add_runs(path, scenarios, seeds, spec);
  return spec;
}

namespace {

bool finished(const fs::path& dir, const SweepRun& r) { return fs::exists(dir / "runs" / r.id / "summary.json"); }

struct SweepFolder {
  fs::path dir;
  std::string exe;  ///< the binary spawned for runs
};

SweepFolder open_sweep_folder(const std::string& out_dir, const SweepOptions& o) {
  SweepFolder f{out_dir, ""};
  fs::create_directories(f.dir / "runs");
  fs::create_directories(f.dir / "specs");
  fs::create_directories(f.dir / "logs");
  fs::create_directories(f.dir / "failed");
  f.exe = o.omniloc_exe.empty() ? fs::read_symlink("/proc/self/exe").string() : o.omniloc_exe;
  fs::create_directories(f.dir / "locks");
  // Staging folders of runs killed mid-write are hidden (".<id>.partial-<host>-<pid>"); clear those
  // whose process is gone, never those of runs still going (another shard or Slurm array task
  // sharing the folder), nor another host's, which cannot be judged from here.
  remove_stale_partials((f.dir / "runs").string());
  return f;
}

// This shard's runs that still need doing; `skipped` counts those --resume finds finished.
std::vector<const SweepRun*> runs_to_do(const SweepSpec& spec, const SweepOptions& o, const fs::path& dir, std::size_t& skipped) {
  std::vector<const SweepRun*> todo;
  for (const auto& r : spec.runs) {
    if (static_cast<int>(r.index % o.shard_count) != o.shard_index) continue;
    if (o.aggregate_only) continue;
    if (o.resume && finished(dir, r)) {
      ++skipped;
      continue;
    }
    todo.push_back(&r);
  }
  if (o.stop_after > 0 && todo.size() > o.stop_after) todo.resize(o.stop_after);
  return todo;
}

// llvmpipe draws with one thread per core by default, so N parallel runs on N cores would run N^2
// rasterizer threads: on 2 cores -j 2 took 19.0-19.7 s for 8 short tracking runs with the default
// and 16.6-17.9 s with one thread per run (docs/performance.md). Results are byte-identical with
// any thread count. The children inherit the variable; a value the user set is kept.
void share_rasterizer_threads(int jobs) {
  if (jobs > 1 && std::getenv("LP_NUM_THREADS") == nullptr) {
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    ::setenv("LP_NUM_THREADS", std::to_string(std::max(1u, cores / static_cast<unsigned>(jobs))).c_str(), 0);
  }
}

class SweepWorkers {
 public:
  SweepWorkers(const SweepFolder& folder, const SweepOptions& o, std::vector<const SweepRun*> todo)
      : folder_(folder), o_(o), todo_(std::move(todo)), tty_(o.progress && ::isatty(2)), t0_(std::chrono::steady_clock::now()) {}

  void run() {
    std::vector<std::thread> pool;
    for (int k = 0; k < std::max(1, o_.jobs); ++k) pool.emplace_back([this] { work(); });
    for (auto& t : pool) t.join();
    if (tty_) *o_.progress << "\n";
  }
  std::size_t done() const { return done_; }
  std::size_t failed() const { return failed_; }
  std::size_t busy() const { return busy_; }

 private:
  enum class Result { ok, failed, finished_elsewhere };

  void work() {
    for (;;) {
      const std::size_t i = next_.fetch_add(1);
      if (i >= todo_.size()) return;
      const SweepRun& r = *todo_[i];
      const fs::path fail_marker = folder_.dir / "failed" / (r.id + ".json");
      double secs = 0;
      // One lock per run: a second sweep (a --resume beside a sweep still running, or a
      // resubmitted shard) skips a run somebody else is running instead of running it twice.
      const std::string lock_path = (folder_.dir / "locks" / (r.id + ".lock")).string();
      const int lock_fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
      if (lock_fd >= 0 && ::flock(lock_fd, LOCK_EX | LOCK_NB) != 0) {
        ::close(lock_fd);
        std::lock_guard<std::mutex> lock(mu_);
        ++busy_;
        if (o_.progress) *o_.progress << r.id << ": skipped, another process is running it\n";
        continue;
      }
      const Result result = run_locked(r, fail_marker, lock_path, lock_fd, secs);
      if (lock_fd >= 0) ::close(lock_fd);
      if (result == Result::finished_elsewhere) {
        std::lock_guard<std::mutex> lock(mu_);
        ++busy_;
        continue;
      }
      report(r, result == Result::ok, secs);
    }
  }

  // Runs `r` holding its lock `lock_fd` (-1: the lock could not be created); `secs` gets the run's time.
  Result run_locked(const SweepRun& r, const fs::path& fail_marker, const std::string& lock_path, int lock_fd, double& secs) {
    // Any exception here (a full disk while writing the spec or the failure record) becomes a
    // recorded failure of this run: an exception escaping a std::thread would abort the sweep.
    try {
      if (lock_fd < 0) throw RuntimeFailure("cannot create lock " + lock_path + ": " + std::strerror(errno));
      // Finished by another process since the list was made.
      if (o_.resume && finished(folder_.dir, r)) return Result::finished_elsewhere;
      const std::string spec_path = (folder_.dir / "specs" / (r.id + ".json")).string();
      write_file_atomic(spec_path, r.scenario.dump(2) + "\n");
      const std::string log = (folder_.dir / "logs" / (r.id + ".log")).string();
      const auto r0 = std::chrono::steady_clock::now();
      const int st = spawn_run(folder_.exe, spec_path, (folder_.dir / "runs" / r.id).string(), log, lock_fd);
      secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
      const bool ok = st >= 0 && WIFEXITED(st) && WEXITSTATUS(st) == 0 && finished(folder_.dir, r);
      if (ok) {
        std::error_code ec;
        fs::remove(fail_marker, ec);
      } else {
        Json f{{"id", r.id}, {"log", tail_of(log, 2000)}};
        if (st >= 0 && WIFEXITED(st)) f["exit_code"] = WEXITSTATUS(st);
        if (st >= 0 && WIFSIGNALED(st)) f["signal"] = WTERMSIG(st);
        write_file_atomic(fail_marker.string(), f.dump(2) + "\n");
      }
      return ok ? Result::ok : Result::failed;
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mu_);
      if (o_.progress) *o_.progress << r.id << ": FAILED: " << e.what() << "\n";
      try {
        write_file_atomic(fail_marker.string(), Json{{"id", r.id}, {"error", e.what()}}.dump(2) + "\n");
      } catch (const std::exception&) {
        // The disk that made the run fail may refuse the record too; the count below still has it.
      }
      return Result::failed;
    }
  }

  void report(const SweepRun& r, bool ok, double secs) {
    std::lock_guard<std::mutex> lock(mu_);
    ++done_;
    if (!ok) ++failed_;
    if (!o_.progress) return;
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
    const double eta = el / done_ * (todo_.size() - done_);
    if (tty_) {
      const int width = 30, filled = static_cast<int>(width * done_ / std::max<std::size_t>(1, todo_.size()));
      *o_.progress << "\r[" << std::string(filled, '#') << std::string(width - filled, '.') << "] " << done_ << "/" << todo_.size()
                   << " failed " << failed_ << " ETA " << fmt_duration(eta) << "   " << std::flush;
    } else {
      *o_.progress << "[" << done_ << "/" << todo_.size() << "] " << r.id << (ok ? " ok " : " FAILED ") << fmt(secs) << " s, ETA "
                   << fmt_duration(eta) << "\n";
    }
  }

  const SweepFolder& folder_;
  const SweepOptions& o_;
  const std::vector<const SweepRun*> todo_;
  const bool tty_;
  const std::chrono::steady_clock::time_point t0_;
  std::mutex mu_;
  std::atomic<std::size_t> next_{0};
  std::size_t done_ = 0, failed_ = 0;
  std::size_t busy_ = 0;  // runs another live process holds the lock of
};

// One row of the aggregate: the runs of one scenario x localizer x parameters.
struct Group {
  std::string scenario, localizer, params;
  std::size_t finished = 0, failed = 0, missing = 0;
  std::map<std::string, std::vector<double>> values;
  Json external;  // an external client's provenance (summary.json "external"), one entry per distinct client
};

// What the folder holds of every run of the sweep, in run order.
struct Census {
  std::vector<Group> groups;
  std::string runs_csv = "index,id,scenario,localizer,params,seed,status\n";
  std::map<std::string, std::size_t> run_versions;  // which builds made the finished runs (a resume may mix them)
  std::size_t missing = 0;
};

Census take_census(const SweepSpec& spec, const fs::path& dir) {
  Census c;
  std::map<std::string, std::size_t> gindex;
  for (const auto& r : spec.runs) {
    auto [it, inserted] = gindex.try_emplace(r.group(), c.groups.size());
    if (inserted) {
      Group g;
      g.scenario = r.scenario_name;
      g.localizer = r.localizer_label;
      g.params = r.params_label;
      c.groups.push_back(std::move(g));
    }
    Group& g = c.groups[it->second];
    std::string status;
    if (finished(dir, r)) {
      status = "ok";
      ++g.finished;
      Json s;
      try {
        s = Json::parse(read_file((dir / "runs" / r.id / "summary.json").string()));
      } catch (const std::exception& e) {
        throw RuntimeFailure("cannot read the finished run " + r.id + ": " + e.what());
      }
      for (const auto& [k, v] : run_metrics(s)) g.values[k].push_back(v);
      // Which client made the group's runs (a resume after the client changed may mix several).
      if (s.contains("external")) {
        if (g.external.is_null()) g.external = Json::array();
        if (std::find(g.external.begin(), g.external.end(), s["external"]) == g.external.end()) g.external.push_back(s["external"]);
      }
      ++c.run_versions[s.contains("omniloc") ? s["omniloc"].value("version", std::string("unknown")) : std::string("unrecorded")];
    } else if (fs::exists(dir / "failed" / (r.id + ".json"))) {
      status = "failed";
      ++g.failed;
    } else {
      status = "missing";
      ++g.missing;
      ++c.missing;
    }
    c.runs_csv +=
        csv_row({std::to_string(r.index), r.id, r.scenario_name, r.localizer_label, r.params_label, std::to_string(r.seed), status});
  }
  return c;
}

// A group's line of the printed table: robot 0's mean errors, its position RMSE with interval.
std::string table_line(const Group& g, std::map<std::string, Interval>& ivs, bool phased) {
  auto m = [&](const std::string& k) {
    const std::string key = phased ? "r0/tracking_phase/" + k : "r0/" + k;
    return ivs.count(key) ? ivs[key].mean : NAN;
  };
  char ci[64];
  if (ivs.count("r0/position_m/rmse")) {
    const Interval& iv = ivs["r0/position_m/rmse"];
    if (iv.n >= 2) std::snprintf(ci, sizeof ci, "%.4f [%.4f, %.4f] n=%zu", iv.mean, iv.low, iv.high, iv.n);
    else std::snprintf(ci, sizeof ci, "%.4f (n=1, no interval)", iv.mean);  // one seed has no spread
  } else {
    std::snprintf(ci, sizeof ci, "-");
  }
  const std::string label = g.scenario + " / " + g.localizer + " / " + g.params + (phased ? " *" : "");
  char line[512];
  std::snprintf(line, sizeof line, "%-44s %4zu %4zu | %9.3f %9.3f %9.4f | %s\n", label.c_str(), g.finished, g.failed,
                m("x_cm/mean"), m("y_cm/mean"), m("theta_rad/mean"), ci);
  return line;
}

// Aggregates every run of the sweep found finished in the folder, in run order: writes runs.csv and
// aggregate.{csv,json}, and the printed table and missing count into `out`.
void write_aggregate(const SweepSpec& spec, const fs::path& dir, SweepOutcome& out) {
  const Census census = take_census(spec, dir);
  out.missing += census.missing;
  std::string csv = "scenario,localizer,params,metric,n,mean,ci95_low,ci95_high\n";
  Json agg{{"sweep", spec.name}, {"runs", spec.runs.size()}, {"omniloc", build_info_json()}, {"run_versions", census.run_versions},
           {"groups", Json::array()}};
  char line[512];
  std::snprintf(line, sizeof line, "%-44s %4s %4s | %9s %9s %9s | %-26s\n", "scenario / localizer / params", "ok", "fail", "mean x cm",
                "mean y cm", "mean th", "position RMSE m (95 % CI)");
  out.table = line;
  bool any_phased = false;
  for (const auto& g : census.groups) {
    Json gj{{"scenario", g.scenario}, {"localizer", g.localizer}, {"params", g.params}, {"finished", g.finished},
            {"failed", g.failed}, {"missing", g.missing}, {"metrics", Json::object()}};
    if (!g.external.is_null()) gj["external"] = g.external;
    std::map<std::string, Interval> ivs;
    for (const auto& [k, v] : g.values) {
      const Interval iv = mean_ci95(v);
      ivs[k] = iv;
      gj["metrics"][k] = {{"n", iv.n}, {"mean", iv.mean}, {"ci95", {iv.low, iv.high}}};
      csv += csv_row({g.scenario, g.localizer, g.params, k, std::to_string(iv.n), fmt(iv.mean), fmt(iv.low), fmt(iv.high)});
    }
    agg["groups"].push_back(gj);
    // Runs with kidnaps or covers: the tracking phase, as the papers' tables (marked "*").
    const bool phased = ivs.count("r0/tracking_phase/x_cm/mean") > 0;
    out.table += table_line(g, ivs, phased);
    any_phased = any_phased || phased;
  }
  if (any_phased) out.table += "* runs with kidnaps or covers: errors of the tracking phase (summary.json tracking_phase); RMSE over all frames\n";
  write_file_atomic((dir / "runs.csv").string(), census.runs_csv);
  write_file_atomic((dir / "aggregate.csv").string(), csv);
  write_file_atomic((dir / "aggregate.json").string(), agg.dump(2) + "\n");
}

}  // namespace

SweepOutcome run_sweep(const SweepSpec& spec, const SweepOptions& o) {
  SweepOutcome out;
  out.out_dir = o.out_dir.empty() ? "results/sweeps/" + spec.name : o.out_dir;
  const SweepFolder folder = open_sweep_folder(out.out_dir, o);
  SweepWorkers workers(folder, o, runs_to_do(spec, o, folder.dir, out.skipped));
  share_rasterizer_threads(o.jobs);
  workers.run();
  out.ran = workers.done();
  out.failed = workers.failed();
  out.skipped += workers.busy();
  write_aggregate(spec, folder.dir, out);
  return out;
}

}  // namespace omniloc::harness
