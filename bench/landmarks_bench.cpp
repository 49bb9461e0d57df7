// Landmark solvers: nanoseconds per solve over a precomputed array of random valid configurations
// (target for total_like: under 200 ns). Configurations: three landmarks in an 18 m x 12 m field,
// at least 2 m apart, triangle angles over 15 degrees; robot pose uniform in 20 m x 14 m, at least
// 0.5 m from the circle through the landmarks and from the lines through landmarks 0-1 and 1-2 (so
// every solver has a fix). Least squares: 4 or 6 landmarks, bearing noise 0.5 degrees.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <vector>

#include "core/angles.hpp"
#include "core/rng.hpp"
#include "localization/landmarks/landmark_solvers.hpp"

using namespace omniloc;
using namespace omniloc::landmarks;

namespace {

constexpr std::size_t kConfigs = 1024;

double line_distance(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
  const Eigen::Vector2d u = (b - a).normalized(), v = p - a;
  return std::fabs(u.x() * v.y() - u.y() * v.x());
}

double circle_distance(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c, const Eigen::Vector2d& p) {
  const double d = 2.0 * (a.x() * (b.y() - c.y()) + b.x() * (c.y() - a.y()) + c.x() * (a.y() - b.y()));
  const double a2 = a.squaredNorm(), b2 = b.squaredNorm(), c2 = c.squaredNorm();
  const Eigen::Vector2d o((a2 * (b.y() - c.y()) + b2 * (c.y() - a.y()) + c2 * (a.y() - b.y())) / d,
                          (a2 * (c.x() - b.x()) + b2 * (a.x() - c.x()) + c2 * (b.x() - a.x())) / d);
  return std::fabs((p - o).norm() - (a - o).norm());
}

/// `n` landmarks (the first three a well-shaped triangle) and their bearings from a random pose.
std::vector<BearingObs> config(Rng& rng, int n, double sigma) {
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

const std::vector<std::vector<BearingObs>>& configs(int n, double sigma) {
  static std::vector<std::vector<BearingObs>> c3, c4, c6;
  auto& c = n == 3 ? c3 : n == 4 ? c4 : c6;
  if (c.empty()) {
    Rng rng(2024 + n);
    for (std::size_t i = 0; i < kConfigs; ++i) c.push_back(config(rng, n, sigma));
  }
  return c;
}

template <typename F>
void run(benchmark::State& state, const std::vector<std::vector<BearingObs>>& cs, F&& solve) {
  std::size_t i = 0, failed = 0;
  for (auto _ : state) {
    const Fix f = solve(std::span<const BearingObs>(cs[i]));
    failed += !f.ok;
    benchmark::DoNotOptimize(f.pose.x);
    benchmark::DoNotOptimize(f.pose.theta);
    i = (i + 1) % cs.size();
  }
  state.counters["failed"] = benchmark::Counter(static_cast<double>(failed), benchmark::Counter::kAvgIterations);
}

}  // namespace

static void BM_ThreePoint004(benchmark::State& state) { run(state, configs(3, 0.0), three_point_004); }
BENCHMARK(BM_ThreePoint004);

static void BM_TwoCircle004(benchmark::State& state) { run(state, configs(3, 0.0), two_circle_004); }
BENCHMARK(BM_TwoCircle004);

static void BM_CircleIntersection003(benchmark::State& state) { run(state, configs(3, 0.0), circle_intersection_003); }
BENCHMARK(BM_CircleIntersection003);

static void BM_TotalLike(benchmark::State& state) { run(state, configs(3, 0.0), total_like); }
BENCHMARK(BM_TotalLike);

static void BM_LeastSquaresBearings(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  run(state, configs(n, deg2rad(0.5)), [](std::span<const BearingObs> o) { return least_squares_bearings(o); });
}
BENCHMARK(BM_LeastSquaresBearings)->Arg(4)->Arg(6);
