#include <gtest/gtest.h>

#include <cmath>

#include "core/angles.hpp"
#include "core/field.hpp"
#include "core/rng.hpp"
#include "localization/field_map.hpp"
#include "localization/matching.hpp"

using namespace omniloc;

namespace {
// Noise-free line points: samples of the markings within `range` of the pose, in the robot frame.
std::vector<Eigen::Vector2d> line_points(const Field& f, const Pose2& pose, double range, Rng& rng, int n, double noise = 0.0) {
  std::vector<Eigen::Vector2d> pts;
  int guard = 0;
  while (static_cast<int>(pts.size()) < n && ++guard < 2000000) {
    const Eigen::Vector2d w(pose.x + rng.uniform(-range, range), pose.y + rng.uniform(-range, range));
    if ((w - pose.translation()).norm() > range || f.distance_to_marking(w) > 0.004) continue;
    Eigen::Vector2d p = pose.inverse_transform(w);
    if (noise > 0) p += Eigen::Vector2d(rng.normal(0, noise), rng.normal(0, noise));
    pts.push_back(p);
  }
  return pts;
}
}  // namespace

TEST(FieldMap, ExactToHalfACellAgainstTheAnalyticModel) {
  const Field f = Field::preset("msl2012");
  const FieldMap m(f, 0.05);
  Rng rng(1);
  double worst = 0;
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector2d p(rng.uniform(-9.9, 9.9), rng.uniform(-6.9, 6.9));
    worst = std::max(worst, std::fabs(m.distance(p) - f.distance_to_marking(p)));
  }
  EXPECT_LE(worst, 0.025);
  // Off the table: still finite, growing.
  EXPECT_GT(m.distance({30, 0}), m.distance({10, 0}));
  Eigen::Vector2d g;
  m.distance({4.5, -5.7}, &g);  // 0.3 m inside the touch line: the gradient points away from it
  EXPECT_GT(g.y(), 0.9);
}

TEST(Matching, RpropConvergesFromHalfAMetreAndAThirdOfARadian) {
  const Field f = Field::preset("msl2012");
  const FieldMap map(f, 0.01);
  MatchingParams p;
  p.c_start = 2.0;  // continuation 2 m -> 0.25 m for this large start offset
  Rng rng(7);
  for (int trial = 0; trial < 8; ++trial) {
    const Pose2 truth(rng.uniform(-7, 7), rng.uniform(-4.5, 4.5), rng.uniform(-kPi, kPi));
    const auto pts = line_points(f, truth, 6.0, rng, 150);
    const double a = rng.uniform(0, kTwoPi);
    const Pose2 start(truth.x + 0.5 * std::cos(a), truth.y + 0.5 * std::sin(a), truth.theta + (trial % 2 ? 0.3 : -0.3));
    // 120 iterations for this large start offset (tracking uses 10-20 from the prediction).
    const MatchResult r = rprop_match(map, pts, start, p, 120);
    EXPECT_LT(std::hypot(r.pose.x - truth.x, r.pose.y - truth.y), 0.01) << "trial " << trial;
    EXPECT_LT(std::fabs(angle_diff(r.pose.theta, truth.theta)), 0.005) << "trial " << trial;
    EXPECT_LT(r.error, 0.01);
    EXPECT_LT(r.covariance(0, 0), 0.01 * 0.01);
  }
}

TEST(Matching, KalmanFusionBeatsEitherSource) {
  // A robot driving a circle: odometry with drift, matches with 5 cm noise; fused error must be
  // lower than both.
  MatchingParams p;
  Rng rng(3);
  PoseKalman kf;
  Pose2 truth(0, 0, 0), odo_only(0, 0, 0);
  kf.reset(truth, Eigen::Vector3d(1e-4, 1e-4, 1e-4).asDiagonal());
  double e_odo = 0, e_meas = 0, e_fused = 0;
  const int n = 600;
  for (int k = 0; k < n; ++k) {
    const Pose2 step(0.03, 0.0, 0.02);
    truth = truth.compose(step);
    const Pose2 noisy(step.x * (1 + rng.normal(0, 0.05)), rng.normal(0, 0.002), step.theta + rng.normal(0, 0.003));
    odo_only = odo_only.compose(noisy);
    kf.predict(noisy, p);
    const Pose2 z(truth.x + rng.normal(0, 0.05), truth.y + rng.normal(0, 0.05), truth.theta + rng.normal(0, 0.02));
    kf.update(z, Eigen::Vector3d(0.05 * 0.05, 0.05 * 0.05, 0.02 * 0.02).asDiagonal());
    e_odo += std::hypot(odo_only.x - truth.x, odo_only.y - truth.y);
    e_meas += std::hypot(z.x - truth.x, z.y - truth.y);
    e_fused += std::hypot(kf.pose().x - truth.x, kf.pose().y - truth.y);
  }
  EXPECT_LT(e_fused, 0.8 * e_meas);
  EXPECT_LT(e_fused, 0.8 * e_odo);
}

TEST(Matching, NoPointsCoastsOnOdometryWithoutJumpOrNaN) {
  const Field f = Field::preset("msl2012");
  MatchingLocalizer loc(f, MatchingParams{}, "");
  loc.reset(Pose2(1, 1, 0));
  Observations none;
  none.camera_ok = false;
  Odometry o;
  o.delta = Pose2(0.05, 0, 0);
  const Estimate e = loc.update(none, o, std::nullopt);
  EXPECT_EQ(e.mode, "coasting");
  EXPECT_NEAR(e.pose.x, 1.05, 1e-12);
  EXPECT_TRUE(std::isfinite(e.pose.y) && std::isfinite(e.pose.theta) && std::isfinite(e.match_error));
  Observations few;
  few.line_points = {{1, 0}, {2, 0}};
  EXPECT_EQ(loc.update(few, o, std::nullopt).mode, "coasting");
}
