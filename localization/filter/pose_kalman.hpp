#pragma once
// Extended Kalman filter on the planar pose (x, y in metres, theta in radians; world frame: origin at
// the centre spot, x towards the opponent goal, theta anticlockwise). Prediction composes the
// odometry increment (robot frame) onto the pose and adds the motion noise of odometry_noise.hpp;
// the update takes a full pose measurement (the matching optimiser's result, paper 002 / Lauer et
// al. 2005) with its covariance. Used by the matching tracker and through it by hybrid and
// grid_global.
#include <Eigen/Core>

#include "core/pose2.hpp"
#include "localization/filter/odometry_noise.hpp"

namespace omniloc::filter {

class PoseKalman {
 public:
  /// Sets the state and its covariance (rows/columns x, y, theta: m^2, m rad, rad^2).
  void reset(const Pose2& pose, const Eigen::Matrix3d& cov) {
    x_ = pose;
    P_ = cov;
  }
  /// x <- x (+) delta; P <- F P F^T + Q with F the Jacobian of the composition with respect to the
  /// pose and Q = diag(sigma_xy^2, sigma_xy^2, sigma_theta^2) from `noise` (the noise is added in
  /// the world frame, isotropic in x and y, so its rotation into the robot frame does not matter).
  void predict(const Pose2& delta, const OdometryNoiseParams& noise);
  /// Measurement z of the full pose with covariance R: K = P (P + R)^-1, x <- x + K (z - x) (the
  /// heading innovation wrapped to (-pi, pi]), P <- (I - K) P, symmetrised against round-off.
  void update(const Pose2& z, const Eigen::Matrix3d& R);
  const Pose2& pose() const { return x_; }
  const Eigen::Matrix3d& covariance() const { return P_; }

 private:
  Pose2 x_;
  Eigen::Matrix3d P_ = Eigen::Matrix3d::Identity();
};

}  // namespace omniloc::filter
