// The accuracy bound (harness/scoring/bound.hpp) proven before any table shows it: closed-form
// answers, the singular cases named, the compass's exact share, the tilt's physics against an exact
// ray intersection, a Monte-Carlo trial in which an efficient estimator of our own reaches the bound
// and none beats it, and the posterior recursion equal to a Kalman filter's covariance.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "core/angles.hpp"
#include "harness/scoring/metrics.hpp"
#include "core/floor_tilt.hpp"
#include "harness/scoring/bound.hpp"

using namespace omniloc;
using namespace omniloc::harness;

namespace {

// Two perpendicular lines crossing at the origin (the x and y axes, 20 m long).
Field cross_field() {
  Field f;
  f.segments.push_back({{-10.0, 0.0}, {10.0, 0.0}});
  f.segments.push_back({{0.0, -10.0}, {0.0, 10.0}});
  return f;
}

std::vector<BoundRow> rows_at(const Field& f, const Pose2& pose, const std::vector<Eigen::Vector2d>& world, double sigma, double h = 0.75) {
  std::vector<BoundRow> rows;
  for (const auto& w : world) {
    const MarkingMatch m = match_marking(f, w);
    rows.push_back(bound_row(m, w, pose, pose.inverse_transform(w), sigma * sigma, h));
  }
  return rows;
}

// A frame at time t whose line points are the world points `world` seen from `pose` (as floats, as
// the camera's are).
FrameRecord frame_seeing(const Pose2& pose, const std::vector<Eigen::Vector2d>& world, double t, bool camera_ok) {
  FrameRecord r;
  r.t = t;
  r.truth = pose;
  r.camera_ok = camera_ok;
  for (const auto& w : world) {
    const Eigen::Vector2d p = pose.inverse_transform(w);
    r.line_points.push_back({static_cast<float>(p.x()), static_cast<float>(p.y())});
  }
  return r;
}

// Points at x = +-2, +-3 on the x axis and y = +-1.5, +-2.5 on the y axis.
const std::vector<Eigen::Vector2d> kCross = {{2, 0}, {-2, 0}, {3, 0}, {-3, 0}, {0, 1.5}, {0, -1.5}, {0, 2.5}, {0, -2.5}};

}  // namespace

// A point on the x axis measures y and, through the lever x, theta; one on the y axis measures x
// and theta through -y. With the points symmetric about the robot at the crossing the information
// is diagonal: J = diag(4, 4, sum x^2 + sum y^2) / sigma^2 = diag(4, 4, 43) / sigma^2.
TEST(Bound, TwoPerpendicularLinesClosedForm) {
  const Field f = cross_field();
  const double sigma = 0.02;
  for (const double theta : {0.0, 0.3, -2.0}) {  // the robot's heading does not change the geometry
    const Pose2 pose(0, 0, theta);
    const Eigen::Matrix3d J = frame_information(rows_at(f, pose, kCross, sigma), Eigen::Matrix2d::Zero());
    const CovarianceBound b = invert_information(J);
    ASSERT_TRUE(b.finite);
    EXPECT_NEAR(b.cov(0, 0), sigma * sigma / 4.0, 1e-15);
    EXPECT_NEAR(b.cov(1, 1), sigma * sigma / 4.0, 1e-15);
    EXPECT_NEAR(b.cov(2, 2), sigma * sigma / 43.0, 1e-15);
    EXPECT_NEAR(b.cov(0, 1), 0.0, 1e-15);
    EXPECT_NEAR(b.cov(0, 2), 0.0, 1e-15);
    EXPECT_NEAR(std::sqrt(b.cov(0, 0) + b.cov(1, 1)), sigma / std::sqrt(2.0), 1e-15);
  }
}

// Points on one line leave the translation along it unknown: no finite bound, and the run's
// summary names why (as it does for too few points, none, and a covered camera).
TEST(Bound, OneLineIsUnboundedAndSaysWhy) {
  const Field f = cross_field();
  const Pose2 pose(0.5, 0.7, 0.2);
  const std::vector<Eigen::Vector2d> line = {{-3, 0}, {-1, 0}, {1.5, 0}, {2.5, 0}, {4, 0}};
  EXPECT_FALSE(invert_information(frame_information(rows_at(f, pose, line, 0.02), Eigen::Matrix2d::Zero())).finite);

  RobotRecord rec;
  const auto frame = [&](const std::vector<Eigen::Vector2d>& world, bool ok) {
    rec.frames.push_back(frame_seeing(pose, world, 0.1 * static_cast<double>(rec.frames.size()), ok));
  };
  // Float points are not exactly on the lines: the run's measured noise is that rounding.
  frame({{2, 0}, {-2, 0}, {3, 0}, {0, 1.5}, {0, -1.5}, {0, 2.5}}, true);
  frame(line, true);
  frame({{2, 0}, {0, 2}}, true);
  frame({}, true);
  frame(line, false);
  BoundSetup setup;
  setup.field = &f;
  const RobotBound b = bound_robot(rec, setup);
  EXPECT_TRUE(b.frames[0].pos.has_value());
  EXPECT_FALSE(b.frames[1].pos.has_value());
  EXPECT_EQ(b.bound["no_bound"]["why"]["points on one line"], 1);
  EXPECT_EQ(b.bound["no_bound"]["why"]["fewer than 3 points"], 1);
  EXPECT_EQ(b.bound["no_bound"]["why"]["no points"], 1);
  EXPECT_EQ(b.bound["no_bound"]["why"]["camera not ok"], 1);
  EXPECT_EQ(b.bound["no_bound"]["frames"], 4);
  EXPECT_EQ(b.bound["single_frame"]["frames"], 1);
  EXPECT_DOUBLE_EQ(b.bound["single_frame"]["share"].get<double>(), 0.2);
  // Nothing to average: the efficiency is null with a reason, never 0.
  EXPECT_TRUE(b.efficiency["position"].is_null());
  EXPECT_TRUE(b.efficiency.contains("why_null"));
}

