// localization/filter/: the particle set (N_eff, weights from logs, low-variance resampling), the
// KLD-adaptive sample size (Fox 2003), the odometry motion noise and the pose Kalman filter, each
// against answers worked out by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "core/angles.hpp"
#include "core/json_reader.hpp"
#include "core/rng.hpp"
#include "localization/filter/kld.hpp"
#include "localization/filter/odometry_noise.hpp"
#include "localization/filter/particle_set.hpp"
#include "localization/filter/pose_kalman.hpp"
#include "localization/mcl.hpp"

using namespace omniloc;
using namespace omniloc::filter;

namespace {

// How often each particle was picked by n low-variance pointers.
std::vector<int> low_variance_counts(const std::vector<double>& w, std::size_t n, Rng& rng) {
  LowVarianceSampler s(w, weight_sum(w), n, rng);
  std::vector<int> counts(w.size(), 0);
  for (std::size_t m = 0; m < n; ++m) ++counts[s.index(m)];
  return counts;
}

}  // namespace

TEST(ParticleSet, EffectiveSampleSizeOfUniformIsNOfOneHotIsOne) {
  EXPECT_NEAR(effective_sample_size(std::vector<double>(50, 0.02)), 50.0, 1e-9);
  EXPECT_DOUBLE_EQ(effective_sample_size(std::vector<double>(50, 7.0)), 50.0);  // scale does not matter
  std::vector<double> one_hot(50, 0.0);
  one_hot[17] = 0.3;
  EXPECT_DOUBLE_EQ(effective_sample_size(one_hot), 1.0);
  EXPECT_DOUBLE_EQ(effective_sample_size({1.0, 1.0, 0.0, 0.0}), 2.0);
  // (0.5 + 0.25 + 0.25)^2 / (0.25 + 0.0625 + 0.0625) = 1 / 0.375
  EXPECT_NEAR(effective_sample_size({0.5, 0.25, 0.25}), 1.0 / 0.375, 1e-12);
  EXPECT_EQ(effective_sample_size({}), 0.0);
  EXPECT_EQ(effective_sample_size({0.0, 0.0}), 0.0);
}

TEST(ParticleSet, NormaliseAndWeightsFromLog) {
  std::vector<double> w{1.0, 3.0};
  normalise(w);
  EXPECT_DOUBLE_EQ(w[0], 0.25);
  EXPECT_DOUBLE_EQ(w[1], 0.75);
  std::vector<double> z{0.0, 0.0, 0.0, 0.0};
  normalise(z);
  for (double v : z) EXPECT_DOUBLE_EQ(v, 0.25);

  // Log-likelihoods far below exp's range: the weights keep their ratios instead of all becoming 0.
  std::vector<double> out;
  EXPECT_DOUBLE_EQ(weights_from_log({-1000.0, -1001.0, -1002.0}, out), -1000.0);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_DOUBLE_EQ(out[0], 1.0);
  EXPECT_DOUBLE_EQ(out[1], std::exp(-1.0));
  EXPECT_DOUBLE_EQ(out[2], std::exp(-2.0));
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(std::isfinite(weights_from_log({-inf, -inf}, out)));
  EXPECT_DOUBLE_EQ(out[0], 0.5);
  EXPECT_DOUBLE_EQ(out[1], 0.5);
}

TEST(ParticleSet, LowVarianceResamplingGivesTheExpectedCounts) {
  // Weights 1, 2, 3, 4 (sum 10) and 10 pointers one apart: cumulative 1, 3, 6, 10, so whatever the
  // random offset in (0, 1) each particle is picked exactly w times. Unnormalised on purpose.
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    Rng rng(seed);
    EXPECT_EQ(low_variance_counts({1, 2, 3, 4}, 10, rng), (std::vector<int>{1, 2, 3, 4})) << "seed " << seed;
  }
  // n w / sum not whole: each particle gets floor(n w / sum) or one more, never fewer or two more.
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    Rng rng(seed);
    const std::vector<double> w{0.05, 0.6, 0.3, 0.05};
    const std::vector<int> c = low_variance_counts(w, 7, rng);
    int total = 0;
    for (std::size_t i = 0; i < w.size(); ++i) {
      EXPECT_GE(c[i], static_cast<int>(std::floor(7 * w[i])));
      EXPECT_LE(c[i], static_cast<int>(std::floor(7 * w[i])) + 1);
      total += c[i];
    }
    EXPECT_EQ(total, 7);
  }
  // Zero weights are never picked.
  Rng rng(5);
  EXPECT_EQ(low_variance_counts({0, 1, 0, 1}, 4, rng), (std::vector<int>{0, 2, 0, 2}));
}

