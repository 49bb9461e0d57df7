#pragma once
// Top-down Box2D world (zero gravity): the floor inside walls, goals, omni-drive robots and a ball.
// World frame, metres, radians, seconds. The world steps at a fixed time step, independent of the
// camera rate.
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "core/field.hpp"
#include "core/pose2.hpp"
#include "sim/world_state.hpp"

class b2World;
class b2Body;

namespace omniloc::sim {

/// Physical description of a robot. Defaults: an MSL robot (~0.52 m across, omni-drive).
struct RobotSpec {
  int id = 0;
  int team = 0;
  Pose2 start;
  double radius = 0.26;       ///< footprint radius, metres
  double height = 0.8;        ///< metres (for rendering)
  double mass = 30.0;         ///< kg
  double max_speed = 4.0;     ///< m/s
  double max_accel = 3.0;     ///< m/s^2
  double max_omega = 6.0;     ///< rad/s
  double max_alpha = 12.0;    ///< rad/s^2
};

/// A velocity command for an omni-drive robot: world-frame linear velocity and angular rate.
struct DriveCommand {
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  ///< m/s, world frame
  double omega = 0.0;                                  ///< rad/s
};

class World {
 public:
  /// rate_hz: physics steps per second; the fixed step is 1 / rate_hz seconds. Time is kept as a
  /// step count, so time() after n steps is n / rate_hz exactly rounded (never a sum of rounded
  /// steps): a frame due at k / camera_rate is taken at the first step whose time() is >= it.
  World(const Field& field, double rate_hz);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  void add_robot(const RobotSpec& spec);
  void set_ball(const Eigen::Vector2d& position, const Eigen::Vector2d& velocity);
  void remove_ball();

  /// Sets the wanted motion; the drive reaches it within the robot's speed and acceleration limits.
  void command(int robot_id, const DriveCommand& cmd);
  /// Moves a robot instantly (kidnapping): no wheel motion is recorded.
  void teleport(int robot_id, const Pose2& pose);
  /// Advances one fixed step.
  void step();

  /// Seconds since the start: steps taken / rate, correctly rounded.
  double time() const { return static_cast<double>(steps_) / rate_; }
  double dt() const { return dt_; }
  const Field& field() const { return field_; }
  WorldState state() const;
  Pose2 pose(int robot_id) const;
  /// What the wheels did during the last step, in the robot frame at the step's start: the drive's
  /// commanded motion, which differs from the true motion when a contact stopped or pushed the body.
  Pose2 wheel_motion(int robot_id) const;
  /// True when the robot touched a wall, goal, robot or the ball during the last step.
  bool in_contact(int robot_id) const;
  const std::vector<RobotSpec>& robot_specs() const { return specs_; }

 private:
  struct Robot;
  Robot& robot(int id);
  const Robot& robot(int id) const;
  void build_static_geometry();

  Field field_;
  double rate_;  ///< steps per second
  double dt_;    ///< 1 / rate_, seconds
  long long steps_ = 0;
  std::unique_ptr<b2World> world_;
  std::vector<RobotSpec> specs_;
  std::vector<std::unique_ptr<Robot>> robots_;
  b2Body* ball_ = nullptr;
  double ball_radius_ = 0.11;
};

}  // namespace omniloc::sim
