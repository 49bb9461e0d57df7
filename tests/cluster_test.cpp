// Sweeps on a real Slurm cluster (label "cluster"): the built omniloc submits with sbatch, the
// cluster runs the array tasks and the merge job, and the aggregates are compared byte for byte
// with a local `omniloc sweep -j 2` of the same sweep. Needs a running cluster: `.ci/run` starts one
// with scripts/slurm-local.sh; without one (or where Slurm cannot be installed) every test skips
// and says why, so `scripts/test.sh` never needs Slurm.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <chrono>
#include <regex>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include "core/atomic_file.hpp"
#include "core/json_reader.hpp"

using namespace omniloc;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

struct Out {
  int code = -1;
  std::string text;
};

// Runs a shell command, stdout and stderr together.
Out sh(const std::string& cmd) {
  Out o;
  FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return o;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) o.text.append(buf, n);
  const int st = ::pclose(p);
  o.code = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return o;
}

std::string exe() { return fs::absolute("omniloc").string(); }

fs::path test_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  return fs::temp_directory_path() / ("omniloc_cluster_" + std::string(info->name()));
}

// Why no cluster can be used here ("" when one answers). A cluster started by
// scripts/slurm-local.sh is found through its slurm.conf even when SLURM_CONF is not exported.
std::string why_no_cluster() {
  if (sh("command -v sbatch").code != 0)
    return "sbatch is not installed (Slurm cannot be installed here, or scripts/slurm-local.sh up was not run)";
  if (!std::getenv("SLURM_CONF")) {
    const char* d = std::getenv("OMNILOC_SLURM_DIR");
    const fs::path dir = d ? d : "/tmp/omniloc-slurm";
    // Only a running local cluster: sinfo spends seconds retrying a controller that is not there.
    if (!fs::exists(dir / "run" / "slurmctld.daemon.pid")) return "no SLURM_CONF and no local cluster running in " + dir.string();
    ::setenv("SLURM_CONF", (dir / "slurm.conf").c_str(), 1);
  }
  const Out s = sh("timeout 20 sinfo -h -o %t");
  if (s.code != 0 || s.text.empty())
    return "no Slurm controller answers (sinfo: " + s.text.substr(0, 200) + ")";
  if (s.text.find("idle") == std::string::npos && s.text.find("mix") == std::string::npos && s.text.find("alloc") == std::string::npos)
    return "no usable Slurm node (sinfo: " + s.text.substr(0, 200) + ")";
  return "";
}

#define REQUIRE_CLUSTER()                                                                                        \
  do {                                                                                                           \
    const std::string why = why_no_cluster();                                                                    \
    if (!why.empty()) GTEST_SKIP() << "no Slurm cluster: " << why << "; run scripts/slurm-local.sh up (as .ci/run does)"; \
  } while (0)

bool active(const std::string& state) {
  static const std::set<std::string> a = {"PENDING", "RUNNING", "CONFIGURING", "COMPLETING", "SUSPENDED", "REQUEUED"};
  return a.count(state) > 0;
}

// States of every element of a job ("<array>_<task>" or "<job>") as squeue lists them.
std::map<std::string, std::string> states(const std::string& id) {
  std::map<std::string, std::string> m;
  std::stringstream ss(sh("squeue -h -r -t all -j " + id + " -o '%i|%T'").text);
  std::string line;
  while (std::getline(ss, line)) {
    const auto bar = line.find('|');
    if (bar != std::string::npos) m[line.substr(0, bar)] = line.substr(bar + 1);
  }
  return m;
}

