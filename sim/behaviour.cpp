// The match-like behaviours of BehaviourScript (declared with the other motion scripts in
// sim/motion.hpp, whose factory builds them from a scenario's "behaviour" motion).
#include "sim/motion.hpp"

#include <algorithm>
#include <cmath>

namespace omniloc::sim {

DriveCommand BehaviourScript::go_to(const RobotState& me, const Eigen::Vector2d& target, double speed, double face) const {
  DriveCommand c;
  const Eigen::Vector2d to = target - me.pose.translation();
  const double d = to.norm();
  const double v = std::min(speed, std::sqrt(2.0 * 2.5 * d));  // brake at 2.5 m/s^2
  if (d > 0.02) c.velocity = to * (v / d);
  c.omega = std::clamp(3.0 * angle_diff(face, me.pose.theta), -3.0, 3.0);
  return c;
}

DriveCommand BehaviourScript::command(const WorldState& world, int self, double t) {
  const RobotState* me = world.robot(self);
  if (!me) return {};
  const Eigen::Vector2d pos = me->pose.translation();
  if (p_.kind == "chase_ball" && world.has_ball) {
    // Get behind the ball as seen from the goal being attacked, then push through it.
    const Eigen::Vector2d goal(p_.attack_side * p_.field_half_x, 0.0);
    const Eigen::Vector2d ball = world.ball.position;
    Eigen::Vector2d dir = goal - ball;
    dir.normalize();
    const Eigen::Vector2d behind = ball - dir * (me->radius + world.ball.radius + 0.05);
    const bool lined_up = (pos - behind).norm() < 0.25;
    const Eigen::Vector2d target = lined_up ? Eigen::Vector2d(ball + dir * 0.5) : behind;
    const Eigen::Vector2d look = ball - pos;
    return go_to(*me, target, p_.speed, std::atan2(look.y(), look.x()));
  }
  if (p_.kind == "mark") {
    const RobotState* other = world.robot(p_.target_robot);
    if (!other) return {};
    // Stand 0.9 m goal-side of the marked robot (the goal we defend is at -attack_side).
    const Eigen::Vector2d own_goal(-p_.attack_side * p_.field_half_x, 0.0);
    Eigen::Vector2d dir = own_goal - other->pose.translation();
    dir.normalize();
    const Eigen::Vector2d target = other->pose.translation() + dir * 0.9;
    const Eigen::Vector2d look = other->pose.translation() - pos;
    return go_to(*me, target, p_.speed, std::atan2(look.y(), look.x()));
  }
  if (p_.kind == "hold") {
    if (!has_target_ || t >= next_change_) {
      const double a = rng_.uniform(0, kTwoPi), r = p_.radius * std::sqrt(rng_.uniform());
      target_ = p_.home + r * Eigen::Vector2d(std::cos(a), std::sin(a));
      next_change_ = t + rng_.uniform(1.0, 3.0);
      has_target_ = true;
    }
    const Eigen::Vector2d look = world.has_ball ? Eigen::Vector2d(world.ball.position - pos) : Eigen::Vector2d(1, 0);
    return go_to(*me, target_, 0.5 * p_.speed, std::atan2(look.y(), look.x()));
  }
  // wander: random targets on the field at random speeds.
  if (!has_target_ || (pos - target_).norm() < 0.2 || t >= next_change_) {
    target_ = {rng_.uniform(-p_.field_half_x + 0.5, p_.field_half_x - 0.5), rng_.uniform(-p_.field_half_y + 0.5, p_.field_half_y - 0.5)};
    next_change_ = t + rng_.uniform(2.0, 6.0);
    has_target_ = true;
  }
  const Eigen::Vector2d to = target_ - pos;
  return go_to(*me, target_, p_.speed, std::atan2(to.y(), to.x()));
}

}  // namespace omniloc::sim
