#include "localization/filter/pose_kalman.hpp"

#include <cmath>

#include <Eigen/Dense>

#include "core/angles.hpp"

namespace omniloc::filter {

void PoseKalman::predict(const Pose2& d, const OdometryNoiseParams& noise) {
  const double th = x_.theta, c = std::cos(th), s = std::sin(th);
  // d(x (+) d) / d(x, y, theta): the increment swings round with the heading.
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  F(0, 2) = -s * d.x - c * d.y;
  F(1, 2) = c * d.x - s * d.y;
  const OdometrySigmas sd = odometry_sigmas(d, noise);
  Eigen::Matrix3d Q = Eigen::Vector3d(sd.xy * sd.xy, sd.xy * sd.xy, sd.theta * sd.theta).asDiagonal();
  x_ = x_.compose(d);
  P_ = F * P_ * F.transpose() + Q;
}

void PoseKalman::update(const Pose2& z, const Eigen::Matrix3d& R) {
  const Eigen::Matrix3d S = P_ + R;
  const Eigen::Matrix3d K = P_ * S.inverse();
  const Eigen::Vector3d innov(z.x - x_.x, z.y - x_.y, angle_diff(z.theta, x_.theta));
  const Eigen::Vector3d dx = K * innov;
  x_ = Pose2(x_.x + dx.x(), x_.y + dx.y(), x_.theta + dx.z());
  P_ = (Eigen::Matrix3d::Identity() - K) * P_;
  P_ = 0.5 * (P_ + P_.transpose()).eval();
}

}  // namespace omniloc::filter
