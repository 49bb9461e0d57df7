#include "batch/sweep.hpp"

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
#include <mutex>
#include <ostream>
#include <sstream>
#include <thread>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/version.hpp"
#include "harness/run_directory.hpp"

namespace omniloc::batch {

namespace fs = std::filesystem;
using harness::remove_stale_partials;

namespace {

// A run as a person reads it in progress lines ("tracking / mcl / occlusion={...}, seed 2"); the
// folder id (sanitized for file names) stays in the files. `name`: the localizer's (default: the
// row label; a finished external client's run: the name it recorded, as the aggregate shows it).
std::string readable(const SweepRun& r, const std::string& name = "") {
  return r.scenario_name + " / " + (name.empty() ? r.localizer_label : name) + (r.params_label == "default" ? "" : " / " + r.params_label) +
         ", seed " + std::to_string(r.seed);
}

std::string fmt_g6(double v) {
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

// Runs one child `omniloc ARGS...`; returns its wait status. `lock_fd` (the run's lock, opened
// close-on-exec) is handed to the child as a plain descriptor, so the lock stays held as long as
// either process lives.
int spawn(const std::string& exe, const std::vector<std::string>& args, const std::string& log, int lock_fd) {
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(exe.c_str()));
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
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
    ::execv(exe.c_str(), argv.data());
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

// Why a run's process failed, in one line for the progress output: its exit or signal and the last
// line its log has (the whole log stays in logs/, its tail in failed/<id>.json).
std::string failure_line(int status, const std::string& log) {
  std::string why = "stopped";
  if (status < 0) why = "could not be started";
  else if (WIFEXITED(status)) why = WEXITSTATUS(status) == 0 ? "exit 0 but no summary.json" : "exit " + std::to_string(WEXITSTATUS(status));
  else if (WIFSIGNALED(status)) why = "signal " + std::to_string(WTERMSIG(status));
  // The head of the log's last message: its last line that is not an indented continuation.
  std::istringstream lines(tail_of(log, 4000));
  std::string line, tail;
  while (std::getline(lines, line)) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (!line.empty() && (line[0] != ' ' || tail.empty())) tail = line;
  }
  if (tail.size() > 200) tail = tail.substr(0, 200) + "...";
  why += "; " + fs::path(log).parent_path().filename().string() + "/" + fs::path(log).filename().string();
  return tail.empty() ? why + " is empty" : why + ": " + tail;
}

}  // namespace

namespace {

// The sweep folder's parts: a full disk or a lost permission is a runtime failure in words, not a
// raw filesystem_error (the folder itself was checked before any work, apps/main.cpp).
void make_folder(const fs::path& p) {
  std::error_code ec;
  fs::create_directories(p, ec);
  if (ec) throw RuntimeFailure("cannot create folder " + p.string() + ": " + ec.message());
}

struct SweepFolder {
  fs::path dir;
  std::string exe;  ///< the binary spawned for runs
};

SweepFolder open_sweep_folder(const std::string& out_dir, const SweepOptions& o) {
  SweepFolder f{out_dir, ""};
  make_folder(f.dir / "runs");
  make_folder(f.dir / "specs");
  make_folder(f.dir / "logs");
  make_folder(f.dir / "failed");
  f.exe = o.omniloc_exe.empty() ? fs::read_symlink("/proc/self/exe").string() : o.omniloc_exe;
  make_folder(f.dir / "locks");
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
    if (o.resume && run_finished(dir, r)) {
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
        if (o_.progress) *o_.progress << readable(r) << ": skipped, another process is running it\n";
        continue;
      }
      std::string why;
      const Result result = run_locked(r, fail_marker, lock_path, lock_fd, secs, why);
      if (lock_fd >= 0) ::close(lock_fd);
      if (result == Result::finished_elsewhere) {
        std::lock_guard<std::mutex> lock(mu_);
        ++busy_;
        continue;
      }
      report(r, result == Result::ok, secs, why);
    }
  }