// The grid the bound matches through gives every point the match it has against every marking, to the
// last bit: random points over each field preset's floor and beyond, and the hard places (segment
// ends, arc centres and ends, spots, the points halfway between two parallel lines).
TEST(Bound, TheGridMatchIsTheMatchAgainstEveryMarking) {
  for (const std::string& name : Field::preset_names()) {
    const Field f = Field::preset(name);
    std::vector<Eigen::Vector2d> pts;
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> ux(-f.half_floor_x() - 1.5, f.half_floor_x() + 1.5), uy(-f.half_floor_y() - 1.5, f.half_floor_y() + 1.5);
    for (int i = 0; i < 100000; ++i) pts.emplace_back(ux(rng), uy(rng));
    const auto near = [&](const Eigen::Vector2d& c) {
      for (double dx : {-0.3, -1e-7, 0.0, 1e-7, 0.3})
        for (double dy : {-0.3, -1e-7, 0.0, 1e-7, 0.3}) pts.emplace_back(c + Eigen::Vector2d(dx, dy));
    };
    for (const auto& s : f.segments) {
      near(s.a);
      near(s.b);
      near(0.5 * (s.a + s.b));
      for (const auto& t : f.segments) near(0.5 * (s.a + t.a));
    }
    for (const auto& a : f.arcs) {
      near(a.centre);
      near(a.centre + a.radius * Eigen::Vector2d(std::cos(a.start), std::sin(a.start)));
      near(a.centre + a.radius * Eigen::Vector2d(std::cos(a.start + a.sweep), std::sin(a.start + a.sweep)));
    }
    for (const auto& sp : f.spots) near(sp.centre);
    const std::vector<MarkingMatch> grid = match_markings(f, pts);
    std::size_t matched = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const MarkingMatch all = match_marking(f, pts[i]);
      const MarkingMatch& g = grid[i];
      if (!(std::fabs(all.residual) < kMatchReach) || all.kind == 0) {
        EXPECT_EQ(g.kind, 0) << name << " point " << pts[i].transpose();
        continue;
      }
      ++matched;
      ASSERT_EQ(g.kind, all.kind) << name << " point " << pts[i].transpose();
      ASSERT_EQ(g.marking, all.marking) << name << " point " << pts[i].transpose();
      ASSERT_EQ(g.residual, all.residual) << name << " point " << pts[i].transpose();
      if (all.kind == 1) {
        ASSERT_EQ(g.normal, all.normal) << name << " point " << pts[i].transpose();
      }
    }
    EXPECT_GT(matched, pts.size() / 10) << name;
  }
}

// The run's noise figure is the exact 1.4826 x MAD of its residuals also on samples large enough for
// the bound's sampled selection (8192 residuals and more in one class): equal, to the last bit, to
// the median and MAD found here by sorting, for an even and an odd count, heavy tails included.
TEST(Bound, NoiseOfALargeSampleIsTheExactMedianAbsoluteDeviation) {
  Field f;
  f.segments.push_back({{-20.0, 0.0}, {20.0, 0.0}});
  const Pose2 pose(0.0, -2.0, 0.3);  // 2 m from the line: every point in the band 1.5-3 m, none grazing
  for (const int extra : {0, 1}) {
    RobotRecord rec;
    std::mt19937_64 rng(17);
    std::normal_distribution<double> noise(0.0, 0.02);
    std::uniform_real_distribution<double> along(-1.0, 1.0);
    std::vector<double> res;
    for (int k = 0; k < 200; ++k) {
      FrameRecord r;
      r.t = 0.1 * k;
      r.truth = pose;
      r.camera_ok = true;
      const int n = 50 + (k == 0 ? extra : 0);
      for (int i = 0; i < n; ++i) {
        const double e = (i % 25 == 0 ? 7.5 : 1.0) * noise(rng);  // one in 25 from a 15 cm spread: the heavy tail
        const Eigen::Vector2d p = pose.inverse_transform(Eigen::Vector2d(along(rng), e));
        r.line_points.push_back({static_cast<float>(p.x()), static_cast<float>(p.y())});
        // The residual the bound takes: the float point mapped back at the true pose.
        const Eigen::Vector2d q(r.line_points.back()[0], r.line_points.back()[1]);
        res.push_back(match_marking(f, pose.rotation() * q + pose.translation()).residual);
      }
      rec.frames.push_back(r);
    }
    ASSERT_EQ(res.size(), 10000u + static_cast<std::size_t>(extra));
    const auto median = [](std::vector<double> v) {
      std::sort(v.begin(), v.end());
      const std::size_t h = v.size() / 2;
      return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
    };
    const double m = median(res);
    std::vector<double> dev;
    for (double x : res) dev.push_back(std::fabs(x - m));
    const double expected = 1.4826 * median(dev);
    BoundSetup setup;
    setup.field = &f;
    const RobotBound b = bound_robot(rec, setup);
    const Json& n = b.bound["noise"];
    EXPECT_EQ(n["band_points"][1].get<std::size_t>() + n["grazing_points"][1].get<std::size_t>() + n["false_points"].get<std::size_t>(),
              res.size());
    EXPECT_EQ(n["total_sigma_m"][1].get<double>(), expected) << "extra point " << extra;
  }
}

