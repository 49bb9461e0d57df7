#include <gtest/gtest.h>

#include <cmath>

#include "core/field.hpp"
#include "core/rng.hpp"
#include "sim/motion.hpp"
#include "sim/sensors.hpp"
#include "sim/world.hpp"

using namespace omniloc;
using namespace omniloc::sim;

namespace {
RobotSpec robot_at(int id, double x, double y, double th = 0.0) {
  RobotSpec s;
  s.id = id;
  s.start = Pose2(x, y, th);
  return s;
}
}  // namespace

TEST(World, RobotsStayInsideTheWallsUnderRandomPushes) {
  const Field f = Field::preset("msl2012");
  World w(f, 200.0);
  for (int i = 0; i < 4; ++i) w.add_robot(robot_at(i, -6.0 + 4.0 * i, 0.5 * i));
  w.set_ball({0, 0}, {3, 1});
  Rng rng(123);
  const int kSteps = 100000;
  double worst = -1e9;
  for (int k = 0; k < kSteps; ++k) {
    if (k % 20 == 0)  // a new random push every 0.1 s, up to and beyond the top speed
      for (int i = 0; i < 4; ++i) w.command(i, {{rng.uniform(-6, 6), rng.uniform(-6, 6)}, rng.uniform(-8, 8)});
    w.step();
    for (const auto& r : w.state().robots) {
      // Signed overshoot beyond the wall, accounting for the robot's radius (a few mm of contact slop allowed).
      worst = std::max(worst, std::fabs(r.pose.x) + r.radius - f.half_floor_x());
      worst = std::max(worst, std::fabs(r.pose.y) + r.radius - f.half_floor_y());
    }
  }
  EXPECT_LT(worst, 0.02) << "a robot went through a wall";
  const auto st = w.state();
  EXPECT_TRUE(f.inside_floor(st.ball.position));
}

TEST(World, DriveRespectsSpeedAndAccelerationLimits) {
  const Field f = Field::preset("msl2012");
  World w(f, 200.0);
  w.add_robot(robot_at(0, -5, 0));
  w.command(0, {{10.0, 0.0}, 0.0});
  // After 0.5 s at 3 m/s^2 the speed is 1.5 m/s; after 3 s it is capped at 4 m/s.
  for (int k = 0; k < 100; ++k) w.step();
  EXPECT_NEAR(w.state().robots[0].velocity.x(), 1.5, 0.02);
  for (int k = 0; k < 500; ++k) w.step();
  EXPECT_NEAR(w.state().robots[0].velocity.norm(), 4.0, 0.02);
}

TEST(World, WheelMotionMatchesTrueMotionWithoutContact) {
  const Field f = Field::preset("msl2012");
  World w(f, 200.0);
  w.add_robot(robot_at(0, 0, 0, 0.3));
  OdometrySensor odo(OdometryNoise{}, Rng(1));
  w.command(0, {{1.0, 0.5}, 0.4});
  for (int k = 0; k < 400; ++k) {
    w.step();
    odo.accumulate(w.wheel_motion(0));
  }
  const Pose2 est = Pose2(0, 0, 0.3).compose(odo.read(2.0).delta);
  const Pose2 truth = w.pose(0);
  EXPECT_NEAR(est.x, truth.x, 2e-3);
  EXPECT_NEAR(est.y, truth.y, 2e-3);
  EXPECT_NEAR(angle_diff(est.theta, truth.theta), 0.0, 2e-3);
}

TEST(World, CollisionMakesOdometryWrong) {
  const Field f = Field::preset("msl2012");
  World w(f, 200.0);
  // Drive into the wall at x = +10: the wheels keep turning, the body stops.
  w.add_robot(robot_at(0, 8.5, 3.0));
  OdometrySensor odo(OdometryNoise{}, Rng(1));
  Pose2 est = w.pose(0);
  w.command(0, {{2.0, 0.0}, 0.0});
  bool touched = false;
  double err_before_contact = 0.0;
  for (int k = 0; k < 600; ++k) {
    w.step();
    odo.accumulate(w.wheel_motion(0));
    est = est.compose(odo.read(w.time()).delta);
    if (!touched && w.in_contact(0)) {
      touched = true;
      err_before_contact = std::fabs(est.x - w.pose(0).x);
    }
  }
  ASSERT_TRUE(touched);
  EXPECT_LT(err_before_contact, 0.02);
  EXPECT_GT(est.x - w.pose(0).x, 1.5) << "odometry should run on past the wall";
  EXPECT_LE(w.pose(0).x, f.half_floor_x() - 0.25);
}

TEST(World, TeleportLeavesNoWheelMotion) {
  const Field f = Field::preset("msl2012");
  World w(f, 200.0);
  w.add_robot(robot_at(0, 0, 0));
  w.teleport(0, Pose2(3, 2, 1));
  w.step();
  EXPECT_NEAR(w.pose(0).x, 3.0, 1e-5);
  EXPECT_NEAR(w.wheel_motion(0).x, 0.0, 1e-12);
}

TEST(Motion, WaypointsAreReachedInOrder) {
  const Field f = Field::preset("msl2012");
  World w(f, 200.0);
  w.add_robot(robot_at(0, 0, 0));
  auto script = MotionScript::from_json(Json::parse(R"({"type": "waypoints", "speed": 2.0, "points": [[2, 0], [2, 2]]})"), "/m", 0);
  for (int k = 0; k < 1200; ++k) {
    w.command(0, script->command(w.state(), 0, w.time()));
    w.step();
  }
  EXPECT_NEAR(w.pose(0).x, 2.0, 0.06);
  EXPECT_NEAR(w.pose(0).y, 2.0, 0.06);
}