TEST(ParticleSet, LowVariancePointersMayBeSkipped) {
  // MCL's random injection replaces some slots; the others keep the particle they had.
  const std::vector<double> w{0.1, 0.4, 0.2, 0.3};
  Rng a(9), b(9);
  LowVarianceSampler all(w, 1.0, 8, a), some(w, 1.0, 8, b);
  std::vector<std::size_t> every;
  for (std::size_t m = 0; m < 8; ++m) every.push_back(all.index(m));
  for (std::size_t m : {1u, 2u, 5u, 7u}) EXPECT_EQ(some.index(m), every[m]) << "pointer " << m;
}

TEST(ParticleSet, SystematicResampleLeavesUniformWeights) {
  ParticleSet<double> s{{10.0, 20.0, 30.0, 40.0}, {0.5, 0.25, 0.125, 0.125}};
  Rng rng(3);
  systematic_resample(s, rng);
  ASSERT_EQ(s.size(), 4u);
  // Pointers u0 + {0, 1/4, 1/2, 3/4} into cumulative 1/2, 3/4, 7/8, 1: two copies of the first, one
  // of the second, and the last pointer lands on the third or the fourth depending on u0.
  EXPECT_EQ(s.x[0], 10.0);
  EXPECT_EQ(s.x[1], 10.0);
  EXPECT_EQ(s.x[2], 20.0);
  EXPECT_TRUE(s.x[3] == 30.0 || s.x[3] == 40.0) << s.x[3];
  for (double v : s.w) EXPECT_DOUBLE_EQ(v, 0.25);
  // Uniform weights: every particle survives once.
  ParticleSet<double> u{{1.0, 2.0, 3.0}, {1.0, 1.0, 1.0}};
  systematic_resample(u, rng);
  EXPECT_EQ(u.x, (std::vector<double>{1.0, 2.0, 3.0}));
}

TEST(Kld, BoundIsFox2003WilsonHilferty) {
  // n = (k - 1) / (2 eps) (1 - 2 / (9 (k - 1)) + sqrt(2 / (9 (k - 1))) z)^3, evaluated by hand:
  // k = 2, eps = 0.05, z = 2.326: 10 * (7/9 + sqrt(2/9) 2.326)^3 = 65.8404...
  EXPECT_NEAR(kld_bound(2, 0.05, 2.326), 65.84044726, 1e-6);
  EXPECT_NEAR(kld_bound(11, 0.05, 2.326), 232.36621804, 1e-6);
  EXPECT_NEAR(kld_bound(101, 0.05, 2.326), 1358.14049627, 1e-6);
  EXPECT_NEAR(kld_bound(11, 0.01, 1.645), 914.63805759, 1e-6);
  // The approximated chi-square quantile against tables: chi2(10 dof, 0.99) = 23.209,
  // chi2(100, 0.99) = 135.807, chi2(10, 0.95) = 18.307; n = chi2 / (2 eps).
  EXPECT_NEAR(kld_bound(11, 0.05, 2.326), 23.209 / 0.1, 0.005 * 232.09);
  EXPECT_NEAR(kld_bound(101, 0.05, 2.326), 135.807 / 0.1, 0.005 * 1358.07);
  EXPECT_NEAR(kld_bound(11, 0.01, 1.645), 18.307 / 0.02, 0.005 * 915.35);
  // More bins need more particles; a tighter epsilon needs more.
  EXPECT_LT(kld_bound(10, 0.05, 2.326), kld_bound(20, 0.05, 2.326));
  EXPECT_LT(kld_bound(10, 0.05, 2.326), kld_bound(10, 0.02, 2.326));
  EXPECT_EQ(kld_bound(1, 0.05, 2.326), 0.0);
  EXPECT_EQ(kld_bound(0, 0.05, 2.326), 0.0);
}

TEST(Kld, HistogramCountsDistinctBins) {
  KldHistogram h(0.5, 0.1745);
  EXPECT_TRUE(h.insert(Pose2(0.1, 0.1, 0.05)));
  EXPECT_FALSE(h.insert(Pose2(0.4, 0.2, 0.1)));   // same 0.5 m cell, same 10 degree bin
  EXPECT_TRUE(h.insert(Pose2(-0.1, 0.1, 0.05)));  // x bin -1: negative bins stay distinct
  EXPECT_TRUE(h.insert(Pose2(0.1, 0.1, 0.2)));    // next heading bin
  EXPECT_TRUE(h.insert(Pose2(0.1, -0.1, -0.05)));
  EXPECT_EQ(h.bins(), 4u);
}

