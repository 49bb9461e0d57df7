// The modern reference localizer (localization/modern/): its parts against known answers.
#include <gtest/gtest.h>

#include <cmath>

#include <Eigen/Dense>

#include "core/field.hpp"
#include "core/floor_tilt.hpp"
#include "core/rng.hpp"
#include "harness/external_session.hpp"
#include "harness/localizer_registry.hpp"
#include "harness/scenario.hpp"
#include "localization/field_map.hpp"
#include "localization/modern/alternative_poses.hpp"
#include "localization/modern/hypothesis_set.hpp"
#include "localization/modern/marking_association.hpp"
#include "localization/modern/ukf_mh.hpp"
#include "localization/modern/ukf_pose.hpp"
#include "testing/scenes.hpp"

using namespace omniloc;
using namespace omniloc::modern;

namespace {

Eigen::Matrix3d spd(double a, double b, double c, double ab, double ac, double bc) {
  Eigen::Matrix3d p;
  p << a, ab, ac, ab, b, bc, ac, bc, c;
  return p;
}

}  // namespace

// On linear measurements the sigma-point update is the Kalman filter's: x+ = x + K (z - H x),
// P+ = (I - K H) P with K = P H^T (H P H^T + R)^-1, for two scalar measurements at once.
TEST(UkfPose, LinearUpdateEqualsKalmanFilter) {
  const Eigen::Vector3d x0(1.0, -2.0, 0.3);
  const Eigen::Matrix3d p0 = spd(0.04, 0.09, 0.01, 0.01, 0.002, -0.003);
  Eigen::Matrix<double, 2, 3> h;
  h << 1.0, 0.5, -2.0, 0.0, 1.0, 3.0;
  const Eigen::Vector2d z(1.2, -1.0), r(0.01, 0.02);
  UkfPose ukf;
  ukf.reset(Pose2(x0.x(), x0.y(), x0.z()), p0);
  const auto linearise = [&](const Eigen::Vector3d&, const SigmaPoints& sp, InformationSum& sum) {
    for (int m = 0; m < 2; ++m) {
      std::array<double, 6> v{};
      for (int s = 0; s < 6; ++s) v[static_cast<std::size_t>(s)] = h.row(m).dot(sp[s]);
      sp.add(v, sp.predict(v), z[m], r[m], sum);
    }
  };
  ukf.update(linearise, 1, Eigen::Matrix3d::Zero());
  const Eigen::Matrix2d s = h * p0 * h.transpose() + Eigen::Matrix2d(r.asDiagonal());
  const Eigen::Matrix<double, 3, 2> k = p0 * h.transpose() * s.inverse();
  const Eigen::Vector3d x1 = x0 + k * (z - h * x0);
  const Eigen::Matrix3d p1 = (Eigen::Matrix3d::Identity() - k * h) * p0;
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(ukf.mean()[i], x1[i], 1e-9) << i;
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(ukf.covariance()(i, j), p1(i, j), 1e-9) << i << "," << j;
  }
  // Iterating a linear update changes nothing (Gauss-Newton converges in one step).
  UkfPose again;
  again.reset(Pose2(x0.x(), x0.y(), x0.z()), p0);
  again.update(linearise, 3, Eigen::Matrix3d::Zero());
  EXPECT_NEAR((again.mean() - x1).norm(), 0.0, 1e-9);
}

// A frame-common error C: the points act as one pose measurement of covariance I^-1 + C.
TEST(UkfPose, CommonErrorCapsTheInformation) {
  const Eigen::Matrix3d p0 = Eigen::Vector3d(0.01, 0.01, 0.001).asDiagonal();
  UkfPose ukf;
  ukf.reset(Pose2(0, 0, 0), p0);
  // 1000 direct measurements of x with variance 1e-4: alone, information 1e7.
  const auto linearise = [&](const Eigen::Vector3d&, const SigmaPoints& sp, InformationSum& sum) {
    for (int m = 0; m < 1000; ++m) {
      std::array<double, 6> v{};
      for (int s = 0; s < 6; ++s) v[static_cast<std::size_t>(s)] = sp[s].x();
      sp.add(v, sp.predict(v), 0.1, 1e-4, sum);
    }
  };
  const Eigen::Matrix3d common = Eigen::Vector3d(0.0009, 0.0009, 0.0001).asDiagonal();
  ukf.update(linearise, 1, common);
  // Scalar check along x: the measurement's variance is 1e-7 + 9e-4.
  const double r = 1e-4 / 1000 + 0.0009;
  const double k = 0.01 / (0.01 + r);
  EXPECT_NEAR(ukf.mean().x(), k * 0.1, 1e-9);
  EXPECT_NEAR(ukf.covariance()(0, 0), (1 - k) * 0.01, 1e-9);
  EXPECT_NEAR(ukf.covariance()(1, 1), 0.01, 1e-12);  // y was not measured
}

// Prediction by a pure turn is linear: mean rotated, covariance P + Q.
TEST(UkfPose, PredictPureTurnIsLinear) {
  const Eigen::Matrix3d p0 = spd(0.04, 0.09, 0.01, 0.01, 0.002, -0.003);
  UkfPose ukf;
  ukf.reset(Pose2(2.0, 1.0, 3.0), p0);
  const Eigen::Matrix3d q = Eigen::Vector3d(1e-4, 1e-4, 4e-4).asDiagonal();
  ukf.predict(Pose2(0, 0, 0.5), q);
  EXPECT_NEAR(ukf.mean().x(), 2.0, 1e-12);
  EXPECT_NEAR(ukf.mean().y(), 1.0, 1e-12);
  EXPECT_NEAR(ukf.mean().z(), wrap_angle(3.5), 1e-12);  // wrapped across pi
  EXPECT_NEAR((ukf.covariance() - (p0 + q)).norm(), 0.0, 1e-11);  // the Cholesky's 1e-12 load
}

TEST(UkfPose, MotionNoiseGrowsWithDistanceAndTurn) {
  const MotionNoise n;  // defaults
  const Eigen::Matrix3d still = motion_covariance(Pose2(0, 0, 0), 0.0, n);
  const Eigen::Matrix3d drive = motion_covariance(Pose2(0.04, 0.0, 0.0), 0.0, n);
  const Eigen::Matrix3d turn = motion_covariance(Pose2(0, 0, 0.2), 0.0, n);
  EXPECT_NEAR(still(0, 0), n.floor_xy * n.floor_xy, 1e-15);
  EXPECT_NEAR(drive(0, 0), 0.015 * 0.015 * 0.04 + 0.0004 * 0.0004 + 1e-6, 1e-15);
  EXPECT_NEAR(turn(2, 2), 0.035 * 0.035 * 0.2 + 1e-6, 1e-15);
  EXPECT_GT(drive(2, 2), still(2, 2));
}

