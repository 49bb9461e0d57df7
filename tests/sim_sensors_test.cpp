#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/field.hpp"
#include "sim/sensors.hpp"
#include "sim/world.hpp"

using namespace omniloc;
using namespace omniloc::sim;

namespace {
// Mean end-point odometry error after driving `distance` metres straight, over many seeds.
double mean_odometry_error(double distance, const OdometryNoise& n, int runs) {
  double sum = 0;
  for (int s = 0; s < runs; ++s) {
    OdometrySensor odo(n, Rng::stream(s, "odo"));
    const double step = 0.005;  // 5 mm per physics step (1 m/s at 200 Hz)
    const int steps = static_cast<int>(distance / step);
    for (int k = 0; k < steps; ++k) odo.accumulate(Pose2(step, 0, 0));
    const Pose2 d = odo.read(0).delta;
    sum += std::hypot(d.x - steps * step, d.y);
  }
  return sum / runs;
}
}  // namespace

TEST(Odometry, ErrorGrowsWithDistance) {
  const OdometryNoise n{0.015, 0.035, 0.01, 0.01};
  const double e2 = mean_odometry_error(2.0, n, 200);
  const double e8 = mean_odometry_error(8.0, n, 200);
  EXPECT_GT(e8, 1.8 * e2);  // at least sqrt-growth (2x), scale error pushes towards linear (4x)
  EXPECT_GT(e2, 0.005);
  EXPECT_LT(e8, 0.5);
}

TEST(Odometry, IdealProfileIsExact) {
  OdometrySensor odo(OdometryNoise{}, Rng(3));
  for (int k = 0; k < 1000; ++k) odo.accumulate(Pose2(0.004, 0.001, 0.002));
  const Pose2 d = odo.read(5).delta;
  Pose2 ref;
  for (int k = 0; k < 1000; ++k) ref = ref.compose(Pose2(0.004, 0.001, 0.002));
  EXPECT_NEAR(d.x, ref.x, 1e-9);
  EXPECT_NEAR(d.y, ref.y, 1e-9);
}

TEST(Heading, BiasFollowsTheConfiguredRandomWalk) {
  HeadingNoise n;
  n.bias_walk = 0.002;  // rad / sqrt(s)
  const double T = 100.0, dt = 0.005;
  const int runs = 400;
  std::vector<double> finals;
  for (int s = 0; s < runs; ++s) {
    HeadingSensor h(n, Rng::stream(s, "heading"));
    for (int k = 0; k < static_cast<int>(T / dt); ++k) h.advance(dt);
    finals.push_back(h.bias());
  }
  double mean = 0, var = 0;
  for (double b : finals) mean += b / runs;
  for (double b : finals) var += (b - mean) * (b - mean) / (runs - 1);
  const double expected = n.bias_walk * n.bias_walk * T;  // 4e-4 rad^2
  EXPECT_NEAR(mean, 0.0, 4 * std::sqrt(expected / runs));
  // Sample variance of 400 normals: relative std sqrt(2/399) = 7 %; allow 3 sigma.
  EXPECT_NEAR(var / expected, 1.0, 0.22);
}

TEST(Heading, OffsetDriftAndWhiteNoise) {
  HeadingNoise n;
  n.offset = kPi;
  n.drift_rate = 0.01;
  HeadingSensor h(n, Rng(9));
  for (int k = 0; k < 1000; ++k) h.advance(0.01);  // 10 s
  EXPECT_NEAR(angle_diff(h.read(10, 0.2).heading, wrap_angle(0.2 + kPi + 0.1)), 0.0, 1e-9);
  HeadingNoise w;
  w.noise_sigma = 0.05;
  HeadingSensor hw(w, Rng(11));
  double s2 = 0;
  for (int k = 0; k < 20000; ++k) s2 += std::pow(hw.read(0, 0).heading, 2);
  EXPECT_NEAR(std::sqrt(s2 / 20000), 0.05, 0.002);
}
