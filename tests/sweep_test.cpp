#include <gtest/gtest.h>

#include <sys/stat.h>

#include <filesystem>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/install_paths.hpp"
#include "harness/run_directory.hpp"
#include "batch/sweep.hpp"

using namespace omniloc;
using namespace omniloc::harness;
using namespace omniloc::batch;
namespace fs = std::filesystem;

namespace {
// Each test gets its own folder: ctest runs tests in parallel.
fs::path test_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  return fs::temp_directory_path() / ("omniloc_sweep_" + std::string(info->name()));
}

// A 48-run sweep of short dead-reckoning runs (2 speeds x 2 noise levels x 12 seeds).
std::string make_sweep() {
  fs::create_directories(test_dir());
  const std::string scen = (test_dir() / "short.json").string();
  write_file_atomic(scen, R"({"name": "short", "duration": 3.0, "robots": [{"id": 0, "start": [0, 0, 0],
    "motion": {"type": "waypoints", "speed": 1.0, "points": [[2, 0], [2, 2]]}}], "localizer": {"type": "odometry_only"}})");
  const std::string sweep = (test_dir() / "sweep.json").string();
  write_file_atomic(sweep, R"({"name": "t", "scenarios": ["short.json"],
    "parameters": {"/robots/0/motion/speed": [0.5, 1.5], "/robots/0/odometry": [{"trans_sigma": 0.01}, {"trans_sigma": 0.05}]},
    "seeds": {"first": 1, "count": 12}})");
  return sweep;
}

SweepOutcome sweep_into(const SweepSpec& spec, const std::string& name, int jobs, bool resume = false, std::size_t stop = 0,
                        int shard = 0, int shards = 1, const std::string& exe = "./omniloc") {
  SweepOptions o;
  o.jobs = jobs;
  o.resume = resume;
  o.stop_after = stop;
  o.shard_index = shard;
  o.shard_count = shards;
  o.out_dir = (test_dir() / name).string();
  o.omniloc_exe = exe;
  return run_sweep(spec, o);
}

std::string aggregate(const std::string& name) {
  return read_file((test_dir() / name / "aggregate.json").string()) + read_file((test_dir() / name / "aggregate.csv").string());
}
}  // namespace

TEST(Sweep, AggregateIndependentOfWorkersResumeAndShards) {
  fs::remove_all(test_dir());
  const SweepSpec spec = load_sweep(make_sweep());
  ASSERT_EQ(spec.runs.size(), 48u);
  EXPECT_EQ(sweep_into(spec, "j1", 1).failed, 0u);
  EXPECT_EQ(sweep_into(spec, "j2", 2).failed, 0u);
  EXPECT_EQ(aggregate("j1"), aggregate("j2"));

  // Interrupted after 17 runs: no aggregate file exists that could pass for the result;
  // resumed: only the rest runs, and then the same aggregate.
  const auto part = sweep_into(spec, "resumed", 2, false, 17);
  EXPECT_EQ(part.missing, 48u - 17u);
  EXPECT_FALSE(part.aggregate_written);
  for (const char* f : {"aggregate.json", "aggregate.csv", "runs.csv"}) EXPECT_FALSE(fs::exists(test_dir() / "resumed" / f)) << f;
  const auto rest = sweep_into(spec, "resumed", 2, true);
  EXPECT_EQ(rest.skipped, 17u);
  EXPECT_EQ(rest.ran, 31u);
  EXPECT_TRUE(rest.aggregate_written);
  EXPECT_EQ(aggregate("resumed"), aggregate("j1"));
  const Json agg = Json::parse(read_file((test_dir() / "resumed" / "aggregate.json").string()));
  EXPECT_EQ(agg["expected"], 48);
  EXPECT_EQ(agg["done"], 48);
  EXPECT_EQ(agg["failed"], 0);
  EXPECT_EQ(agg["complete"], true);

  // Two shards into one folder: neither writes the sweep's aggregate, each its own progress; the
  // merge (--aggregate-only) then equals the whole.
  const auto first = sweep_into(spec, "sharded", 1, false, 0, 0, 2);
  EXPECT_FALSE(first.aggregate_written);
  EXPECT_FALSE(fs::exists(test_dir() / "sharded" / "aggregate.json"));
  const auto second = sweep_into(spec, "sharded", 1, false, 0, 1, 2);
  EXPECT_EQ(second.ran, 24u);
  EXPECT_FALSE(fs::exists(test_dir() / "sharded" / "aggregate.json")) << "a shard wrote the sweep's aggregate";
  const Json progress = Json::parse(read_file((test_dir() / "sharded" / "progress" / "shard-1-of-2.json").string()));
  EXPECT_EQ(progress["runs"], 24);
  EXPECT_EQ(progress["done"], 24);
  SweepOptions merge;
  merge.aggregate_only = true;
  merge.out_dir = (test_dir() / "sharded").string();
  EXPECT_TRUE(run_sweep(spec, merge).aggregate_written);
  EXPECT_EQ(aggregate("sharded"), aggregate("j1"));
}

