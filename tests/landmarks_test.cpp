// Landmark positioning solvers (localization/landmarks): exactness on noise-free bearings away from
// each solver's singular set, agreement between solvers, refusal of every degenerate input, and
// least squares over 4-6 landmarks against a single triple under bearing noise.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "core/angles.hpp"
#include "core/rng.hpp"
#include "experiments/landmark_maps.hpp"
#include "localization/landmarks/landmark_solvers.hpp"
#include "testing/scenes.hpp"

using namespace omniloc;
using namespace omniloc::landmarks;
using scenes::circumcircle;
using scenes::distance_to_circle;
using scenes::distance_to_line;

namespace {

using Solver = std::function<Fix(std::span<const BearingObs>)>;

struct NamedSolver {
  const char* name;
  Solver solve;
  // Singular set as a predicate "within `margin` metres of it" (see below).
  bool (*near_singular)(const std::vector<Eigen::Vector2d>& L, const Eigen::Vector2d& p, double margin);
};

/// Noise-free (or noisy) bearings of landmarks L seen from pose.
std::vector<BearingObs> observe(const std::vector<Eigen::Vector2d>& L, const Pose2& pose, Rng* rng = nullptr, double sigma = 0.0) {
  std::vector<BearingObs> obs;
  for (const auto& l : L) {
    double b = wrap_angle(std::atan2(l.y() - pose.y, l.x() - pose.x) - pose.theta);
    if (rng) b += rng->normal(0.0, sigma);
    obs.push_back({l, b});
  }
  return obs;
}

// Singular sets, per solver:
//  circle only (total_like, circle_intersection_003): robot within `margin` of the circle through
//    the three landmarks (this includes being within `margin` of a landmark);
//  circle + two lines (three_point_004, two_circle_004): also within `margin` of the line through
//    landmarks 0 and 1 or 1 and 2 (the robot sees that pair in the same or opposite direction: the
//    landmarks nearly collinear as seen from the robot; the methods divide by the sine of that angle).
bool near_circle(const std::vector<Eigen::Vector2d>& L, const Eigen::Vector2d& p, double margin) {
  return distance_to_circle(L[0], L[1], L[2], p) < margin;
}
bool near_circle_or_lines(const std::vector<Eigen::Vector2d>& L, const Eigen::Vector2d& p, double margin) {
  return near_circle(L, p, margin) || distance_to_line(L[0], L[1], p) < margin || distance_to_line(L[1], L[2], p) < margin;
}

const std::vector<NamedSolver>& closed_forms() {
  static const std::vector<NamedSolver> s = {
      {"three_point_004", three_point_004, near_circle_or_lines},
      {"two_circle_004", two_circle_004, near_circle_or_lines},
      {"circle_intersection_003", circle_intersection_003, near_circle},
      {"total_like", total_like, near_circle},
  };
  return s;
}

/// Three landmarks in an 18 m x 12 m field, at least 2 m apart, every triangle angle over 15 degrees.
std::vector<Eigen::Vector2d> random_triangle(Rng& rng) {
  for (;;) {
    std::vector<Eigen::Vector2d> L;
    for (int i = 0; i < 3; ++i) L.emplace_back(rng.uniform(-9, 9), rng.uniform(-6, 6));
    bool good = true;
    for (int i = 0; i < 3 && good; ++i) {
      const Eigen::Vector2d u = L[(i + 1) % 3] - L[i], v = L[(i + 2) % 3] - L[i];
      if (u.norm() < 2.0) good = false;
      const double ang = std::acos(std::clamp(u.dot(v) / (u.norm() * v.norm()), -1.0, 1.0));
      if (ang < deg2rad(15)) good = false;
    }
    if (good) return L;
  }
}

Pose2 random_pose(Rng& rng) { return Pose2(rng.uniform(-10, 10), rng.uniform(-7, 7), rng.uniform(-kPi, kPi)); }

double pos_err(const Fix& f, const Pose2& p) { return std::hypot(f.pose.x - p.x, f.pose.y - p.y); }

void expect_clean_refusal(const Fix& f, const std::string& what) {
  EXPECT_FALSE(f.ok) << what;
  EXPECT_FALSE(f.reason.empty()) << what;
  EXPECT_TRUE(std::isfinite(f.pose.x) && std::isfinite(f.pose.y) && std::isfinite(f.pose.theta)) << what;
  EXPECT_TRUE(std::isfinite(f.reliability)) << what;
}

constexpr double kMargin = 0.2;  // metres from the singular set: skipped in the exactness test
constexpr double kTolPos = 1e-6, kTolAng = 1e-6;

}  // namespace

