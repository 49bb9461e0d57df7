#pragma once
// Cooperative ball localisation in Hough space (paper 001: Xu, Xie, Wang, Ni, "Target localization
// algorithm for cooperative multi-soccer robots based on Hough space", J. Image and Graphics 2012,
// section 4, eqs. (8)-(11)).
//
// Every robot that sees the ball contributes the line from its own (self-localised) position to its
// own estimate of the ball. Line i is written in normal form rho_i = x cos(theta_i) + y sin(theta_i)
// (a point (theta_i, rho_i) of Hough space). The ball (X, Y) minimises
//     J = sum_i K_i (rho_i - X cos(theta_i) - Y sin(theta_i))^2,
// i.e. the weighted sum of squared perpendicular distances from (X, Y) to the lines, with K_i = 1
// (paper eq. (9)) or K_i = 1 / L_i, L_i the robot-ball distance (eq. (10)-(11)).
//
// All coordinates are in the world frame, metres; stamps in seconds. Pure algorithm: no randomness,
// no I/O, no simulator access.
#include <string>
#include <vector>

#include <Eigen/Core>

namespace omniloc {

/// One robot's sighting of the ball, already converted to the world frame.
struct BallLine {
  Eigen::Vector2d robot = Eigen::Vector2d::Zero();          ///< world, metres: the robot's self-localised position
  Eigen::Vector2d ball_estimate = Eigen::Vector2d::Zero();  ///< world, metres: robot pose + its bearing/distance to the ball
  double stamp = 0.0;                                        ///< seconds, time of the image
};

enum class BallWeighting {
  Equal,            ///< K_i = 1 (paper eq. (9))
  InverseDistance,  ///< K_i = 1 / max(L_i, min_distance) (paper eq. (10))
};

struct HoughBallConfig {
  BallWeighting weighting = BallWeighting::InverseDistance;
  /// Metres. L_i below this is clamped to it before K_i = 1 / L_i, so a ball touching the robot gets
  /// the finite weight 1 / 0.05 = 20 per metre instead of an infinite one.
  double min_distance = 0.05;
  /// Below this robot-ball distance (metres) the line's direction is undefined; the sighting then
  /// constrains the ball to the point itself (two perpendicular lines through ball_estimate, each
  /// with weight 1 / min_distance under InverseDistance).
  double direction_epsilon = 1e-9;
  /// Reciprocal condition number lambda_min / lambda_max of the 2x2 normal matrix below which the
  /// lines are treated as parallel (robots collinear with the ball). For two equally weighted lines
  /// at angle delta the ratio is tan^2(delta / 2): 1e-4 rejects lines within about 1.15 degrees.
  double min_reciprocal_condition = 1e-4;
  /// Seconds. Sightings older than the newest stamp by more than this are ignored (network
  /// latency, paper 001 shares them over ZigBee). Infinity keeps all.
  double max_age = 1e300;
};

/// A sighting as a Hough-space point with its weight (exposed for tests and diagnostics).
struct HoughLine {
  double theta = 0.0;     ///< rad, direction of the line's unit normal (world frame)
  double rho = 0.0;       ///< metres, signed distance of the line from the world origin
  double distance = 0.0;  ///< metres, L_i = |ball_estimate - robot| (unclamped)
  double weight = 1.0;    ///< K_i, 1/metres under InverseDistance, 1 under Equal
  bool point_constraint = false;  ///< L_i < direction_epsilon: direction undefined, used as a point
};

/// The Hough representation of one sighting under `cfg` (no validity checks on the input).
HoughLine hough_line(const BallLine& line, const HoughBallConfig& cfg = {});

struct BallFix {
  enum class Status {
    Ok,             ///< least-squares intersection of >= 2 usable lines
    SingleRobot,    ///< exactly one usable sighting: its own bearing + distance estimate
    NoObservation,  ///< no usable sighting (position is (0, 0) and must not be used)
    Degenerate,     ///< lines (nearly) parallel: position is the weighted mean of the estimates
  };
  Status status = Status::NoObservation;
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< world, metres; always finite
  int used = 0;        ///< sightings that entered the estimate
  std::string reason;  ///< human-readable explanation (empty only for a plain Ok)
};

const char* to_string(BallFix::Status s);

/// Cooperative ball fix from all robots' sightings. Non-finite sightings and stale ones (see
/// max_age) are skipped and counted in `reason`. Never returns a NaN position.
BallFix hough_ball_fix(const std::vector<BallLine>& lines, const HoughBallConfig& cfg = {});

}  // namespace omniloc