TEST(Sweep, CrashingRunIsRecordedAndTheSweepContinues) {
  fs::remove_all(test_dir());
  const SweepSpec spec = load_sweep(make_sweep());
  // A stand-in binary that crashes on one run and is the real omniloc for the others.
  const std::string fake = (test_dir() / "crashy.sh").string();
  write_file_atomic(fake, "#!/bin/sh\ncase \"$2\" in *__s5.json) kill -SEGV $$ ;; esac\nexec " + fs::absolute("omniloc").string() + " \"$@\"\n");
  ::chmod(fake.c_str(), 0755);
  const auto out = sweep_into(spec, "crash", 2, false, 0, 0, 1, fake);
  EXPECT_EQ(out.failed, 4u);  // seed 5 in each of the 4 parameter groups
  EXPECT_EQ(out.ran, 48u);
  const std::string runs = read_file((test_dir() / "crash" / "runs.csv").string());
  EXPECT_NE(runs.find("__s5,short"), std::string::npos);
  const auto failed = Json::parse(read_file((test_dir() / "crash" / "failed" / (spec.runs[4].id + ".json")).string()));
  EXPECT_EQ(failed["signal"], 11);
  EXPECT_FALSE(fs::exists(test_dir() / "crash" / "runs" / spec.runs[4].id));
}

TEST(Sweep, BadSweepFailsBeforeAnyRun) {
  fs::create_directories(test_dir());
  const std::string bad1 = (test_dir() / "bad1.json").string();
  write_file_atomic(bad1, R"({"scenarios": ["nope.json"]})");
  try {
    load_sweep(bad1);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.path(), "/scenarios/0");
  }
  make_sweep();
  const std::string bad2 = (test_dir() / "bad2.json").string();
  write_file_atomic(bad2, R"({"scenarios": ["short.json"], "localizers": [{"type": "no_such_localizer"}]})");
  try {
    load_sweep(bad2);
    FAIL();
  } catch (const ConfigError& e) {
    // Named by its place in the sweep file, with the run it was checked for.
    EXPECT_EQ(e.path().rfind("/localizers/0/type (sweep ", 0), 0u) << e.what();
    EXPECT_NE(e.path().find("localizer \"no_such_localizer\""), std::string::npos) << e.what();
  }
  const std::string bad3 = (test_dir() / "bad3.json").string();
  write_file_atomic(bad3, R"({"scenarios": ["short.json"], "parameters": {"/robots/0/motion/speed": [-3]}})");
  EXPECT_THROW(load_sweep(bad3), ConfigError);
}

