#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/install_paths.hpp"

// Runs the real omniloc binary (the tests' working directory is the build folder); `out` and `err`
// receive what it printed when given.
namespace {
int run(const std::string& args, std::string* out = nullptr, std::string* err = nullptr) {
  const auto tmp = std::filesystem::temp_directory_path() / ("omniloc_cli_" + std::to_string(::getpid()));
  const std::string o = tmp.string() + ".out", e = tmp.string() + ".err";
  const int st = std::system(("./omniloc " + args + " >" + o + " 2>" + e).c_str());
  if (out) *out = omniloc::read_file(o);
  if (err) *err = omniloc::read_file(e);
  std::filesystem::remove(o);
  std::filesystem::remove(e);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}
const std::string kScenario = std::string(omniloc::source_dir().string()) + "/scenarios/quickstart.json";
}  // namespace

TEST(Cli, ValidateGoodAndBad) {
  EXPECT_EQ(run("validate " + kScenario), 0);
  std::string text = omniloc::read_file(kScenario);
  text.replace(text.find("\"duration\""), 10, "\"duraton\"");
  const auto bad = std::filesystem::temp_directory_path() / "omniloc_cli_bad.json";
  omniloc::write_file_atomic(bad.string(), text);
  EXPECT_EQ(run("validate " + bad.string()), 2);
  const auto out = std::filesystem::temp_directory_path() / "omniloc_cli_out";
  std::filesystem::remove_all(out);
  EXPECT_EQ(run("run " + bad.string() + " -o " + out.string()), 2);
  EXPECT_FALSE(std::filesystem::exists(out)) << "a rejected scenario must write nothing";
}

TEST(Cli, UsageErrorsExitTwo) {
  EXPECT_EQ(run("frobnicate"), 2);
  EXPECT_EQ(run("run"), 2);
  EXPECT_EQ(run("run " + kScenario + " --seed abc"), 2);
  EXPECT_EQ(run("validate /nonexistent.json"), 2);
  EXPECT_EQ(run("list"), 0);
}

// A number option given a word exits 2 before any work, and the message names the option (atoi
// once turned "--robot abc" into robot 0 and "--frames-every abc" into 0). Every option whose value
// is a number in some command's --help must have a case here, so a new one cannot skip the strict parser.
TEST(Cli, EveryNumberOptionRejectsAWordAndNamesIt) {
  const std::string q = kScenario;
  const std::string sweep = std::string(omniloc::source_dir().string()) + "/scenarios/sweeps/odometry_drift.json";
  const auto out = std::filesystem::temp_directory_path() / ("omniloc_cli_numbers_" + std::to_string(::getpid()));
  const std::string o = " -o " + out.string();
  struct Case {
    std::string command, option, args;
  };
  const std::vector<Case> cases = {
      {"run", "--seed", "run " + q + " --seed abc" + o},
      {"run", "--frames-every", "run " + q + " --frames-every abc" + o},
      {"render", "--t", "render " + q + " --t abc -o x.png"},
      {"render", "--robot", "render " + q + " --robot abc -o x.png"},
      {"render", "--seed", "render " + q + " --seed abc -o x.png"},
      {"calibrate", "--seed", "calibrate " + q + " --seed abc" + o},
      {"colour-calibrate", "--seed", "colour-calibrate " + q + " --seed abc" + o},
      {"sweep", "-j", "sweep " + sweep + " -j abc" + o},
      {"sweep", "--shard", "sweep " + sweep + " --shard abc" + o},
      {"sweep", "--stop-after", "sweep " + sweep + " --stop-after abc" + o},
      {"sweep", "--tasks", "sweep " + sweep + " --slurm --dry-run --tasks abc" + o},
      {"sweep", "--cpus-per-task", "sweep " + sweep + " --slurm --dry-run --tasks 2 --cpus-per-task abc" + o},
      {"sweep", "--time", "sweep " + sweep + " --slurm --dry-run --tasks 2 --time abc" + o},
      {"experiment", "--seed", "experiment cooperative_001 --seed abc" + o},
  };
  std::set<std::pair<std::string, std::string>> covered;
  for (const auto& c : cases) {
    std::string err;
    EXPECT_EQ(run(c.args, nullptr, &err), 2) << c.args;
    EXPECT_NE(err.find(c.option), std::string::npos) << c.args << ": the message should name " << c.option << ", got: " << err;
    covered.insert({c.command, c.option});
  }
  EXPECT_FALSE(std::filesystem::exists(out)) << "a rejected command line must write nothing";
  std::filesystem::remove_all(out);
  // The value names the option tables give numbers (apps/main.cpp).
  const std::set<std::string> number_values = {"N", "ID", "SECONDS", "C", "I/N", "HH:MM:SS"};
  for (const char* cmd : {"run", "render", "calibrate", "colour-calibrate", "validate", "list", "sweep", "experiment"}) {
    std::string help;
    ASSERT_EQ(run(std::string(cmd) + " --help", &help), 0) << cmd;
    std::istringstream lines(help);
    for (std::string line; std::getline(lines, line);) {
      std::istringstream words(line);
      std::string name, value;
      if (!(words >> name >> value) || name.rfind("-", 0) != 0 || !number_values.count(value)) continue;
      EXPECT_TRUE(covered.count({cmd, name})) << "omniloc " << cmd << " " << name << " " << value << " has no case above";
    }
  }
}

