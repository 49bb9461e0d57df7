// Regression tests for bad input (README "Bad input"): one test per class of hostile input that used to crash, exit with
// the wrong code or destroy data. Most run the real omniloc binary (working directory: the build
// folder), since the promise is about what the program does: exit 0 or 2, never a signal, nothing
// written on bad input, nothing replaced that the user did not ask to replace.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/cli_args.hpp"
#include "core/json_parse.hpp"
#include "harness/run_directory.hpp"
#include "harness/scenario.hpp"
#include "batch/sweep.hpp"
#include "core/install_paths.hpp"

namespace fs = std::filesystem;
using omniloc::ConfigError;
using omniloc::Json;

namespace {

const std::string kQuickstart = std::string(omniloc::source_dir().string()) + "/scenarios/quickstart.json";

// Runs ./omniloc; returns the exit code, or 128 + signal when it died of one (a test failure).
int cli_run(const std::string& args, std::string* err = nullptr) {
  const fs::path log = fs::temp_directory_path() / ("omniloc_robust_" + std::to_string(::getpid()) + ".err");
  const int st = std::system(("./omniloc " + args + " >/dev/null 2>" + log.string()).c_str());
  if (err) *err = omniloc::read_file(log.string());
  fs::remove(log);
  if (WIFSIGNALED(st)) return 128 + WTERMSIG(st);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

// CPU seconds (user + system) of the finished child processes so far (cli_run's).
double children_cpu_s() {
  rusage u{};
  ::getrusage(RUSAGE_CHILDREN, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("omniloc_robust_" + std::to_string(::getpid())) / name;
  fs::create_directories(d.parent_path());
  return d;
}

std::string write(const std::string& name, const std::string& text) {
  const fs::path p = scratch(name);
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

Json quickstart() { return omniloc::read_json_strict(kQuickstart, "quickstart"); }

std::string write_json(const std::string& name, const Json& j) { return write(name, j.dump(1)); }

// The ConfigError path of parsing `text` ("" when it parses).
std::string parse_error_path(const std::string& text) {
  try {
    (void)omniloc::parse_json_strict(text, "test");
  } catch (const ConfigError& e) {
    return e.path().empty() ? "/" : e.path();
  }
  return "";
}

}  // namespace

// 184 inputs crashed validate with SIGSEGV: 100000 levels of nesting overflowed the recursive dump
// used by json_brief and the recursive copies of the scenario reader.
TEST(RobustInput, DeepNestingIsAnErrorWithItsPath) {
  const std::string deep = "{\"duration\": " + std::string(100000, '[') + std::string(100000, ']') + "}";
  std::string err;
  EXPECT_EQ(cli_run("validate " + write("deep.json", deep), &err), 2);
  EXPECT_NE(err.find("/duration/0/0"), std::string::npos) << err;
  EXPECT_NE(err.find("nested more than 64"), std::string::npos) << err;
  EXPECT_EQ(cli_run("validate " + write("deep_top.json", std::string(70000, '[') + std::string(70000, ']'))), 2);
  // 64 levels pass the reader (and then fail as a scenario with a path); 65 do not.
  EXPECT_EQ(parse_error_path(std::string(64, '[') + std::string(64, ']')), "");
  EXPECT_EQ(parse_error_path(std::string(65, '[') + std::string(65, ']')), "/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0");
}

TEST(RobustInput, JsonBriefIsShortAndDoesNotRecurse) {
  // A value built in code may be deeper than the reader allows; the brief must not recurse over it.
  Json j = Json::array();
  Json* p = &j;
  for (int i = 0; i < 200; ++i) {
    p->push_back(Json::array());
    p = &p->back();
  }
  const std::string b = omniloc::json_brief(j);
  EXPECT_LE(b.size(), 60u);
  EXPECT_EQ(b.substr(0, 5), "[[[[[");
  EXPECT_EQ(omniloc::json_brief(Json{{"a", 1}, {"b", "x"}}), R"({"a":1,"b":"x"})");
  EXPECT_EQ(omniloc::json_brief(Json(std::string("\xff\xfe"))), "\"\xEF\xBF\xBD\xEF\xBF\xBD\"");  // invalid UTF-8 replaced, no throw
}

// 125 inputs exited 1: json's out_of_range 406 escaped as a generic exception.
TEST(RobustInput, NumberOutOfRangeIsAConfigError) {
  EXPECT_EQ(parse_error_path(R"({"duration": 1e400})"), "/duration");
  EXPECT_EQ(parse_error_path(R"({"robots": [{"start": [0, -1e999, 0]}]})"), "/robots/0/start/1");
  Json q = quickstart();
  std::string text = q.dump();
  text.replace(text.find("\"duration\":40.0"), 15, "\"duration\":1e400");
  std::string err;
  EXPECT_EQ(cli_run("validate " + write("big.json", text), &err), 2);
  EXPECT_NE(err.find("/duration"), std::string::npos) << err;
}

TEST(RobustInput, DuplicateKeysNulBytesAndTrailingTextAreErrors) {
  EXPECT_EQ(parse_error_path(R"({"a": {"b": 1, "b": 2}})"), "/a/b");
  EXPECT_EQ(parse_error_path(std::string("{\"a\": 1}\0{\"b\": 2}", 17)), "/");
  EXPECT_EQ(parse_error_path(R"({"a": 1} x)"), "/");
  std::string text = omniloc::read_file(kQuickstart);
  text.insert(text.find("\"seed\""), std::string("\"seed\": 5,\n  "));
  EXPECT_EQ(cli_run("validate " + write("dup.json", text)), 2);
  std::string nul = omniloc::read_file(kQuickstart);
  nul.insert(nul.size() - 2, std::string(1, '\0'));
  std::string err;
  EXPECT_EQ(cli_run("validate " + write("nul.json", nul), &err), 2);
  EXPECT_NE(err.find("NUL byte at line"), std::string::npos) << err;
}

TEST(RobustInput, DirectoryOrHugeFileAsScenario) {
  const fs::path d = scratch("a_folder.json");
  fs::create_directories(d);
  EXPECT_EQ(cli_run("validate " + d.string()), 2);
  EXPECT_EQ(cli_run("run " + d.string() + " -o " + scratch("dir_out").string()), 2);
  const std::string big = write("huge.json", "[" + std::string(omniloc::kJsonMaxBytes, ' ') + "]");
  EXPECT_EQ(cli_run("validate " + big), 2);
}

// validate accepted a calibration path that run could not read; run then created folders and caches.
TEST(RobustInput, UnreadableDataFilesAreCaughtByValidateWithTheirPath) {
  Json q = quickstart();
  q["vision"] = {{"calibration", "/nonexistent/map.json"}};
  std::string err;
  EXPECT_EQ(cli_run("validate " + write_json("calib.json", q), &err), 2);
  EXPECT_NE(err.find("/vision/calibration"), std::string::npos) << err;
  q["vision"] = {{"colour_table", scratch("").string()}};  // a folder
  EXPECT_EQ(cli_run("validate " + write_json("table.json", q), &err), 2);
  EXPECT_NE(err.find("/vision/colour_table"), std::string::npos) << err;
  q["vision"] = {{"calibration", write("garbage_map.json", "{\"not\": \"a map\"}")}};
  const fs::path out = scratch("calib_out") / "deeper";
  EXPECT_EQ(cli_run("run " + write_json("calib2.json", q) + " -o " + out.string(), &err), 2);
  EXPECT_NE(err.find("/vision/calibration"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(out.parent_path())) << "a rejected scenario must not create the parents of -o";
}

// Camera settings validate accepted but calibration could not use.
TEST(RobustInput, CameraThatCannotBeCalibratedIsRejected) {
  Json q = quickstart();
  q["camera"] = {{"width", 64}, {"height", 64}};
  std::string err;
  EXPECT_EQ(cli_run("validate " + write_json("cam_small.json", q), &err), 2);
  EXPECT_NE(err.find("/camera/width"), std::string::npos) << err;
  q["camera"] = {{"centre_offset_px", {1e6, 0}}};
  EXPECT_EQ(cli_run("validate " + write_json("cam_offset.json", q), &err), 2);
  EXPECT_NE(err.find("/camera/centre_offset_px"), std::string::npos) << err;
}

// A ball velocity of 1e39 passed validation and aborted inside Box2D.
TEST(RobustInput, ImpossibleVelocitiesAndPositionsAreRejected) {
  Json q = quickstart();
  q["ball"]["velocity"] = {1e39, 0};
  std::string err;
  EXPECT_EQ(cli_run("validate " + write_json("ball.json", q), &err), 2);
  EXPECT_NE(err.find("/ball/velocity"), std::string::npos) << err;
  q = quickstart();
  q["robots"][0]["motion"]["points"][1] = {100.0, 0.0};
  EXPECT_EQ(cli_run("validate " + write_json("waypoint.json", q), &err), 2);
  EXPECT_NE(err.find("/robots/0/motion/points/1"), std::string::npos) << err;
  q = quickstart();
  q["robots"][1]["motion"] = {{"type", "constant"}, {"velocity", {1e39, 0}}};
  EXPECT_EQ(cli_run("validate " + write_json("constant.json", q), &err), 2);
  EXPECT_NE(err.find("/robots/1/motion/velocity/0"), std::string::npos) << err;
}

// "..", "../../x" wrote outside results/; "", "/" and "." collapsed into results/runs/<seed>.
TEST(RobustInput, ScenarioNamesAreSafeFileNames) {
  for (const char* bad : {"..", "../../x", "", "/", ".", "a/b", "a b", "x\\y"}) {
    Json q = quickstart();
    q["name"] = bad;
    std::string err;
    EXPECT_EQ(cli_run("validate " + write_json("name.json", q), &err), 2) << bad;
    EXPECT_NE(err.find("/name"), std::string::npos) << err;
  }
  Json q = quickstart();
  q["name"] = "ok_name-1.2";
  EXPECT_EQ(cli_run("validate " + write_json("name_ok.json", q)), 0);
}

// 100000 occlusion sectors took 34 s (pairwise overlap check).
TEST(RobustInput, LargeInputsValidateInLinearTime) {
  Json q = quickstart();
  Json sectors = Json::array();
  for (int i = 0; i < 360; ++i) sectors.push_back({i * 1.0, 0.9});
  q["occlusion"] = {{"sectors", sectors}};
  // The children's CPU time, not the wall clock: a busy machine stretches the one, not the other.
  const double cpu0 = children_cpu_s();
  EXPECT_EQ(cli_run("validate " + write_json("sectors_ok.json", q)), 0);
  sectors[200] = {10.5, 0.9};  // overlaps sector 10
  q["occlusion"] = {{"sectors", sectors}};
  std::string err;
  EXPECT_EQ(cli_run("validate " + write_json("sectors_overlap.json", q), &err), 2);
  EXPECT_NE(err.find("/occlusion/sectors/200"), std::string::npos) << err;
  for (int i = 360; i < 100000; ++i) sectors.push_back({i * 0.0036, 0.001});
  q["occlusion"] = {{"sectors", sectors}};
  EXPECT_EQ(cli_run("validate " + write_json("sectors_many.json", q), &err), 2);
  EXPECT_NE(err.find("/occlusion/sectors"), std::string::npos) << err;
  EXPECT_LT(children_cpu_s() - cpu0, 20.0);
}

// run -o deleted an existing file or a folder with other content and exited 0.
TEST(RobustInput, OutputTargetIsNeverReplacedWithoutOverwrite) {
  const fs::path dir = scratch("precious");
  fs::create_directories(dir);
  std::ofstream(dir / "thesis.tex") << "years of work";
  std::string err;
  EXPECT_EQ(cli_run("run " + kQuickstart + " -o " + dir.string() + " --quiet", &err), 2);
  EXPECT_NE(err.find("--overwrite"), std::string::npos) << err;
  EXPECT_TRUE(fs::exists(dir / "thesis.tex"));
  const std::string file = write("precious.txt", "keep me");
  EXPECT_EQ(cli_run("run " + kQuickstart + " -o " + file + " --quiet"), 2);
  EXPECT_EQ(omniloc::read_file(file), "keep me");
}

// --seed -1 ran as 2^64 - 1; --t nan rendered; atoi coerced the rest; --stop-after abc exited 1.
TEST(RobustInput, StrictCommandLine) {
  const std::string q = kQuickstart;
  const std::string sweep = std::string(omniloc::source_dir().string()) + "/scenarios/sweeps/odometry_drift.json";
  for (const std::string& args : std::vector<std::string>
       {"run " + q + " --seed -1", "run " + q + " --seed 1x", "run " + q + " --seed 99999999999999999999", "run " + q + " --frames-every 0",
        "run " + q + " --frames-every abc", "run " + q + " --frames-every -5", "render " + q + " --t nan -o x.png",
        "render " + q + " --t 0.2abc -o x.png", "render " + q + " --t 1e9 -o x.png", "render " + q + " --robot abc -o x.png",
        "render " + q + " --robot 7 -o x.png", "sweep " + sweep + " --stop-after abc", "sweep " + sweep + " -j 0", "sweep " + sweep + " -j 2x",
        "sweep " + sweep + " --shard 1/1", "sweep " + sweep + " --shard a/2", "run " + q + " --bogus", "run " + q + " --quiet=1", "run", "run a b",
        "list extra", "validate"}) {
    std::string err;
    EXPECT_EQ(cli_run(args, &err), 2) << args;
    EXPECT_EQ(err.find("usage: omniloc <command>"), std::string::npos) << "a usage error names the option, not the whole manual: " << err;
  }
  for (const char* cmd : {"run", "render", "calibrate", "colour-calibrate", "validate", "list", "sweep", "experiment"})
    EXPECT_EQ(cli_run(std::string(cmd) + " --help"), 0) << cmd;
  EXPECT_EQ(cli_run("--version"), 0);
}

TEST(RobustInput, CliNumberParsing) {
  long long i = 0;
  std::uint64_t u = 0;
  double d = 0;
  EXPECT_TRUE(omniloc::cli::parse_int("-5", i));
  EXPECT_EQ(i, -5);
  EXPECT_FALSE(omniloc::cli::parse_int(" 5", i));
  EXPECT_FALSE(omniloc::cli::parse_int("5 ", i));
  EXPECT_FALSE(omniloc::cli::parse_uint("-1", u));
  EXPECT_FALSE(omniloc::cli::parse_uint("18446744073709551616", u));
  EXPECT_TRUE(omniloc::cli::parse_double("0.25", d));
  EXPECT_FALSE(omniloc::cli::parse_double("inf", d));
  EXPECT_FALSE(omniloc::cli::parse_double("nan", d));
  EXPECT_FALSE(omniloc::cli::parse_double("", d));
}

// validate reported "/robots missing" for a sweep file.
TEST(RobustInput, ValidateChecksSweepAndExperimentFiles) {
  std::string err;
  EXPECT_EQ(cli_run("validate " + std::string(omniloc::source_dir().string()) + "/scenarios/sweeps/odometry_drift.json", &err), 0) << err;
  EXPECT_EQ(cli_run("validate " + std::string(omniloc::source_dir().string()) + "/scenarios/experiments/cooperative_001.json", &err), 0) << err;
  const std::string bad = write("sweep_bad.json", R"({"scenarios": [")" + kQuickstart + R"("], "parameters": {"/duration": [10, -1]}})");
  EXPECT_EQ(cli_run("validate " + bad, &err), 2);
  EXPECT_NE(err.find("/duration"), std::string::npos) << err;
}

// A run killed outside a sweep left a hidden .partial folder for ever.
TEST(RobustInput, StalePartialFoldersAreCleanedLiveOnesKept) {
  const fs::path parent = scratch("partials");
  fs::create_directories(parent);
  const std::string tag = omniloc::harness::RunDirectory::staging_tag();
  const std::string host = tag.substr(0, tag.rfind('-'));
  // pid 999999999 is above pid_max: never alive.
  const fs::path stale = parent / (".old_run.partial-" + host + "-999999999");
  const fs::path stale_legacy = parent / ".older.partial-999999998";
  const fs::path live = parent / (".live_run.partial-" + host + "-" + std::to_string(::getpid()));
  const fs::path other_host = parent / ".remote.partial-othernode-999999999";
  for (const auto& p : {stale, stale_legacy, live, other_host}) fs::create_directories(p);
  {
    omniloc::harness::RunDirectory d((parent / "new_run").string());
    d.write("x.txt", "x");
    d.commit();
  }
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_FALSE(fs::exists(stale_legacy));
  EXPECT_TRUE(fs::exists(live));
  EXPECT_TRUE(fs::exists(other_host)) << "another host's staging folder cannot be judged from here";
  EXPECT_EQ(omniloc::read_file((parent / "new_run" / "x.txt").string()), "x");
}

// sweep --resume on a full disk aborted (an exception escaped a worker thread); a resume beside a
// live sweep ran the same runs a second time.
TEST(RobustInput, SweepWorkerFailuresAreRecordedAndLockedRunsSkipped) {
  const fs::path dir = scratch("sweep_out");
  fs::remove_all(dir);
  const std::string file = write("tiny_sweep.json", R"({"name": "tiny", "scenarios": [")" + kQuickstart + R"("], "seeds": [1, 2]})");
  const auto spec = omniloc::batch::load_sweep(file);
  ASSERT_EQ(spec.runs.size(), 2u);
  // Run 0: its spec file cannot be written (a folder stands in the way, as a full disk would refuse it).
  fs::create_directories(dir / "specs" / (spec.runs[0].id + ".json") / "blocker");
  // Run 1: another live process holds its lock.
  fs::create_directories(dir / "locks");
  const int fd = ::open((dir / "locks" / (spec.runs[1].id + ".lock")).c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  omniloc::batch::SweepOptions o;
  o.out_dir = dir.string();
  o.jobs = 2;
  o.omniloc_exe = "/bin/false";  // must never be started here
  const auto r = omniloc::batch::run_sweep(spec, o);
  ::close(fd);
  EXPECT_EQ(r.failed, 1u);
  EXPECT_EQ(r.skipped, 1u);
  EXPECT_TRUE(fs::exists(dir / "failed" / (spec.runs[0].id + ".json")));
  EXPECT_FALSE(fs::exists(dir / "logs" / (spec.runs[1].id + ".log"))) << "a locked run must not be started";
}

// After kill -9 of a sweep its children kept running, and a later --resume ran the same runs
// beside them. Children now die with the sweep (PR_SET_PDEATHSIG).
TEST(RobustInput, SweepChildrenDieWithTheSweep) {
  const fs::path dir = scratch("sweep_kill");
  fs::remove_all(dir);
  fs::create_directories(dir);
  // Stands in for `omniloc run`: records its pid, then takes far longer than the test.
  const std::string exe = write("sweep_kill/fake_run.sh", "#!/bin/sh\necho $$ > " + (dir / "child.pid").string() + ".tmp\nmv " +
                                                              (dir / "child.pid").string() + ".tmp " + (dir / "child.pid").string() +
                                                              "\nexec sleep 300\n");
  fs::permissions(exe, fs::perms::owner_all);
  const std::string file = write("kill_sweep.json", R"({"name": "kill", "scenarios": [")" + kQuickstart + R"("], "seeds": [1]})");
  const auto spec = omniloc::batch::load_sweep(file);
  const pid_t sweep = ::fork();
  ASSERT_GE(sweep, 0);
  if (sweep == 0) {
    omniloc::batch::SweepOptions o;
    o.out_dir = (dir / "out").string();
    o.omniloc_exe = exe;
    (void)omniloc::batch::run_sweep(spec, o);
    ::_exit(0);
  }
  const fs::path pid_file = dir / "child.pid";
  for (int i = 0; i < 200 && !fs::exists(pid_file); ++i) ::usleep(50000);
  ASSERT_TRUE(fs::exists(pid_file)) << "the sweep never started its child";
  const pid_t child = static_cast<pid_t>(std::stol(omniloc::read_file(pid_file.string())));
  ::kill(sweep, SIGKILL);
  ::waitpid(sweep, nullptr, 0);
  // Gone, or a zombie waiting for init to reap it: either way no longer running.
  auto running = [&] {
    std::ifstream stat("/proc/" + std::to_string(child) + "/stat");
    std::string pid, comm, state;
    if (!(stat >> pid >> comm >> state)) return false;
    return state != "Z" && state != "X";
  };
  bool alive = true;
  for (int i = 0; i < 100 && (alive = running()); ++i) ::usleep(50000);
  EXPECT_FALSE(alive) << "child " << child << " outlived its sweep";
  if (alive) ::kill(child, SIGKILL);
}

namespace {

// The hand-written recording (a log not made by omniloc) copied to a scratch folder, with `change`
// applied to frame 3 (or to the header when `header` is set).
std::string handwritten(const std::string& name, const std::function<void(Json&)>& change, bool header = false) {
  const fs::path src = fs::path(omniloc::source_dir().string()) / "tests" / "data" / "handwritten_recording";
  const fs::path dir = scratch(name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  Json head = omniloc::parse_json_strict(omniloc::read_file((src / "recording.json").string()), "recording.json");
  std::istringstream frames(omniloc::read_file((src / "frames.jsonl").string()));
  std::string text, line;
  for (int k = 0; std::getline(frames, line); ++k) {
    if (k == 3 && !header) {
      Json f = omniloc::parse_json_strict(line, "frame");
      change(f);
      line = f.dump();
    }
    text += line + "\n";
  }
  if (header) change(head);
  std::ofstream(dir / "frames.jsonl", std::ios::binary) << text;
  std::ofstream(dir / "recording.json", std::ios::binary) << head.dump(1);
  return dir.string();
}

}  // namespace

// A single line point at -1e308 m in one frame of a recording crashed matching and grid_global
// (SIGSEGV); every number a recording carries is now range-checked where it is read
// (docs/recording.md section 7): exit 2 naming the file, the line and the JSON path, nothing written.
TEST(RobustInput, RecordingNumbersOutsideTheirLimitsAreExit2) {
  const std::vector<std::pair<std::string, Json>> cases = {
      {"/robots/0/line_points/0/0", -1e308}, {"/robots/0/line_points/1/1", 50.5}, {"/robots/0/odometry/0", 1e20},
      {"/robots/0/odometry/2", -1000.5},     {"/robots/0/heading", 1e300},        {"/robots/0/truth/2", 2000.0},
      {"/robots/0/truth/0", -51.0},          {"/t", 3600.5},                      {"/t", -0.5},
      {"/robots/0/camera", Json{{"exposure_ms", 1e9}, {"gain", 1.0}}},             {"/robots/0/camera", Json{{"exposure_ms", 10.0}, {"gain", -1.0}}},
      {"/robots/0/blobs", Json::array({Json{{"colour", "yellow"}, {"kind", "region"}, {"bearing", 0.1}, {"left_bearing", 0.2},
                                            {"right_bearing", 1e9}, {"distance", 3.0}, {"area_px", 40}, {"left_occluded", false},
                                            {"right_occluded", false}}})},
  };
  for (const auto& c : cases) {
    const std::string& path = c.first;  // not a structured binding: clang 14 cannot capture those
    const Json& value = c.second;
    const std::string dir = handwritten("bad_value", [&](Json& f) { f[Json::json_pointer(path)] = value; });
    for (const char* localizer : {"matching", "grid_global", "mcl"}) {
      const fs::path out = scratch("bad_value_out");
      fs::remove_all(out);
      std::string err;
      EXPECT_EQ(cli_run("replay " + dir + " --localizer '{\"type\": \"" + localizer + "\"}' -o " + out.string() + " --quiet", &err), 2)
          << path << " = " << value.dump() << " with " << localizer << ": " << err;
      EXPECT_NE(err.find("frames.jsonl line 4 " + path), std::string::npos)
          << "the error names the file, line and path: " << err;
      EXPECT_FALSE(fs::exists(out)) << "nothing written";
    }
  }
  // Just inside the limits: read, and every localizer survives them.
  const std::string dir = handwritten("edge_values", [](Json& f) {
    f["robots"][0]["line_points"].push_back(Json::array({-50.0, 50.0}));
    f["robots"][0]["heading"] = -1000.0;
    f["robots"][0]["odometry"] = Json::array({50.0, -50.0, 1000.0});
  });
  for (const char* localizer : {"matching", "grid_global", "mcl", "hybrid", "landmarks", "odometry_only"}) {
    std::string err;
    EXPECT_EQ(cli_run("replay " + dir + " --localizer '{\"type\": \"" + localizer + "\"}' -o " + scratch("edge_out").string() + " --overwrite --quiet", &err), 0)
        << localizer << ": " << err;
  }
}

// A recording.json whose `omniloc` block held {"version": 3} ended in a raw
// [json.exception.type_error.302] (exit 1); docs/recording.md says other writers may put anything there.
TEST(RobustInput, AnotherWritersOmnilocBlockIsIgnored) {
  for (const Json& block : {Json{{"version", 3}}, Json(3), Json("x"), Json::array({1}), Json(nullptr), Json{{"build", "mine"}}}) {
    const std::string dir = handwritten("omniloc_block", [&](Json& h) { h["omniloc"] = block; }, true);
    const fs::path out = scratch("omniloc_block_out");
    std::string err;
    ASSERT_EQ(cli_run("replay " + dir + " --localizer '{\"type\": \"matching\"}' -o " + out.string() + " --overwrite --quiet", &err), 0)
        << block.dump() << ": " << err;
    const Json summary = omniloc::parse_json_strict(omniloc::read_file((out / "summary.json").string()), "summary.json");
    EXPECT_EQ(summary["omniloc"]["replay"]["recorded_with"], block.is_object() ? "unknown" : "not omniloc") << block.dump();
  }
}