// After a kidnap the posterior bound of the blind frames is an average over where the robot may be
// put, which one run's error can lie below: the efficiency over all frames says so where it stands,
// and only when the run had a kidnap.
TEST(Bound, AKidnapRunsAllFramesEfficiencySaysToReadTheTrackingPhase) {
  const Field f = cross_field();
  const Pose2 pose(0.5, 0.7, 0.2);
  RobotRecord rec;
  for (int k = 0; k < 10; ++k) {
    FrameRecord r = frame_seeing(pose, kCross, 0.1 * k, true);
    r.est = pose;
    r.valid = true;
    rec.frames.push_back(r);
  }
  BoundSetup setup;
  setup.field = &f;
  setup.start_pose_given = true;
  EXPECT_FALSE(bound_robot(rec, setup).efficiency.contains("all_frames_note"));
  setup.resets = {0.45};
  setup.excluded = {{0.45, 0.65}};
  const RobotBound b = bound_robot(rec, setup);
  EXPECT_TRUE(b.efficiency.contains("all_frames_note"));
  EXPECT_TRUE(b.efficiency.contains("tracking_phase"));
  setup.has_odometry = false;  // against the single-frame bound, which a kidnap does not reset
  EXPECT_FALSE(bound_robot(rec, setup).efficiency.contains("all_frames_note"));
}

// A compass adds exactly 1 / sigma^2 to the heading information: with the diagonal geometry above
// the heading variance goes from sigma_p^2 / 43 to 1 / (43 / sigma_p^2 + 1 / sigma_c^2).
TEST(Bound, CompassAddsItsInformation) {
  const Field f = cross_field();
  RobotRecord with, without;
  for (int k = 0; k < 3; ++k) {
    FrameRecord r;
    r.t = 0.1 * k;
    r.camera_ok = true;
    for (const auto& w : kCross) r.line_points.push_back({static_cast<float>(w.x()), static_cast<float>(w.y())});
    without.frames.push_back(r);
    r.heading = 0.0;
    with.frames.push_back(r);
  }
  BoundSetup setup;
  setup.field = &f;
  const RobotBound b0 = bound_robot(without, setup);
  setup.has_heading_sensor = true;
  setup.heading_sigma = 0.01;
  const RobotBound b1 = bound_robot(with, setup);
  ASSERT_TRUE(b0.frames[0].heading && b1.frames[0].heading);
  const double j0 = 1.0 / std::pow(*b0.frames[0].heading, 2), j1 = 1.0 / std::pow(*b1.frames[0].heading, 2);
  EXPECT_NEAR(j1 - j0, 1.0 / (0.01 * 0.01), 1e-9 * j1);
  EXPECT_EQ(*b0.frames[0].pos, *b1.frames[0].pos);  // the heading is uncoupled here: position unchanged
}

// The tilt's first-order floor shift against the exact intersection of the turned ray with the
// floor: (r^2 + h^2) / h per radian towards the point, h across it.
TEST(Bound, TiltJacobianMatchesTheRayGeometry) {
  const double h = 0.75, eps = 1e-7;
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(5, 0), Eigen::Vector2d(-1.2, 3.3), Eigen::Vector2d(0.4, -0.9)}) {
    const Eigen::Matrix2d M = floor_tilt_jacobian(p, h);
    for (int axis = 0; axis < 2; ++axis) {
      Eigen::Vector3d w = Eigen::Vector3d::Zero();
      w(axis) = eps;
      const Eigen::Vector3d ray = Eigen::AngleAxisd(w.norm(), w.normalized()) * Eigen::Vector3d(p.x(), p.y(), -h);
      const Eigen::Vector2d hit = ray.head<2>() * (h / -ray.z());
      EXPECT_NEAR((hit - p).x() / eps, M(0, axis), 1e-5 * (1 + M.norm()));
      EXPECT_NEAR((hit - p).y() / eps, M(1, axis), 1e-5 * (1 + M.norm()));
    }
  }
  EXPECT_NEAR(floor_tilt_jacobian({5, 0}, h).col(1).norm(), (25 + h * h) / h, 1e-12);
  EXPECT_NEAR(floor_tilt_jacobian({5, 0}, h).col(0).norm(), h, 1e-12);
}

