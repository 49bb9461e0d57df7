#pragma once
// What every landmark solver takes and gives (frames and units: landmark_fix.hpp): the bearings
// seen, the fix, and the tolerances that call landmarks the same or collinear. Below both the
// shared checks (landmark_fix.hpp) and the inline closed-form parts (triple_fix.hpp).
#include <string>

#include <Eigen/Core>

#include "core/pose2.hpp"

namespace omniloc::landmarks {

/// One landmark seen by the robot.
struct BearingObs {
  Eigen::Vector2d landmark = Eigen::Vector2d::Zero();  ///< known landmark position, world frame, metres
  double bearing = 0.0;  ///< radians, robot frame, anticlockwise from the robot's x axis
};

/// Result of a landmark solver.
struct Fix {
  bool ok = false;
  Pose2 pose;  ///< world frame: x, y in metres, theta in radians (-pi, pi]; all zero when !ok
  /// Larger = better; 0 when !ok. All solvers use the same measure: the inverse of the position
  /// dilution of precision of the bearings at the solution, 1 / sqrt(trace of the (x, y) block of
  /// (J^T J)^-1), J the Jacobian of the bearings w.r.t. (x, y, theta). Unit: radians per metre, i.e.
  /// 1 / (metres of position error per radian of bearing noise). It goes to 0 on the singular set.
  double reliability = 0.0;
  std::string reason;  ///< why there is no fix; empty when ok
};

/// A refused fix (ok = false, zero pose, zero reliability).
Fix no_fix(std::string reason);

/// Two landmarks closer than this (metres) are taken to be the same landmark given twice.
inline constexpr double kSameLandmark = 1e-6;
/// Relative tolerance for the collinearity of landmarks and for the closed forms' denominators
/// (the robot on the circle through the three landmarks, or on the line through two of them).
inline constexpr double kSingularTol = 1e-9;

}  // namespace omniloc::landmarks