// The nearest marking and its signed distance, at known places of the 2012 MSL field.
TEST(MarkingAssociation, PicksTheNearestMarking) {
  const Field f = Field::preset("msl2012");
  const MarkingAssociation a(f);
  // 7 cm beside the halfway line (x = 0), half-way to the touch line: the halfway line.
  const LocalMarking halfway = a.associate(Eigen::Vector2d(0.07, 4.5));
  ASSERT_GE(halfway.marking, 0);
  EXPECT_FALSE(halfway.circle);
  EXPECT_NEAR(halfway.distance, 0.07, 1e-12);
  EXPECT_NEAR(a.distance(halfway.marking, Eigen::Vector2d(0.0, -5.0)), 0.0, 1e-12);  // the whole line
  EXPECT_NEAR(halfway.value(0.07, 4.5), 0.07, 1e-12);
  EXPECT_NEAR(halfway.value(-0.03, 4.5), -0.03, 1e-12);  // signed: across the line
  // On the centre circle's inside (radius 2 m), away from the halfway line: the circle.
  const Eigen::Vector2d inside(1.9 * std::cos(0.7), 1.9 * std::sin(0.7));
  const LocalMarking circle = a.associate(inside);
  ASSERT_TRUE(circle.circle);
  EXPECT_NEAR(circle.distance, 0.1, 1e-9);
  EXPECT_NEAR(circle.value(inside.x(), inside.y()), 0.1, 1e-9);
  // Everywhere: the association's distance is the field's exact distance to the nearest marking
  // (except spots, which it does not use).
  Rng rng(5);
  Field no_spots = f;
  no_spots.spots.clear();
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector2d p(rng.uniform(-10, 10), rng.uniform(-7, 7));
    EXPECT_NEAR(a.associate(p).distance, no_spots.distance_to_marking(p), 1e-9) << p.transpose();
  }
}

TEST(HypothesisSet, MergesOneBasinAndTwinsOnlyWhenAsked) {
  const HypothesisSetParams p;
  const auto make = [](double x, double y, double th, double v, std::uint32_t id) {
    Hypothesis h;
    h.ukf.reset(Pose2(x, y, th), Eigen::Matrix3d::Identity() * 0.01);
    h.validity = v;
    h.id = id;
    return h;
  };
  std::vector<Hypothesis> s = {make(1.0, 2.0, 0.1, 0.3, 0), make(1.1, 2.05, 0.15, 0.8, 1), make(-1.0, -2.0, 0.1 + kPi, 0.5, 2)};
  merge(s, p, false);
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].id, 1u);  // the more valid of the close pair stays
  EXPECT_EQ(s[1].id, 2u);  // the twin stays: something could tell it apart
  merge(s, p, true);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].id, 1u);
  // Pruning: old and invalid goes, never the last one; best() keeps the lead within the hysteresis.
  std::vector<Hypothesis> t = {make(0, 0, 0, 0.05, 0), make(3, 0, 0, 0.6, 1), make(-3, 0, 0, 0.62, 2)};
  for (auto& h : t) h.age = 2.0;
  prune(t, p);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(best(t, 0, 0.05), 0);  // index 0 (id 1) leads; 0.62 is not 0.05 above 0.6
  EXPECT_EQ(best(t, -1, 0.05), 1);
}

TEST(AlternativePoses, SimplexFitsThePoseFromAnOffsetStart) {
  const Field f = Field::preset("msl2012");
  const FieldMap map(f, 0.05);
  Rng rng(3);
  const Pose2 truth(-3.0, 1.0, 0.4);
  const auto pts = scenes::line_points(f, truth, 40, rng);
  const Candidate c = simplex_fit(map, pts, Eigen::Vector3d(truth.x + 0.3, truth.y - 0.25, truth.theta + 0.1), AlternativePoseParams{});
  EXPECT_LT(std::hypot(c.pose.x() - truth.x, c.pose.y() - truth.y), 0.02);
  EXPECT_LT(std::fabs(angle_diff(c.pose.z(), truth.theta)), 0.01);
  EXPECT_LT(c.score, 0.05);
}

// The second gate. A robot at (3, 0.3) facing +x has the penalty area's line 3.75 m ahead, square
// to its view: there a tilt of the camera moves a point along the line's normal by (r^2 + h^2) / h,
// 19 m per radian (10 cm at the declared 0.3 deg), so the first gate (3 sigma of a point's whole
// spread, the tilt's included) is 30 cm wide. After 30 frames of exact points (a standing robot)
// one frame brings the same points and seven more 15 cm in front of that line: the first gate lets
// them through and they pull the estimate; judged once the frame's own tilt, fitted to all its
// points, is taken out, they are 5 or more white spreads off and are left out. A tilted frame is not
// taken for outliers: with points moved by a tilt of 0.1 deg in roll and pitch (far points by up to
// 8 cm), the gate leaves none of them out and the estimate is the one without the gate.
TEST(UkfMh, PointsOffTheirMarkingOnceTheFramesTiltIsOutAreLeftOut) {
  const Field f = Field::preset("msl2012");
  const Pose2 truth(3.0, 0.3, 0.0);
  Rng rng(11);
  const std::vector<Eigen::Vector2d> clean = scenes::line_points(f, truth, 80, rng);
  std::vector<Eigen::Vector2d> off = clean;
  for (double y = -0.9; y <= 0.91; y += 0.3) off.emplace_back(6.75 - 0.15 - truth.x, y - truth.y);  // 15 cm short of x = 6.75
  std::vector<Eigen::Vector2d> tilted;
  const Eigen::Vector2d tilt(0.0017, -0.0017);  // 0.1 deg in roll and pitch
  for (const auto& q : clean) tilted.push_back(q + floor_tilt_jacobian(q, 0.75) * tilt);
  const auto shift = [&](const std::vector<Eigen::Vector2d>& last, double gate) {
    UkfMhParams p;
    p.white_gate_sigmas = gate;
    p.tilt_sd = 0.3 * kPi / 180.0;
    p.mount_height = 0.75;
    p.latency = 0.0;
    p.alt_tracking_restarts = 0;
    UkfMhLocalizer loc(f, p, 1, "");
    loc.reset(truth);
    Observations obs;
    for (int k = 0; k < 30; ++k) {
      obs.t = k / 30.0;
      obs.line_points = clean;
      loc.update(obs, Odometry{obs.t, Pose2()}, std::nullopt);
    }
    obs.t = 1.0;
    obs.line_points = last;
    return loc.update(obs, Odometry{obs.t, Pose2()}, std::nullopt).pose;
  };
  const Pose2 settled = shift(clean, 4.0);
  const double pulled = shift(off, 0.0).x - settled.x, kept = shift(off, 4.0).x - settled.x;
  EXPECT_GT(pulled, 0.001);
  EXPECT_LT(std::fabs(kept), 0.1 * pulled);
  const Pose2 gate = shift(tilted, 4.0), none = shift(tilted, 0.0), settled_none = shift(clean, 0.0);
  EXPECT_EQ(settled_none.x, settled.x);  // exact points: the gate leaves none of them out
  // The tilted frame: the tilt moved far points by up to 8 cm, and the gate left none of them out.
  EXPECT_GT(std::hypot(none.x - settled.x, none.y - settled.y), 1e-5);
  EXPECT_EQ(gate.x, none.x);
  EXPECT_EQ(gate.y, none.y);
  EXPECT_EQ(gate.theta, none.theta);
}