TEST(Landmarks, ClosedFormsExactOnNoiseFreeBearingsAwayFromTheirSingularSets) {
  for (const auto& s : closed_forms()) {
    Rng rng(20240501);
    int evaluated = 0, skipped = 0, draws = 0;
    double worst_pos = 0, worst_ang = 0;
    while (evaluated < 200) {
      ASSERT_LT(++draws, 2000) << s.name;
      const auto L = random_triangle(rng);
      const Pose2 truth = random_pose(rng);
      if (s.near_singular(L, truth.translation(), kMargin)) {
        ++skipped;
        continue;
      }
      ++evaluated;
      const Fix f = s.solve(observe(L, truth));
      ASSERT_TRUE(f.ok) << s.name << ": " << f.reason;
      EXPECT_GT(f.reliability, 0.0);
      worst_pos = std::max(worst_pos, pos_err(f, truth));
      worst_ang = std::max(worst_ang, std::fabs(angle_diff(f.pose.theta, truth.theta)));
    }
    EXPECT_LT(worst_pos, kTolPos) << s.name;
    EXPECT_LT(worst_ang, kTolAng) << s.name;
    std::printf("  %-24s 200 poses recovered (worst %.1e m, %.1e rad); %d skipped within %.1f m of the singular set\n", s.name,
                worst_pos, worst_ang, skipped, kMargin);
    EXPECT_LT(skipped, 200) << s.name;  // the skipped set is a thin band, not most of the field
  }
}

TEST(Landmarks, LeastSquaresExactOnNoiseFreeBearings) {
  Rng rng(7);
  for (int n = 3; n <= 6; ++n) {
    int evaluated = 0;
    while (evaluated < 50) {
      auto L = random_triangle(rng);
      while (static_cast<int>(L.size()) < n) L.emplace_back(rng.uniform(-9, 9), rng.uniform(-6, 6));
      const Pose2 truth = random_pose(rng);
      bool near_landmark = false;
      for (const auto& l : L) near_landmark |= (l - truth.translation()).norm() < kMargin;
      if (n == 3 && near_circle(L, truth.translation(), kMargin)) continue;  // singular set for 3
      if (near_landmark) continue;
      ++evaluated;
      const Fix f = least_squares_bearings(observe(L, truth));
      ASSERT_TRUE(f.ok) << n << ": " << f.reason;
      EXPECT_LT(pos_err(f, truth), kTolPos) << n;
      EXPECT_LT(std::fabs(angle_diff(f.pose.theta, truth.theta)), kTolAng) << n;
    }
  }
}

TEST(Landmarks, SolversAgreeWithEachOther) {
  Rng rng(99);
  int evaluated = 0;
  double worst = 0;
  while (evaluated < 200) {
    const auto L = random_triangle(rng);
    const Pose2 truth = random_pose(rng);
    if (near_circle_or_lines(L, truth.translation(), kMargin)) continue;  // the union of all singular sets
    ++evaluated;
    const auto obs = observe(L, truth);
    std::vector<Fix> fixes;
    for (const auto& s : closed_forms()) fixes.push_back(s.solve(obs));
    fixes.push_back(least_squares_bearings(obs));
    for (std::size_t i = 0; i < fixes.size(); ++i) {
      ASSERT_TRUE(fixes[i].ok) << i << ": " << fixes[i].reason;
      // Same geometry, same reliability measure.
      EXPECT_NEAR(fixes[i].reliability, fixes[0].reliability, 1e-6 * fixes[0].reliability) << i;
      for (std::size_t j = 0; j < i; ++j) {
        worst = std::max(worst, pos_err(fixes[i], fixes[j].pose));
        EXPECT_LT(std::fabs(angle_diff(fixes[i].pose.theta, fixes[j].pose.theta)), kTolAng) << i << " vs " << j;
      }
    }
  }
  EXPECT_LT(worst, kTolPos);
}