TEST(Sweep, ConfidenceInterval) {
  // The one rule (docs/results.md "Intervals"; python/omniloc/core/stats.py interval() gives the same).
  // n >= 5: Student t. 1..5: mean 3, sd 1.58114, t(4) = 2.776445: half width 1.963243.
  const Interval iv = mean_ci95({1.0, 2.0, 3.0, 4.0, 5.0});
  EXPECT_DOUBLE_EQ(iv.mean, 3.0);
  EXPECT_STREQ(iv.kind, kT95Interval);
  EXPECT_NEAR(iv.high - iv.mean, 1.963243, 1e-5);
  EXPECT_NEAR(iv.mean - iv.low, 1.963243, 1e-5);
  EXPECT_EQ(interval_text(iv, 3), "3.000 [1.037, 4.963] (n=5, t95)");
  // 2..4 seeds: no reliable interval; the seeds' range, said as such.
  const Interval r = mean_ci95({1.0, 2.0, 3.0, 4.0});
  EXPECT_STREQ(r.kind, kRangeInterval);
  EXPECT_EQ(r.low, 1.0);
  EXPECT_EQ(r.high, 4.0);
  EXPECT_EQ(interval_text(r, 2), "2.50 (seeds' range 1.00 to 4.00, n=4)");
  // One seed: none.
  EXPECT_EQ(mean_ci95({5.0}).low, 5.0);
  EXPECT_STREQ(mean_ci95({5.0}).kind, kNoInterval);
  EXPECT_EQ(interval_text(mean_ci95({5.0}), 4), "5.0000 (n=1, no interval)");
  // A non-negative sample never gets a negative bound (unclipped t: 2.06 - 5.53 < 0); a signed one may.
  const Interval skew = mean_ci95({0.05, 0.1, 0.1, 0.05, 10.0});
  EXPECT_EQ(skew.low, 0.0);
  EXPECT_GT(skew.high, skew.mean);
  EXPECT_LT(mean_ci95({-1.0, 0.05, 0.1, 0.05, 10.0}).low, 0.0);
  // df above the table: t(40) = 2.021075.
  std::vector<double> many(41);
  for (std::size_t i = 0; i < many.size(); ++i) many[i] = i % 2 ? 1.0 : 3.0;
  const Interval m = mean_ci95(many);
  double s2 = 0;
  for (double x : many) s2 += (x - m.mean) * (x - m.mean);
  EXPECT_NEAR(m.high - m.mean, 2.021075 * std::sqrt(s2 / 40) / std::sqrt(41.0), 1e-5);
}

namespace {
// RFC 4180 reader (quoted fields, doubled quotes, commas and line breaks inside quotes).
std::vector<std::vector<std::string>> parse_csv(const std::string& s) {
  std::vector<std::vector<std::string>> rows(1, std::vector<std::string>(1));
  bool quoted = false;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const char c = s[i];
    if (quoted) {
      if (c == '"' && i + 1 < s.size() && s[i + 1] == '"') rows.back().back() += '"', ++i;
      else if (c == '"') quoted = false;
      else rows.back().back() += c;
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      rows.back().emplace_back();
    } else if (c == '\n') {
      rows.emplace_back(1);
    } else {
      rows.back().back() += c;
    }
  }
  if (rows.back().size() == 1 && rows.back()[0].empty()) rows.pop_back();
  return rows;
}
}  // namespace

TEST(Sweep, CsvFilesAreValidWithJsonObjectParameters) {
  fs::remove_all(test_dir());
  const SweepSpec spec = load_sweep(make_sweep());
  sweep_into(spec, "csv", 2, false, 6);  // a few finished runs are enough for aggregate rows ...
  SweepOptions take;                       // ... once the rest are recorded as failed (a final aggregate)
  take.aggregate_only = true;
  take.out_dir = (test_dir() / "csv").string();
  for (std::size_t i = 6; i < spec.runs.size(); ++i)
    write_file_atomic((test_dir() / "csv" / "failed" / (spec.runs[i].id + ".json")).string(), "{}\n");
  ASSERT_TRUE(run_sweep(spec, take).aggregate_written);
  for (const char* f : {"runs.csv", "aggregate.csv"}) {
    const auto rows = parse_csv(read_file((test_dir() / "csv" / f).string()));
    ASSERT_GT(rows.size(), 1u) << f;
    for (const auto& r : rows) EXPECT_EQ(r.size(), rows[0].size()) << f << ": a row with another column count";
  }
  // The params column carries the label unchanged, inner quotes and commas included.
  const auto runs = parse_csv(read_file((test_dir() / "csv" / "runs.csv").string()));
  EXPECT_EQ(runs[1][4], spec.runs[0].params_label);
  EXPECT_NE(runs[1][4].find("odometry={\"trans_sigma\":0.01}"), std::string::npos) << runs[1][4];
  // Every row names its interval kind, then how many runs had no value (columns added at the end, so
  // old readers of ci95_low / ci95_high read them as before); kind follows n; a non-negative metric
  // never has a negative bound. Dead reckoning answers every frame: no run lacks a value (of its
  // errors: a run without vision has no single-frame accuracy bound, so those statistics are null).
  const auto agg = parse_csv(read_file((test_dir() / "csv" / "aggregate.csv").string()));
  ASSERT_EQ(agg[0][9], "interval");
  ASSERT_EQ(agg[0].back(), "no_value");
  ASSERT_EQ(agg[0][7], "ci95_low");
  for (std::size_t i = 1; i < agg.size(); ++i) {
    const std::size_t n = std::stoul(agg[i][5]);
    EXPECT_EQ(agg[i][9], n >= kMinTSeeds ? kT95Interval : n >= 2 ? kRangeInterval : kNoInterval) << agg[i][4];
    const bool bound = agg[i][4].find("/bound/") != std::string::npos || agg[i][4].find("/efficiency") != std::string::npos;
    if (!bound) {
      EXPECT_EQ(agg[i].back(), "0") << agg[i][4];
    }
    if (agg[i][4].find("_cm/") != std::string::npos || agg[i][4].find("position_m/") != std::string::npos) {
      EXPECT_GE(std::stod(agg[i][7]), 0.0) << agg[i][4];
    }
  }
}

