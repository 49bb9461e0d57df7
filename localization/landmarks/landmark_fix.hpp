#pragma once
// Landmark positioning from bearings: common types and checks shared by the solvers in
// localization/landmarks/.
//
// Frames and units (the project's, see core/pose2.hpp):
//  - world frame: metres; x, y as on the field; angles anticlockwise from the world x axis;
//  - robot frame: origin at the robot centre, x forward; a bearing is the direction to a landmark,
//    in radians, anticlockwise from the robot's x axis (any value; it is used modulo 2 pi).
// So a robot at pose (x, y, theta) sees landmark L at bearing atan2(L.y - y, L.x - x) - theta.
//
// Every solver returns a Fix and never a NaN: a case it cannot solve gives ok = false, a reason and
// an all-zero pose.
#include <span>
#include <string>

#include <Eigen/Core>

#include "core/pose2.hpp"
#include "localization/landmarks/fix.hpp"

namespace omniloc::landmarks {

/// Checks shared by all solvers: at least 3 observations, all numbers finite, no landmark given
/// twice (closer than kSameLandmark), not all landmarks on one line. Returns the reason, or "" when
/// the input is usable.
std::string check_input(std::span<const BearingObs> obs);

/// As check_input, and exactly three observations (the closed-form solvers).
std::string check_triple(std::span<const BearingObs> obs);

/// Heading of a robot at `position` given the bearings: the circular mean of
/// atan2(L_i - position) - bearing_i, each term weighted by the landmark's distance (far landmarks
/// are less sensitive to an error in the position). Returns false when undefined (the robot on a
/// landmark). `dirs` as in finish_fix (may be empty).
bool heading_from_bearings(std::span<const BearingObs> obs, std::span<const Eigen::Vector2d> dirs,
                           const Eigen::Vector2d& position, double& theta);

/// Reliability (see Fix::reliability) of the bearings at `position`; 0 when singular.
double bearing_reliability(std::span<const BearingObs> obs, const Eigen::Vector2d& position);

/// Completes a solver's position into a Fix: heading from the bearings (heading_from_bearings),
/// reliability, and the final checks (finite numbers; reliability * scale >= kSingularTol, else the
/// geometry is singular). `scale` is a length in metres (landmark_scale). `dirs`, if not empty, holds
/// (cos bearing_i, sin bearing_i) already computed by the caller.
Fix finish_fix(std::span<const BearingObs> obs, std::span<const Eigen::Vector2d> dirs, const Eigen::Vector2d& position,
               double scale);

/// Largest distance between two of the landmarks (metres): the scale for relative tolerances.
double landmark_scale(std::span<const BearingObs> obs);

}  // namespace omniloc::landmarks
