#include <gtest/gtest.h>

#include <cmath>

#include "harness/scoring/metrics.hpp"
#include "harness/scoring/recovery.hpp"

using namespace omniloc;
using namespace omniloc::harness;

namespace {
// 30 Hz frames over [0, 10) s; the estimate is produced by `f(t)` against a fixed truth.
template <class F>
std::vector<ScoredFrame> frames(F f) {
  std::vector<ScoredFrame> v;
  const Pose2 truth(2.0, 1.0, 0.5);
  for (int k = 0; k < 300; ++k) {
    const double t = k / 30.0;
    v.push_back({t, truth, f(t, truth), true});
  }
  return v;
}
}  // namespace

TEST(Recovery, TimeIsMeasuredFromUncoverUntilTheErrorStaysSmall) {
  // Wrong until 4.2 s, right afterwards; uncovered at 3.0 s -> recovery after 1.2 s of vision.
  auto fr = frames([](double t, const Pose2& truth) { return t < 4.2 ? Pose2(-3, 2, 0) : Pose2(truth.x + 0.05, truth.y, truth.theta); });
  const EpisodeResult r = score_episode(fr, {2.0, 3.0, 100.0});
  EXPECT_TRUE(r.recovered);
  EXPECT_NEAR(r.recovery_time, 1.2, 1.0 / 30 + 1e-9);
  EXPECT_TRUE(r.false_recovery);  // it stood behind (-3, 2) for a second: reported, not hidden
  EXPECT_FALSE(r.mirrored);
  ASSERT_FALSE(r.after.empty());
  EXPECT_NEAR(summarize(r.after).x_cm.mean, 5.0, 1e-9);
}

TEST(Recovery, BriefGoodMomentIsNotRecovery) {
  auto fr = frames([](double t, const Pose2& truth) {
    return (t > 4.0 && t < 4.5) ? truth : Pose2(truth.x + 2.0, truth.y, truth.theta);
  });
  EXPECT_FALSE(score_episode(fr, {2.0, 3.0, 100.0}).recovered);
}

TEST(Recovery, MirrorPoseIsFlagged) {
  auto fr = frames([](double, const Pose2& truth) { return Pose2(-truth.x, -truth.y, truth.theta + kPi); });
  const EpisodeResult r = score_episode(fr, {0.0, 0.5, 100.0});
  EXPECT_FALSE(r.recovered);
  EXPECT_TRUE(r.false_recovery);
  EXPECT_TRUE(r.mirrored);
  const Json s = recovery_summary({r});
  EXPECT_EQ(s["mirrored"], 1);
  EXPECT_EQ(s["recovered_fraction"], 0.0);
}

TEST(Recovery, InvalidEstimatesAreNeitherRecoveryNorFalseRecovery) {
  auto fr = frames([](double, const Pose2&) { return Pose2(5, 5, 0); });
  for (auto& f : fr) f.valid = false;
  const EpisodeResult r = score_episode(fr, {0.0, 0.5, 100.0});
  EXPECT_FALSE(r.recovered);
  EXPECT_FALSE(r.false_recovery);
}

TEST(Recovery, TrackingPhaseLeavesOutTheCarriedPeriodAndTheTimeToRecovery) {
  // 2 cm off before the kidnap at 2 s, 3 m off (carried, then searching) until 5 s, 4 cm off after:
  // uncovered at 3 s, recovered at 5 s -> [2, 5) is left out; the tracking phase sees only 2 and 4 cm.
  auto fr = frames([](double t, const Pose2& truth) {
    if (t < 2.0) return Pose2(truth.x + 0.02, truth.y, truth.theta);
    if (t < 5.0) return Pose2(truth.x + 3.0, truth.y, truth.theta);
    return Pose2(truth.x + 0.04, truth.y, truth.theta);
  });
  const PhaseSplit p = split_tracking_phase(fr, {{2.0, 3.0, 100.0}});
  ASSERT_EQ(p.excluded.size(), 1u);
  EXPECT_NEAR(p.excluded[0].first, 2.0, 1e-9);
  EXPECT_NEAR(p.excluded[0].second, 5.0, 1.0 / 30 + 1e-9);
  EXPECT_NEAR(p.excluded_s, 3.0, 1.0 / 30 + 1e-9);
  const ErrorSummary s = summarize(p.tracking);
  EXPECT_EQ(s.frames, 60u + 150u);  // [0, 2) and [5, 10) at 30 Hz
  EXPECT_NEAR(s.x_cm.max, 4.0, 1e-9);
  EXPECT_NEAR(s.x_cm.mean, (60 * 2.0 + 150 * 4.0) / 210.0, 1e-9);
  // All frames would include the 3 m: the headline must not.
  EXPECT_GT(summarize([&] {
              std::vector<FrameError> all;
              for (const auto& f : fr) all.push_back({f.t, f.est.x - f.truth.x, 0.0, 0.0});
              return all;
            }()).x_cm.max, 299.0);
}