namespace {
// Frames of exact line points seen from `truth` (a standing robot), fed to a fresh localizer.
struct ColdStart {
  double first_valid_s = -1;
  Estimate last;
};
// `outliers` of the 80 points lie more than 0.6 m from every marking (no pose near the truth can
// explain them).
ColdStart cold_start(const Pose2& truth, std::optional<double> heading, std::uint64_t seed, const UkfMhParams& p = {}, int outliers = 0) {
  const Field f = Field::preset("msl2012");
  UkfMhLocalizer loc(f, p, seed, "");
  const FieldMap prefilter(f, 0.05);
  const MarkingAssociation assoc(f);
  loc.reset(std::nullopt);
  Rng rng(seed);
  ColdStart out;
  for (int k = 0; k < 60; ++k) {  // 2 s at 30 Hz
    Observations obs;
    obs.t = k / 30.0;
    obs.line_points = scenes::line_points(f, truth, 80 - outliers, rng, {.noise = 0.02, .prefilter = &prefilter});
    while (static_cast<int>(obs.line_points.size()) < 80) {
      const Eigen::Vector2d o(rng.uniform(-5.0, 5.0), rng.uniform(-5.0, 5.0));
      const Eigen::Vector2d w = truth.transform(o);
      if (o.norm() < 5.0 && std::fabs(w.x()) < f.half_floor_x() && std::fabs(w.y()) < f.half_floor_y() && assoc.associate(w).distance > 0.6)
        obs.line_points.push_back(o);
    }
    out.last = loc.update(obs, Odometry{obs.t, Pose2()}, heading);
    if (out.first_valid_s < 0 && out.last.valid) out.first_valid_s = obs.t;
  }
  return out;
}
}  // namespace

// A cold start on synthetic frames: right (5 cm, 0.05 rad) and valid within 1 s, with a compass on
// the true pose, without one on the true pose or its twin.
TEST(UkfMh, ColdStartConverges) {
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const Pose2 truth(-2.0 + seed, 1.5 - 0.7 * seed, -0.5 + 0.6 * seed);
    const ColdStart with = cold_start(truth, truth.theta, seed);
    ASSERT_TRUE(with.last.valid) << seed;
    EXPECT_GE(with.first_valid_s, 0.0);
    EXPECT_LE(with.first_valid_s, 1.0) << seed;
    EXPECT_LT(std::hypot(with.last.pose.x - truth.x, with.last.pose.y - truth.y), 0.05) << seed;
    EXPECT_LT(std::fabs(angle_diff(with.last.pose.theta, truth.theta)), 0.05) << seed;
    EXPECT_EQ(with.last.extra.at("twin_ambiguous"), 0.0);
    const ColdStart without = cold_start(truth, std::nullopt, seed);
    ASSERT_TRUE(without.last.valid) << seed;
    EXPECT_LE(without.first_valid_s, 1.0) << seed;
    const double sign = without.last.pose.x * truth.x > 0 ? 1.0 : -1.0;  // the truth or its twin
    EXPECT_LT(std::hypot(without.last.pose.x - sign * truth.x, without.last.pose.y - sign * truth.y), 0.05) << seed;
    EXPECT_LT(std::fabs(angle_diff(without.last.pose.theta, truth.theta + (sign > 0 ? 0.0 : kPi))), 0.05) << seed;
    EXPECT_EQ(without.last.extra.at("twin_ambiguous"), 1.0);
  }
}

// A kidnap: tracking one pose, then the points come from another. The old pose must stop being
// valid within a second and the new one be found.
TEST(UkfMh, RecoversFromAKidnap) {
  const Field f = Field::preset("msl2012");
  UkfMhLocalizer loc(f, UkfMhParams{}, 7, "");
  const Pose2 a(-4.0, 2.0, 0.3), b(3.0, -1.5, 0.3);
  loc.reset(a);
  const FieldMap prefilter(f, 0.05);
  Rng rng(7);
  double invalid_at = -1, found_at = -1;
  for (int k = 0; k < 120; ++k) {
    const bool after = k >= 30;
    Observations obs;
    obs.t = k / 30.0;
    obs.line_points = scenes::line_points(f, after ? b : a, 80, rng, {.noise = 0.02, .prefilter = &prefilter});
    const Estimate e = loc.update(obs, Odometry{obs.t, Pose2()}, 0.3);
    if (!after) {
      ASSERT_TRUE(e.valid) << k;
      continue;
    }
    const double err = std::hypot(e.pose.x - b.x, e.pose.y - b.y);
    if (invalid_at < 0 && (!e.valid || err < 0.25)) invalid_at = obs.t - 1.0;
    if (found_at < 0 && e.valid && err < 0.05) found_at = obs.t - 1.0;
    if (e.valid) {
      EXPECT_TRUE(err < 0.5 || obs.t - 1.0 <= 1.0) << "valid " << err << " m off at " << obs.t;
    }
  }
  EXPECT_GE(invalid_at, 0.0);
  EXPECT_LE(invalid_at, 1.0);
  EXPECT_GE(found_at, 0.0);
  EXPECT_LE(found_at, 2.0);
}