// The Woodbury form equals H^T R^-1 H with R = D + A C A^T built densely, tilt and marking offsets.
TEST(Bound, InformationEqualsDenseGeneralizedLeastSquares) {
  const Field f = cross_field();
  const Pose2 pose(0.3, -0.2, 0.4);
  std::vector<BoundRow> rows = rows_at(f, pose, kCross, 0.02);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    rows[i].line = i < 4 ? 0 : 1;
    rows[i].load = 0.02 + 0.01 * static_cast<double>(i);
    rows[i].var = 1e-4 * (1.0 + 0.3 * static_cast<double>(i));
  }
  Eigen::Matrix2d C;
  C << 2.5e-5, 3e-6, 3e-6, 1.5e-5;
  const double rho = 0.2;
  const int n = static_cast<int>(rows.size());
  Eigen::MatrixXd H(n, 3), R = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    H.row(i) = rows[static_cast<std::size_t>(i)].h.transpose();
    for (int j = 0; j < n; ++j) {
      const auto& a = rows[static_cast<std::size_t>(i)];
      const auto& b = rows[static_cast<std::size_t>(j)];
      R(i, j) = a.a.dot(C * b.a) + (a.line == b.line ? rho * a.load * b.load : 0.0) + (i == j ? a.var : 0.0);
    }
  }
  const Eigen::Matrix3d dense = H.transpose() * R.ldlt().solve(H);
  const Eigen::Matrix3d fast = frame_information(rows, C, rho);
  EXPECT_LT((dense - fast).cwiseAbs().maxCoeff(), 1e-9 * dense.cwiseAbs().maxCoeff());
}

// Monte Carlo: synthetic points on lines and the centre circle with the stated noise (white per
// range, a per-frame tilt, an offset per marking); a Gauss-Newton generalized least-squares fit
// with the true association reaches the bound within 10 % over 2000 trials, and neither it nor an
// ordinary least-squares fit (ignoring the correlations) beats it beyond sampling error.
TEST(Bound, MonteCarloEfficientEstimatorReachesTheBound) {
  Field f;
  f.segments = {{{-9, -6}, {9, -6}}, {{-9, -6}, {-9, 6}}, {{0, -6}, {0, 6}}, {{-9, 2}, {-6, 2}}};
  f.arcs.push_back({{0, 0}, 2.0, 0.0, kTwoPi});
  const Pose2 truth(-3.0, -2.5, 0.5);
  const double h = 0.75;
  std::vector<Eigen::Vector2d> world;
  for (double x = -8.5; x <= -0.5; x += 0.5) world.push_back({x, -6});
  for (double y = -5.5; y <= 1.5; y += 0.6) world.push_back({-9, y});
  for (double y = -5.0; y <= 1.0; y += 0.5) world.push_back({0, y});
  for (double a = 2.5; a <= 4.6; a += 0.25) world.push_back(Eigen::Vector2d(std::cos(a), std::sin(a)) * 2.0);
  const auto sigma_of = [](double r) { return 0.01 + 0.004 * r; };
  const Eigen::Matrix2d C = Eigen::Matrix2d::Identity() * std::pow(0.004, 2);
  const double rho = 0.15;
  std::vector<BoundRow> rows;
  std::vector<MarkingMatch> match;
  std::vector<Eigen::Vector2d> robot;
  for (const auto& w : world) {
    const MarkingMatch m = match_marking(f, w);
    const Eigen::Vector2d p = truth.inverse_transform(w);
    const double s = sigma_of(p.norm());
    BoundRow row = bound_row(m, w, truth, p, (1 - rho) * s * s, h);
    row.line = m.marking;
    row.load = s;
    rows.push_back(row);
    match.push_back(m);
    robot.push_back(p);
  }
  const CovarianceBound bound = invert_information(frame_information(rows, C, rho));
  ASSERT_TRUE(bound.finite);
  const int n = static_cast<int>(rows.size());
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const auto& a = rows[static_cast<std::size_t>(i)];
      const auto& b = rows[static_cast<std::size_t>(j)];
      R(i, j) = a.a.dot(C * b.a) + (a.line == b.line ? rho * a.load * b.load : 0.0) + (i == j ? a.var : 0.0);
    }
  const Eigen::MatrixXd W = R.inverse();
  // The signed distance of world point w to point i's own marking (known association).
  const auto residual = [&](std::size_t i, const Eigen::Vector2d& w) {
    if (match[i].marking < static_cast<int>(f.segments.size())) {
      const auto& s = f.segments[static_cast<std::size_t>(match[i].marking)];
      const Eigen::Vector2d d = (s.b - s.a).normalized();
      return Eigen::Vector2d(-d.y(), d.x()).dot(w - s.a);
    }
    return (w - f.arcs[0].centre).norm() - f.arcs[0].radius;
  };
  std::mt19937_64 rng(20261128);
  std::normal_distribution<double> N01;
  const int trials = 2000;
  Eigen::Vector3d mse_gls = Eigen::Vector3d::Zero(), mse_ols = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector2d> noisy(world.size());
  for (int t = 0; t < trials; ++t) {
    const Eigen::Vector2d tilt(N01(rng) * 0.004, N01(rng) * 0.004);
    std::vector<double> offset(f.segments.size() + f.arcs.size());
    for (double& o : offset) o = N01(rng) * std::sqrt(rho);
    for (std::size_t i = 0; i < world.size(); ++i) {
      const double s = sigma_of(robot[i].norm());
      // The errors as the model makes them: the tilt moves the point on the floor, the marking's
      // offset and the white noise move it along the marking's normal (robot frame).
      const Eigen::Vector2d nr = truth.rotation().transpose() * match[i].normal;
      noisy[i] = robot[i] + floor_tilt_jacobian(robot[i], h) * tilt + nr * (s * offset[static_cast<std::size_t>(match[i].marking)] + std::sqrt(1 - rho) * s * N01(rng));
    }
    for (int which = 0; which < 2; ++which) {
      Eigen::Vector3d x(truth.x, truth.y, truth.theta);
      for (int it = 0; it < 6; ++it) {
        const Pose2 p(x(0), x(1), x(2));
        Eigen::MatrixXd H(n, 3);
        Eigen::VectorXd e(n);
        for (std::size_t i = 0; i < world.size(); ++i) {
          const Eigen::Vector2d w = p.transform(noisy[i]);
          const double r0 = residual(i, w);
          // d(residual)/d(pose) by the residual's own gradient (central differences, exact enough).
          for (int k = 0; k < 3; ++k) {
            Eigen::Vector3d dx = Eigen::Vector3d::Zero();
            dx(k) = 1e-6;
            const Pose2 a(x(0) + dx(0), x(1) + dx(1), x(2) + dx(2)), b(x(0) - dx(0), x(1) - dx(1), x(2) - dx(2));
            H(static_cast<int>(i), k) = (residual(i, a.transform(noisy[i])) - residual(i, b.transform(noisy[i]))) / 2e-6;
          }
          e(static_cast<int>(i)) = r0;
        }
        const Eigen::MatrixXd Wk = which == 0 ? W : Eigen::MatrixXd::Identity(n, n);
        x -= (H.transpose() * Wk * H).ldlt().solve(H.transpose() * Wk * e);
      }
      const Eigen::Vector3d err(x(0) - truth.x, x(1) - truth.y, angle_diff(x(2), truth.theta));
      (which == 0 ? mse_gls : mse_ols) += err.cwiseProduct(err) / trials;
    }
  }
  const double pos_bound = bound.cov(0, 0) + bound.cov(1, 1), th_bound = bound.cov(2, 2);
  const double pos_gls = mse_gls(0) + mse_gls(1), pos_ols = mse_ols(0) + mse_ols(1);
  std::printf("position MSE / bound: GLS %.4f, OLS %.4f; heading: GLS %.4f, OLS %.4f\n", pos_gls / pos_bound, pos_ols / pos_bound,
              mse_gls(2) / th_bound, mse_ols(2) / th_bound);
  EXPECT_NEAR(pos_gls / pos_bound, 1.0, 0.10);
  EXPECT_NEAR(mse_gls(2) / th_bound, 1.0, 0.10);
  // A mean square over N trials has a relative standard error of sqrt(2 / N) (3 % for 2000): below
  // the bound by more than three of them is a beaten bound.
  const double floor = 1.0 - 3.0 * std::sqrt(2.0 / trials);
  EXPECT_GT(pos_gls / pos_bound, floor);
  EXPECT_GT(mse_gls(2) / th_bound, floor);
  EXPECT_GT(pos_ols / pos_bound, floor);
  EXPECT_GT(mse_ols(2) / th_bound, floor);
  // Ignoring the tilt and the offsets costs accuracy: the correlations are real in this model.
  EXPECT_GT(pos_ols, 1.1 * pos_gls);
}