// Polls until no element of the job is pending or running (`sbatch --wait` would report success
// for a merge job cancelled without running, so the state is read instead).
std::map<std::string, std::string> wait_for(const std::string& id, double timeout_s = 180) {
  const auto t0 = Clock::now();
  for (;;) {
    auto m = states(id);
    bool busy = m.empty();
    for (const auto& [k, s] : m) busy = busy || active(s);
    if (!busy) return m;
    if (std::chrono::duration<double>(Clock::now() - t0).count() > timeout_s) {
      ADD_FAILURE() << "job " << id << " still not finished after " << timeout_s << " s";
      return m;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

// A sweep of 12 dead-reckoning runs (2 speeds x 6 seeds) of `duration` simulated seconds.
std::string make_sweep(double duration) {
  fs::remove_all(test_dir());
  fs::create_directories(test_dir());
  write_file_atomic((test_dir() / "short.json").string(),
                    R"({"name": "short", "duration": )" + std::to_string(duration) + R"(, "robots": [{"id": 0, "start": [0, 0, 0],
    "motion": {"type": "waypoints", "speed": 1.0, "points": [[2, 0], [2, 2], [0, 2]]}}], "localizer": {"type": "odometry_only"}})");
  const std::string sweep = (test_dir() / "sweep.json").string();
  write_file_atomic(sweep, R"({"name": "cluster", "scenarios": ["short.json"],
    "parameters": {"/robots/0/motion/speed": [0.5, 1.5]}, "seeds": {"first": 1, "count": 6}})");
  return sweep;
}

std::string aggregate(const fs::path& dir) {
  return read_file((dir / "aggregate.json").string()) + read_file((dir / "aggregate.csv").string());
}

// The local reference: the same sweep with two workers, no Slurm.
std::string local_reference(const std::string& sweep) {
  const fs::path ref = test_dir() / "local";
  const Out o = sh(exe() + " sweep " + sweep + " -j 2 -o " + ref.string());
  EXPECT_EQ(o.code, 0) << o.text;
  return aggregate(ref);
}

Json submission(const fs::path& results) { return Json::parse(read_file((results / "slurm" / "submission.json").string())); }

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace

TEST(Cluster, ArrayOfFourTasksGivesTheLocalAggregates) {
  REQUIRE_CLUSTER();
  const std::string sweep = make_sweep(3.0);
  const std::string ref = local_reference(sweep);
  const fs::path res = test_dir() / "slurm";
  const auto t0 = Clock::now();
  const Out sub = sh(exe() + " sweep " + sweep + " --slurm --tasks 4 --time 00:10:00 -o " + res.string());
  ASSERT_EQ(sub.code, 0) << sub.text;
  EXPECT_NE(sub.text.find("squeue -j"), std::string::npos) << sub.text;
  const Json s = submission(res);
  const std::string array = s["submissions"][0]["array_job"], merge = s["submissions"][0]["merge_job"];
  const auto a = wait_for(array);
  EXPECT_EQ(a.size(), 4u);
  for (const auto& [k, st] : a) EXPECT_EQ(st, "COMPLETED") << k;
  const auto m = wait_for(merge);
  EXPECT_EQ(m.at(merge), "COMPLETED") << read_file((res / "slurm" / "logs" / ("merge-" + merge + ".log")).string());
  std::cout << "[ cluster  ] 12 runs in 4 array tasks + merge, submit to merge done: " << since(t0) << " s\n";

  EXPECT_EQ(aggregate(res), ref);
  for (int k = 0; k < 4; ++k) EXPECT_TRUE(fs::exists(res / "slurm" / "logs" / ("task-" + array + "_" + std::to_string(k) + ".log")));
  EXPECT_NE(read_file((res / "slurm" / "report.txt").string()).find("complete: every run finished"), std::string::npos);
  EXPECT_EQ(s["tasks"], 4);
  EXPECT_EQ(s["runs_sha256"].get<std::string>().size(), 64u);
  const Out st = sh(exe() + " sweep " + sweep + " --status -o " + res.string());
  EXPECT_EQ(st.code, 0) << st.text;
  EXPECT_NE(st.text.find(array + "_3 COMPLETED"), std::string::npos) << st.text;
}