TEST(Sweep, ScenarioEntriesCarryTheirOwnParametersAndLocalizers) {
  fs::remove_all(test_dir());
  make_sweep();
  const std::string f = (test_dir() / "entries.json").string();
  write_file_atomic(f, R"({"name": "entries", "scenarios": [
      "short.json",
      {"file": "short.json", "parameters": {"/robots/0/motion/speed": [0.5, 1.5]}},
      {"file": "short.json", "localizers": [{"type": "odometry_only", "label": "dead_reckoning"}]}],
    "parameters": {"/duration": [2.0]}, "seeds": [1, 2]})");
  const SweepSpec spec = load_sweep(f);
  // (1 + 2 + 1) conditions x 2 seeds; the sweep's own parameters apply to every entry.
  ASSERT_EQ(spec.runs.size(), 8u);
  EXPECT_EQ(spec.runs[0].params_label, "duration=2.0");
  EXPECT_EQ(spec.runs[2].params_label, "duration=2.0,speed=0.5");
  EXPECT_EQ(spec.runs[4].params_label, "duration=2.0,speed=1.5");
  EXPECT_EQ(spec.runs[6].localizer_label, "dead_reckoning");
  EXPECT_DOUBLE_EQ(spec.runs[4].scenario["robots"][0]["motion"]["speed"].get<double>(), 1.5);

  // A switch is labelled by what it switches, not "enabled=true".
  const std::string sw = (test_dir() / "switch.json").string();
  write_file_atomic(sw, R"({"name": "switch", "scenarios": ["short.json"],
    "parameters": {"/vision/exposure_control/enabled": [true, false]}, "seeds": [1]})");
  const SweepSpec s2 = load_sweep(sw);
  ASSERT_EQ(s2.runs.size(), 2u);
  EXPECT_EQ(s2.runs[0].params_label, "exposure_control=on");
  EXPECT_EQ(s2.runs[1].params_label, "exposure_control=off");

  const std::string bad = (test_dir() / "bad_entry.json").string();
  write_file_atomic(bad, R"({"scenarios": [{"file": "short.json", "parameters": {"speed": [1]}}]})");
  try {
    load_sweep(bad);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.path(), "/scenarios/0/parameters/speed") << e.what();
  }
  write_file_atomic(bad, R"({"scenarios": [{"path": "short.json"}]})");
  EXPECT_THROW(load_sweep(bad), ConfigError);
}