// Twins on the legacy field (coloured goals), no compass: a yellow blob decides between a pose and
// its point mirror. Seen where the yellow goal is from the truth, it ends on the truth; seen where
// the twin would see it (pi further round), on the twin.
TEST(UkfMh, GoalColourDecidesTheTwin) {
  const Field f = Field::preset("msl2007");
  const FieldMap prefilter(f, 0.05);
  for (std::uint64_t seed = 1; seed <= 3; ++seed)
    for (bool mirrored : {false, true}) {
      const Pose2 truth(-1.5 + seed, 1.0 - 0.5 * seed, 2.5 - 1.7 * seed);
      const Pose2 want = mirrored ? Pose2(-truth.x, -truth.y, truth.theta + kPi) : truth;
      UkfMhLocalizer loc(f, UkfMhParams{}, seed, "");
      loc.reset(std::nullopt);
      Rng rng(seed);
      Estimate e;
      for (int k = 0; k < 60; ++k) {
        Observations obs;
        obs.t = k / 30.0;
        obs.line_points = scenes::line_points(f, truth, 80, rng, {.noise = 0.02, .prefilter = &prefilter});
        Blob yellow;
        yellow.colour = kYellow;  // the goal at +x, seen from `want`
        yellow.bearing = wrap_angle(std::atan2(0.0 - want.y, 6.0 - want.x) - want.theta);
        obs.blobs.push_back(yellow);
        e = loc.update(obs, Odometry{obs.t, Pose2()}, std::nullopt);
      }
      ASSERT_TRUE(e.valid) << seed << " " << mirrored;
      EXPECT_EQ(e.extra.at("twin_ambiguous"), 0.0);
      EXPECT_LT(std::hypot(e.pose.x - want.x, e.pose.y - want.y), 0.05) << seed << " " << mirrored << ": " << e.pose.x << ", " << e.pose.y;
      EXPECT_LT(std::fabs(angle_diff(e.pose.theta, want.theta)), 0.05) << seed << " " << mirrored;
    }
}

// Consistent evidence: a proposal that explains nearly every point in each of its first
// trust_frames updates is valid after them (B-Human's validity filter alone takes about 0.35 s from
// half credit); one that explains four fifths is not trusted so (the best wrong poses of the field
// explain up to three quarters) and waits for the filter, which reaches valid_min after a second or
// more at that share (0.8 - 0.4 e^(-t / 0.5 s) = 0.75 at 1.04 s; later when a few of the right
// points miss too).
TEST(UkfMh, ConsistentEvidenceTrustsAProposalEarly) {
  const Pose2 truth(-2.0, 1.5, 0.4);
  UkfMhParams off;
  off.trust_share = 1.1;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const ColdStart trusted = cold_start(truth, truth.theta, seed);
    ASSERT_TRUE(trusted.last.valid) << seed;
    // The proposal enters on frame 0; trust_frames = 5 updates later it is valid (frame 5).
    EXPECT_NEAR(trusted.first_valid_s, 5.0 / 30.0, 1.5 / 30.0) << seed;
    const ColdStart filtered = cold_start(truth, truth.theta, seed, off);
    EXPECT_GE(filtered.first_valid_s, 0.3) << seed;
    EXPECT_LE(filtered.first_valid_s, 0.5) << seed;
    const ColdStart four_fifths = cold_start(truth, truth.theta, seed, UkfMhParams{}, 16);
    EXPECT_TRUE(four_fifths.first_valid_s < 0.0 || four_fifths.first_valid_s >= 0.8) << seed << ": " << four_fifths.first_valid_s;
    const ColdStart three_fifths = cold_start(truth, truth.theta, seed, UkfMhParams{}, 32);
    EXPECT_LT(three_fifths.first_valid_s, 0.0) << seed;  // never valid: 60 % is below valid_min
  }
}

// The camera's latency is declared by the scenario's camera (its noise profile's latency_ms): every
// localizer may know it when built (LocalizerContext), an external one in hello.camera.latency_s, and
// ukf_mh takes it as the default of `latency`; a number given in the parameters overrides it.
TEST(UkfMh, LatencyDefaultsToTheCamerasDeclaredLatency) {
  const auto scenario = [](const char* profile, const Json& camera) {
    Json j = {{"duration", 1.0}, {"noise_profile", profile}, {"robots", Json::parse(R"([{"id": 0, "start": [0, -2, 0]}])")},
              {"localizer", {{"type", "ukf_mh"}}}};
    if (!camera.is_null()) j["camera"] = camera;
    return harness::parse_scenario(j, "latency");
  };
  const harness::Scenario robot = scenario("robot", nullptr);
  EXPECT_DOUBLE_EQ(harness::declared_camera_latency(robot), 0.033);  // data/noise_profiles.json: one frame at 30 Hz
  EXPECT_DOUBLE_EQ(harness::declared_camera_latency(scenario("ideal", nullptr)), 0.0);
  EXPECT_DOUBLE_EQ(harness::declared_camera_latency(scenario("robot", {{"latency_ms", 50.0}})), 0.05);

  // hello.camera: the calibration object as given, plus the declared latency.
  const Json camera = {{"width", 640}, {"height", 640}};
  const external::Session s = harness::make_session(robot, 0, camera, false, 1, "");
  EXPECT_EQ(s.camera.at("width"), 640);
  EXPECT_DOUBLE_EQ(s.camera.at("latency_s").get<double>(), 0.033);
  EXPECT_DOUBLE_EQ(harness::make_session(scenario("ideal", nullptr), 0, Json::object(), false, 1, "").camera.at("latency_s").get<double>(), 0.0);

  harness::LocalizerContext ctx;
  ctx.field = &robot.field;
  ctx.camera_latency = 0.033;
  const auto latency = [&](const Json& spec) {
    Json eff;
    harness::make_localizer(harness::LocalizerSpec(spec, "/localizer"), ctx, &eff);
    return eff.at("latency").get<double>();
  };
  EXPECT_DOUBLE_EQ(latency({{"type", "ukf_mh"}}), 0.033);
  EXPECT_DOUBLE_EQ(latency({{"type", "ukf_mh"}, {"latency", 0.0}}), 0.0);  // "unknown", said explicitly
  EXPECT_DOUBLE_EQ(latency({{"type", "ukf_mh"}, {"latency", 0.02}}), 0.02);
  ctx.camera_latency = 0.0;
  EXPECT_DOUBLE_EQ(latency({{"type", "ukf_mh"}}), 0.0);
  // Built without a context (tests, benchmarks): unknown.
  const Json no_params = Json::object();  // the reader keeps a reference: the object must outlive it
  JsonReader none(no_params, "/localizer");
  EXPECT_DOUBLE_EQ(UkfMhParams::from_json(none).latency, 0.0);
}