TEST(Landmarks, OnTheSingularSets) {
  Rng rng(5);
  const std::vector<std::pair<const char*, Solver>> all = {
      {"three_point_004", three_point_004},
      {"two_circle_004", two_circle_004},
      {"circle_intersection_003", circle_intersection_003},
      {"total_like", total_like},
      {"least_squares_bearings", [](std::span<const BearingObs> o) { return least_squares_bearings(o); }},
  };
  for (int rep = 0; rep < 20; ++rep) {
    const auto L = random_triangle(rng);
    Eigen::Vector2d c;
    double r = 0;
    circumcircle(L[0], L[1], L[2], c, r);
    // On the circle through the three landmarks: nobody can place the robot.
    const double phi = rng.uniform(-kPi, kPi);
    const Pose2 on_circle(c.x() + r * std::cos(phi), c.y() + r * std::sin(phi), rng.uniform(-kPi, kPi));
    for (const auto& [name, solve] : all) expect_clean_refusal(solve(observe(L, on_circle)), std::string(name) + " on the circle");
    // On the line through landmarks 0 and 1, outside and between them (bearing difference 0 and pi):
    // singular for the paper-004 methods only; the others place the robot exactly.
    for (const double t : {-0.7, 0.4, 1.8}) {
      const Eigen::Vector2d p = L[0] + t * (L[1] - L[0]);
      const Pose2 on_line(p.x(), p.y(), rng.uniform(-kPi, kPi));
      if (near_circle(L, p, kMargin)) continue;
      const auto obs = observe(L, on_line);
      expect_clean_refusal(three_point_004(obs), "three_point_004 on line 0-1");
      expect_clean_refusal(two_circle_004(obs), "two_circle_004 on line 0-1");
      for (std::size_t k = 2; k < all.size(); ++k) {
        const Fix f = all[k].second(obs);
        ASSERT_TRUE(f.ok) << all[k].first << ": " << f.reason;
        EXPECT_LT(pos_err(f, on_line), kTolPos) << all[k].first << " t=" << t;
        EXPECT_LT(std::fabs(angle_diff(f.pose.theta, on_line.theta)), kTolAng) << all[k].first;
      }
    }
  }
}

TEST(Landmarks, TotalLikeExactOnEveryLineThroughTwoLandmarks) {
  // Before commit 16640f5, ToTal-like placed a robot on the line through landmarks 1 and 2 up to 4 mm wrong (the
  // clamped cotangent of that pair entered both factors of D). On each line the bearing difference
  // of its pair is 0 (beyond the landmarks) or pi (between them) to rounding, so that cotangent is
  // clamped (kCotMax = 1e14); the solver puts it in T31, where the position is a ratio of two terms
  // linear in it, so the clamp moves the fix by ~range^2 / (baseline * 1e14): measured worst 8e-12 m,
  // at t = 3 (robots up to ~40 m away). Rounding, with no cancellation left, is ~1e-15 relative.
  // 1e-9 m leaves two decades. Positions: beyond either landmark, between them, near either one.
  Rng rng(23);
  double worst = 0;
  int fixes = 0;
  for (int rep = 0; rep < 50; ++rep) {
    const auto L = random_triangle(rng);
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector2d& A = L[static_cast<std::size_t>(i)];
      const Eigen::Vector2d& B = L[static_cast<std::size_t>((i + 1) % 3)];
      for (const double t : {-1.5, -0.7, -0.05, 0.1, 0.4, 0.5, 0.93, 1.08, 1.8, 3.0}) {
        const Eigen::Vector2d p = A + t * (B - A);
        const Pose2 truth(p.x(), p.y(), rng.uniform(-kPi, kPi));
        if (near_circle(L, p, kMargin)) continue;  // where the line crosses the circle
        const Fix f = total_like(observe(L, truth));
        ASSERT_TRUE(f.ok) << "line " << i << "-" << (i + 1) % 3 << " t=" << t << ": " << f.reason;
        EXPECT_LT(pos_err(f, truth), 1e-9) << "line " << i << "-" << (i + 1) % 3 << " t=" << t;
        EXPECT_LT(std::fabs(angle_diff(f.pose.theta, truth.theta)), 1e-9) << "line " << i << "-" << (i + 1) % 3 << " t=" << t;
        worst = std::max(worst, pos_err(f, truth));
        ++fixes;
      }
    }
  }
  std::printf("total_like on the three lines: %d fixes, worst position error %.3g m\n", fixes, worst);
}

