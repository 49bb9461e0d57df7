#pragma once
// Match-like behaviours for the other robots of a crowded field (issue: crowd). Seeded randomness
// from the Rng passed at construction, so the same seed gives the same match.
#include <string>

#include "core/field.hpp"
#include "core/rng.hpp"
#include "sim/motion.hpp"

namespace omniloc::sim {

struct BehaviourParams {
  std::string kind = "wander";  ///< "chase_ball", "mark", "hold", "wander"
  double speed = 2.0;           ///< m/s cruising speed
  int target_robot = -1;        ///< mark: the robot to mark
  Eigen::Vector2d home = Eigen::Vector2d::Zero();  ///< hold: the position to hold; wander: unused
  double radius = 1.0;          ///< hold: jitter radius (m); wander: unused
  int attack_side = 1;          ///< +1 attacks the goal at +x, -1 the goal at -x
  double field_half_x = 9.0, field_half_y = 6.0;  ///< wander/chase bounds (the lines), metres
};

class BehaviourScript : public MotionScript {
 public:
  BehaviourScript(const BehaviourParams& p, Rng rng) : p_(p), rng_(rng) {}
  std::string type() const override { return "behaviour"; }
  DriveCommand command(const WorldState& world, int self, double t) override;
  void on_teleport() override { has_target_ = false; }

 private:
  DriveCommand go_to(const RobotState& me, const Eigen::Vector2d& target, double speed, double face) const;
  BehaviourParams p_;
  Rng rng_;
  Eigen::Vector2d target_ = Eigen::Vector2d::Zero();
  bool has_target_ = false;
  double next_change_ = 0.0;
};

}  // namespace omniloc::sim