TEST(Kld, TwoBinsStopAtTheBoundOneBinDrawsTheMaximum) {
  // Particles alternate between two bins, equal weights: once both bins are hit k = 2, and the draw
  // stops at the first n >= 65.84, n = 66 (min_particles 1), or at min_particles when that is larger.
  std::vector<Pose2> poses;
  for (int i = 0; i < 600; ++i) poses.push_back(i % 2 ? Pose2(0.1, 0.1, 0.0) : Pose2(3.1, 0.1, 0.0));
  const std::vector<double> w(poses.size(), 1.0);
  const auto pose_of = [&](std::size_t i) -> const Pose2& { return poses[i]; };
  KldParams p;
  p.enabled = true;
  p.min_particles = 1;
  Rng rng(11);
  EXPECT_EQ(kld_resample(w, 600.0, 600, p, pose_of, rng).size(), 66u);
  p.min_particles = 100;
  EXPECT_EQ(kld_resample(w, 600.0, 600, p, pose_of, rng).size(), 100u);
  // One bin: the bound needs k >= 2, so the set keeps its maximum (as amcl).
  for (auto& q : poses) q = Pose2(0.1, 0.1, 0.0);
  EXPECT_EQ(kld_resample(w, 600.0, 600, p, pose_of, rng).size(), 600u);
}

TEST(Kld, CountShrinksWhenParticlesConcentrate) {
  Rng rng(21);
  KldParams p;
  p.enabled = true;
  const auto draw = [&](const std::vector<Pose2>& poses) {
    const std::vector<double> w(poses.size(), 1.0);
    return kld_resample(w, static_cast<double>(poses.size()), 600, p, [&](std::size_t i) -> const Pose2& { return poses[i]; }, rng);
  };
  // Spread over an 18 m x 12 m field with any heading: hundreds of bins, the bound exceeds 600.
  std::vector<Pose2> spread;
  for (int i = 0; i < 600; ++i) spread.emplace_back(rng.uniform(-9.5, 9.5), rng.uniform(-6.5, 6.5), rng.uniform(-kPi, kPi));
  EXPECT_EQ(draw(spread).size(), 600u);
  // Concentrated (10 cm, 0.05 rad): a handful of bins.
  std::vector<Pose2> tight;
  for (int i = 0; i < 600; ++i) tight.emplace_back(1.2 + rng.normal(0, 0.1), -0.7 + rng.normal(0, 0.1), 0.3 + rng.normal(0, 0.05));
  const auto drawn = draw(tight);
  EXPECT_LT(drawn.size(), 400u);
  EXPECT_GE(drawn.size(), static_cast<std::size_t>(p.min_particles));
  // The stopping rule, replayed: n is the first count reaching both the minimum and the bound.
  KldHistogram h(p.bin_xy, p.bin_theta);
  for (std::size_t m = 0; m < drawn.size(); ++m) {
    h.insert(tight[drawn[m]]);
    const bool done = h.bins() > 1 && m + 1 >= static_cast<std::size_t>(p.min_particles) &&
                      static_cast<double>(m + 1) >= kld_bound(h.bins(), p.epsilon, p.z);
    EXPECT_EQ(done, m + 1 == drawn.size()) << "draw " << m + 1 << ", bins " << h.bins();
  }
}

TEST(OdometryNoise, SigmasGrowWithTheMotion) {
  const OdometryNoiseParams p{0.1, 0.2, 0.05, 0.01, 0.02};
  const OdometrySigmas s = odometry_sigmas(Pose2(0.3, 0.4, 0.5), p);  // 0.5 m, 0.5 rad
  EXPECT_NEAR(s.xy, 0.1 * 0.5 + 0.01, 1e-15);
  EXPECT_NEAR(s.theta, 0.2 * 0.5 + 0.05 * 0.5 + 0.02, 1e-15);
  const OdometrySigmas still = odometry_sigmas(Pose2(), p);
  EXPECT_DOUBLE_EQ(still.xy, 0.01);
  EXPECT_DOUBLE_EQ(still.theta, 0.02);
}

TEST(OdometryNoise, PerturbHasTheGivenSpread) {
  Rng rng(4);
  const Pose2 q(1.0, -2.0, 0.5);
  const OdometrySigmas s{0.03, 0.02};
  double sx = 0, sy = 0, st = 0, sxx = 0, syy = 0, stt = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const Pose2 r = perturb(q, s, rng);
    const double dx = r.x - q.x, dy = r.y - q.y, dt = angle_diff(r.theta, q.theta);
    sx += dx, sy += dy, st += dt, sxx += dx * dx, syy += dy * dy, stt += dt * dt;
  }
  EXPECT_NEAR(sx / n, 0.0, 0.001);
  EXPECT_NEAR(sy / n, 0.0, 0.001);
  EXPECT_NEAR(st / n, 0.0, 0.001);
  EXPECT_NEAR(std::sqrt(sxx / n), 0.03, 0.001);
  EXPECT_NEAR(std::sqrt(syy / n), 0.03, 0.001);
  EXPECT_NEAR(std::sqrt(stt / n), 0.02, 0.001);
}