TEST(Landmarks, TotalLikeNearTheCircleIsExactFlaggedOrRefused) {
  // Within a few cm of the circle through the landmarks D -> 0 and the fix is ill-conditioned, but
  // on noise-free bearings it stays exact to rounding amplified by 1 / D: we require a finite fix
  // within 1e-6 m, or a refusal with a reason, and reliability (1/D-like) falling towards the circle.
  Rng rng(29);
  for (int rep = 0; rep < 50; ++rep) {
    const auto L = random_triangle(rng);
    Eigen::Vector2d c;
    double r = 0;
    circumcircle(L[0], L[1], L[2], c, r);
    const double phi = rng.uniform(-kPi, kPi);
    const Eigen::Vector2d u(std::cos(phi), std::sin(phi));
    double last_rel = -1;
    for (const double d : {0.05, 0.02, 0.005, 0.001, 1e-4}) {
      for (const double side : {-1.0, 1.0}) {
        const Eigen::Vector2d p = c + (r + side * d) * u;
        bool near_landmark = false;
        for (const auto& l : L) near_landmark |= (l - p).norm() < 0.1;
        if (near_landmark) continue;
        const Pose2 truth(p.x(), p.y(), rng.uniform(-kPi, kPi));
        const Fix f = total_like(observe(L, truth));
        EXPECT_TRUE(std::isfinite(f.pose.x) && std::isfinite(f.pose.y) && std::isfinite(f.reliability)) << "d=" << d;
        if (!f.ok) {
          EXPECT_FALSE(f.reason.empty()) << "d=" << d;
          continue;
        }
        EXPECT_LT(pos_err(f, truth), 1e-6) << "d=" << side * d;
        if (side > 0) {
          if (last_rel >= 0) {
            EXPECT_LT(f.reliability, last_rel) << "d=" << d;
          }
          last_rel = f.reliability;
        }
      }
    }
  }
}

TEST(Landmarks, DegenerateInputsAreRefusedWithAReason) {
  const std::vector<std::pair<const char*, Solver>> all = {
      {"three_point_004", three_point_004},
      {"two_circle_004", two_circle_004},
      {"circle_intersection_003", circle_intersection_003},
      {"total_like", total_like},
      {"least_squares_bearings", [](std::span<const BearingObs> o) { return least_squares_bearings(o); }},
  };
  const Pose2 robot(1.0, -2.0, 0.3);
  const std::vector<Eigen::Vector2d> good = {{-4, 3}, {2, 4}, {5, -1}};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<std::pair<std::string, std::vector<BearingObs>>> cases;
  cases.push_back({"no landmarks", {}});
  cases.push_back({"one landmark", {observe(good, robot)[0]}});
  cases.push_back({"two landmarks", {observe(good, robot)[0], observe(good, robot)[1]}});
  cases.push_back({"collinear landmarks", observe({{-4, 0}, {0, 2}, {4, 4}}, robot)});
  cases.push_back({"same landmark twice", observe({{-4, 3}, {-4, 3}, {5, -1}}, robot)});
  cases.push_back({"same landmark twice (last)", observe({{-4, 3}, {2, 4}, {2, 4}}, robot)});
  {
    Eigen::Vector2d c;
    double r = 0;
    circumcircle(good[0], good[1], good[2], c, r);
    cases.push_back({"robot on the circle", observe(good, Pose2(c.x(), c.y() - r, 1.0))});
    cases.push_back({"robot on a landmark", observe(good, Pose2(2, 4, 0.0))});
  }
  auto o = observe(good, robot);
  o[1].landmark.x() = nan;
  cases.push_back({"NaN landmark", o});
  o = observe(good, robot);
  o[2].landmark.y() = inf;
  cases.push_back({"infinite landmark", o});
  o = observe(good, robot);
  o[0].bearing = nan;
  cases.push_back({"NaN bearing", o});
  o = observe(good, robot);
  o[1].bearing = -inf;
  cases.push_back({"infinite bearing", o});
  for (const auto& [what, obs] : cases)
    for (const auto& [name, solve] : all) {
      const Fix f = solve(obs);
      expect_clean_refusal(f, std::string(name) + ": " + what);
    }
  // The same valid triple is solved by everybody (the cases above are refused for their defect only).
  for (const auto& [name, solve] : all) {
    const Fix f = solve(observe(good, robot));
    ASSERT_TRUE(f.ok) << name << ": " << f.reason;
    EXPECT_TRUE(f.reason.empty());
    EXPECT_LT(pos_err(f, robot), kTolPos) << name;
  }
  // Closed forms take exactly three.
  const auto four = observe({{-4, 3}, {2, 4}, {5, -1}, {0, 6}}, robot);
  for (std::size_t i = 0; i < 4; ++i) expect_clean_refusal(closed_forms()[i].solve(four), std::string(closed_forms()[i].name) + ": 4 landmarks");
  EXPECT_TRUE(least_squares_bearings(four).ok);
}

