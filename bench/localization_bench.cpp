// Localizer steps on synthetic line points (targets: matching + Kalman <= 0.1 ms with 200 points).
#include <benchmark/benchmark.h>

#include "core/field.hpp"
#include "core/rng.hpp"
#include "localization/grid_global.hpp"
#include "localization/matching.hpp"
#include "localization/mcl.hpp"
#include "localization/modern/ukf_mh.hpp"
#include "testing/scenes.hpp"

using namespace omniloc;

static void BM_MatchingUpdate(benchmark::State& state) {
  const Field f = Field::preset("msl2012");
  MatchingLocalizer loc(f, MatchingParams{}, "");
  Rng rng(1);
  const Pose2 truth(-3.0, 1.0, 0.4);
  Observations obs;
  obs.line_points = scenes::line_points(f, truth, static_cast<int>(state.range(0)), rng, scenes::kBenchmarkLinePoints);
  Odometry odo;
  double iterations = 0;
  for (auto _ : state) {
    state.PauseTiming();
    loc.reset(Pose2(truth.x + 0.03, truth.y - 0.02, truth.theta + 0.01));
    state.ResumeTiming();
    const Estimate e = loc.update(obs, odo, std::nullopt);
    iterations = e.extra.at("iterations");
    benchmark::DoNotOptimize(e.pose);
  }
  // The speed targets' unit (docs/performance.md "Targets and measured figures"): time per line
  // point and RPROP iteration (the peers' figure), and per point and data-term evaluation (each
  // update also evaluates the error once and the gradient six times for the Hessian that gives the
  // Kalman filter its covariance).
  const double points = static_cast<double>(obs.line_points.size());
  state.counters["rprop_iterations"] = iterations;
  state.counters["s_per_point_iteration"] = benchmark::Counter(points * iterations, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["s_per_point_evaluation"] = benchmark::Counter(points * (iterations + 7), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_MatchingUpdate)->Arg(200)->Arg(100)->Unit(benchmark::kMicrosecond);

// The modern reference (ukf_mh) on the tracking path: one frame of a robot driving 3 cm per frame
// (1 m/s at 30 Hz) through the same scene as BM_MatchingUpdate. range(1) = 0: every frame a plain
// tracking frame (alternative-pose rounds off), which is the median frame; 1: the defaults, with an
// alternative-pose round every alt_period (0.5 s, every 15th frame), so the mean includes them.
static void BM_UkfMhUpdate(benchmark::State& state) {
  const Field f = Field::preset("msl2012");
  modern::UkfMhParams p;
  if (state.range(1) == 0) p.alt_period = 1e9;
  // As a run of the robot profile builds it: the camera's declared tilt and height, and a compass.
  p.tilt_sd = 0.3 * kPi / 180.0;
  p.mount_height = 0.75;
  modern::UkfMhLocalizer loc(f, p, 1, "");
  Rng rng(1);
  const Pose2 truth(-3.0, 1.0, 0.4);
  Observations obs;
  obs.line_points = scenes::line_points(f, truth, static_cast<int>(state.range(0)), rng, scenes::kBenchmarkLinePoints);
  loc.reset(truth);
  // The scene stays put while odometry says the robot moved 3 cm and back: the filter predicts,
  // associates and updates every frame as on a drive, and the pose stays in the scene.
  double t = 0.0;
  int k = 0;
  double hypotheses = 0;
  for (auto _ : state) {
    t += 1.0 / 30.0;
    obs.t = t;
    const Odometry odo{t, Pose2((k++ & 1) ? 0.03 : -0.03, 0.0, 0.0)};
    const Estimate e = loc.update(obs, odo, truth.theta);
    hypotheses = e.extra.at("hypotheses");
    benchmark::DoNotOptimize(e.pose);
  }
  state.counters["hypotheses"] = hypotheses;
}
BENCHMARK(BM_UkfMhUpdate)->Args({200, 0})->Args({100, 0})->Args({200, 1})->Unit(benchmark::kMicrosecond);

static void BM_FieldMapLookup(benchmark::State& state) {
  const Field f = Field::preset("msl2012");
  const FieldMap m(f, 0.05);
  Rng rng(2);
  std::vector<Eigen::Vector2d> q;
  for (int i = 0; i < 1024; ++i) q.emplace_back(rng.uniform(-9, 9), rng.uniform(-6, 6));
  std::size_t i = 0;
  for (auto _ : state) {
    Eigen::Vector2d g;
    benchmark::DoNotOptimize(m.distance(q[i++ & 1023], &g));
  }
}
BENCHMARK(BM_FieldMapLookup);

// The same lookups within 0.75 m of one place (a 30 x 30-cell patch, 7 KB of the table: L1-resident),
// as the matcher's and MCL's lookups around a pose mostly are; against BM_FieldMapLookup it shows
// what the misses of random points over the whole table cost.
static void BM_FieldMapLookupNear(benchmark::State& state) {
  const Field f = Field::preset("msl2012");
  const FieldMap m(f, 0.05);
  Rng rng(2);
  std::vector<Eigen::Vector2d> q;
  for (int i = 0; i < 1024; ++i) q.emplace_back(rng.uniform(-3.75, -2.25), rng.uniform(0.25, 1.75));
  std::size_t i = 0;
  for (auto _ : state) {
    Eigen::Vector2d g;
    benchmark::DoNotOptimize(m.distance(q[i++ & 1023], &g));
  }
}
BENCHMARK(BM_FieldMapLookupNear);


static void BM_McLUpdate(benchmark::State& state) {
  const Field f = Field::preset("msl2012");
  McLLocalizer mcl(f, McLParams{}, 1, "");
  Rng rng(3);
  const Pose2 truth(2.0, -1.0, 0.7);
  Observations obs;
  obs.line_points = scenes::line_points(f, truth, 200, rng, scenes::kBenchmarkLinePoints);
  Odometry odo;
  odo.delta = Pose2(0.03, 0.0, 0.01);
  mcl.reset(std::nullopt);
  for (auto _ : state) benchmark::DoNotOptimize(mcl.update(obs, odo, truth.theta));
}
BENCHMARK(BM_McLUpdate)->Unit(benchmark::kMicrosecond);

// One full global localisation of paper 000: 315 samples, 5 RPROP runs, three passes (the
// acceptance threshold is set to 0 so every pass runs: the worst case).
static void BM_GridGlobalAttempt(benchmark::State& state) {
  const Field f = Field::preset("msl2012");
  const FieldMap map(f, 0.05, "");
  Rng rng(5);
  const Pose2 truth(-3.2, 2.1, -0.4);
  const auto pts = scenes::line_points(f, truth, 200, rng, scenes::kBenchmarkLinePoints);
  GridGlobalParams p;
  p.accept_error = 0.0;
  for (auto _ : state) benchmark::DoNotOptimize(grid_search(f, map, pts, truth.theta, p));
}
BENCHMARK(BM_GridGlobalAttempt)->Unit(benchmark::kMillisecond);