// A run that cannot be written (its results path is a dangling symlink: the real binary fails to
// commit it) fails its array task; the merge is cancelled rather than left pending, --status names
// the shard and the run, and --resubmit-missing completes the sweep with the local aggregates.
TEST(Cluster, FailedTaskCancelsTheMergeAndResubmitMissingCompletes) {
  REQUIRE_CLUSTER();
  const std::string sweep = make_sweep(3.0);
  const std::string ref = local_reference(sweep);
  const fs::path res = test_dir() / "slurm";
  // Run 6 (speed 1.5, seed 1) belongs to shard 6 % 4 = 2.
  const std::string bad_id = "short__odometry_only__speed=1.5__s1";
  fs::create_directories(res / "runs");
  fs::create_symlink(test_dir() / "nowhere" / "x", res / "runs" / bad_id);

  const auto t0 = Clock::now();
  const Out sub = sh(exe() + " sweep " + sweep + " --slurm --tasks 4 -o " + res.string());
  ASSERT_EQ(sub.code, 0) << sub.text;
  Json s = submission(res);
  const std::string array = s["submissions"][0]["array_job"], merge = s["submissions"][0]["merge_job"];
  const auto a = wait_for(array);
  const auto m = wait_for(merge);
  EXPECT_EQ(a.at(array + "_2"), "FAILED");
  EXPECT_EQ(a.at(array + "_0"), "COMPLETED");
  EXPECT_EQ(m.at(merge), "CANCELLED");  // --kill-on-invalid-dep=yes: not PENDING forever
  // Three shards finished, one failed, no merge: nothing may look like the sweep's result (only the merge writes it).
  for (const char* f : {"aggregate.json", "aggregate.csv", "runs.csv"}) EXPECT_FALSE(fs::exists(res / f)) << f;
  EXPECT_TRUE(fs::exists(res / "progress" / "shard-0-of-4.json"));

  const Out st = sh(exe() + " sweep " + sweep + " --status -o " + res.string());
  EXPECT_EQ(st.code, 1) << st.text;
  EXPECT_NE(st.text.find("failed: " + bad_id), std::string::npos) << st.text;
  EXPECT_NE(st.text.find(array + "_2 FAILED"), std::string::npos) << st.text;
  EXPECT_NE(st.text.find("incomplete shards: 2;"), std::string::npos) << st.text;
  EXPECT_NE(st.text.find("aggregate: none yet"), std::string::npos) << st.text;

  fs::remove(res / "runs" / bad_id);  // the fault is repaired
  const Out again = sh(exe() + " sweep " + sweep + " --slurm --resubmit-missing -o " + res.string());
  ASSERT_EQ(again.code, 0) << again.text;
  s = submission(res);
  ASSERT_EQ(s["submissions"].size(), 2u);
  EXPECT_EQ(s["submissions"][1]["shards"], Json::array({2}));
  const std::string array2 = s["submissions"][1]["array_job"], merge2 = s["submissions"][1]["merge_job"];
  const auto a2 = wait_for(array2);
  EXPECT_EQ(a2.size(), 1u);
  EXPECT_EQ(a2.at(array2 + "_2"), "COMPLETED");
  EXPECT_EQ(wait_for(merge2).at(merge2), "COMPLETED");
  std::cout << "[ cluster  ] failed task, cancelled merge, resubmission, merge: " << since(t0) << " s\n";
  // The resubmitted task skipped the two runs its shard had finished.
  EXPECT_NE(read_file((res / "slurm" / "logs" / ("task-" + array2 + "_2.log")).string()).find("ran 1, skipped 2"), std::string::npos);
  EXPECT_EQ(aggregate(res), ref);
  EXPECT_EQ(sh(exe() + " sweep " + sweep + " --status -o " + res.string()).code, 0);
  const Out none = sh(exe() + " sweep " + sweep + " --slurm --resubmit-missing -o " + res.string());
  EXPECT_EQ(none.code, 0);
  EXPECT_NE(none.text.find("nothing to resubmit"), std::string::npos) << none.text;
}