// The camera's mirror height and vibration are declared by the scenario's camera as its latency is:
// LocalizerContext, hello.camera.mount_height_m / vibration_rad, and ukf_mh's defaults of
// `mount_height` and `tilt_sd`.
TEST(UkfMh, TiltDefaultsToTheCamerasDeclaredGeometry) {
  const auto scenario = [](const char* profile, const Json& camera) {
    Json j = {{"duration", 1.0}, {"noise_profile", profile}, {"robots", Json::parse(R"([{"id": 0, "start": [0, -2, 0]}])")},
              {"localizer", {{"type", "ukf_mh"}}}};
    if (!camera.is_null()) j["camera"] = camera;
    return harness::parse_scenario(j, "tilt");
  };
  const harness::Scenario robot = scenario("robot", nullptr);
  EXPECT_DOUBLE_EQ(harness::declared_camera_mount_height(robot), 0.75);       // docs/camera.md
  EXPECT_NEAR(harness::declared_camera_vibration(robot), 0.3 * kPi / 180.0, 1e-15);  // 0.3 deg, each axis
  EXPECT_DOUBLE_EQ(harness::declared_camera_vibration(scenario("ideal", nullptr)), 0.0);
  EXPECT_DOUBLE_EQ(harness::declared_camera_mount_height(scenario("robot", {{"mount_height", 0.9}})), 0.9);
  const external::Session s = harness::make_session(robot, 0, Json::object(), false, 1, "");
  EXPECT_DOUBLE_EQ(s.camera.at("mount_height_m").get<double>(), 0.75);
  EXPECT_NEAR(s.camera.at("vibration_rad").get<double>(), 0.3 * kPi / 180.0, 1e-15);

  harness::LocalizerContext ctx;
  ctx.field = &robot.field;
  ctx.camera_mount_height = 0.75;
  ctx.camera_vibration = 0.005;
  const auto effective = [&](const Json& spec) {
    Json eff;
    harness::make_localizer(harness::LocalizerSpec(spec, "/localizer"), ctx, &eff);
    return eff;
  };
  const Json d = effective({{"type", "ukf_mh"}});
  EXPECT_DOUBLE_EQ(d.at("mount_height").get<double>(), 0.75);
  EXPECT_DOUBLE_EQ(d.at("tilt_sd").get<double>(), 0.005);
  EXPECT_DOUBLE_EQ(effective({{"type", "ukf_mh"}, {"tilt_sd", 0.0}}).at("tilt_sd").get<double>(), 0.0);
  const Json no_params = Json::object();
  JsonReader none(no_params, "/localizer");
  const UkfMhParams unknown = UkfMhParams::from_json(none);
  EXPECT_FALSE(unknown.tilt_modelled());  // built without a context: no tilt model, the common covariance instead
  EXPECT_DOUBLE_EQ(unknown.common_xy_var(), 0.03 * 0.03);
  JsonReader none2(no_params, "/localizer");
  const UkfMhParams declared = UkfMhParams::from_json(none2, {0.033, 0.75, 0.005});
  EXPECT_TRUE(declared.tilt_modelled());
  EXPECT_DOUBLE_EQ(declared.common_xy_var(), 0.0);  // the tilt is the frame-common error: not counted twice
}

// The floor geometry of a tilt against the exact ray: a floor point seen from h above the floor,
// the camera turned by a small rotation about the robot's x or y axis, the turned ray met with the
// floor again. The Jacobian is its first-order change (central differences, error O(eps^2)).
TEST(UkfPose, FloorTiltJacobianIsTheTurnedRaysFloorPoint) {
  const double h = 0.75, eps = 1e-6;
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(3.0, 0.0), Eigen::Vector2d(-1.0, 2.0), Eigen::Vector2d(0.4, -0.3)}) {
    const Eigen::Vector3d ray(p.x(), p.y(), -h);
    const Eigen::Matrix2d m = floor_tilt_jacobian(p, h);
    for (int axis = 0; axis < 2; ++axis) {
      const auto floor_point = [&](double angle) {
        const Eigen::Vector3d r = Eigen::AngleAxisd(angle, axis == 0 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY()) * ray;
        return Eigen::Vector2d(r.head<2>() * (h / -r.z()));
      };
      const Eigen::Vector2d d = (floor_point(eps) - floor_point(-eps)) / (2 * eps);
      EXPECT_NEAR(m(0, axis), d.x(), 1e-6) << p.transpose() << " axis " << axis;
      EXPECT_NEAR(m(1, axis), d.y(), 1e-6) << p.transpose() << " axis " << axis;
    }
  }
  // Along the range: (r^2 + h^2) / h per radian; across it: h.
  EXPECT_NEAR(floor_tilt_jacobian(Eigen::Vector2d(3.0, 0.0), h)(0, 1), -(9.0 + h * h) / h, 1e-12);
  EXPECT_NEAR(floor_tilt_jacobian(Eigen::Vector2d(3.0, 0.0), h)(1, 0), h, 1e-12);
}

// Marginalising the tilt from the sums equals the dense generalized least squares with the points'
// covariance D + A T A^T: J = H^T (D + A T A^T)^-1 H, g = H^T (D + A T A^T)^-1 e.
TEST(UkfPose, TiltMarginalisationEqualsDenseGls) {
  Rng rng(7);
  const int m = 40;
  Eigen::MatrixXd h(m, 3), a(m, 2);
  Eigen::VectorXd d(m), e(m);
  InformationSum sum;
  for (int i = 0; i < m; ++i) {
    h.row(i) << rng.normal(0, 1), rng.normal(0, 1), rng.normal(0, 3);
    a.row(i) << rng.normal(0, 5), rng.normal(0, 5);
    d(i) = 0.01 + 0.01 * rng.uniform(0, 1);
    e(i) = rng.normal(0, 0.05);
    const double w = 1.0 / d(i);
    sum.info += h.row(i).transpose() * w * h.row(i);
    sum.grad += h.row(i).transpose() * w * e(i);
    sum.info_tilt += h.row(i).transpose() * w * a.row(i);
    sum.tilt_info += a.row(i).transpose() * w * a.row(i);
    sum.tilt_grad += a.row(i).transpose() * w * e(i);
  }
  const Eigen::Matrix2d t = Eigen::Vector2d(2.7e-5, 1.5e-5).asDiagonal();
  const Eigen::MatrixXd r = Eigen::MatrixXd(d.asDiagonal()) + a * t * a.transpose();
  const Eigen::MatrixXd ri = r.inverse();
  const Eigen::Matrix3d j_dense = h.transpose() * ri * h;
  const Eigen::Vector3d g_dense = h.transpose() * ri * e;
  Eigen::Matrix3d j;
  Eigen::Vector3d g;
  sum.marginalise_tilt(t, j, g);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(g(i), g_dense(i), 1e-8 * std::max(1.0, std::fabs(g_dense(i)))) << i;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(j(i, k), j_dense(i, k), 1e-8 * j_dense.norm()) << i << "," << k;
  }
  // No tilt: the independent points' sums unchanged.
  sum.marginalise_tilt(Eigen::Matrix2d::Zero(), j, g);
  EXPECT_EQ(j, sum.info);
  EXPECT_EQ(g, sum.grad);
}

