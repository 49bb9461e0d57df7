#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <vector>

#include "core/angles.hpp"
#include "core/field.hpp"
#include "core/rng.hpp"
#include "localization/field_map.hpp"
#include "localization/match_data_term.hpp"
#include "localization/matching.hpp"
#include "testing/scenes.hpp"

using namespace omniloc;

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

TEST(FieldMap, WorldAndCellLookupsAgreeAndACopyOwnsItsTable) {
  const Field f = Field::preset("msl2012");
  auto original = std::make_unique<FieldMap>(f, 0.05);
  const FieldMap copy = *original;  // the table points into the copy's own cells
  const FieldMap::Table t = copy.table();
  Rng rng(4);
  std::vector<Eigen::Vector2d> pts;
  for (int i = 0; i < 200; ++i) pts.emplace_back(rng.uniform(-11, 11), rng.uniform(-8, 8));  // some off the table
  std::vector<double> before;
  for (const auto& p : pts) before.push_back(original->distance(p));
  original.reset();
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Vector2d& p = pts[i];
    EXPECT_EQ(copy.distance(p), before[i]);
    Eigen::Vector2d g;
    const double d = copy.distance(p, &g);
    // The cell-unit lookup gives the same distance and the gradient per cell.
    const FieldMap::Sample s = t.at_cells<true>((p.x() - t.x0) * t.inv_cell, (p.y() - t.y0) * t.inv_cell);
    EXPECT_EQ(s.d, d);
    EXPECT_NEAR(s.gx * t.inv_cell, g.x(), 1e-12);
    EXPECT_NEAR(s.gy * t.inv_cell, g.y(), 1e-12);
    // On the table the gradient is that of the interpolant: a central difference over a tenth of a
    // cell agrees (away from cell borders, where the bilinear gradient jumps). Off the table it is
    // the outward direction by design.
    const double h = 0.0025, fx = (p.x() - t.x0) * t.inv_cell, fy = (p.y() - t.y0) * t.inv_cell;
    const double ax = fx - std::floor(fx), ay = fy - std::floor(fy);
    const bool on = fx > 1 && fy > 1 && fx < t.last_x - 1 && fy < t.last_y - 1;
    if (on && ax > 0.1 && ax < 0.9 && ay > 0.1 && ay < 0.9) {
      EXPECT_NEAR((copy.distance(p + Eigen::Vector2d(h, 0)) - copy.distance(p - Eigen::Vector2d(h, 0))) / (2 * h), g.x(), 1e-6);
      EXPECT_NEAR((copy.distance(p + Eigen::Vector2d(0, h)) - copy.distance(p - Eigen::Vector2d(0, h))) / (2 * h), g.y(), 1e-6);
    }
  }
}

// A line point at -1e308 m made -inf cells, a NaN gradient and then a NaN pose, whose lookup
// (std::clamp passes NaN through) indexed far outside the table: SIGSEGV in matching and grid_global.
// Any value now lands on the table; on the table and just off it nothing changes.
TEST(FieldMap, LookupOfAnyValueStaysOnTheTable) {
  const Field f = Field::preset("msl2012");
  const FieldMap m(f, 0.05);
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  for (const double x : {nan, inf, -inf, 1e308, -1e308, -0.0, 0.0, 49.0})
    for (const double y : {nan, inf, -inf, 1e308, -1e308, 0.0, -7.0}) {
      Eigen::Vector2d g;
      const double d = m.distance({x, y}, &g);  // must not crash; NaN in, NaN or a distance out
      if (std::isfinite(x) && std::isfinite(y) && std::fabs(x) < 1e300 && std::fabs(y) < 1e300) {
        EXPECT_TRUE(std::isfinite(d)) << x << ", " << y;
        EXPECT_GE(d, 0.0);
      }
    }
  // Off the table: the border's value plus the distance to it, as before.
  const FieldMap::Table t = m.table();
  EXPECT_DOUBLE_EQ(m.distance({-20, 3}), t.interpolate<false>(0.0, t.cells_y(3)).d + (0.0 - t.cells_x(-20)) * t.cell);
}