TEST(Landmarks, LeastSquaresRefusesWhenItDoesNotConverge) {
  Rng rng(3);
  const std::vector<Eigen::Vector2d> L = {{-4, 3}, {2, 4}, {5, -1}, {0, -5}, {-6, -3}};
  const auto obs = observe(L, Pose2(1, 0.5, 0.2), &rng, 0.02);
  LeastSquaresOptions one;
  one.max_iterations = 1;
  const Fix f = least_squares_bearings(obs, one);
  expect_clean_refusal(f, "one iteration");
  EXPECT_NE(f.reason.find("converge"), std::string::npos) << f.reason;
  EXPECT_TRUE(least_squares_bearings(obs).ok);
}

TEST(Landmarks, LeastSquaresOverFourToSixLandmarksBeatsASingleTriple) {
  Rng rng(11);
  const double sigma = deg2rad(0.5);  // bearing noise
  double sum_ls = 0, sum_triple = 0;
  int trials = 0, ls_failed = 0, wins = 0;
  while (trials < 300) {
    const int n = 4 + static_cast<int>(rng.uniform_index(3));
    auto L = random_triangle(rng);
    while (static_cast<int>(L.size()) < n) {
      const Eigen::Vector2d c(rng.uniform(-9, 9), rng.uniform(-6, 6));
      bool far = true;
      for (const auto& l : L) far &= (l - c).norm() > 1.0;
      if (far) L.push_back(c);
    }
    const Pose2 truth = random_pose(rng);
    bool near_landmark = false;
    for (const auto& l : L) near_landmark |= (l - truth.translation()).norm() < 0.5;
    if (near_landmark) continue;
    const auto obs = observe(L, truth, &rng, sigma);
    // The single triple: the best-spread one (largest reliability), i.e. least squares' own start.
    Fix best;
    for (int a = 0; a < n; ++a)
      for (int b = a + 1; b < n; ++b)
        for (int c = b + 1; c < n; ++c) {
          const std::array<BearingObs, 3> t{obs[a], obs[b], obs[c]};
          const Fix f = total_like(t);
          if (f.ok && f.reliability > best.reliability) best = f;
        }
    if (!best.ok) continue;
    ++trials;
    const Fix ls = least_squares_bearings(obs);
    if (!ls.ok) {
      ++ls_failed;
      continue;
    }
    sum_ls += pos_err(ls, truth);
    sum_triple += pos_err(best, truth);
    wins += pos_err(ls, truth) < pos_err(best, truth);
  }
  const int used = trials - ls_failed;
  std::printf("  mean position error over %d trials (sigma 0.5 deg): least squares %.4f m, best triple %.4f m; LS better in %d\n",
              used, sum_ls / used, sum_triple / used, wins);
  EXPECT_LE(ls_failed, 3);
  EXPECT_LT(sum_ls, sum_triple);
  EXPECT_GT(wins, used / 2);
}

TEST(Landmarks, ReliabilityFallsTowardsTheCircle) {
  const std::vector<Eigen::Vector2d> L = {{-4, 3}, {2, 4}, {5, -1}};
  Eigen::Vector2d c;
  double r = 0;
  circumcircle(L[0], L[1], L[2], c, r);
  double last = 0;
  for (const double d : {0.001, 0.01, 0.1, 1.0}) {
    const Pose2 p(c.x(), c.y() - r + d, 0.0);  // inside the circle, d from it
    const Fix f = total_like(observe(L, p));
    ASSERT_TRUE(f.ok) << f.reason;
    EXPECT_GT(f.reliability, last);
    last = f.reliability;
  }
}

