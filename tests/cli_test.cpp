#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/atomic_file.hpp"

// Runs the real omniloc binary (the tests' working directory is the build folder).
namespace {
int run(const std::string& args) {
  const int st = std::system(("./omniloc " + args + " >/dev/null 2>&1").c_str());
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}
const std::string kScenario = std::string(OMNILOC_SOURCE_DIR) + "/scenarios/quickstart.json";
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