TEST(Matching, PointsAtAnyValueNeverCrashTheMatcher) {
  const Field f = Field::preset("msl2012");
  const FieldMap map(f, 0.05);
  Rng rng(3);
  const Pose2 truth(1.0, 0.5, 0.2);
  const auto good = scenes::line_points(f, truth, 80, rng);
  for (const double bad : {-1e308, 1e308, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
    auto pts = good;
    pts[0] = Eigen::Vector2d(bad, 0.5);
    const MatchResult r = rprop_match(map, pts, truth, MatchingParams{}, 20);  // must return, whatever it found
    (void)r;
  }
  // At the reader's limit (50 m, docs/recording.md) the lookup is finite and the match unharmed.
  auto pts = good;
  pts[0] = Eigen::Vector2d(-50.0, 50.0);
  const MatchResult r = rprop_match(map, pts, truth, MatchingParams{}, 20);
  EXPECT_LT(std::hypot(r.pose.x - truth.x, r.pose.y - truth.y), 0.05);
}

TEST(Matching, PairedAndSinglePointDataTermsAgree) {
  // The matcher's data term takes points two at a time (SSE2 lanes) and falls back to one at a time
  // for a pair with a point off the table and for an odd last point: the mean error over a set
  // must equal the mean of the single-point errors (only the order of the sums differs).
  const Field f = Field::preset("msl2012");
  const FieldMap map(f, 0.05);
  Rng rng(5);
  const Pose2 pose(1.5, -2.0, 0.7);
  std::vector<Eigen::Vector2d> pts = scenes::line_points(f, pose, 101, rng);
  pts.emplace_back(20.0, 0.0);  // off the table, in a pair with an on-table point
  pts.emplace_back(0.3, 0.2);
  for (double c : {0.25, 1.0}) {
    double sum = 0;
    for (const auto& p : pts) sum += match_error(map, {p}, pose, c);
    EXPECT_NEAR(match_error(map, pts, pose, c), sum / pts.size(), 1e-13) << "c = " << c;
  }
}

TEST(Matching, WeightedDataTermIsTheWeightedSumOfSinglePoints) {
  // Weights scale each point's term (pairs in SSE2 lanes, the odd point and off-table pairs one at
  // a time); weights of 1 give the unweighted sum's bits.
  const Field f = Field::preset("msl2012");
  const FieldMap map(f, 0.05);
  Rng rng(11);
  const Eigen::Vector3d q(-2.0, 1.0, -0.4);
  std::vector<Eigen::Vector2d> pts = scenes::line_points(f, Pose2(q.x(), q.y(), q.z()), 60, rng);
  pts.emplace_back(20.0, 0.0);
  pts.emplace_back(0.4, -0.1);
  PointWeights w, ones;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    w.w.push_back(rng.uniform(0.1, 2.0));
    w.total += w.w.back();
    ones.w.push_back(1.0);
  }
  ones.total = static_cast<double>(pts.size());
  double sum = 0;
  Eigen::Vector3d gsum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < pts.size(); ++i) {
    Eigen::Vector3d g;
    sum += w.w[i] * match_data_term(map, {pts[i]}, q, 0.25, &g);
    gsum += w.w[i] * g;
  }
  Eigen::Vector3d g;
  EXPECT_NEAR(match_data_term(map, pts, q, 0.25, &g, &w), sum, 1e-12);
  EXPECT_NEAR((g - gsum).norm(), 0.0, 1e-9 * gsum.norm());
  Eigen::Vector3d g1, g0;
  EXPECT_EQ(match_data_term(map, pts, q, 0.25, &g1, &ones), match_data_term(map, pts, q, 0.25, &g0));
  EXPECT_EQ(g1, g0);
}

TEST(Matching, RangeWeightsAreNuBotsAndOneAtTheReferenceRange) {
  MatchingParams p;  // d = 2.5 m, ref = 1.5 m (NuBot, Whites::calculateWeights: 250 cm, 150 cm)
  const PointWeights w = range_weights({{1.5, 0.0}, {0.0, 0.0}, {0.0, -6.0}, {3.0, 4.0}}, p);
  ASSERT_EQ(w.w.size(), 4u);
  EXPECT_DOUBLE_EQ(w.w[0], 1.0);
  EXPECT_DOUBLE_EQ(w.w[1], 8.5 / 6.25);
  EXPECT_DOUBLE_EQ(w.w[2], 8.5 / 42.25);
  EXPECT_DOUBLE_EQ(w.w[3], 8.5 / 31.25);
  EXPECT_DOUBLE_EQ(w.total, w.w[0] + w.w[1] + w.w[2] + w.w[3]);
  p.range_weights = false;
  EXPECT_TRUE(range_weights({{1.0, 0.0}}, p).w.empty());
}