// The markings' shared offsets (standardized prior variance rho, load l_i per point) and the tilt,
// marginalised from the sums that SigmaPoints::add accumulates, equal the dense generalized least
// squares with the points' covariance D + L rho L^T + A T A^T (linear measurements, so the
// regression is exact).
TEST(UkfPose, MarkingOffsetMarginalisationEqualsDenseGls) {
  Rng rng(11);
  const int m = 30, groups = 4;
  const SigmaPoints sp(Eigen::Vector3d(0.5, -0.2, 0.1), spd(0.01, 0.02, 0.003, 0.001, 0.0005, -0.0002));
  Eigen::MatrixXd h(m, 3), a(m, 2), l = Eigen::MatrixXd::Zero(m, groups);
  Eigen::VectorXd d(m), e(m);
  InformationSum sum;
  for (int i = 0; i < m; ++i) {
    h.row(i) << rng.normal(0, 1), rng.normal(0, 1), rng.normal(0, 3);
    a.row(i) << rng.normal(0, 5), rng.normal(0, 5);
    d(i) = 0.0002 + 0.0002 * rng.uniform(0, 1);
    const int k = (i * 7) % groups;
    l(i, k) = 0.01 + 0.02 * rng.uniform(0, 1);
    e(i) = rng.normal(0, 0.02);
    std::array<double, 6> v{};
    for (int q = 0; q < 6; ++q) v[static_cast<std::size_t>(q)] = h.row(i).dot(sp[q]) + 0.3;
    const SigmaPoints::Predicted pr = sp.predict(v);
    const Eigen::Vector2d ai = a.row(i).transpose();
    sp.add(v, pr, pr.mean + e(i), d(i), sum, &ai, 7 + 3 * k, l(i, k));
  }
  EXPECT_EQ(sum.n_groups, groups);
  const double rho = 0.12;
  for (const Eigen::Matrix2d& t : {Eigen::Matrix2d(Eigen::Vector2d(2.7e-5, 1.5e-5).asDiagonal()), Eigen::Matrix2d(Eigen::Matrix2d::Zero())}) {
    const Eigen::MatrixXd r = Eigen::MatrixXd(d.asDiagonal()) + rho * l * l.transpose() + a * t * a.transpose();
    const Eigen::MatrixXd ri = r.inverse();
    const Eigen::Matrix3d j_dense = h.transpose() * ri * h;
    const Eigen::Vector3d g_dense = h.transpose() * ri * e;
    Eigen::Matrix3d j;
    Eigen::Vector3d g;
    sum.marginalise(t, rho, j, g);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(g(i), g_dense(i), 1e-8 * std::max(1.0, std::fabs(g_dense(i)))) << i;
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(j(i, k), j_dense(i, k), 1e-8 * j_dense.norm()) << i << "," << k;
    }
  }
  // No offsets and no tilt: the independent points' sums.
  Eigen::Matrix3d j;
  Eigen::Vector3d g;
  sum.marginalise(Eigen::Matrix2d::Zero(), 0.0, j, g);
  EXPECT_EQ(j, sum.info);
  EXPECT_EQ(g, sum.grad);
}

// n points on one marking, each of variance v with correlation rho: together they tell the
// marking's normal offset as n / (v (1 + (n - 1) rho)), not n / v; 15 points at rho 0.1 are worth
// 6.25 independent ones.
TEST(UkfPose, OneMarkingsPointsAreWorthLessThanIndependentOnes) {
  const SigmaPoints sp(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity() * 0.01);
  const double v = 0.0004, rho = 0.1;
  const int n = 15;
  InformationSum sum;
  for (int i = 0; i < n; ++i) {
    std::array<double, 6> x{};
    for (int q = 0; q < 6; ++q) x[static_cast<std::size_t>(q)] = sp[q].x();
    sp.add(x, sp.predict(x), 0.0, (1.0 - rho) * v, sum, nullptr, 3, std::sqrt(v));
  }
  Eigen::Matrix3d j;
  Eigen::Vector3d g;
  sum.marginalise(Eigen::Matrix2d::Zero(), rho, j, g);
  EXPECT_NEAR(j(0, 0), n / (v * (1 + (n - 1) * rho)), 1e-6 * n / v);
  EXPECT_NEAR(j(0, 0) * v, 6.25, 1e-9);
  EXPECT_NEAR(j(1, 1), 0.0, 1e-9);
}

// A point whose scan ray meets its marking at a grazing angle (|n . u| below 0.3) is anywhere across
// the line's width: its variance grows by w^2 / 12, (0.125 m)^2 / 12 = 1.302e-3 m^2 for the MSL line
// at a grazing_spread of 1 / sqrt(12) line widths. A ray 0.29 off square grazes; one 0.31 off
// square, or crossing squarely, keeps the point's own variance; a threshold of 0 has no grazing class.
TEST(UkfMh, GrazingPointSpreadsOverTheLinesWidth) {
  const double own = 0.02 * 0.02, spread = 0.125 / std::sqrt(12.0), gv = spread * spread;
  const Eigen::Vector2d ray(1.0, 0.0);
  const auto normal_at = [](double c) { return Eigen::Vector2d(c, std::sqrt(1.0 - c * c)); };
  EXPECT_NEAR(incidence_variance(own, ray, normal_at(0.0), 0.3, gv), own + 1.3020833333333333e-3, 1e-15);
  EXPECT_NEAR(incidence_variance(own, ray, normal_at(-0.29), 0.3, gv), own + 1.3020833333333333e-3, 1e-15);
  EXPECT_NEAR(incidence_variance(own, ray, normal_at(0.29), 0.3, gv), own + 1.3020833333333333e-3, 1e-15);
  EXPECT_EQ(incidence_variance(own, ray, normal_at(0.31), 0.3, gv), own);
  EXPECT_EQ(incidence_variance(own, ray, normal_at(-1.0), 0.3, gv), own);
  EXPECT_EQ(incidence_variance(own, ray, normal_at(0.0), 0.0, gv), own);
}