// No command replaces a user's file or non-empty folder without --overwrite. Each command
// with -o is refused (exit 2, the file untouched, the message naming --overwrite) before any work,
// and does its work when told --overwrite.
TEST(Cli, NoCommandOverwritesWithoutBeingTold) {
  const auto dir = std::filesystem::temp_directory_path() / ("omniloc_cli_overwrite_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "full");
  omniloc::write_file_atomic((dir / "full" / "keep.txt").string(), "mine");
  const std::string file = (dir / "keep.png").string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"render " + kScenario + " --t 0 -o " + file, file},
      {"calibrate " + kScenario + " -o " + file, file},
      {"colour-calibrate " + kScenario + " -o " + file, file},
      {"experiment error_budget --quick -o " + (dir / "full").string(), (dir / "full" / "keep.txt").string()},
  };
  for (const auto& [args, target] : cases) {
    omniloc::write_file_atomic(file, "mine");
    std::string err;
    EXPECT_EQ(run(args, nullptr, &err), 2) << args;
    EXPECT_NE(err.find("--overwrite"), std::string::npos) << args << ": " << err;
    EXPECT_EQ(omniloc::read_file(target), "mine") << args << " touched " << target;
  }
  // Told to: the picture is replaced.
  EXPECT_EQ(run("render " + kScenario + " --t 0 -o " + file + " --overwrite"), 0);
  EXPECT_NE(omniloc::read_file(file), "mine");
  std::filesystem::remove_all(dir);
}

// A relative scenario or sweep path that is not there from the working directory but is a
// shipped file (share_dir(); in a build tree the source tree) is used from there, with a note on
// stderr; a file of that name in the working directory still wins, silently.
TEST(Cli, ShippedInputsAreFoundFromAnyWorkingDirectory) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("omniloc_cli_cwd_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "scenarios");
  const std::string bin = (fs::current_path() / "omniloc").string();
  const auto in_dir = [&](const std::string& args, std::string* err) {
    const std::string e = (dir / "err.txt").string();
    const int st = std::system(("cd " + dir.string() + " && env -u OMNILOC_SHARE_DIR " + bin + " " + args + " >/dev/null 2>" + e).c_str());
    *err = omniloc::read_file(e);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  };
  const fs::path source(omniloc::source_dir().string());
  std::string err;
  EXPECT_EQ(in_dir("validate scenarios/quickstart.json", &err), 0) << err;
  EXPECT_NE(err.find("omniloc: using " + (source / "scenarios/quickstart.json").string()), std::string::npos) << err;
  // A sweep names its scenarios relative to itself, so a shipped sweep works from anywhere too.
  EXPECT_EQ(in_dir("validate scenarios/sweeps/odometry_drift.json", &err), 0) << err;
  EXPECT_NE(err.find("omniloc: using " + (source / "scenarios/sweeps/odometry_drift.json").string()), std::string::npos) << err;
  // Not shipped and not here: the usual error (exit 2), no note.
  EXPECT_EQ(in_dir("run scenarios/no_such_scenario.json", &err), 2) << err;
  EXPECT_EQ(err.find("omniloc: using"), std::string::npos) << err;
  // The working directory's own file wins (here a broken one, so the exit code tells which was read).
  omniloc::write_file_atomic((dir / "scenarios/quickstart.json").string(), "{\"duraton\": 1}");
  EXPECT_EQ(in_dir("validate scenarios/quickstart.json", &err), 2) << err;
  EXPECT_EQ(err.find("omniloc: using"), std::string::npos) << err;
  fs::remove_all(dir);
}