TEST(Recovery, TrackingPhaseOfAnEpisodeNeverRecoveredEndsAtTheNextDisruption) {
  // Lost from the kidnap at 2 s to the next kidnap at 6 s; recovered 1 s after the second (uncover 7 s).
  auto fr = frames([](double t, const Pose2& truth) {
    return (t >= 2.0 && t < 8.0) ? Pose2(truth.x + 2.0, truth.y, truth.theta) : truth;
  });
  const PhaseSplit p = split_tracking_phase(fr, {{2.0, 3.0, 6.0}, {6.0, 7.0, 100.0}});
  ASSERT_EQ(p.excluded.size(), 2u);
  EXPECT_NEAR(p.excluded[0].second, 6.0, 1e-9);  // never recovered: up to the episode's end
  EXPECT_NEAR(p.excluded[1].second, 8.0, 1.0 / 30 + 1e-9);
  EXPECT_NEAR(summarize(p.tracking).x_cm.max, 0.0, 1e-12);
  EXPECT_EQ(summarize(p.tracking).frames, 60u + 60u);  // [0, 2) and [8, 10)
}

TEST(Recovery, ExcludedTimeOfAnEpisodeNeverRecoveredEndsWithTheRun) {
  // Lost from the kidnap at 8 s to the end of the frames (9.967 s); the episode's t_end lies past it.
  auto fr = frames([](double t, const Pose2& truth) { return t >= 8.0 ? Pose2(truth.x + 2.0, truth.y, truth.theta) : truth; });
  const PhaseSplit p = split_tracking_phase(fr, {{8.0, 9.0, 11.0}});
  EXPECT_NEAR(p.excluded[0].second, 11.0, 1e-9);
  EXPECT_NEAR(p.excluded_s, 299.0 / 30.0 - 8.0, 1e-9);
  EXPECT_EQ(summarize(p.tracking).frames, 240u);
}

TEST(Metrics, PositionMeanIsTheMeanDistanceNotTheRmse) {
  // Errors of 3-4-5 and 6-8-10 triangles: distances 5 and 10 m. Mean 7.5, RMSE sqrt((25 + 100) / 2).
  const std::vector<FrameError> e = {{0.0, 3.0, 4.0, 0.0}, {0.1, -6.0, 8.0, 0.0}};
  const ErrorSummary s = summarize(e);
  EXPECT_DOUBLE_EQ(s.pos_mean_m, 7.5);
  EXPECT_DOUBLE_EQ(s.pos_rmse_m, std::sqrt(62.5));
  EXPECT_LT(s.pos_mean_m, s.pos_rmse_m);  // the RMSE weighs the larger error more
  EXPECT_DOUBLE_EQ(s.pos_max_m, 10.0);
  const Json j = to_json(s);
  EXPECT_DOUBLE_EQ(j["position_m"]["mean"].get<double>(), 7.5);
  EXPECT_DOUBLE_EQ(j["position_m"]["rmse"].get<double>(), std::sqrt(62.5));
  EXPECT_DOUBLE_EQ(summarize({}).pos_mean_m, 0.0);  // no frames scored: zero, as the other statistics
}
