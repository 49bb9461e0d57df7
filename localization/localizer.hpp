#pragma once
// The one interface every localizer implements. A localizer sees only robot-side data:
// line points / blobs from the vision front end (robot frame), odometry and an optional absolute
// heading. It never sees the simulator.
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/messages.hpp"
#include "core/pose2.hpp"

namespace omniloc {

/// What the vision front end extracted from one image.
struct Observations {
  double t = 0.0;        ///< seconds
  bool camera_ok = true; ///< false when the image was unusable (covered, black, missing)
  /// White line points in the robot frame, metres (x forward, y left).
  std::vector<Eigen::Vector2d> line_points;
};

/// A localizer's answer for one frame.
struct Estimate {
  Pose2 pose;                                      ///< world frame
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  ///< (x, y, theta), m^2 / rad^2
  bool valid = false;       ///< false until the localizer has a pose it stands behind
  std::string mode;         ///< e.g. "tracking", "global", "coasting" (written to frames.csv)
  double match_error = 0.0; ///< localizer-specific quality figure (lower is better)
  /// Extra numbers for frames.csv (e.g. "global_ms", "particles"), stable keys per localizer.
  std::map<std::string, double> extra;
};

class Localizer {
 public:
  virtual ~Localizer() = default;
  /// Registry name, e.g. "matching".
  virtual std::string type() const = 0;
  /// Starts over. `start` is given to tracking localizers; global ones get nullopt and must search.
  virtual void reset(const std::optional<Pose2>& start) = 0;
  /// One frame: odometry since the previous frame, observations of this frame, optional heading
  /// (world frame, radians) from compass / MTi.
  virtual Estimate update(const Observations& obs, const Odometry& odometry, std::optional<double> heading) = 0;
};

}  // namespace omniloc