// `omniloc sweep --localizer`: the given localizers replace the file's and every entry's own, so a
// shipped suite runs any localizer unedited (docs/ci.md); their errors are named "--localizer/<i>".
TEST(Sweep, LocalizerOverrideReplacesEveryEntrysLocalizers) {
  fs::remove_all(test_dir());
  make_sweep();
  const std::string f = (test_dir() / "override.json").string();
  write_file_atomic(f, R"({"name": "override", "localizers": [{"type": "mcl"}], "scenarios": [
      "short.json",
      {"file": "short.json", "parameters": {"/duration": [2.0]}, "localizers": [{"type": "odometry_only", "label": "dead_reckoning"}]}],
    "seeds": [1]})");
  const SweepSpec own = load_sweep(f);
  ASSERT_EQ(own.runs.size(), 2u);
  EXPECT_EQ(own.runs[0].localizer_label, "mcl");
  EXPECT_EQ(own.runs[1].localizer_label, "dead_reckoning");
  const SweepSpec over = load_sweep(f, Json::array({{{"type", "odometry_only"}, {"label", "mine"}}, {{"type", "matching"}}}));
  ASSERT_EQ(over.runs.size(), 4u);  // 2 entries x 2 localizers
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(over.runs[i].localizer_label, i % 2 == 0 ? "mine" : "matching") << i;
    EXPECT_EQ(over.runs[i].scenario["localizer"]["type"], i % 2 == 0 ? "odometry_only" : "matching") << i;
  }
  try {
    load_sweep(f, Json::array({{{"type", "matching"}}, {{"type", 3}}}));
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.path(), "--localizer/1/type") << e.what();
  }
}

// A localizer error names where the localizer was written: a sweep's own entry by its path in the
// sweep file, a recording's own by the recording's file (no --localizer was given for it).
TEST(Sweep, ErrorsInARecordingsLocalizerNameWhereItWasWritten) {
  fs::remove_all(test_dir());
  fs::create_directories(test_dir());
  const fs::path rec = test_dir() / "rec";
  fs::copy(fs::path(source_dir()) / "data/recordings/ci_tracking/1", rec);
  Json h = Json::parse(read_file((rec / "recording.json").string()));
  h["scenario"]["localizer"] = {{"type", "mcl"}, {"bogus", 1}};
  write_file_atomic((rec / "recording.json").string(), h.dump());
  const std::string own = (test_dir() / "own.json").string();
  write_file_atomic(own, R"({"name": "own", "scenarios": [{"recording": "rec"}]})");
  const std::string run = "recording " + rec.string() + ", localizer \"mcl\"";
  try {
    load_sweep(own);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.path(), "sweep " + own + ", " + run + ": " + rec.string() + "/recording.json /scenario/localizer/bogus") << e.what();
  }
  const std::string given = (test_dir() / "given.json").string();
  write_file_atomic(given, R"({"name": "given", "scenarios": [{"recording": "rec", "localizers": [{"type": "odometry_only"}, {"type": "mcl", "x": 1}]}]})");
  try {
    load_sweep(given);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.path(), "/scenarios/0/localizers/1/x (sweep " + given + ", " + run + ")") << e.what();
  }
  try {
    load_sweep(given, Json::array({{{"type", "nope"}}}));
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.path(), "--localizer/0/type (sweep " + given + ", recording " + rec.string() + ", localizer \"nope\")") << e.what();
  }
}

// Shards share one results folder (Slurm array tasks): a shard starting must not delete the staging
// folder another shard is writing, only the leftovers of its own runs.
TEST(Sweep, ShardLeavesLiveStagingFoldersAloneAndClearsDeadOnes) {
  // Shards (Slurm array tasks) share the runs folder: a shard starting up must not delete the
  // staging folder of a run another live process is writing, but does clear one whose process died.
  fs::remove_all(test_dir());
  const SweepSpec spec = load_sweep(make_sweep());
  const fs::path runs = test_dir() / "shared" / "runs";
  const std::string live_tag = omniloc::harness::RunDirectory::staging_tag();  // this test process: alive
  const std::string host = live_tag.substr(0, live_tag.rfind('-'));
  const fs::path other = runs / ("." + spec.runs[1].id + ".partial-" + live_tag);        // run 1: shard 1 of 2, live
  const fs::path dead = runs / ("." + spec.runs[3].id + ".partial-" + host + "-999999999");  // no such pid
  fs::create_directories(other);
  fs::create_directories(dead);
  sweep_into(spec, "shared", 1, true, 1, 0, 2);
  EXPECT_TRUE(fs::exists(other));
  EXPECT_FALSE(fs::exists(dead));
}