  // Runs `r` holding its lock `lock_fd` (-1: the lock could not be created); `secs` gets the run's time,
  // `why` the reason of a failed process (empty when the failure was reported here already).
  Result run_locked(const SweepRun& r, const fs::path& fail_marker, const std::string& lock_path, int lock_fd, double& secs,
                    std::string& why) {
    // Any exception here (a full disk while writing the spec or the failure record) becomes a
    // recorded failure of this run: an exception escaping a std::thread would abort the sweep.
    try {
      if (lock_fd < 0) throw RuntimeFailure("cannot create lock " + lock_path + ": " + std::strerror(errno));
      // Finished by another process since the list was made.
      if (o_.resume && run_finished(folder_.dir, r)) return Result::finished_elsewhere;
      const std::string spec_path = (folder_.dir / "specs" / (r.id + ".json")).string();
      write_file_atomic(spec_path, r.scenario.dump(2) + "\n");
      const std::string log = (folder_.dir / "logs" / (r.id + ".log")).string();
      const auto r0 = std::chrono::steady_clock::now();
      const std::string out = (folder_.dir / "runs" / r.id).string();
      // --overwrite: the sweep owns runs/<id>/ and replaces a previous result of the same run.
      std::vector<std::string> args = {"run", spec_path, "-o", out, "--overwrite", "--quiet"};
      // Every world once per machine: the run looks in the world cache (drawing it there, under its
      // lock, if no run did before); without the cache, once per sweep folder for runs that share it.
      if (!o_.share_worlds) args.push_back("--draw-each");
      if (o_.debug_view) args.push_back("--debug-view");
      const bool folder_world = r.recording.empty() && !r.world.empty() && o_.share_worlds && !o_.world_cache;
      const std::string recording = folder_world ? world_recording(r) : r.recording;
      if (!recording.empty()) {
        // The localizer alone, as replay takes it; the rest of the run is the recording's.
        const std::string loc_path = (folder_.dir / "specs" / (r.id + ".localizer.json")).string();
        write_file_atomic(loc_path, r.scenario.value("localizer", Json::object()).dump(2) + "\n");
        args = {"replay", recording, "--localizer", loc_path, "--seed", std::to_string(r.seed), "-o", out, "--overwrite", "--quiet"};
        if (o_.debug_view) args.push_back("--debug-view");
      }
      const int st = spawn(folder_.exe, args, log, lock_fd);
      secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
      const bool ok = st >= 0 && WIFEXITED(st) && WEXITSTATUS(st) == 0 && run_finished(folder_.dir, r);
      if (ok) {
        std::error_code ec;
        fs::remove(fail_marker, ec);
      } else {
        why = failure_line(st, log);
        Json f{{"id", r.id}, {"log", tail_of(log, 2000)}};
        if (st >= 0 && WIFEXITED(st)) f["exit_code"] = WEXITSTATUS(st);
        if (st >= 0 && WIFSIGNALED(st)) f["signal"] = WTERMSIG(st);
        write_file_atomic(fail_marker.string(), f.dump(2) + "\n");
      }
      return ok ? Result::ok : Result::failed;
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mu_);
      if (o_.progress) *o_.progress << readable(r) << ": FAILED: " << e.what() << "\n";
      try {
        write_file_atomic(fail_marker.string(), Json{{"id", r.id}, {"error", e.what()}}.dump(2) + "\n");
      } catch (const std::exception&) {
        // The disk that made the run fail may refuse the record too; the count below still has it.
      }
      return Result::failed;
    }
  }

  // The recording of `r`'s world in the sweep folder (recordings/<world>/), drawn by whichever worker
  // (or shard, or Slurm task) needs it first while the others wait on its lock; throws when it could
  // not be drawn, which fails the run (the next run of the same world tries again).
  std::string world_recording(const SweepRun& r) {
    const fs::path dir = folder_.dir / "recordings" / r.world;
    const std::string lock_path = (folder_.dir / "locks" / ("world_" + r.world + ".lock")).string();
    const int fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) throw RuntimeFailure("cannot create lock " + lock_path + ": " + std::strerror(errno));
    while (::flock(fd, LOCK_EX) != 0 && errno == EINTR) {
    }
    struct Unlock {
      int fd;
      ~Unlock() { ::close(fd); }
    } unlock{fd};
    if (fs::exists(dir / "recording.json")) return dir.string();
    make_folder(dir.parent_path());
    remove_stale_partials(dir.parent_path().string());
    Json world = r.scenario;
    world.erase("localizer");  // perception runs whatever the localizer; the recording keeps no localizer
    const std::string spec_path = (folder_.dir / "specs" / ("world_" + r.world + ".json")).string();
    write_file_atomic(spec_path, world.dump(2) + "\n");
    const std::string log = (folder_.dir / "logs" / ("world_" + r.world + ".log")).string();
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (o_.progress && !tty_) *o_.progress << "drawing " << r.scenario_name << (r.params_label == "default" ? "" : " / " + r.params_label)
                                              << ", seed " << r.seed << " once for its localizers\n";
    }
    const int st = spawn(folder_.exe, {"record", spec_path, "-o", dir.string(), "--overwrite", "--quiet"}, log, -1);
    if (!(st >= 0 && WIFEXITED(st) && WEXITSTATUS(st) == 0 && fs::exists(dir / "recording.json")))
      throw RuntimeFailure("drawing the world " + r.world + " failed: " + tail_of(log, 1500));
    return dir.string();
  }

  void report(const SweepRun& r, bool ok, double secs, const std::string& why) {
    std::lock_guard<std::mutex> lock(mu_);
    ++done_;
    if (!ok) ++failed_;
    if (!o_.progress) return;
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
    const double eta = el / done_ * (todo_.size() - done_);
    if (tty_) {
      // A failure keeps its own line above the bar, so its reason is not overwritten.
      if (!ok) *o_.progress << "\r" << readable(r) << ": FAILED" << (why.empty() ? "" : " (" + why + ")") << "\n";
      const int width = 30, filled = static_cast<int>(width * done_ / std::max<std::size_t>(1, todo_.size()));
      *o_.progress << "\r[" << std::string(filled, '#') << std::string(width - filled, '.') << "] " << done_ << "/" << todo_.size()
                   << " failed " << failed_ << " ETA " << fmt_duration(eta) << "   " << std::flush;
    } else {
      *o_.progress << "[" << done_ << "/" << todo_.size() << "] " << readable(r, ok ? run_localizer_name(folder_.dir, r) : "")
                   << (ok ? ": ok " : ": FAILED ") << fmt_g6(secs) << " s" << (why.empty() ? "" : " (" + why + ")") << ", ETA "
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

// A shard's own record: its runs' states, for `sweep --status` and people, never read as a result.
void write_shard_progress(const SweepSpec& spec, const SweepOptions& o, const fs::path& dir, SweepOutcome& out) {
  std::size_t runs = 0, done = 0, failed = 0;
  for (const auto& r : spec.runs) {
    if (static_cast<int>(r.index % o.shard_count) != o.shard_index) continue;
    ++runs;
    if (run_finished(dir, r)) ++done;
    else if (fs::exists(dir / "failed" / (r.id + ".json"))) ++failed;
  }
  out.missing = runs - done - failed;
  // Named as on the command line (--shard I/N, I from 0).
  const std::string name = "shard-" + std::to_string(o.shard_index) + "-of-" + std::to_string(o.shard_count) + ".json";
  make_folder(dir / "progress");
  write_file_atomic((dir / "progress" / name).string(),
                    Json{{"shard", o.shard_index}, {"shards", o.shard_count}, {"runs", runs}, {"done", done}, {"failed", failed},
                         {"missing", out.missing}, {"omniloc", build_info_json()}}
                            .dump(2) + "\n");
  char line[256];
  std::snprintf(line, sizeof line, "shard %d/%d: %zu runs, %zu done, %zu failed, %zu missing; the sweep's aggregate is written by "
                "`omniloc sweep SPEC --aggregate-only` once every shard is done\n", o.shard_index, o.shard_count, runs, done, failed,
                out.missing);
  out.table = line;
}

}  // namespace

SweepOutcome run_sweep(const SweepSpec& spec, const SweepOptions& o) {
  SweepOutcome out;
  out.out_dir = o.out_dir.empty() ? "results/sweeps/" + spec.name : o.out_dir;
  out.expected = spec.runs.size();
  const SweepFolder folder = open_sweep_folder(out.out_dir, o);
  SweepWorkers workers(folder, o, runs_to_do(spec, o, folder.dir, out.skipped));
  share_rasterizer_threads(o.jobs);
  workers.run();
  out.ran = workers.done();
  out.failed = workers.failed();
  out.skipped += workers.busy();
  if (o.shard_count > 1 && !o.aggregate_only) {
    write_shard_progress(spec, o, folder.dir, out);
    return out;
  }
  const AggregateOutcome a = write_final_aggregate(spec, folder.dir);
  out.missing = a.missing;
  out.table = a.table;
  out.aggregate_written = a.written;
  if (!a.written)
    out.table += "incomplete: " + std::to_string(a.missing) + " of " + std::to_string(a.expected) +
                 " runs missing; no aggregate written (run again with --resume, or see --status)\n";
  return out;
}

}  // namespace omniloc::batch