TEST(Landmarks, NeverNaNNearTheSingularSetsOrOnInconsistentBearings) {
  Rng rng(17);
  const std::vector<std::pair<const char*, Solver>> all = {
      {"three_point_004", three_point_004},
      {"two_circle_004", two_circle_004},
      {"circle_intersection_003", circle_intersection_003},
      {"total_like", total_like},
      {"least_squares_bearings", [](std::span<const BearingObs> o) { return least_squares_bearings(o); }},
  };
  const auto check = [&](const std::vector<BearingObs>& obs, const char* what) {
    for (const auto& [name, solve] : all) {
      const Fix f = solve(obs);
      EXPECT_TRUE(std::isfinite(f.pose.x) && std::isfinite(f.pose.y) && std::isfinite(f.pose.theta) && std::isfinite(f.reliability))
          << name << " " << what;
      EXPECT_EQ(f.ok, f.reason.empty()) << name << " " << what << ": " << f.reason;
    }
  };
  for (int rep = 0; rep < 300; ++rep) {
    const auto L = random_triangle(rng);
    Eigen::Vector2d c;
    double r = 0;
    circumcircle(L[0], L[1], L[2], c, r);
    const double d = std::pow(10.0, rng.uniform(-14, -1)) * (rng.uniform() < 0.5 ? -1 : 1);
    const double phi = rng.uniform(-kPi, kPi);
    check(observe(L, Pose2(c.x() + (r + d) * std::cos(phi), c.y() + (r + d) * std::sin(phi), rng.uniform(-kPi, kPi))), "near circle");
    const Eigen::Vector2d u = (L[1] - L[0]).normalized();
    const Eigen::Vector2d p = L[0] + rng.uniform(-2, 3) * (L[1] - L[0]) + d * Eigen::Vector2d(-u.y(), u.x());
    check(observe(L, Pose2(p.x(), p.y(), 0.3)), "near line 0-1");
    auto obs = observe(L, random_pose(rng));
    for (auto& o : obs) o.bearing = rng.uniform(-10, 10);  // bearings of no consistent pose
    check(obs, "random bearings");
  }
}

// --- Paper 004 as printed (experiments/landmark_maps.hpp): landmark choice and implied bearing errors ------

namespace {
Eigen::Vector2d fix_position(const std::array<Eigen::Vector2d, 3>& L, const Eigen::Vector2d& p, const std::array<double, 3>& err_rad) {
  std::array<BearingObs, 3> obs;
  for (std::size_t k = 0; k < 3; ++k) obs[k] = {L[k], std::atan2(L[k].y() - p.y(), L[k].x() - p.x()) - 0.3 + err_rad[k]};  // heading 0.3
  const Fix f = total_like(obs);
  EXPECT_TRUE(f.ok) << f.reason;
  return {f.pose.x, f.pose.y};
}
}  // namespace

TEST(LandmarkMapsAsPrinted, ImpliedBearingsZeroAtTheTruth) {
  const std::array<Eigen::Vector2d, 3> L = {Eigen::Vector2d(0, 1.5), Eigen::Vector2d(0, 2.5), Eigen::Vector2d(6, 1.5)};
  const auto ib = experiments::implied_bearings(L, {0.75, 1.0}, {0.75, 1.0});
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(ib.diff_deg[k], 0.0);
    EXPECT_EQ(ib.min_bearing_deg[k], 0.0);
  }
  EXPECT_EQ(ib.norm_deg, 0.0);
}

TEST(LandmarkMapsAsPrinted, ImpliedBearingsHandComputed) {
  // Posts A (-1, 0), B (1, 0), C (0, 2). The truth (0, -1) sees A at 135, B at 45, C at 90 degrees:
  // angles A-B, B-C, A-C = 90, -45, 45. The estimate (0, -2) sees A at 90 + a, B at 90 - a, C at 90, with
  // a = atan(1/2) in degrees: angles 2a, -a, a. Changes: 2a - 90, 45 - a, a - 45; the smallest zero-sum
  // bearing errors are (a - 45, 45 - a, 0) (by symmetry C's bearing need not move).
  const std::array<Eigen::Vector2d, 3> L = {Eigen::Vector2d(-1, 0), Eigen::Vector2d(1, 0), Eigen::Vector2d(0, 2)};
  const double a = rad2deg(std::atan(0.5));
  const auto ib = experiments::implied_bearings(L, {0, -1}, {0, -2});
  EXPECT_NEAR(ib.diff_deg[0], 2 * a - 90, 1e-12);
  EXPECT_NEAR(ib.diff_deg[1], 45 - a, 1e-12);
  EXPECT_NEAR(ib.diff_deg[2], a - 45, 1e-12);
  EXPECT_NEAR(ib.min_bearing_deg[0], a - 45, 1e-12);
  EXPECT_NEAR(ib.min_bearing_deg[1], 45 - a, 1e-12);
  EXPECT_NEAR(ib.min_bearing_deg[2], 0.0, 1e-12);
  EXPECT_NEAR(ib.norm_deg, std::sqrt(2.0) * (45 - a), 1e-12);
  // They are what the camera would have to measure: an exact fix from the true bearings plus these
  // errors lands on the estimate.
  const Eigen::Vector2d q = fix_position(L, {0, -1}, {deg2rad(ib.min_bearing_deg[0]), deg2rad(ib.min_bearing_deg[1]), deg2rad(ib.min_bearing_deg[2])});
  EXPECT_NEAR(q.x(), 0.0, 1e-9);
  EXPECT_NEAR(q.y(), -2.0, 1e-9);
}

