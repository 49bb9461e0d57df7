#pragma once
// Synthetic inputs shared by the Google Benchmark programs and the instruction-count workloads
// (bench/icount.cpp), so both measure the same scenes: noisy line points seen from a pose, and
// random three-beacon (or n-beacon) bearing configurations. World frame, metres, radians.
#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "core/angles.hpp"
#include "core/field.hpp"
#include "core/pose2.hpp"
#include "core/rng.hpp"
#include "localization/landmarks/landmark_solvers.hpp"

namespace omniloc::bench_scenes {

/// `n` points on the field's lines within 6 m of `pose`, in the robot frame, with 3 cm noise.
inline std::vector<Eigen::Vector2d> line_points(const Field& f, const Pose2& pose, int n, Rng& rng) {
  std::vector<Eigen::Vector2d> pts;
  while (static_cast<int>(pts.size()) < n) {
    const Eigen::Vector2d w(pose.x + rng.uniform(-6, 6), pose.y + rng.uniform(-6, 6));
    if (f.distance_to_marking(w) < 0.004) pts.push_back(pose.inverse_transform(w) + Eigen::Vector2d(rng.normal(0, 0.03), rng.normal(0, 0.03)));
  }
  return pts;
}

// Landmark configurations: three landmarks in an 18 m x 12 m field, at least 2 m apart, triangle
// angles over 15 degrees; robot pose uniform in 20 m x 14 m, at least 0.5 m from the circle through
// the landmarks and from the lines through landmarks 0-1 and 1-2 (so every solver has a fix).
using landmarks::BearingObs;

inline constexpr std::size_t kConfigs = 1024;

inline double line_distance(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
  const Eigen::Vector2d u = (b - a).normalized(), v = p - a;
  return std::fabs(u.x() * v.y() - u.y() * v.x());
}

inline double circle_distance(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c, const Eigen::Vector2d& p) {
  const double d = 2.0 * (a.x() * (b.y() - c.y()) + b.x() * (c.y() - a.y()) + c.x() * (a.y() - b.y()));
  const double a2 = a.squaredNorm(), b2 = b.squaredNorm(), c2 = c.squaredNorm();
  const Eigen::Vector2d o((a2 * (b.y() - c.y()) + b2 * (c.y() - a.y()) + c2 * (a.y() - b.y())) / d,
                          (a2 * (c.x() - b.x()) + b2 * (a.x() - c.x()) + c2 * (b.x() - a.x())) / d);
  return std::fabs((p - o).norm() - (a - o).norm());
}

/// `n` landmarks (the first three a well-shaped triangle) and their bearings from a random pose.
inline std::vector<BearingObs> landmark_config(Rng& rng, int n, double sigma) {
  for (;;) {
    std::vector<Eigen::Vector2d> L;
    while (static_cast<int>(L.size()) < n) {
      const Eigen::Vector2d c(rng.uniform(-9, 9), rng.uniform(-6, 6));
      bool ok = true;
      for (const auto& l : L) ok &= (l - c).norm() > 2.0;
      if (ok) L.push_back(c);
    }
    bool good = true;
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector2d u = L[(i + 1) % 3] - L[i], v = L[(i + 2) % 3] - L[i];
      good &= std::acos(std::clamp(u.dot(v) / (u.norm() * v.norm()), -1.0, 1.0)) > deg2rad(15);
    }
    const Pose2 pose(rng.uniform(-10, 10), rng.uniform(-7, 7), rng.uniform(-kPi, kPi));
    const Eigen::Vector2d p = pose.translation();
    good = good && circle_distance(L[0], L[1], L[2], p) > 0.5 && line_distance(L[0], L[1], p) > 0.5 && line_distance(L[1], L[2], p) > 0.5;
    for (const auto& l : L) good &= (l - p).norm() > 0.5;
    if (!good) continue;
    std::vector<BearingObs> obs;
    for (const auto& l : L) obs.push_back({l, wrap_angle(std::atan2(l.y() - pose.y, l.x() - pose.x) - pose.theta + rng.normal(0.0, sigma))});
    return obs;
  }
}

/// kConfigs configurations of `n` landmarks with bearing noise `sigma` (radians), fixed seeds.
inline const std::vector<std::vector<BearingObs>>& landmark_configs(int n, double sigma) {
  static std::vector<std::vector<BearingObs>> c3, c4, c6;
  auto& c = n == 3 ? c3 : n == 4 ? c4 : c6;
  if (c.empty()) {
    Rng rng(2024 + n);
    for (std::size_t i = 0; i < kConfigs; ++i) c.push_back(landmark_config(rng, n, sigma));
  }
  return c;
}

}  // namespace omniloc::bench_scenes
