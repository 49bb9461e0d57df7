// Scenario test (label "scenario"): the modern reference localizer `ukf_mh` on the shipped CI
// recordings of paper 002's tracking path (data/recordings/ci_tracking, seeds 1-5, 10 s each, robot
// noise profile), beside `matching` on the same frames. No frame is drawn: replays only.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <iostream>

#include "core/install_paths.hpp"
#include "harness/recording/recording_source.hpp"
#include "harness/recording/replay_scenario.hpp"
#include "harness/runner.hpp"
#include "harness/scenario.hpp"

using namespace omniloc;

namespace {

Json replay(const std::string& dir, const Json& localizer, const std::string& out) {
  harness::RecordingHeader header = harness::RecordingHeader::read(dir);
  const harness::Scenario s = harness::replay_scenario(header, harness::LocalizerSpec(localizer, "--localizer"));
  harness::RecordingSource source(std::move(header));
  harness::RunOptions o;
  o.seed = source.header().seed;
  o.out_dir = out;
  o.replay = true;
  const auto r = harness::run_frames(s, *o.seed, source, o, Json::object());
  return r.summary["robots"][0];
}

}  // namespace

TEST(ModernLocalizer, TrackingPathAgainstMatchingAndTheLatencyBound) {
  const auto tmp = std::filesystem::temp_directory_path() / "omniloc_modern_localizer";
  std::filesystem::remove_all(tmp);
  double sq_ukf = 0, sq_unknown = 0, sq_matching = 0;
  for (int seed = 1; seed <= 5; ++seed) {
    const std::string rec = std::string(omniloc::source_dir().string()) + "/data/recordings/ci_tracking/" + std::to_string(seed);
    const Json ukf = replay(rec, {{"type", "ukf_mh"}}, (tmp / ("ukf" + std::to_string(seed))).string());
    const Json unknown = replay(rec, {{"type", "ukf_mh"}, {"latency", 0.0}}, (tmp / ("lat0_" + std::to_string(seed))).string());
    const Json matching = replay(rec, {{"type", "matching"}}, (tmp / ("m" + std::to_string(seed))).string());
    // Global start: right (25 cm / 10 deg) within 1 s of the first frame, never valid while wrong.
    ASSERT_TRUE(ukf["first_within_s"].is_number()) << seed;
    EXPECT_LE(ukf["first_within_s"].get<double>(), 1.0) << seed;
    EXPECT_EQ(ukf["wrong_frames"].get<int>(), 0) << seed;
    // By default ukf_mh knows the camera's declared latency (the recorded scenario's robot profile:
    // 33 ms), so the lag is gone and what is left is the per-frame camera vibration (0.3 deg: about
    // 3 cm of common shift of a frame's points at 3 m from a 0.75 m viewpoint), which a filter over
    // frames must average below one frame's: RMSE < 3 cm on every seed (measured 1.7-2.5 cm).
    EXPECT_LT(ukf["position_m"]["rmse"].get<double>(), 0.03) << seed;
    const double r_ukf = ukf["position_m"]["rmse"].get<double>(), r_0 = unknown["position_m"]["rmse"].get<double>(),
                 r_m = matching["position_m"]["rmse"].get<double>();
    sq_ukf += r_ukf * r_ukf;
    sq_unknown += r_0 * r_0;
    sq_matching += r_m * r_m;
    std::cout << "seed " << seed << ": ukf_mh " << 100 * r_ukf << " cm (latency 0: " << 100 * r_0 << " cm), matching " << 100 * r_m << " cm\n";
  }
  std::filesystem::remove_all(tmp);
  // The requirement: at most 0.8 x matching's position RMSE on the same frames (measured 0.48 x).
  EXPECT_LT(std::sqrt(sq_ukf / 5), 0.8 * std::sqrt(sq_matching / 5));
  // Told latency 0, both carry the same 3.3 cm lag (33 ms at 1 m/s; docs/error_budget.md: 3.05 cm
  // RMSE from latency alone with matching), so the gain over matching is what the multi-frame
  // filter and the exact marking geometry remove of the rest: at least 10 % over the five seeds
  // (measured 0.85 x).
  EXPECT_LT(std::sqrt(sq_unknown / 5), 0.9 * std::sqrt(sq_matching / 5));
}
