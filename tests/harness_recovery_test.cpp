#include <gtest/gtest.h>

#include "harness/recovery.hpp"

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
