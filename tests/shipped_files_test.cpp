// Every scenario, sweep and experiment description shipped in scenarios/ must validate (they are
// documentation too).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>

#include "core/error.hpp"
#include "core/json_reader.hpp"
#include "experiments/experiment.hpp"
#include "harness/scenario.hpp"
#include "batch/sweep.hpp"
#include "core/install_paths.hpp"

namespace fs = std::filesystem;

TEST(ShippedFiles, EveryScenarioAndSweepValidates) {
  // As users run them: from the repository root (relative paths in scenario files, such as an
  // external localizer's command, are taken against omniloc's working directory; docs/protocol.md).
  const fs::path before = fs::current_path();
  fs::current_path(omniloc::source_dir().string());
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(fs::path(omniloc::source_dir().string()) / "scenarios")) {
    if (e.path().extension() != ".json") continue;
    const bool sweep = e.path().parent_path().filename() == "sweeps";
    const bool experiment = e.path().parent_path().filename() == "experiments";
    try {
      if (sweep) {
        omniloc::batch::load_sweep(e.path().string());
      } else if (experiment) {
        // An experiment's description file: validated by the experiment named in its "experiment" key.
        std::ifstream in(e.path());
        const omniloc::Json j = omniloc::Json::parse(in, nullptr, false);
        const std::string name = j.is_object() && j.contains("experiment") && j["experiment"].is_string() ? j["experiment"].get<std::string>() : "";
        bool found = false;
        for (const auto& x : omniloc::experiments::all())
          if (x.name == name && x.validate) {
            x.validate(e.path().string());
            found = true;
          }
        if (!found) ADD_FAILURE() << e.path() << ": no experiment \"" << name << "\" that validates description files";
      } else {
        omniloc::harness::load_scenario(e.path().string());
      }
    } catch (const omniloc::ConfigError& err) {
      ADD_FAILURE() << e.path() << ": " << err.what();
    }
    ++n;
  }
  EXPECT_GE(n, 4);
  fs::current_path(before);
}

// The default main job runs scenarios/sweeps/paper_suite.json: every paper scenario must be in it,
// and every published row's variant (occlusion fractions, auto-adjust off, other localizers) with it.
TEST(ShippedFiles, PaperSuiteRunsEveryPaperScenario) {
  const auto spec = omniloc::batch::load_sweep(std::string(omniloc::source_dir().string()) + "/scenarios/sweeps/paper_suite.json");
  std::set<std::string> in_suite;
  for (const auto& r : spec.runs) in_suite.insert(r.scenario_name);
  for (const auto& e : fs::directory_iterator(fs::path(omniloc::source_dir().string()) / "scenarios" / "paper")) {
    if (e.path().extension() != ".json") continue;
    EXPECT_TRUE(in_suite.count(e.path().stem().string())) << e.path() << " is not in the paper suite";
  }
  std::set<std::string> seeds;
  for (const auto& r : spec.runs) seeds.insert(std::to_string(r.seed));
  EXPECT_GE(seeds.size(), 3u) << "intervals need at least two seeds; the suite promises three";
}