// The posterior recursion against a Kalman filter on a linear Gaussian system: the same covariance
// at every step to 1e-12, also through frames without a measurement and from a known start.
TEST(Bound, PosteriorEqualsKalmanCovariance) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(3, 3), Pk = P;  // a known start: zero covariance
  for (int k = 0; k < 60; ++k) {
    Eigen::MatrixXd F = Eigen::MatrixXd::Identity(3, 3);
    F(0, 2) = 0.1 * U(rng);
    F(1, 2) = 0.1 * U(rng);
    Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(3, 3);
    Q.diagonal() << 1e-4 * (1 + U(rng)), 1e-4 * (1 + U(rng)), 1e-5 * (1 + U(rng));
    Eigen::MatrixXd Hm(2, 3);
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 3; ++j) Hm(i, j) = U(rng);
    Eigen::Matrix2d Rm;
    Rm << 4e-4, 1e-4, 1e-4, 9e-4;
    const bool measured = k % 7 != 3;  // every seventh frame without a measurement (camera covered)
    const Eigen::MatrixXd Jz = measured ? Eigen::MatrixXd(Hm.transpose() * Rm.inverse() * Hm) : Eigen::MatrixXd::Zero(3, 3);
    P = posterior_step(P, F, Q, Jz);
    const Eigen::MatrixXd Pp = F * Pk * F.transpose() + Q;
    if (measured) {
      const Eigen::MatrixXd K = Pp * Hm.transpose() * (Hm * Pp * Hm.transpose() + Rm).inverse();
      Pk = (Eigen::MatrixXd::Identity(3, 3) - K * Hm) * Pp;
      Pk = 0.5 * (Pk + Pk.transpose());
    } else {
      Pk = Pp;
    }
    EXPECT_LT((P - Pk).cwiseAbs().maxCoeff(), 1e-12) << "step " << k;
  }
}