// Points whose rays graze the sideline 20 cm off it (robot frame (x, -1.3) for x = 5 ... 6.6 m,
// |n . u| = 0.19-0.25) pull the pose towards them (1.75 cm to -y without a grazing class); given the
// grazing spread of a line width / sqrt(12) they weigh less and pull it less, and told a spread of
// 10 line widths they hardly move it. The point noise is pinned at 5 cm at 1.5 m and the second gate
// is off, so that the weights below are known numbers whatever the defaults.
TEST(UkfMh, GrazingPointsWeighLessWithTheirSpread) {
  const Field f = Field::preset("msl2012");
  const Pose2 truth(0.5, -4.5, 0.0);
  Rng rng(5);
  Observations clean;
  clean.t = 0.0;
  clean.line_points = scenes::line_points(f, truth, 60, rng);
  Observations with = clean;
  for (double x = 5.0; x <= 6.61; x += 0.4) {
    with.line_points.emplace_back(x, -1.3);
    with.line_points.emplace_back(-x, -1.3);
  }
  const auto estimate = [&](const Observations& obs, double spread) {
    UkfMhParams p;
    p.grazing_spread = spread;
    p.point_sigma = 0.05;
    p.white_gate_sigmas = 0.0;
    p.alt_tracking_restarts = 0;  // no proposals: the one hypothesis's update alone
    UkfMhLocalizer loc(f, p, 1, "");
    loc.reset(truth);
    return loc.update(obs, Odometry{0.0, Pose2()}, std::nullopt).pose;
  };
  const double base = estimate(clean, 0.0).y;
  const double none = estimate(with, 0.0).y - base, spread = estimate(with, 1.0 / std::sqrt(12.0)).y - base,
               wide = estimate(with, 10.0).y - base;
  // All three pull to -y. These far points' own variance is 0.0152 m^2, the spread adds 0.0013 m^2:
  // their weight falls to 0.92 of it, and the pull about so (measured 0.92).
  EXPECT_LT(none, -0.01);
  EXPECT_GT(spread, 0.97 * none);
  EXPECT_LT(spread, 0.8 * none);
  EXPECT_GT(wide, 0.2 * none);
}

namespace {

// Noise-free line points of a robot at `truth` in a 4 x 3 m box of lines (x = +-2, y = +-1.5) whose
// image was taken with the camera tilted by `tilt`: each point is where the tilted camera sees it.
// The pose is then estimated from `start` with the tilt marginalised or with one pose covariance.
Eigen::Vector3d estimate_under_tilt(const Eigen::Vector3d& truth, const Eigen::Vector2d& tilt, bool tilt_model) {
  const double h = 0.75;
  struct Line {
    Eigen::Vector2d n;
    double offset;
  };
  const std::vector<Line> lines = {{{1, 0}, 2.0}, {{-1, 0}, 2.0}, {{0, 1}, 1.5}, {{0, -1}, 1.5}};
  std::vector<Eigen::Vector2d> seen;  // robot frame
  std::vector<int> on;
  const double c = std::cos(truth.z()), s = std::sin(truth.z());
  for (int k = 0; k < 4; ++k)
    for (double u = -1.4; u <= 1.41; u += 0.2) {
      const Eigen::Vector2d w = lines[static_cast<std::size_t>(k)].n * lines[static_cast<std::size_t>(k)].offset +
                                u * Eigen::Vector2d(-lines[static_cast<std::size_t>(k)].n.y(), lines[static_cast<std::size_t>(k)].n.x());
      const Eigen::Vector2d d = w - truth.head<2>();
      const Eigen::Vector2d o(c * d.x() + s * d.y(), -s * d.x() + c * d.y());
      seen.push_back(o + floor_tilt_jacobian(o, h) * tilt);
      on.push_back(k);
    }
  UkfPose ukf;
  ukf.reset(Pose2(truth.x() + 0.02, truth.y() - 0.02, truth.z() + 0.01), Eigen::Vector3d(0.1 * 0.1, 0.1 * 0.1, 0.05 * 0.05).asDiagonal());
  const double var = 0.02 * 0.02, sd = 0.3 * kPi / 180;
  const auto linearise = [&](const Eigen::Vector3d& at, const SigmaPoints& sp, InformationSum& sum) {
    for (std::size_t i = 0; i < seen.size(); ++i) {
      const Line& l = lines[static_cast<std::size_t>(on[i])];
      std::array<double, 6> v{};
      for (int q = 0; q < 6; ++q) {
        const Eigen::Vector3d& x = sp[q];
        const Eigen::Vector2d w(x.x() + std::cos(x.z()) * seen[i].x() - std::sin(x.z()) * seen[i].y(),
                                x.y() + std::sin(x.z()) * seen[i].x() + std::cos(x.z()) * seen[i].y());
        v[static_cast<std::size_t>(q)] = l.n.dot(w) - l.offset;
      }
      const Eigen::Vector2d n_robot(std::cos(at.z()) * l.n.x() + std::sin(at.z()) * l.n.y(), -std::sin(at.z()) * l.n.x() + std::cos(at.z()) * l.n.y());
      const Eigen::Vector2d a = floor_tilt_jacobian(seen[i], h).transpose() * n_robot;
      sp.add(v, sp.predict(v), 0.0, var, sum, &a);
    }
  };
  const Eigen::Matrix2d t = tilt_model ? Eigen::Matrix2d(sd * sd * Eigen::Matrix2d::Identity()) : Eigen::Matrix2d::Zero();
  const Eigen::Matrix3d common = tilt_model ? Eigen::Matrix3d::Zero() : Eigen::Matrix3d(Eigen::Vector3d(0.03 * 0.03, 0.03 * 0.03, 0.01 * 0.01).asDiagonal());
  ukf.update(linearise, 3, common, t);
  return ukf.mean() - truth;
}

}  // namespace

