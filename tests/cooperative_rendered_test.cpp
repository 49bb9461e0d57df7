// The rendered-image mode of the paper-001 simulation (experiments/cooperative_001_rendered.*):
// the ball measured in a rendered panorama, and the determinism of the mode under a seed.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/angles.hpp"
#include "core/error.hpp"
#include "core/rng.hpp"
#include "experiments/cooperative_001.hpp"
#include "harness/vision_setup.hpp"
#include "localization/vision/blobs.hpp"
#include "sim/render/panoramic_camera.hpp"

using namespace omniloc;
namespace fs = std::filesystem;

namespace {

Json shipped() {
  std::ifstream in(experiments::cooperative_001_default_file());
  return Json::parse(in);
}

std::string parse_error_path(const Json& j) {
  try {
    experiments::parse_cooperative_001(j);
  } catch (const ConfigError& e) {
    return e.path();
  }
  ADD_FAILURE() << "no ConfigError";
  return "";
}

}  // namespace

TEST(CoopRendered, BallCentreDistanceGeometry) {
  // A ball of radius r right below the tangent construction: with h = r the steepest ray touching the
  // ball is horizontal only at infinity; check the closed form against a direct construction instead.
  const double h = 0.75, r = 0.11;
  for (double D : {0.5, 1.0, 2.0, 4.0}) {
    // Steepest ray from (0, h) touching the ball centred at (D, r): depression alpha + beta.
    const double dist = std::hypot(D, h - r);
    const double ang = std::atan2(h - r, D) + std::asin(r / dist);
    const double d = h / std::tan(ang);  // where it meets the floor
    EXPECT_LT(d, D);
    EXPECT_NEAR(experiments::ball_centre_distance(d, h, r), D, 1e-12) << D;
  }
  EXPECT_NEAR(experiments::ball_centre_distance(2.0, 0.75, 0.0), 2.0, 1e-15);
}

TEST(CoopRendered, ConfigErrorsNameTheirPath) {
  {
    Json j = shipped();
    j["rendered"]["trials"] = 0;
    EXPECT_EQ(parse_error_path(j), "/rendered/trials");
  }
  {
    Json j = shipped();
    j["rendered"]["field"]["length"] = 8.0;
    EXPECT_EQ(parse_error_path(j), "/rendered/field/length");
  }
  {
    Json j = shipped();
    j["rendered"]["camera"]["width"] = -3;
    EXPECT_EQ(parse_error_path(j), "/rendered/camera/width");
  }
  {
    Json j = shipped();
    j["rendered"]["self_localisation"]["localizer"]["type"] = "magic";
    EXPECT_EQ(parse_error_path(j), "/rendered/self_localisation/localizer/type");
  }
  {
    Json j = shipped();
    j["rendered"]["headings_deg"] = {0, 1};
    EXPECT_EQ(parse_error_path(j), "/rendered/headings_deg");
  }
  {
    Json j = shipped();
    j["rendered"]["bogus"] = 1;
    EXPECT_EQ(parse_error_path(j), "/rendered/bogus");
  }
  const auto c = experiments::parse_cooperative_001(shipped());
  ASSERT_TRUE(c.rendered.has_value());
  EXPECT_DOUBLE_EQ(c.rendered->field.length, 6.0);
  EXPECT_DOUBLE_EQ(c.rendered->field.width, 4.0);
  EXPECT_EQ(c.rendered->pose_source, experiments::CoopPoseSource::Matching);
}

