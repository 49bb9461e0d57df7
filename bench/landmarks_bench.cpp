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
#include "testing/scenes.hpp"

using namespace omniloc;
using namespace omniloc::landmarks;
using scenes::landmark_configs;

namespace {

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

static void BM_ThreePoint004(benchmark::State& state) { run(state, landmark_configs(3, 0.0), three_point_004); }
BENCHMARK(BM_ThreePoint004);

static void BM_TwoCircle004(benchmark::State& state) { run(state, landmark_configs(3, 0.0), two_circle_004); }
BENCHMARK(BM_TwoCircle004);

static void BM_CircleIntersection003(benchmark::State& state) { run(state, landmark_configs(3, 0.0), circle_intersection_003); }
BENCHMARK(BM_CircleIntersection003);

static void BM_TotalLike(benchmark::State& state) { run(state, landmark_configs(3, 0.0), total_like); }
BENCHMARK(BM_TotalLike);

static void BM_LeastSquaresBearings(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  run(state, landmark_configs(n, deg2rad(0.5)), [](std::span<const BearingObs> o) { return least_squares_bearings(o); });
}
BENCHMARK(BM_LeastSquaresBearings)->Arg(4)->Arg(6);
