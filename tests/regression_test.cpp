// Regression gates: every scenario in scenarios/regression/ must reproduce the summary committed in
// results/reference/regression/ byte for byte. A deliberate change is made with
// scripts/update_reference.sh and shows in the diff.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "core/atomic_file.hpp"
#include "harness/runner.hpp"
#include "harness/scenario.hpp"
#include "core/install_paths.hpp"

using namespace omniloc;
namespace fs = std::filesystem;

TEST(Regression, SummariesMatchTheCommittedReference) {
  // The references are OSMesa's bytes; a GPU draws other pixels (docs/camera.md "GPUs"), so a
  // sweep-wide OMNILOC_GL_BACKEND=egl in the environment must not reach the gate.
  ::unsetenv("OMNILOC_GL_BACKEND");
  const fs::path dir = fs::path(omniloc::source_dir().string()) / "scenarios" / "regression";
  int checked = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".json") continue;
    const std::string name = e.path().stem().string();
    const fs::path ref = fs::path(omniloc::source_dir().string()) / "results" / "reference" / "regression" / (name + ".summary.json");
    ASSERT_TRUE(fs::exists(ref)) << "no committed reference for " << name << " (run scripts/update_reference.sh)";
    const auto s = harness::load_scenario(e.path().string());
    harness::RunOptions o;
    o.out_dir = (fs::temp_directory_path() / ("omniloc_regression_" + name)).string();
    harness::run_scenario(s, o);
    // Everything but the provenance block ("omniloc": version, compiler), which names the build.
    Json got = Json::parse(read_file(o.out_dir + "/summary.json"));
    ASSERT_TRUE(got.contains("omniloc")) << "summary.json must record the build that made it";
    got.erase("omniloc");
    EXPECT_EQ(got.dump(2) + "\n", read_file(ref.string()))
        << name << ": the numbers moved. If that is deliberate, run scripts/update_reference.sh and commit the diff.";
    ++checked;
  }
  EXPECT_GT(checked, 0);
}
