// Every scenario and sweep shipped in scenarios/ must validate (they are documentation too).
#include <gtest/gtest.h>

#include <filesystem>

#include "core/error.hpp"
#include "harness/scenario.hpp"
#include "harness/sweep.hpp"

namespace fs = std::filesystem;

TEST(ShippedFiles, EveryScenarioAndSweepValidates) {
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(fs::path(OMNILOC_SOURCE_DIR) / "scenarios")) {
    if (e.path().extension() != ".json") continue;
    const bool sweep = e.path().parent_path().filename() == "sweeps";
    try {
      if (sweep)
        omniloc::harness::load_sweep(e.path().string());
      else
        omniloc::harness::load_scenario(e.path().string());
    } catch (const omniloc::ConfigError& err) {
      ADD_FAILURE() << e.path() << ": " << err.what();
    }
    ++n;
  }
  EXPECT_GE(n, 4);
}