// The posterior bound's own check: the filter the bound describes, run on measurements drawn as
// the model says (each frame's error independent, with the frame's information as its inverse
// covariance, and the process error drawn from Q), misses its own covariance by no more than
// sampling error; the same measurements made to repeat from frame to frame (an AR(1) error with
// correlation 0.95 and the same marginal covariance: the same line at the same pixels for seconds)
// make it miss by more than 1.3, which is what the check is there to show.
TEST(Bound, PosteriorCheckFindsFrameToFrameCorrelation) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> N01;
  const int frames = 4000;
  const Eigen::Matrix3d info = Eigen::Vector3d(1.0 / 1e-4, 1.0 / 4e-4, 1.0 / 1e-5).asDiagonal();  // 1 cm, 2 cm, 3 mrad
  const Eigen::Matrix3d cov = info.inverse();
  Eigen::Matrix3d Q = Eigen::Vector3d(4e-6, 4e-6, 1e-6).asDiagonal();  // 2 mm, 1 mrad per frame
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  F(0, 2) = -0.02;
  F(1, 2) = 0.03;
  for (const double rho : {0.0, 0.95}) {
    std::vector<OracleStep> steps(frames);
    Eigen::Vector3d z = Eigen::Vector3d::Zero();
    for (int k = 0; k < frames; ++k) {
      OracleStep& s = steps[static_cast<std::size_t>(k)];
      s.F = F;
      s.Q = Q;
      s.info = info;
      s.process_error = Eigen::Vector3d(std::sqrt(Q(0, 0)) * N01(rng), std::sqrt(Q(1, 1)) * N01(rng), std::sqrt(Q(2, 2)) * N01(rng));
      // The frame's measurement error z (the efficient single-frame estimator's error, covariance
      // info^-1), correlated with the previous frame's by rho; the score is -info z.
      const Eigen::Vector3d fresh(std::sqrt(cov(0, 0)) * N01(rng), std::sqrt(cov(1, 1)) * N01(rng), std::sqrt(cov(2, 2)) * N01(rng));
      z = k == 0 ? fresh : Eigen::Vector3d(rho * z + std::sqrt(1 - rho * rho) * fresh);
      // The state's error moves with its process error; the measurement sees the state plus z, so
      // relative to the filter's error-state model the frame's error is z.
      s.score = -info * z;
    }
    const OracleResult r = posterior_oracle(steps, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero(), 1.0);
    const double pos = std::sqrt(r.pos_sq / r.pos_var), th = std::sqrt(r.heading_sq / r.heading_var);
    std::printf("correlation %.2f: the check's filter at %.3f x its position covariance, %.3f x its heading\n", rho, pos, th);
    ASSERT_EQ(r.frames, static_cast<std::size_t>(frames));
    if (rho == 0.0) {
      // A mean square over ~4000 frames of a filter whose errors are correlated over a few frames:
      // a few per cent of sampling error.
      EXPECT_NEAR(pos, 1.0, 0.06);
      EXPECT_NEAR(th, 1.0, 0.06);
    } else {
      EXPECT_GT(pos, 1.3);
    }
  }
}

// Errors carried from frame to frame, closed form: a robot standing still (no motion, no process
// noise) sees the same frame information J every frame, and a share rho of each frame's error is
// the same in every frame (a = 1). The best estimate after n frames is their mean, whose covariance
// is J^-1 (rho + (1 - rho) / n): the carried share is never averaged away. With rho = 0 it is J^-1 / n.
TEST(Bound, CarriedErrorsStandingStillClosedForm) {
  Eigen::Matrix3d J;
  J << 1.0 / 1e-4, 2e3, 0.0, 2e3, 1.0 / 4e-4, 1e2, 0.0, 1e2, 1.0 / 1e-5;
  const Eigen::Matrix3d C = J.inverse();
  for (const double rho : {0.0, 0.3, 0.8}) {
    Eigen::MatrixXd P = Eigen::MatrixXd::Zero(6, 6);
    P.topLeftCorner(3, 3) = 1e6 * Eigen::Matrix3d::Identity();  // nothing known of the pose
    P.bottomRightCorner(3, 3).setIdentity();                    // z: unit variance
    const Eigen::MatrixXd F = Eigen::MatrixXd::Identity(6, 6), Q = Eigen::MatrixXd::Zero(6, 6);  // a = 1
    const Eigen::MatrixXd Jz = correlated_frame_information(J, rho, 6);
    for (int n = 1; n <= 40; ++n) {
      P = posterior_step(P, F, Q, Jz);
      const Eigen::Matrix3d want = C * (rho + (1.0 - rho) / n);
      EXPECT_LT(((P.topLeftCorner(3, 3) - want).array() / want.array().abs().max(1e-12)).abs().maxCoeff(), 1e-5) << "rho " << rho << " n " << n;
    }
  }
  // One frame's information marginalised over z (its prior: unit variance) is J itself: the model
  // keeps each frame's own covariance and adds only its correlation with the other frames.
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(6, 6);
  P.topLeftCorner(3, 3) = 0.01 * Eigen::Matrix3d::Identity();
  P.bottomRightCorner(3, 3).setIdentity();
  const Eigen::MatrixXd I6 = Eigen::MatrixXd::Identity(6, 6), Z6 = Eigen::MatrixXd::Zero(6, 6);
  const Eigen::MatrixXd Pc = posterior_step(P, I6, Z6, correlated_frame_information(J, 0.4, 6));
  const Eigen::Matrix3d Pw = (Eigen::Matrix3d(100.0 * Eigen::Matrix3d::Identity()) + J).inverse();
  EXPECT_LT((Pc.topLeftCorner(3, 3) - Pw).cwiseAbs().maxCoeff() / Pw.cwiseAbs().maxCoeff(), 1e-9);
}

