// Cooperative ball localisation (paper 001, Xu et al. 2012): Hough fix of 5 robots' sightings and one
// step of each particle tracker with 100 particles (the paper's on-robot count).
#include <benchmark/benchmark.h>

#include <vector>

#include "core/rng.hpp"
#include "localization/cooperative/ball_trackers.hpp"
#include "localization/cooperative/hough_ball.hpp"

using namespace omniloc;

static void BM_HoughFix(benchmark::State& state) {
  // Paper 001 table 1 layout (mm -> m) with 0.1 m noise on the ball estimates.
  const Eigen::Vector2d ball(3.0, 3.2);
  const std::vector<Eigen::Vector2d> robots = {{1.0, 3.5}, {0.25, 2.0}, {1.75, 0.35}, {4.25, 2.4}, {5.6, 3.9}};
  Rng rng(1);
  std::vector<BallLine> lines;
  for (const auto& r : robots) lines.push_back({r, ball + Eigen::Vector2d(rng.normal(0, 0.1), rng.normal(0, 0.1)), 0.0});
  for (auto _ : state) benchmark::DoNotOptimize(hough_ball_fix(lines));
}
BENCHMARK(BM_HoughFix);

static void tracker_step(benchmark::State& state, ParticleFilterKind kind) {
  CvModelConfig m;
  ParticleTrackerConfig c;
  c.particles = static_cast<int>(state.range(0));
  ParticleBallTracker t(kind, m, c);
  Eigen::Matrix4d P0 = Eigen::Matrix4d::Identity() * 0.05;
  t.init(Eigen::Vector4d(0.0, 0.0, 1.0, 0.5), P0);
  Rng rng(2);
  Eigen::Vector2d truth(0.0, 0.0);
  for (auto _ : state) {
    truth += Eigen::Vector2d(1.0, 0.5) * m.dt;
    const Eigen::Vector2d z = truth + Eigen::Vector2d(rng.normal(0, 0.05), rng.normal(0, 0.05));
    benchmark::DoNotOptimize(t.step(z, rng));
  }
}
static void BM_PfStep(benchmark::State& s) { tracker_step(s, ParticleFilterKind::Bootstrap); }
static void BM_FbpfStep(benchmark::State& s) { tracker_step(s, ParticleFilterKind::Fission); }
static void BM_MfbpfStep(benchmark::State& s) { tracker_step(s, ParticleFilterKind::ModifiedFission); }
BENCHMARK(BM_PfStep)->Arg(100)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FbpfStep)->Arg(100)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_MfbpfStep)->Arg(100)->Unit(benchmark::kMicrosecond);

static void BM_KalmanStep(benchmark::State& state) {
  KalmanBallTracker t;
  t.init(Eigen::Vector4d(0.0, 0.0, 1.0, 0.5), Eigen::Matrix4d::Identity());
  Rng rng(3);
  for (auto _ : state) benchmark::DoNotOptimize(t.step(Eigen::Vector2d(rng.normal(), rng.normal()), rng));
}
BENCHMARK(BM_KalmanStep);