// A tilt of two standard deviations (0.6 deg) moves the far points by centimetres. Marginalised with
// its geometry it moves the pose by 3 mm (the near points pin the pose, the spread in range separates
// the tilt; what is left is the prior's shrinkage of so large a tilt); one pose covariance takes the
// far points' shift for a pose error of 7 cm.
TEST(UkfPose, TiltMarginalisationKeepsThePoseWhereOneCovarianceDoesNot) {
  const Eigen::Vector3d truth(0.8, 0.4, 0.3);
  const Eigen::Vector2d tilt(0.6 * kPi / 180, -0.6 * kPi / 180);
  // What the tilt does to each model's estimate (the same prior, the same points but for the tilt).
  const Eigen::Vector3d with_tilt = estimate_under_tilt(truth, tilt, true) - estimate_under_tilt(truth, Eigen::Vector2d::Zero(), true);
  const Eigen::Vector3d one_cov = estimate_under_tilt(truth, tilt, false) - estimate_under_tilt(truth, Eigen::Vector2d::Zero(), false);
  EXPECT_LT(with_tilt.head<2>().norm(), 0.004) << with_tilt.transpose();
  EXPECT_LT(std::fabs(with_tilt.z()), 0.001) << with_tilt.transpose();
  EXPECT_GT(one_cov.head<2>().norm(), 0.05) << one_cov.transpose();
  EXPECT_GT(std::fabs(one_cov.z()), 0.003) << one_cov.transpose();
}

// The compass reading theta + b + noise is a linear measurement of the joint (x, b): fuse_heading is
// the Kalman update of the 4-D state exactly, and a pose update that does not see b moves b as the
// 4-D Kalman filter does (Gaussian conditioning).
TEST(UkfPose, CompassFusionEqualsTheJointKalmanFilter) {
  const Eigen::Vector3d x0(1.0, -2.0, 0.3);
  const Eigen::Matrix3d p0 = spd(0.04, 0.09, 0.01, 0.01, 0.002, -0.003);
  UkfPose ukf;
  ukf.reset(Pose2(x0.x(), x0.y(), x0.z()), p0);
  ukf.start_bias(0.02 * 0.02);
  // 1. A linear pose measurement (x + 2 theta) that does not see b: b gains a cross-covariance.
  const Eigen::RowVector3d hx(1.0, 0.0, 2.0);
  const double zx = 1.5, rx = 0.01;
  ukf.update(
      [&](const Eigen::Vector3d&, const SigmaPoints& sp, InformationSum& sum) {
        std::array<double, 6> v{};
        for (int s = 0; s < 6; ++s) v[static_cast<std::size_t>(s)] = hx.dot(sp[s]);
        sp.add(v, sp.predict(v), zx, rx, sum);
      },
      1, Eigen::Matrix3d::Zero());
  // The joint filter: (x, b), b uncorrelated at first; a measurement with H = [hx, 0] leaves b alone.
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p.topLeftCorner<3, 3>() = p0;
  p(3, 3) = 0.02 * 0.02;
  Eigen::Vector4d x;
  x << x0, 0.0;
  const auto kalman = [&](const Eigen::RowVector4d& hrow, double z, double r) {
    const double s = hrow * p * hrow.transpose() + r;
    const Eigen::Vector4d k = p * hrow.transpose() / s;
    x += k * (z - hrow.dot(x));
    p = (Eigen::Matrix4d::Identity() - k * hrow) * p;
  };
  kalman((Eigen::RowVector4d() << hx, 0.0).finished(), zx, rx);
  EXPECT_NEAR(ukf.bias(), 0.0, 1e-12);  // uncorrelated at first: nothing to condition
  // 2. A compass reading: H = [0 0 1 1].
  const double zc = 0.33, rc = 0.0175 * 0.0175;
  ukf.fuse_heading(zc, rc);
  kalman((Eigen::RowVector4d() << 0, 0, 1, 1).finished(), zc, rc);
  // 3. Another pose measurement: now b moves with the pose through their cross-covariance.
  ukf.update(
      [&](const Eigen::Vector3d&, const SigmaPoints& sp, InformationSum& sum) {
        std::array<double, 6> v{};
        for (int s = 0; s < 6; ++s) v[static_cast<std::size_t>(s)] = sp[s].z();
        sp.add(v, sp.predict(v), 0.31, 1e-4, sum);
      },
      1, Eigen::Matrix3d::Zero());
  kalman((Eigen::RowVector4d() << 0, 0, 1, 0).finished(), 0.31, 1e-4);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(ukf.mean()[i], x[i], 1e-9) << i;
    EXPECT_NEAR(ukf.bias_cross()[i], p(i, 3), 1e-9) << i;
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(ukf.covariance()(i, j), p(i, j), 1e-9) << i << "," << j;
  }
  EXPECT_NEAR(ukf.bias(), x[3], 1e-9);
  EXPECT_NEAR(ukf.bias_variance(), p(3, 3), 1e-12);
  EXPECT_GT(std::fabs(ukf.bias()), 1e-4);  // the test moved the bias
  // Without a bias state the compass is the scalar Kalman update of theta.
  UkfPose plain;
  plain.reset(Pose2(x0.x(), x0.y(), x0.z()), p0);
  plain.fuse_heading(zc, rc);
  const Eigen::Vector3d k = p0.col(2) / (p0(2, 2) + rc);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(plain.mean()[i], x0[i] + k[i] * (zc - x0.z()), 1e-12) << i;
}

// A merge keeps the lead as best() does: the reported hypothesis goes only to one more valid by the
// hysteresis.
TEST(HypothesisSet, MergeKeepsTheLeadWithinTheHysteresis) {
  const HypothesisSetParams p;
  const auto make = [](double x, double v, std::uint32_t id) {
    Hypothesis h;
    h.ukf.reset(Pose2(x, 0.0, 0.0), Eigen::Matrix3d::Identity() * 0.01);
    h.validity = v;
    h.id = id;
    return h;
  };
  std::vector<Hypothesis> s = {make(0.0, 0.95, 0), make(0.2, 0.97, 1)};
  merge(s, p, false, 0, 0.05);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].id, 0u);  // the lead stays: 0.97 is not 0.05 above 0.95
  s = {make(0.0, 0.90, 0), make(0.2, 0.97, 1)};
  merge(s, p, false, 0, 0.05);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].id, 1u);  // clearly more valid: it takes over
  s = {make(0.0, 0.95, 0), make(0.2, 0.97, 1)};
  merge(s, p, false);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].id, 1u);  // no lead given: the more valid stays
}