TEST(LandmarkMapsAsPrinted, SinglePostFit) {
  const std::array<Eigen::Vector2d, 3> L = {Eigen::Vector2d(0, 1.5), Eigen::Vector2d(0, 2.5), Eigen::Vector2d(6, 1.5)};
  const Eigen::Vector2d truth(0.75, 1.0);
  // An estimate made by an error of post 2 alone is reproduced exactly by post 2 alone.
  const Eigen::Vector2d e = fix_position(L, truth, {0, 0, deg2rad(3.0)});
  const auto fit2 = experiments::single_post_fit(L, truth, e, 2);
  EXPECT_NEAR(fit2.error_deg, 3.0, 1e-7);
  EXPECT_NEAR(fit2.miss, 0.0, 1e-9);
  // Post 0 alone cannot: its best point lies on the circle through posts 1, 2 and the truth, and the fix
  // from its error is exactly that point.
  const auto fit0 = experiments::single_post_fit(L, truth, e, 0);
  EXPECT_GT(fit0.miss, 1e-3);
  const Eigen::Vector2d q = fix_position(L, truth, {deg2rad(fit0.error_deg), 0, 0});
  EXPECT_NEAR(q.x(), fit0.point.x(), 1e-9);
  EXPECT_NEAR(q.y(), fit0.point.y(), 1e-9);
  // No error: zero, wherever the estimate is the truth.
  const auto none = experiments::single_post_fit(L, truth, truth, 1);
  EXPECT_NEAR(none.error_deg, 0.0, 1e-12);
  EXPECT_NEAR(none.miss, 0.0, 1e-12);
  // Truth on the line through the other two posts: no circle, NaN.
  EXPECT_TRUE(std::isnan(experiments::single_post_fit(L, {0, 4}, e, 2).error_deg));
}

TEST(LandmarkMapsAsPrinted, BothRulesPickTheSamePosts) {
  // Paper 004 sec. 2.2 (the nearer goal's two posts and the other goal's nearer post) and sec. 2.3 (the
  // three nearest posts) choose the same three posts: at the five table positions ...
  const experiments::Field004 f;
  const std::array<std::array<int, 3>, 5> two_circle = {{{0, 1, 3}, {0, 1, 2}, {0, 1, 2}, {3, 2, 0}, {3, 2, 0}}};
  for (std::size_t k = 0; k < 5; ++k) {
    const auto c = experiments::choose_posts_004(f, experiments::kTable1True[k] / 100.0);
    EXPECT_EQ(c.two_circle, two_circle[k]) << k;
    EXPECT_TRUE(c.same_set) << k;
    EXPECT_EQ(c.d1_tie, k == 0) << k;             // (300, 315): on the centre line
    EXPECT_EQ(c.third_tie, k == 0 || k == 1 || k == 3) << k;  // and y = 200 cm: the far goal's posts equally near
    const auto alt = experiments::choose_posts_004(f, experiments::kTable1True[k] / 100.0, true);
    EXPECT_TRUE(alt.same_set) << k;
  }
  const auto alt = experiments::choose_posts_004(f, experiments::kTable1True[0] / 100.0, true);
  EXPECT_EQ(alt.two_circle, (std::array<int, 3>{3, 2, 1}));  // the tie the other way: the blue goal is D1
  // ... and everywhere on the field (the farthest post is always the far goal's farther post).
  for (double x = 0.025; x < 6.0; x += 0.05)
    for (double y = 0.025; y < 4.0; y += 0.05) ASSERT_TRUE(experiments::choose_posts_004(f, {x, y}).same_set) << x << " " << y;
}