// One robot alone on the paper's 6 m x 4 m field, the ball at known robot-frame positions; default
// camera (vibration and pixel noise on), calibration map and colour table from vision_setup.
TEST(CoopRendered, SingleFrameBearingAndDistance) {
  const auto c = experiments::parse_cooperative_001(shipped());
  const auto& g = *c.rendered;
  sim::PanoramicCamera cam(g.camera, g.field);
  const CalibrationMap map = harness::calibration_for(g.camera, "auto", 1);
  const ColourTable table = harness::colour_table_for(g.camera, g.field, "auto", 1);
  BlobParams bp;
  bp.colours = {kBallOrange};
  bp.min_area_px = g.min_area_px;
  const BlobDetector det(bp, map, table);
  Rng rng(12345);
  // Field frame (origin at the centre of the 6 m x 4 m field). Ball positions inside the field lines,
  // clear of the goals, from 0.8 m to 3.8 m away, all round the robot.
  const Pose2 robot(-1.2, -0.5, 0.4);
  const Eigen::Vector2d balls[] = {{-0.4, -0.5}, {-1.2, 0.6}, {-2.4, -1.2}, {-1.5, -1.7}, {0.8, 0.5}, {1.8, -1.2}, {-0.2, 1.6}, {2.5, 0.4}};
  double worst_b = 0, worst_d = 0;
  for (const Eigen::Vector2d& ball : balls) {
      const Eigen::Vector2d rel = robot.inverse_transform(ball);
      const double D = rel.norm(), beta = std::atan2(rel.y(), rel.x());
      sim::WorldState w;
      sim::RobotState r;
      r.id = 0;
      r.pose = robot;
      w.robots.push_back(r);
      w.ball.position = ball;
      w.ball.radius = g.ball_radius;
      const Image img = cam.render(w, 0, g.camera.initial, rng);
      const auto s = experiments::ball_sighting_from_blobs(det.detect(img), g.min_area_px, g.camera.mount_height, g.ball_radius);
      ASSERT_TRUE(s.seen) << D << " " << beta;
      ASSERT_TRUE(s.has_distance) << D << " " << beta;
      const double be = std::abs(wrap_angle(s.bearing - beta)), de = s.distance - D;
      std::printf("D %.2f m beta %+.2f rad: bearing error %.3f deg, distance error %+.1f mm (contact %+.1f mm), %d px\n", D, beta,
                  be * 180.0 / kPi, 1000 * de, 1000 * (s.contact_distance - D), s.area_px);
      worst_b = std::max(worst_b, be);
      worst_d = std::max(worst_d, std::abs(de) / D);
      EXPECT_LT(be, 1.0 * kPi / 180.0) << D << " " << beta;
      EXPECT_LT(std::abs(de), 0.03 * D + 0.02) << D << " " << beta;
  }
  std::printf("worst bearing error %.3f deg, worst relative distance error %.2f %%\n", worst_b * 180.0 / kPi, 100 * worst_d);
}

// The rendered mode under a seed: two quick runs give the same numbers. A shortened path (5 ball
// positions, 0.2 m) and few self-localisation frames keep the test short; everything else is the
// shipped set-up (five robots, default camera with vibration and pixel noise, matching localizer).
TEST(CoopRendered, QuickRunIsDeterministicUnderASeed) {
  Json cfg = shipped();
  cfg["ball"]["end"] = {3.12, 3.04};  // 0.2 m along the paper's path direction (0.6, -0.8)
  cfg["quick_trials"] = {{"path", 2}, {"per_subset", 1}, {"tracking", 1}, {"growth_model", 2}};
  cfg["rendered"]["quick_trials"] = 1;
  cfg["rendered"]["self_localisation"]["frames"] = 4;
  cfg["rendered"]["tracking_repeats"] = 2;
  const fs::path d = fs::temp_directory_path() / ("omniloc_coop_rendered_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  fs::remove_all(d);
  fs::create_directories(d);
  std::ofstream(d / "description.json") << cfg.dump(1);
  auto run = [&](const std::string& name, std::uint64_t seed) {
    experiments::ExperimentArgs a;
    a.seed = seed;
    a.quick = true;
    a.config = (d / "description.json").string();
    a.out_dir = (d / name).string();
    std::ostringstream out;
    EXPECT_EQ(experiments::run_cooperative_001(a, out), 0);
    std::ifstream in(d / name / "cooperative_001.json");
    Json j = Json::parse(in)["rendered"];
    // Timings differ between runs; everything else must not.
    for (const char* k : {"elapsed_s", "render_ms_per_frame"}) j.erase(k);
    std::ifstream csv(d / name / "robots_vs_error_rendered.csv");
    std::stringstream ss;
    ss << csv.rdbuf();
    return std::make_pair(j, ss.str());
  };
  const auto t0 = std::chrono::steady_clock::now();
  const auto [a, a_csv] = run("a", 7);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto [b, b_csv] = run("b", 7);
  ASSERT_TRUE(a.is_object());
  EXPECT_EQ(a, b);
  EXPECT_EQ(a_csv, b_csv);
  EXPECT_EQ(a["sightings"]["total"].get<int>(), 5 * 5);
  EXPECT_GT(a["sightings"]["usable"].get<int>(), 15);
  // Sanity of the numbers, not a calibration: fixes from five cameras within 0.2 m on average.
  EXPECT_LT(a["weighted"]["mean_mm"].get<double>(), 200.0);
  EXPECT_LT(a["self_localisation"]["position_error_mean_mm"].get<double>(), 150.0);
  std::printf("one shortened rendered quick run: %.1f s\n", secs);
  // Another seed: other image noise and other starts, so other numbers.
  const auto [c, c_csv] = run("c", 8);
  EXPECT_NE(a["self_localisation"], c["self_localisation"]);
  fs::remove_all(d);
}