// scancel of one running array element: its finished runs stay, the merge is cancelled, and the
// resubmitted shard redoes only the rest, giving the local aggregates byte for byte.
TEST(Cluster, TaskKilledMidRunIsRecovered) {
  REQUIRE_CLUSTER();
  const std::string sweep = make_sweep(80.0);  // runs (about 1 s each) long enough to be caught between two runs of a shard
  const std::string ref = local_reference(sweep);
  const fs::path res = test_dir() / "slurm";
  const auto t0 = Clock::now();
  const Out sub = sh(exe() + " sweep " + sweep + " --slurm --tasks 4 -o " + res.string());
  ASSERT_EQ(sub.code, 0) << sub.text;
  Json s = submission(res);
  const std::string array = s["submissions"][0]["array_job"], merge = s["submissions"][0]["merge_job"];
  // Shard 1 holds runs 1, 5 and 9; kill its task once run 1 is finished and the next has started.
  const fs::path first = res / "runs" / "short__odometry_only__speed=0.5__s2" / "summary.json";
  const auto w0 = Clock::now();
  while (!fs::exists(first) && since(w0) < 120) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_TRUE(fs::exists(first));
  const std::string kept = read_file(first.string());
  ASSERT_EQ(states(array).at(array + "_1"), "RUNNING") << "shard 1 finished before it could be killed";
  ASSERT_EQ(sh("scancel " + array + "_1").code, 0);
  const auto a = wait_for(array);
  EXPECT_EQ(a.at(array + "_1"), "CANCELLED");
  EXPECT_EQ(wait_for(merge).at(merge), "CANCELLED");
  EXPECT_EQ(read_file(first.string()), kept);  // the finished run is untouched
  EXPECT_FALSE(fs::exists(res / "aggregate.json")) << "a shard wrote the sweep's aggregate";

  const Out st = sh(exe() + " sweep " + sweep + " --status -o " + res.string());
  EXPECT_EQ(st.code, 1);
  EXPECT_NE(st.text.find(array + "_1 CANCELLED"), std::string::npos) << st.text;

  const Out again = sh(exe() + " sweep " + sweep + " --slurm --resubmit-missing -o " + res.string());
  ASSERT_EQ(again.code, 0) << again.text;
  s = submission(res);
  EXPECT_EQ(s["submissions"][1]["shards"], Json::array({1}));
  const std::string array2 = s["submissions"][1]["array_job"], merge2 = s["submissions"][1]["merge_job"];
  EXPECT_EQ(wait_for(array2).at(array2 + "_1"), "COMPLETED");
  EXPECT_EQ(wait_for(merge2).at(merge2), "COMPLETED");
  std::cout << "[ cluster  ] killed task, resubmission, merge: " << since(t0) << " s\n";
  // It skipped what the killed task had finished: run 1 and, when run 5 ended before the scancel
  // landed (on a busy machine the kill can come a run later), run 5 too; it ran only the rest.
  const std::string log2 = read_file((res / "slurm" / "logs" / ("task-" + array2 + "_1.log")).string());
  std::smatch counts;
  ASSERT_TRUE(std::regex_search(log2, counts, std::regex("ran ([0-9]+), skipped ([0-9]+)"))) << log2;
  const int ran = std::stoi(counts[1].str()), skipped = std::stoi(counts[2].str());
  EXPECT_GE(skipped, 1) << log2;
  EXPECT_EQ(ran + skipped, 3) << log2;
  EXPECT_EQ(read_file(first.string()), kept);
  EXPECT_EQ(aggregate(res), ref);
}

