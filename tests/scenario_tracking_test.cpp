// Scenario test (label "scenario"): the paper tracking path from rendered images with ideal noise.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "harness/runner.hpp"
#include "harness/scenario.hpp"
#include "core/install_paths.hpp"

using namespace omniloc;

TEST(ScenarioTracking, IdealNoiseTracksUnder2cm) {
  Json j = Json::parse(std::ifstream(std::string(omniloc::source_dir().string()) + "/scenarios/paper/tracking.json"));
  j["noise_profile"] = "ideal";
  j["duration"] = 15.0;  // the first two straight lines and a corner
  const auto s = harness::parse_scenario(j, "tracking_ideal");
  harness::RunOptions o;
  o.out_dir = (std::filesystem::temp_directory_path() / "omniloc_tracking_ideal").string();
  const auto r = harness::run_scenario(s, o);
  ASSERT_EQ(r.robots.size(), 1u);
  const auto& e = r.robots[0].all;
  EXPECT_EQ(r.robots[0].valid_frames, r.robots[0].frames);
  const double mean_pos_cm = std::hypot(e.x_cm.mean, e.y_cm.mean);
  EXPECT_LT(mean_pos_cm, 2.0) << r.table;
  EXPECT_LT(e.theta_rad.mean, 0.02) << r.table;
}
