// Scenario test (label "scenario"): matching's accuracy on the paper tracking path under the `robot`
// noise profile, a committed reference that keeps it from drifting back (docs/vision_and_tracking.md
// "Against NuBot's code"). One recording (20 s, seed 1) is replayed by the default matching and by
// the matcher as paper 002 states it (every line point weighs 1: `range_weights` off), so both see
// the same frames.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "harness/recording/recording_writer.hpp"
#include "harness/recording/recording_source.hpp"
#include "harness/recording/replay_scenario.hpp"
#include "harness/runner.hpp"
#include "harness/scenario.hpp"
#include "core/install_paths.hpp"

using namespace omniloc;

namespace {

struct Accuracy {
  double rmse_cm, p95_cm, max_cm, theta_rmse_mrad;
};

Accuracy replay(const std::string& dir, const Json& localizer, const std::string& out) {
  harness::RecordingHeader header = harness::RecordingHeader::read(dir);
  const harness::Scenario s = harness::replay_scenario(header, harness::LocalizerSpec(localizer, "/localizer"));
  harness::RecordingSource source(std::move(header));
  harness::RunOptions o;
  o.seed = source.header().seed;
  o.out_dir = out;
  o.replay = true;
  const auto r = harness::run_frames(s, *o.seed, source, o, Json::object());
  const Json& rob = r.summary["robots"][0];
  return {100 * rob["position_m"]["rmse"].get<double>(), 100 * rob["position_m"]["p95"].get<double>(),
          100 * rob["position_m"]["max"].get<double>(), 1000 * rob["theta_rmse_rad"].get<double>()};
}

}  // namespace

TEST(MatchingAccuracy, RangeWeightsOnThePaperPath) {
  Json j = Json::parse(std::ifstream(std::string(omniloc::source_dir().string()) + "/scenarios/paper/tracking.json"));
  j["duration"] = 20.0;  // four straight lines and three corners
  const auto sc = harness::parse_scenario(j, "tracking_accuracy");
  const auto tmp = std::filesystem::temp_directory_path() / "omniloc_matching_accuracy";
  std::filesystem::remove_all(tmp);
  harness::RecordOptions ro;
  ro.out_dir = (tmp / "recording").string();
  harness::record_scenario(sc, ro);
  const Accuracy now = replay(ro.out_dir, {{"type", "matching"}}, (tmp / "default").string());
  const Accuracy paper =
      replay(ro.out_dir, {{"type", "matching"}, {"range_weights", false}}, (tmp / "unweighted").string());
  std::filesystem::remove_all(tmp);
  // The committed reference: the default measured 4.08 / 6.57 / 10.26 cm, 6.03 mrad (commit c5fed72, GCC 12.2
  // Release, 2-vCPU VM) (rmse / p95 /
  // max cm, heading mrad); the bounds leave 10 % for other compilers and CPUs (the regression test
  // holds the exact bits). The unweighted matcher measured 5.25 / 9.33 / 18.88 cm,
  // 10.24 mrad: the bounds lie between the two.
  EXPECT_LT(now.rmse_cm, 1.1 * 4.08) << "paper-style: " << paper.rmse_cm;
  EXPECT_LT(now.p95_cm, 1.1 * 6.57);
  EXPECT_LT(now.max_cm, 1.1 * 10.26);
  EXPECT_LT(now.theta_rmse_mrad, 1.1 * 6.03);
  // Why the default: far points err most (a pixel and the camera's tilt move them most), and the
  // unweighted matcher lets them set the heading.
  EXPECT_LT(now.rmse_cm, paper.rmse_cm);
  EXPECT_LT(now.theta_rmse_mrad, 0.75 * paper.theta_rmse_mrad);
  std::cout << "default " << now.rmse_cm << " / " << now.p95_cm << " / " << now.max_cm << " cm, " << now.theta_rmse_mrad << " mrad; unweighted "
            << paper.rmse_cm << " / " << paper.p95_cm << " / " << paper.max_cm << " cm, " << paper.theta_rmse_mrad << " mrad\n";
}