TEST(Matching, TiltCovarianceMatchesTheSpreadOfTiltedMatches) {
  // The covariance's tilt share predicts how far a tilt of the camera moves the matched pose: tilt
  // the exact points of a pose by tau ~ N(0, tilt_sd^2) per axis ((h^2 + r^2) / h per radian,
  // radially), match from the truth, and compare the poses' spread with the predicted one.
  const Field f = Field::preset("msl2012");
  const FieldMap map(f, 0.01);
  Rng rng(17);
  const Pose2 truth(-3.0, 1.5, 0.3);
  std::vector<Eigen::Vector2d> pts = scenes::line_points(f, truth, 200, rng);
  MatchingParams p;
  p.tilt_sd = 0.002;  // moves a point at 6 m by 10 cm: within the robust error's near-quadratic range (c = 25 cm)
  MatchingParams independent = p;
  independent.tilt_sd = 0.0;
  const Eigen::Matrix3d predicted = rprop_match(map, pts, truth, p, 100).covariance - rprop_match(map, pts, truth, independent, 100).covariance;
  Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
  const int n = 200;
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector2d tau(rng.normal(0, p.tilt_sd), rng.normal(0, p.tilt_sd));
    std::vector<Eigen::Vector2d> moved;
    for (const auto& o : pts) moved.push_back(o + o.normalized() * (o.normalized().dot(tau) * (0.75 * 0.75 + o.squaredNorm()) / 0.75));
    const MatchResult r = rprop_match(map, moved, truth, independent, 100);
    const Eigen::Vector3d d(r.pose.x - truth.x, r.pose.y - truth.y, angle_diff(r.pose.theta, truth.theta));
    spread += d * d.transpose() / n;
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_GT(predicted(i, i), 0.0);
    // Linearised against the robust error's full response, and 200 draws (a variance is then good
    // to about 10 %): within 40 %.
    EXPECT_NEAR(std::sqrt(predicted(i, i)), std::sqrt(spread(i, i)), 0.4 * std::sqrt(spread(i, i))) << "axis " << i;
  }
}

TEST(Matching, RpropConvergesFromHalfAMetreAndAThirdOfARadian) {
  const Field f = Field::preset("msl2012");
  const FieldMap map(f, 0.01);
  MatchingParams p;
  p.c_start = 2.0;  // continuation 2 m -> 0.25 m for this large start offset
  Rng rng(7);
  for (int trial = 0; trial < 8; ++trial) {
    const Pose2 truth(rng.uniform(-7, 7), rng.uniform(-4.5, 4.5), rng.uniform(-kPi, kPi));
    const auto pts = scenes::line_points(f, truth, 150, rng);
    const double a = rng.uniform(0, kTwoPi);
    const Pose2 start(truth.x + 0.5 * std::cos(a), truth.y + 0.5 * std::sin(a), truth.theta + (trial % 2 ? 0.3 : -0.3));
    // 120 iterations for this large start offset (tracking uses 10-20 from the prediction).
    const MatchResult r = rprop_match(map, pts, start, p, 120);
    EXPECT_LT(std::hypot(r.pose.x - truth.x, r.pose.y - truth.y), 0.01) << "trial " << trial;
    EXPECT_LT(std::fabs(angle_diff(r.pose.theta, truth.theta)), 0.005) << "trial " << trial;
    EXPECT_LT(r.error, 0.01);
    EXPECT_LT(r.covariance(0, 0), 0.015 * 0.015);  // 150 points, 5 cm noise at weight 1, far ones weigh less
  }
}