// The temporal model's fit recovers the share and the coefficient of errors drawn as it says, pairs
// across a kidnap left out, and says why when a run is too short to measure them.
TEST(Bound, CarriedErrorsFitRecoversTheModel) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> N01;
  const auto draw = [&](double rho, double a, int n, std::vector<Eigen::Vector3d>& eta, std::vector<int>& seg) {
    Eigen::Vector3d z(N01(rng), N01(rng), N01(rng));
    for (int k = 0; k < n; ++k) {
      if (k == n / 2) z = Eigen::Vector3d(N01(rng), N01(rng), N01(rng));  // a kidnap: a new stretch
      z = a * z + std::sqrt(1 - a * a) * Eigen::Vector3d(N01(rng), N01(rng), N01(rng));
      eta.push_back(std::sqrt(rho) * z + std::sqrt(1 - rho) * Eigen::Vector3d(N01(rng), N01(rng), N01(rng)));
      seg.push_back(k < n / 2 ? 0 : 1);
    }
  };
  for (const auto& [rho, a] : {std::pair{0.3, 0.95}, std::pair{0.6, 0.8}, std::pair{0.0, 0.0}}) {
    std::vector<Eigen::Vector3d> eta;
    std::vector<int> seg;
    draw(rho, a, 40000, eta, seg);
    const TemporalCorrelation tc = fit_temporal_correlation(eta, std::vector<bool>(eta.size(), true), seg, 30);
    std::printf("drawn share %.2f coefficient %.2f: fitted %.3f %.3f\n", rho, a, tc.rho, tc.a);
    EXPECT_TRUE(tc.why.empty());
    EXPECT_EQ(tc.pairs, eta.size() - 2);  // the pair across the kidnap is not one
    EXPECT_NEAR(tc.rho, rho, 0.04);
    if (rho > 0) {
      EXPECT_NEAR(tc.a, a, 0.02);
    }
  }
  std::vector<Eigen::Vector3d> eta;
  std::vector<int> seg;
  draw(0.3, 0.95, 60, eta, seg);
  const TemporalCorrelation tc = fit_temporal_correlation(eta, std::vector<bool>(eta.size(), true), seg, 30);
  EXPECT_EQ(tc.rho, 0.0);
  EXPECT_NE(tc.why.find("fewer than 90 pairs"), std::string::npos) << tc.why;
}

