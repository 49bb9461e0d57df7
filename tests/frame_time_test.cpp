// Frame times (docs/protocol.md, `frame.t`): frame k is taken at the first physics step at or after
// k / camera_rate, and its t is that step's time computed from the step count (n / physics_rate),
// never a sum of rounded steps. Outside clients found t_33 = 1.0999999999999985 < 1.1 at 30 Hz when
// time was summed (79 of 601 frames in 20 s).
#include <gtest/gtest.h>

#include <cmath>

#include "harness/scenario.hpp"
#include "harness/simulation.hpp"

using namespace omniloc;
using namespace omniloc::harness;

namespace {

// Steps a still robot through `duration` seconds frame by frame, as the run loop does.
void check_frames(double camera_rate, double physics_rate, double duration) {
  const Json j = {{"duration", duration}, {"camera_rate", camera_rate}, {"physics_rate", physics_rate}, {"noise_profile", "ideal"},
                  {"robots", Json::array({{{"start", {0, 0, 0}}, {"motion", {{"type", "still"}}}}})}};
  const Scenario sc = parse_scenario(j, "frame_time");
  Simulation sim(sc, 1);
  const long long n_frames = static_cast<long long>(std::floor(sc.duration * sc.camera_rate + 1e-9)) + 1;
  long long late = 0;
  for (long long k = 0; k < n_frames; ++k) {
    const double due = static_cast<double>(k) / camera_rate;
    sim.advance_to(due);
    const double t = sim.state().t;
    ASSERT_GE(t, due) << "frame " << k << " at " << camera_rate << " / " << physics_rate << " Hz";
    // The first step at or after the due time: the step before it is earlier than the due time.
    const long long n = std::llround(t * physics_rate);
    ASSERT_EQ(t, static_cast<double>(n) / physics_rate) << "frame " << k << ": t is not n / physics_rate";
    ASSERT_LT(static_cast<double>(n - 1) / physics_rate, due) << "frame " << k << " is a step late";
    late += t > due;
  }
  // 30 Hz on 200 Hz: two of every three frames fall between steps.
  if (camera_rate == 30.0 && physics_rate == 200.0) {
    EXPECT_EQ(late, n_frames - (n_frames + 2) / 3);
  }
}

TEST(FrameTime, EveryFrameAtOrAfterItsDueTimeOverTenMinutes) { check_frames(30.0, 200.0, 600.0); }

TEST(FrameTime, RatesThatDoNotDivide) {
  check_frames(29.97, 200.0, 120.0);
  check_frames(25.0, 1000.0, 120.0);
  check_frames(60.0, 240.0, 120.0);
  check_frames(7.0, 333.0, 120.0);
}

TEST(FrameTime, TheFramesOutsideClientsReported) {
  const Json j = {{"duration", 2.0}, {"noise_profile", "ideal"}, {"robots", Json::array({{{"start", {0, 0, 0}}}})}};
  const Scenario sc = parse_scenario(j, "frame_time");
  Simulation sim(sc, 1);
  sim.advance_to(2.0 / 30.0);
  EXPECT_EQ(sim.state().t, 0.07);  // was 0.06999999999999999
  sim.advance_to(33.0 / 30.0);
  EXPECT_EQ(sim.state().t, 1.1);  // was 1.0999999999999985
}

}  // namespace