TEST(Matching, KalmanFusionBeatsEitherSource) {
  // A robot driving a circle: odometry with drift, matches with 5 cm noise; fused error must be
  // lower than both.
  MatchingParams p;
  Rng rng(3);
  filter::PoseKalman kf;
  Pose2 truth(0, 0, 0), odo_only(0, 0, 0);
  kf.reset(truth, Eigen::Vector3d(1e-4, 1e-4, 1e-4).asDiagonal());
  double e_odo = 0, e_meas = 0, e_fused = 0;
  const int n = 600;
  for (int k = 0; k < n; ++k) {
    const Pose2 step(0.03, 0.0, 0.02);
    truth = truth.compose(step);
    const Pose2 noisy(step.x * (1 + rng.normal(0, 0.05)), rng.normal(0, 0.002), step.theta + rng.normal(0, 0.003));
    odo_only = odo_only.compose(noisy);
    kf.predict(noisy, p.odometry);
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
  EXPECT_EQ(e.mode, LocalizerMode::kCoasting);
  EXPECT_NEAR(e.pose.x, 1.05, 1e-12);
  EXPECT_TRUE(std::isfinite(e.pose.y) && std::isfinite(e.pose.theta) && std::isfinite(e.match_error));
  Observations few;
  few.line_points = {{1, 0}, {2, 0}};
  EXPECT_EQ(loc.update(few, o, std::nullopt).mode, LocalizerMode::kCoasting);
}

// Cold starts (after a kidnap or from the grid search): from the true pose offset by
// (dxy, dxy, dth) with random signs, on random poses of the MSL field with 200 line points (3 cm
// noise), the tracking optimiser (default parameters and initial steps, its own iteration cap, the
// heading prior pulling towards the start as in tracking) must converge.
namespace {
struct ColdStarts {
  double within_5cm = 0;  ///< fraction of the runs ending within 5 cm of the truth
  double median_m = 0;    ///< median position error
  double median_iterations = 0;
};

ColdStarts cold_starts(const FieldMap& map, const Field& f, const MatchingParams& p, double dxy, double dth, int n, Rng& rng) {
  std::vector<double> err, its;
  int good = 0;
  for (int i = 0; i < n; ++i) {
    const Pose2 truth(rng.uniform(-9, 9), rng.uniform(-6, 6), rng.uniform(-kPi, kPi));
    const auto pts = scenes::line_points(f, truth, 200, rng, {.noise = 0.03, .prefilter = &map});
    const auto sign = [&] { return rng.uniform() < 0.5 ? -1.0 : 1.0; };
    const Pose2 start(truth.x + sign() * dxy, truth.y + sign() * dxy, truth.theta + sign() * dth);
    const MatchResult r = rprop_match(map, pts, start, p, p.max_iterations, start.theta);
    const double e = std::hypot(r.pose.x - truth.x, r.pose.y - truth.y);
    err.push_back(e);
    its.push_back(r.iterations);
    good += e < 0.05;
  }
  const auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  return {static_cast<double>(good) / n, median(err), median(its)};
}
}  // namespace

TEST(Matching, ConvergesFromColdStartsOnRandomPoses) {
  // 300 poses each (about 2 s in Release). Measured before commit d1d9692: a fixed 10 iterations gave 33.7 % and
  // a median of 8.4 cm from the far start, median 2.8 cm from the near one; now 100 % and 0.4-0.5 cm (500 poses).
  const Field f = Field::preset("msl2012");
  const MatchingParams p;
  const FieldMap map(f, p.cell);
  Rng rng(17);
  const int n = 300;
  const ColdStarts far = cold_starts(map, f, p, 0.30, 0.15, n, rng);
  const ColdStarts near = cold_starts(map, f, p, 0.10, 0.05, n, rng);
  std::printf("(30 cm, 30 cm, 0.15 rad): %.1f %% within 5 cm, median %.2f cm, %.0f iterations\n", 100 * far.within_5cm, 100 * far.median_m, far.median_iterations);
  std::printf("(10 cm, 10 cm, 0.05 rad): %.1f %% within 5 cm, median %.2f cm, %.0f iterations\n", 100 * near.within_5cm, 100 * near.median_m, near.median_iterations);
  EXPECT_GE(far.within_5cm, 0.99);
  EXPECT_LT(near.median_m, 0.01);
  // Typical runs stop on the step tolerance, not on the cap.
  EXPECT_LT(far.median_iterations, p.max_iterations);
  EXPECT_LT(near.median_iterations, p.max_iterations);
}

TEST(Matching, RemovedIterationKeysAreRejectedWithTheirReplacement) {
  for (const char* key : {"iterations", "iterations_few", "many_points"}) {
    const Json j = {{key, 10}};
    JsonReader r(j, "/localizer");
    EXPECT_THROW(MatchingParams::from_json(r), ConfigError) << key;
  }
  const Json j = {{"max_iterations", 30}, {"step_tol", 0.002}};
  JsonReader r(j, "/localizer");
  const MatchingParams p = MatchingParams::from_json(r);
  EXPECT_EQ(p.max_iterations, 30);
  EXPECT_DOUBLE_EQ(p.step_tol, 0.002);
  EXPECT_DOUBLE_EQ(p.c_start, 2 * p.c);
}
