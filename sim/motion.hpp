#pragma once
// Motion scripts: what moves a robot in a scenario. They drive the simulated body from the true
// world state (the papers push the robot by hand along carpet seams); localization never sees them.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/json_reader.hpp"
#include "core/rng.hpp"
#include "sim/world.hpp"
#include "sim/world_state.hpp"

namespace omniloc::sim {

class MotionScript {
 public:
  virtual ~MotionScript() = default;
  virtual std::string type() const = 0;
  /// The drive command for robot `self` at time t (seconds).
  virtual DriveCommand command(const WorldState& world, int self, double t) = 0;
  /// Called after the robot was teleported (scripts may re-plan).
  virtual void on_teleport() {}

  /// Builds a script from JSON {"type": ...}. `seed` seeds scripts with randomness (wander...);
  /// `field` bounds behaviours (defaults to the 18 x 12 MSL field when null).
  static std::unique_ptr<MotionScript> from_json(const Json& j, const std::string& path, std::uint64_t seed,
                                                 const Field* field = nullptr);
  static std::vector<std::string> types();
};

/// Stands still.
class StillScript : public MotionScript {
 public:
  std::string type() const override { return "still"; }
  DriveCommand command(const WorldState&, int, double) override { return {}; }
};

/// Constant velocity (world or robot frame) and turn rate.
class ConstantScript : public MotionScript {
 public:
  ConstantScript(Eigen::Vector2d velocity, double omega, bool robot_frame)
      : velocity_(velocity), omega_(omega), robot_frame_(robot_frame) {}
  std::string type() const override { return "constant"; }
  DriveCommand command(const WorldState& world, int self, double t) override;

 private:
  Eigen::Vector2d velocity_;
  double omega_;
  bool robot_frame_;
};

/// Follows waypoints at a given speed (the papers' "pushed along straight lines of the field").
class WaypointScript : public MotionScript {
 public:
  enum class Heading { Keep, Face, Spin };
  WaypointScript(std::vector<Eigen::Vector2d> points, double speed, bool loop, Heading heading, double spin_rate,
                 double tolerance);
  std::string type() const override { return "waypoints"; }
  DriveCommand command(const WorldState& world, int self, double t) override;
  void on_teleport() override;

 private:
  std::vector<Eigen::Vector2d> points_;
  double speed_;
  bool loop_;
  Heading heading_;
  double spin_rate_;
  double tolerance_;
  std::size_t next_ = 0;
};

/// Match-like behaviours for the other robots of a crowded field (sim/behaviour.cpp). Seeded
/// randomness from the Rng passed at construction, so the same seed gives the same match.
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