// --dry-run writes a folder a cluster user can read and submit, and needs no Slurm at all; bad
// options fail with exit 2 before anything is written.
TEST(Cluster, DryRunWritesTheSubmissionFolderWithoutSlurm) {
  const std::string sweep = make_sweep(3.0);
  const fs::path res = test_dir() / "dry";
  const Out bad = sh(exe() + " sweep " + sweep + " --slurm --dry-run --time 90 -o " + res.string());
  EXPECT_EQ(bad.code, 2) << bad.text;
  EXPECT_NE(bad.text.find("--time"), std::string::npos) << bad.text;
  EXPECT_EQ(sh(exe() + " sweep " + sweep + " --slurm --dry-run --tasks 13 -o " + res.string()).code, 2);
  EXPECT_FALSE(fs::exists(res));

  const Out o = sh(exe() + " sweep " + sweep + " --slurm --dry-run --tasks 3 --partition short --time 01:30:00 --cpus-per-task 2 "
                   "--sbatch-arg --mem=2G -o " + res.string());
  ASSERT_EQ(o.code, 0) << o.text;
  const std::string array = read_file((res / "slurm" / "array.sbatch").string());
  EXPECT_NE(array.find("#SBATCH --array=0-2\n"), std::string::npos) << array;
  EXPECT_NE(array.find("#SBATCH --partition=short\n#SBATCH --time=01:30:00\n#SBATCH --mem=2G\n"), std::string::npos) << array;
  EXPECT_NE(array.find("N=3\n"), std::string::npos) << array;
  EXPECT_NE(array.find("--shard \"${SLURM_ARRAY_TASK_ID}/${N}\" --resume -j 2"), std::string::npos) << array;
  // One world cache for every task of the submission, named by its absolute path.
  EXPECT_NE(array.find(" --cache /"), std::string::npos) << array;
  EXPECT_EQ(array.find("SLURM_ARRAY_TASK_COUNT}"), std::string::npos);
  const std::string merge = read_file((res / "slurm" / "merge.sbatch").string());
  EXPECT_NE(merge.find("--aggregate-only"), std::string::npos);
  const std::string cmds = read_file((res / "slurm" / "commands.txt").string());
  EXPECT_NE(cmds.find("--dependency=afterok:<ARRAY_JOB_ID> --kill-on-invalid-dep=yes"), std::string::npos) << cmds;
  EXPECT_NE(cmds.find(" --shard 2/3 --resume"), std::string::npos) << cmds;
  const Json s = submission(res);
  EXPECT_EQ(s["tasks"], 3);
  EXPECT_EQ(s["runs"], 12);
  EXPECT_TRUE(s["submissions"].empty());
  EXPECT_TRUE(s["omniloc"].contains("version"));
  // bash accepts both scripts.
  EXPECT_EQ(sh("bash -n " + (res / "slurm" / "array.sbatch").string() + " && bash -n " + (res / "slurm" / "merge.sbatch").string()).code, 0);
}

// --gpus-per-task (docs/cluster.md "GPUs"): the GPUs as a generic resource among the #SBATCH lines (sbatch reads
// none after the first command) and rendering on them with egl; no Slurm needed.
TEST(Cluster, DryRunRequestsGpusPerTask) {
  const std::string sweep = make_sweep(3.0);
  const fs::path res = test_dir() / "dry_gpu";
  const Out bad = sh(exe() + " sweep " + sweep + " --slurm --dry-run --tasks 2 --gpus-per-task 17 -o " + res.string());
  EXPECT_EQ(bad.code, 2) << bad.text;
  EXPECT_NE(bad.text.find("--gpus-per-task"), std::string::npos) << bad.text;
  EXPECT_FALSE(fs::exists(res));
  const Out o = sh(exe() + " sweep " + sweep + " --slurm --dry-run --tasks 2 --cpus-per-task 4 --gpus-per-task 1 -o " + res.string());
  ASSERT_EQ(o.code, 0) << o.text;
  const std::string array = read_file((res / "slurm" / "array.sbatch").string());
  const auto gres = array.find("#SBATCH --gres=gpu:1\n");
  ASSERT_NE(gres, std::string::npos) << array;
  // Every line before it is a comment or an #SBATCH line.
  for (std::size_t at = 0; at < gres; at = array.find('\n', at) + 1) EXPECT_EQ(array[at], '#') << array.substr(at, 40);
  EXPECT_NE(array.find("export OMNILOC_GL_BACKEND=\"${OMNILOC_GL_BACKEND:-egl}\"\n"), std::string::npos) << array;
  EXPECT_EQ(submission(res)["gpus_per_task"], 1);
  EXPECT_EQ(sh("bash -n " + (res / "slurm" / "array.sbatch").string()).code, 0);
  // Without GPUs, neither line.
  const fs::path cpu = test_dir() / "dry_cpu";
  ASSERT_EQ(sh(exe() + " sweep " + sweep + " --slurm --dry-run --tasks 2 -o " + cpu.string()).code, 0);
  const std::string plain = read_file((cpu / "slurm" / "array.sbatch").string());
  EXPECT_EQ(plain.find("--gres"), std::string::npos);
  EXPECT_EQ(plain.find("OMNILOC_GL_BACKEND"), std::string::npos);
}