TEST(OdometryNoise, JsonKeysStayThoseOfEachLocalizer) {
  // Matching reads odo_rot_per_m, MCL does not (its effective config keeps its four keys).
  const Json j = Json::parse(R"({"odo_trans_frac": 0.2, "odo_rot_per_m": 0.1})");
  Json eff;
  JsonReader r(j, "/localizer", &eff);
  const OdometryNoiseParams d{0.05, 0.05, 0.02, 0.002, 0.002};
  const OdometryNoiseParams p = OdometryNoiseParams::from_json(r, d, OdometryNoiseParams::Keys::WithRotPerMetre);
  r.finish();
  EXPECT_EQ(p.trans_frac, 0.2);
  EXPECT_EQ(p.rot_per_m, 0.1);
  EXPECT_EQ(p.floor_xy, 0.002);
  EXPECT_EQ(eff.size(), 5u);
  EXPECT_TRUE(eff.contains("odo_floor_theta"));

  Json eff_mcl;
  JsonReader planar(j, "/localizer", &eff_mcl);
  const OdometryNoiseParams q = OdometryNoiseParams::from_json(planar, McLParams{}.odometry, OdometryNoiseParams::Keys::Planar);
  EXPECT_EQ(q.rot_per_m, 0.0);
  EXPECT_EQ(eff_mcl.size(), 4u);
  EXPECT_FALSE(eff_mcl.contains("odo_rot_per_m"));
  EXPECT_THROW(planar.finish(), ConfigError);  // odo_rot_per_m is not an MCL key
}

TEST(PoseKalman, PredictAndUpdateGiveTheHandWorkedResult) {
  // P = 0.01 I at the origin, heading 0; move 1 m forward without process noise:
  // F = [1 0 0; 0 1 1; 0 0 1], P' = F P F^T = [0.01 0 0; 0 0.02 0.01; 0 0.01 0.01].
  PoseKalman kf;
  kf.reset(Pose2(0, 0, 0), Eigen::Matrix3d::Identity() * 0.01);
  kf.predict(Pose2(1, 0, 0), OdometryNoiseParams{});
  EXPECT_DOUBLE_EQ(kf.pose().x, 1.0);
  Eigen::Matrix3d want;
  want << 0.01, 0, 0, 0, 0.02, 0.01, 0, 0.01, 0.01;
  EXPECT_TRUE(kf.covariance().isApprox(want, 1e-12)) << kf.covariance();
  // Measure (1, 0.1, 0) with R = 0.01 I. x: K = 0.5. (y, theta): S = [0.03 0.01; 0.01 0.02],
  // K = P S^-1 = [0.6 0.2; 0.2 0.4]; innovation (0.1, 0) moves y by 0.06 and theta by 0.02;
  // P = (I - K) P = [0.006 0.002; 0.002 0.004], and 0.005 for x.
  kf.update(Pose2(1, 0.1, 0), Eigen::Matrix3d::Identity() * 0.01);
  EXPECT_NEAR(kf.pose().x, 1.0, 1e-12);
  EXPECT_NEAR(kf.pose().y, 0.06, 1e-12);
  EXPECT_NEAR(kf.pose().theta, 0.02, 1e-12);
  want << 0.005, 0, 0, 0, 0.006, 0.002, 0, 0.002, 0.004;
  EXPECT_TRUE(kf.covariance().isApprox(want, 1e-9)) << kf.covariance();
}

TEST(PoseKalman, PredictAddsTheOdometryNoise) {
  // Heading pi/2: 1 m forward goes to +y. Q = diag(0.052^2, 0.052^2, 0.047^2) from
  // sigma_xy = 0.05 * 1 + 0.002, sigma_theta = 0.05 * 0.5 + 0.02 * 1 + 0.002.
  PoseKalman kf;
  kf.reset(Pose2(0, 0, kPi / 2), Eigen::Matrix3d::Zero());
  kf.predict(Pose2(1, 0, 0.5), OdometryNoiseParams{0.05, 0.05, 0.02, 0.002, 0.002});
  EXPECT_NEAR(kf.pose().x, 0.0, 1e-12);
  EXPECT_NEAR(kf.pose().y, 1.0, 1e-12);
  EXPECT_NEAR(kf.pose().theta, kPi / 2 + 0.5, 1e-12);
  const Eigen::Matrix3d want = Eigen::Vector3d(0.052 * 0.052, 0.052 * 0.052, 0.047 * 0.047).asDiagonal();
  EXPECT_TRUE(kf.covariance().isApprox(want, 1e-12)) << kf.covariance();
  // A heading measurement across +-pi is wrapped, not taken the long way round.
  kf.reset(Pose2(0, 0, kPi - 0.01), Eigen::Matrix3d::Identity() * 0.01);
  kf.update(Pose2(0, 0, -kPi + 0.01), Eigen::Matrix3d::Identity() * 0.01);
  EXPECT_NEAR(std::fabs(kf.pose().theta), kPi, 1e-9);
}
