#pragma once
// Planar pose (x, y in metres, theta in radians) and frame transforms.
// World frame: origin at the centre spot, x towards the opponent goal, y left, theta anticlockwise.
// Robot frame: origin at the robot centre, x forward.
#include <Eigen/Core>

#include "core/angles.hpp"

namespace omniloc {

struct Pose2 {
  double x = 0.0;      ///< metres
  double y = 0.0;      ///< metres
  double theta = 0.0;  ///< radians, kept in (-pi, pi] by the helpers below

  Pose2() = default;
  Pose2(double x_, double y_, double theta_) : x(x_), y(y_), theta(wrap_angle(theta_)) {}

  Eigen::Vector2d translation() const { return {x, y}; }
  Eigen::Matrix2d rotation() const;

  /// Maps a point from this pose's local frame to the parent frame.
  Eigen::Vector2d transform(const Eigen::Vector2d& local) const;
  /// Maps a point from the parent frame into this pose's local frame.
  Eigen::Vector2d inverse_transform(const Eigen::Vector2d& parent) const;

  /// this * other: other is expressed in this pose's frame.
  Pose2 compose(const Pose2& other) const;
  Pose2 inverse() const;
  /// The motion `delta` such that this.compose(delta) == to (delta in this pose's frame).
  Pose2 between(const Pose2& to) const;
};

}  // namespace omniloc