// Monte Carlo: a linear Gaussian system whose frames carry errors as the model says (share 0.3,
// coefficient 0.95: about 20 frames of memory), frames of three kinds in turn, one of them with the
// points on one line only (information of rank 2). Over 1000 runs the temporal model's filter misses
// its covariance (the bound with carried errors) by no more than sampling error, well within 10 %;
// the filter that takes the frames as independent does not beat that bound, and misses its own
// covariance (the independent bound) by more than 10 %.
TEST(Bound, CarriedErrorsMonteCarloFilterReachesTheBoundNoneBeatsIt) {
  std::mt19937_64 rng(23);
  std::normal_distribution<double> N01;
  const double rho = 0.3, a = 0.95;
  TemporalCorrelation tc;
  tc.rho = rho;
  tc.a = a;
  std::array<Eigen::Matrix3d, 3> infos;
  infos[0] = Eigen::Vector3d(1.0 / 1e-4, 1.0 / 4e-4, 1.0 / 1e-5).asDiagonal();
  infos[1] << 1.0 / 2e-4, 3e3, 0.0, 3e3, 1.0 / 1e-4, 5e2, 0.0, 5e2, 1.0 / 3e-5;
  const Eigen::Vector3d n(0.6, 0.8, 0.3);  // one line: no information along (0.8, -0.6, 0)
  const Eigen::Vector3d along = Eigen::Vector3d(0.8, -0.6, 0.0).normalized();
  const Eigen::Vector3d other = n - n.dot(along) * along;
  infos[2] = 1e4 * (n * n.transpose()) + 3e4 * (other.cross(along).normalized() * other.cross(along).normalized().transpose());
  std::array<Eigen::Matrix3d, 3> roots;
  for (int i = 0; i < 3; ++i) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(infos[static_cast<std::size_t>(i)]);
    Eigen::Vector3d w = es.eigenvalues().cwiseMax(0.0).cwiseSqrt();
    roots[static_cast<std::size_t>(i)] = es.eigenvectors() * w.asDiagonal() * es.eigenvectors().transpose();
  }
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(3, 3);
  F(0, 2) = -0.02;
  F(1, 2) = 0.03;
  const Eigen::MatrixXd Q = Eigen::Vector3d(4e-6, 4e-6, 1e-6).asDiagonal();
  const int trials = 1000, frames = 150;
  OracleResult carried, white, white_own;
  for (int t = 0; t < trials; ++t) {
    std::vector<OracleStep> steps(frames);
    std::vector<Eigen::Vector3d> eta(frames);
    Eigen::Vector3d z(N01(rng), N01(rng), N01(rng));
    for (int k = 0; k < frames; ++k) {
      OracleStep& s = steps[static_cast<std::size_t>(k)];
      const std::size_t kind = static_cast<std::size_t>(k % 3);
      s.F = F;
      s.Q = Q;
      s.info = infos[kind];
      s.process_error = Eigen::Vector3d(std::sqrt(Q(0, 0)) * N01(rng), std::sqrt(Q(1, 1)) * N01(rng), std::sqrt(Q(2, 2)) * N01(rng));
      if (k > 0) z = a * z + std::sqrt(1 - a * a) * Eigen::Vector3d(N01(rng), N01(rng), N01(rng));
      const Eigen::Vector3d fresh(N01(rng), N01(rng), N01(rng));
      Eigen::Vector3d e = std::sqrt(rho) * z + std::sqrt(1 - rho) * fresh;
      if (kind == 2) e -= e.dot(along) * along;  // nothing is measured along the line
      eta[static_cast<std::size_t>(k)] = e;
      s.score = -(roots[kind] * e);  // eta = -J^{-1/2} score on J's range
      if (t == 0) {
        EXPECT_LT((whitened_error(s.info, s.score) - e).norm(), 1e-9) << "frame " << k;  // and back, on one line too
      }
    }
    const OracleResult r = posterior_oracle_correlated(steps, eta, tc, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero(), 1.0, &white);
    if (t == 0) {
      // The bound's recursion (posterior_step on the frames' information with carried errors) is
      // the covariance this filter carries: the same variances, frame by frame.
      Eigen::MatrixXd P = Eigen::MatrixXd::Zero(6, 6), Fa = Eigen::MatrixXd::Zero(6, 6), Qa = Eigen::MatrixXd::Zero(6, 6);
      P.bottomRightCorner(3, 3).setIdentity();
      Fa.topLeftCorner(3, 3) = F;
      Fa.bottomRightCorner(3, 3) = a * Eigen::Matrix3d::Identity();
      Qa.topLeftCorner(3, 3) = Q;
      Qa.bottomRightCorner(3, 3) = (1 - a * a) * Eigen::Matrix3d::Identity();
      double pos_var = 0;
      for (int k = 0; k < frames; ++k) {
        const Eigen::MatrixXd Jz = correlated_frame_information(infos[static_cast<std::size_t>(k % 3)], rho, 6);
        P = k == 0 ? posterior_step(P, Eigen::MatrixXd::Identity(6, 6), Eigen::MatrixXd::Zero(6, 6), Jz) : posterior_step(P, Fa, Qa, Jz);
        pos_var += P(0, 0) + P(1, 1);
      }
      EXPECT_NEAR(pos_var / r.pos_var, 1.0, 1e-9);
    }
    carried.pos_sq += r.pos_sq;
    carried.pos_var += r.pos_var;
    carried.heading_sq += r.heading_sq;
    carried.heading_var += r.heading_var;
    const OracleResult w = posterior_oracle(steps, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero(), 1.0);
    white_own.pos_sq += w.pos_sq;
    white_own.pos_var += w.pos_var;
  }
  const double c_pos = std::sqrt(carried.pos_sq / carried.pos_var), c_th = std::sqrt(carried.heading_sq / carried.heading_var);
  const double w_pos = std::sqrt(white.pos_sq / white.pos_var), w_th = std::sqrt(white.heading_sq / white.heading_var);
  const double w_own = std::sqrt(white_own.pos_sq / white_own.pos_var);
  std::printf("carried errors: their filter at %.3f / %.3f x the bound (position / heading); the independent filter at %.3f / %.3f x it "
              "and %.3f x its own covariance\n",
              c_pos, c_th, w_pos, w_th, w_own);
  EXPECT_NEAR(c_pos, 1.0, 0.05);
  EXPECT_NEAR(c_th, 1.0, 0.05);
  EXPECT_GT(w_pos, 0.97);
  EXPECT_GT(w_th, 0.97);
  EXPECT_GT(w_own, 1.1);
}

// RPE over one frame (TUM / evo, no alignment): one estimate 3 cm off sideways spoils the two pairs
// it belongs to by exactly 3 cm each; over one second there is no pair in half a second of frames
// (null, never 0); a pair across a teleport is left out.
TEST(Rpe, OneFrameJitterAndNullWithoutPairs) {
  RobotRecord rec;
  for (int k = 0; k < 5; ++k) {
    FrameRecord r;
    r.t = 0.1 * k;
    r.truth = Pose2(0.1 * k, 0.0, 0.0);
    r.est = r.truth;
    if (k == 2) r.est.y += 0.03;
    r.valid = true;
    rec.frames.push_back(r);
  }
  const Json j = rpe_json(rec, {});
  EXPECT_EQ(j["frame"]["pairs"], 4);
  EXPECT_NEAR(j["frame"]["translation_rms_m"].get<double>(), 0.03 / std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(j["frame"]["rotation_rms_rad"].get<double>(), 0.0, 1e-12);
  EXPECT_EQ(j["1s"]["pairs"], 0);
  EXPECT_TRUE(j["1s"]["translation_rms_m"].is_null());
  // A teleport at the frame of t = 0.1 s moves the robot after that frame: the pair (0.1, 0.2) goes.
  const Json m = rpe_json(rec, {0.1});
  EXPECT_EQ(m["frame"]["pairs"], 3);
  EXPECT_NEAR(m["frame"]["translation_rms_m"].get<double>(), 0.03 / std::sqrt(3.0), 1e-12);
}
